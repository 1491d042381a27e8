"""Sphinx configuration of the ehm documentation.

Build: ``python -m sphinx -W --keep-going -b html docs docs/_build/html`` (needs ``pip install -e ".[docs]"``).
Add ``-D plot_gallery=0`` for a quick build that does not run the examples.
"""

import os
import sys
from pathlib import Path

import ehm

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE / "_ext"))
import param_table  # noqa: E402
import sickness_figures  # noqa: E402
import validation_table  # noqa: E402

os.environ.setdefault("MPLBACKEND", "Agg")

# The model page's parameter table, generated from the file ehm ships (never copied by hand).
param_table.write(HERE.parent / "src" / "ehm" / "data" / "default_params.toml", HERE / "_generated")
# The validation page's table and grid of every posture and back support, computed by this version of ehm.
validation_table.write(HERE / "_generated")
# The motion-sickness page's figures, drawn from the model as it is (again only when it changed).
sickness_figures.write(HERE / "_generated", HERE.parent / "src" / "ehm")

project = "ehm"
author = "the ehm authors"
copyright = "the ehm authors, MIT licence"
release = version = ehm.__version__

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
    "numpydoc",
    "myst_parser",
    "sphinx_gallery.gen_gallery",
    "sphinx_copybutton",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
exclude_patterns = ["_build", "_generated", "_ext", "auto_examples/*.ipynb", "auto_examples/*.py",
                    "auto_examples/*.zip", "auto_examples/*.md5"]
templates_path = ["_templates"]

# API pages: one per public name, at ehm.NAME; numpydoc sections carry the types.
autosummary_generate = True
autodoc_typehints = "none"
autodoc_member_order = "bysource"
numpydoc_show_class_members = False
numpydoc_validation_checks = set()

myst_enable_extensions = ["colon_fence", "dollarmath"]
myst_heading_anchors = 3

# Every cross-reference must resolve (-W turns a broken one into an error).
nitpicky = True
# No intersphinx: the CI machine reaches package registries only, so references into the libraries ehm
# builds on (numpy.random.default_rng, scipy.signal.chirp, warnings.warn, pythonfmu.Fmi2Slave, ...) have no
# inventory to resolve against.  They stay written as references, for the day intersphinx is possible, and
# are let through here; only these packages, so that a broken reference to ehm itself still fails the build.
nitpick_ignore_regex = [
    (r"py:.*", r"(numpy|scipy|warnings|pint|pandas|pythonfmu)(\..*)?"),
]

sphinx_gallery_conf = {
    "examples_dirs": ["../examples"],
    "gallery_dirs": ["auto_examples"],
    "filename_pattern": r"/plot_",
    "doc_module": ("ehm",),
    "backreferences_dir": "api/generated/backreferences",
    "remove_config_comments": True,
    "abort_on_example_error": True,
    "download_all_examples": False,
}

html_theme = "pydata_sphinx_theme"
html_title = f"ehm {release}"
html_theme_options = {"navigation_with_keys": False, "show_toc_level": 2}
html_show_sourcelink = False
