"""Every public name of ``ehm.__all__`` has its place in the API reference (docs/api/*.rst or *.md).

No Sphinx needed: the check reads the autosummary lists as text, so a name added to ``__all__`` without a
line in the reference fails here, before the documentation is ever built.
"""

import re
from pathlib import Path

import ehm

API_DIR = Path(__file__).resolve().parents[1] / "docs" / "api"


def _listed_names() -> set[str]:
    names = set()
    for page in sorted(API_DIR.glob("*.rst")) + sorted(API_DIR.glob("*.md")):
        for line in page.read_text(encoding="utf-8").splitlines():
            # autosummary entries are indented bare names (optionally spelt ehm.NAME)
            m = re.fullmatch(r"\s+(?:ehm\.)?([A-Za-z_][A-Za-z0-9_]*)\s*", line)
            if m:
                names.add(m.group(1))
    return names


def test_api_reference_lists_every_public_name():
    assert API_DIR.is_dir(), f"{API_DIR} is missing"
    public = {name for name in ehm.__all__ if name != "__version__"}
    missing = sorted(public - _listed_names())
    assert not missing, f"public names missing from docs/api/: {', '.join(missing)}"


def test_api_reference_lists_only_public_names():
    listed = _listed_names()
    stray = sorted(name for name in listed if name not in ehm.__all__)
    assert not stray, f"docs/api/ lists names that ehm does not export: {', '.join(stray)}"
