"""``python -m ehm.interfaces.cli``: the ``ehm`` command."""

import sys

from . import main

sys.exit(main())
