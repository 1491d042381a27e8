"""``python -m ehm.cli``: the ``ehm`` command."""

import sys

from . import main

sys.exit(main())
