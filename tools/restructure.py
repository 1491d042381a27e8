#!/usr/bin/env python
"""Floors as folders: move ehm's modules into folders named after their layers, rewrite every import and every
reference to a moved module, and keep the old import paths working for one release.

Run from the root of a worktree (a checkout of ehm)::

    python tools/restructure.py           # apply: git mv, rewrite, write the compat table and the contracts
    python tools/restructure.py --check   # say what would be done, change nothing (exit 1 if anything would)

The script is data driven (``MOVES``, ``FOLDERS``, ``FOLDER_FLOORS`` below) and idempotent: a module whose old
file is gone and whose new file exists counts as moved; a module that exists in neither place is skipped (a tree
where another change already put it elsewhere).  Run twice, the second run changes nothing.

What it does, in order:

1. ``git mv`` every module and package of ``MOVES`` whose old file still exists to its new place, creating the
   folders (each with a one-paragraph ``__init__.py`` docstring, written only when the folder has none).
2. Rewrites imports in every ``.py`` file under ``src/ehm`` (moved or not), ``tests/``, ``benchmarks/``,
   ``examples/``, ``tools/`` and ``docs/``.  The rule: **an import keeps its form**.  A relative import inside
   ``src/ehm`` is resolved against the file's OLD location, mapped, and written again relative to the file's NEW
   location; an absolute import (``from ehm.x import``, ``import ehm.x``) stays absolute, with the new dotted
   name.  ``from . import io``-style imports of a module by name follow the module (``as`` keeps the local
   name when the module was renamed).
3. Rewrites dotted names ``ehm.x.y`` wherever they appear as text: strings (``monkeypatch.setattr("ehm.x.N")``,
   ``importlib.import_module``, ``mock.patch``), attribute chains after ``import ehm.x``, docstrings, the
   documentation (``automodule``/``autosummary`` targets, roles, prose; reST title underlines are re-measured),
   ``README.md``, ``CONTRIBUTING.md``, ``pyproject.toml`` (entry points, import-linter contracts), and file
   paths ``src/ehm/x.py`` / ``src/ehm/x/``.  ``CHANGELOG.md`` is history and is left alone.
4. Writes ``src/ehm/_compat.py`` (the table old -> new and a ``sys.meta_path`` finder that aliases an old name
   to the SAME module object, with a ``DeprecationWarning`` naming the new path) and installs it from
   ``ehm/__init__.py``.
5. Writes the import-linter contracts in ``pyproject.toml``: the ``layers`` contract over the folders (bottom to
   top, exhaustive, no ``ignore_imports``) and one ``layers`` contract per folder (``layers-<folder>``), unless
   the folder already has a contract of its own (a contract whose ``containers`` names it).

Anything the data does not place (a new top-level module, a module of a folder without a floor) stops the run
with a message saying what to add, before anything is changed.
"""

from __future__ import annotations

import argparse
import ast
import re
import shutil
import subprocess
import sys
from pathlib import Path

# ----------------------------------------------------------------------------------------------------------------
# The data.  Old dotted name -> new dotted name; a package moves with everything in it.
MOVES: dict[str, str] = {
    # the ground: atomic files (renamed: ``io`` is the standard library's name)
    "ehm.io": "ehm.files",
    # body: who sits, as data (below the engine, which builds from it)
    "ehm.tables": "ehm.body.tables",
    "ehm.posture": "ehm.body.posture",
    "ehm.seat": "ehm.body.supports",          # back supports and where their pads sit (engine.seat is the seat)
    "ehm.params": "ehm.body.params",
    "ehm.timestep": "ehm.body.timestep",
    # standards: reference curves, transfer functions, ISO 2631, motion sickness (numerical leaves)
    "ehm.references": "ehm.standards.references",
    "ehm.transfer": "ehm.standards.transfer",
    "ehm.comfort": "ehm.standards.comfort",
    "ehm.sickness": "ehm.standards.sickness",
    # engine: MuJoCo (stays); its seat module renamed after what it holds
    "ehm.engine.seat": "ehm.engine.seat_geometry",
    # inputs: seat motions, drives, IMU logs, outside data
    "ehm.resampling": "ehm.inputs.resampling",
    "ehm.kinematics": "ehm.inputs.kinematics",
    "ehm.attitude": "ehm.inputs.attitude",
    "ehm.motion": "ehm.inputs.motion",
    "ehm.imu": "ehm.inputs.imu",
    "ehm.drives": "ehm.inputs.drives",
    "ehm.readers": "ehm.inputs.readers",
    # person: the person as a value and its body size (above the engine: scaling solves with it)
    "ehm.scaling": "ehm.person.scaling",
    # outputs: what a run gives and how it is written, tabled and drawn
    "ehm.dataframes": "ehm.outputs.dataframes",
    "ehm.outdir": "ehm.outputs.outdir",
    "ehm.runfiles": "ehm.outputs.runfiles",
    "ehm.results": "ehm.outputs.results",
    "ehm.plotting": "ehm.outputs.plotting",
    "ehm.animation": "ehm.outputs.animation",
    "ehm.report": "ehm.outputs.report",
    # routes (the package is written by hand; these map today's modules for the imports and the compat table)
    "ehm.linear": "ehm.routes.linear",
    "ehm.linear_poses": "ehm.routes.poses",
    "ehm.hybrid": "ehm.routes.hybrid",
    "ehm.segments": "ehm.routes.parallel",
    # analysis: what is computed from runs of a person
    "ehm.frf": "ehm.analysis.frf",
    "ehm.criterion": "ehm.analysis.criterion",
    "ehm.convergence": "ehm.analysis.convergence",
    "ehm.stepping": "ehm.analysis.stepping",
    "ehm.study": "ehm.analysis.study",
    "ehm.assessment": "ehm.analysis.assessment",
    "ehm.validation": "ehm.analysis.validation",
    "ehm.fit": "ehm.analysis.fit",
    # interfaces: to people and other tools
    "ehm.cluster": "ehm.interfaces.cluster",
    "ehm.fmu_native": "ehm.interfaces.fmu_native",
    "ehm.fmu": "ehm.interfaces.fmu",
    "ehm.batch": "ehm.interfaces.batch",
    "ehm.cli": "ehm.interfaces.cli",
}

# The floors of ``ehm`` itself, top to bottom: folders and the few modules left at the top.  ``a | b``: one floor,
# neither imports the other.  The top-level contract is exhaustive: every child of ``ehm`` is named here.
# A floor's text after "#" is its comment in pyproject.toml (here and in FOLDERS).
FOLDER_FLOORS: list[str] = [
    "interfaces         # the ehm command, batch studies on Dask, the Python and the native FMU",
    "analysis           # FRF tables, comfort and sickness of a drive, the step check, studies, validation, fit",
    "simulation         # SeatedHuman: the one door to the routes",
    "routes             # how a person is run through a drive: nonlinear, linear, hybrid, in parallel segments",
    "outputs            # results, a run's files, output folders, DataFrames, figures, pictures, reports",
    "person             # the person as one value; individual body sizes",
    "engine | inputs    # MuJoCo (the model, its runs, linearisation); seat motions, drives, IMU logs, outside data",
    "body | standards   # parameters, body tables, postures, back supports, the time step; ISO 2631, references",
    "files | processes  # atomic files and manifests; worker processes",
    "errors | _compat   # EhmError and its kinds, EhmWarning; the old import paths (one release)",
]

# Each folder: its ``__init__`` docstring (written when the folder has no ``__init__.py``; plain literals, no
# cross-reference roles: the API reference shows these docstrings and checks every reference) and its modules' floors,
# top to bottom (today's floors), for a ``layers`` contract named ``layers-<folder>``.  ``floors=None``: no
# contract generated (the folder keeps or gets its own).
FOLDERS: dict[str, dict] = {
    "body": {
        "doc": """The person as data: parameter files (``params``), the body tables (``tables``), named
postures (``posture``), the back supports and where their pads sit (``supports``), and the time step's
known error and range (``timestep``).  Nothing here builds or runs a model; these modules import only
``ehm.errors`` and ``ehm.files``, and the engine is built from them.""",
        "floors": ["params              # parameter files: load, check, change, export",
                   "posture | supports  # named postures; back supports and where their pads sit",
                   "tables | timestep   # body tables; the time step's known error and range"],
    },
    "standards": {
        "doc": """Numerical leaves after published standards and models: reference curves, bands and findings
with their sources (``references``), transfer-function estimates (``transfer``), ISO 2631-1 weightings and
values and the ISO 2631-5 spinal dose (``comfort``), and the motion sickness model (``sickness``).  Pure
array functions: they import only ``ehm.errors``, never the model.""",
        "floors": ["comfort | sickness | transfer  # ISO 2631-1 and -5; motion sickness; transfer functions",
                   "references                     # reference curves, bands and findings with their sources"],
    },
    "inputs": {
        "doc": """What moves the seat: seat motions and the generated ones (``motion``), anti-aliased
resampling (``resampling``), seat rotation kinematics (``kinematics``), the IMU attitude filter
(``attitude``), IMU logs to seat motion (``imu``), synthetic drives (``drives``) and outside data in
(``readers``, one module per format).  They import the ground (``ehm.errors``, ``ehm.files``) and
``ehm.standards``, never the model, a route or an output.""",
        "floors": ["readers                             # outside data in, one module per format",
                   ("imu | drives | handling             # IMU logs to seat motion; SYNTHETIC drives; handled loggers "
                    "found"),
                   "motion                              # SeatMotion and the generated motions",
                   "resampling | kinematics | attitude  # anti-aliased resampling; seat rotation; the IMU filter",
                   ("vocabulary                          # which words a message's fix uses (the command line's or "
                    "Python's)")],
    },
    "person": {
        "doc": """The person: individual body sizes (``scaling``) and the person as one value.  Above the
engine (a body size is solved with the model's inertia) and ``ehm.body``; below the routes, which take the
person as data.""",
        "floors": ["(person)  # the person as one value",
                   "scaling   # individual body sizes"],
    },
    "outputs": {
        "doc": """What a run gives and where it goes: run results (``results``), a run's files written chunk by
chunk (``runfiles``), output folders put in place (``outdir``), DataFrames and Datasets out
(``dataframes``), figures (``plotting``), pictures and animations (``animation``) and reports
(``report``).  They take data and import the engine, ``ehm.standards`` and the ground, never a route,
the door (``ehm.simulation``) or an analysis.""",
        "floors": ["plotting | animation | report  # figures; pictures and animations; the HTML report",
                   "results                        # RunResult, PointMotion, concatenate_runs",
                   "runfiles | outdir              # a run's files chunk by chunk; output folders put in place",
                   "dataframes                     # results out as DataFrames, Datasets, notebook tables"],
    },
    "routes": {
        "doc": """The routes: how a person is run through a drive (linear, hybrid, nonlinear, in parallel
segments).  They take the person and the drive as data, import the engine, the inputs and the outputs, and never
the door (``ehm.simulation``) that calls them.""",
        "floors": ["(parallel)  # a long nonlinear run in segments on several cores",
                   "(hybrid)    # the checked linear route and the hybrid route",
                   "(poses)     # the linear route's poses for pictures",
                   "(linear)    # the linear route"],
        "own_contract": True,   # the routes package states its own floors; this one only if it has none
    },
    "analysis": {
        "doc": """What is computed from runs of a person: transfer-function tables (``frf``), the paper's
criterion (``criterion``), the time step's check (``convergence``), step-by-step simulation
(``stepping``), the locking study (``study``), comfort and sickness of a drive (``assessment``),
validation against the references (``validation``) and parameter identification (``fit``).  They stand
on the door (``ehm.simulation``) and everything below it; only ``ehm.interfaces`` imports them.""",
        "floors": ["fit                                                      # parameter identification",
                   "validation                                               # the person against the references",
                   "assessment | convergence | criterion | stepping | study  # analyses of a person",
                   "frf                                                      # transfer-function tables"],
    },
    "interfaces": {
        "doc": """ehm to people and other tools: the ``ehm`` command (``cli``), batch studies on Dask
(``batch``, ``cluster``), the Python FMU (``fmu``) and the native one (``fmu_native``).  The
top floor: they may import everything below, and nothing of ehm imports them.""",
        "floors": ["cli                   # the ehm command",
                   "batch | fmu           # Dask batch studies; the Python FMU",
                   "fmu_native | cluster  # the native FMU; the Dask clusters of batch studies"],
    },
}

# Text that names a moved module without the ``ehm.`` prefix (relative roles in docstrings): path, old, new.
TEXT_FIXES: list[tuple[str, str, str]] = [
    ("src/ehm/engine/__init__.py", ":mod:`.seat`", ":mod:`.seat_geometry`"),
]

# Where text is rewritten; files never rewritten (history, this script, the compat table and its test).
PY_ROOTS = ["src/ehm", "tests", "benchmarks", "examples", "tools", "scripts", "docs"]
TEXT_GLOBS = ["*.py", "docs/**/*.md", "docs/**/*.rst", "docs/**/*.txt", "src/ehm/native/*.c", "README.md",
              "CONTRIBUTING.md", "pyproject.toml", "*.cfg", "*.ini", ".ci/*", ".pre-commit-config.yaml",
              ".github/**/*.yml"]
SKIP = {"CHANGELOG.md", "docs/changelog.md", "tools/restructure.py", "src/ehm/_compat.py", "tests/test_compat.py"}
SKIP_DIRS = {"_build", "__pycache__", ".git", "auto_examples", "generated"}

SRC = Path("src")
PKG = SRC / "ehm"


# ----------------------------------------------------------------------------------------------------------------
def new_name(dotted: str) -> str:
    """``dotted`` after the moves: its longest prefix in ``MOVES`` replaced."""
    parts = dotted.split(".")
    for i in range(len(parts), 1, -1):
        head = ".".join(parts[:i])
        if head in MOVES:
            return ".".join([MOVES[head], *parts[i:]])
    return dotted


def module_file(dotted: str, root: Path = SRC) -> Path | None:
    """The file or package folder of ``dotted`` under ``root``, if it exists."""
    base = root.joinpath(*dotted.split("."))
    if (base / "__init__.py").is_file():
        return base
    if base.with_suffix(".py").is_file():
        return base.with_suffix(".py")
    return None


def dotted_of(path: Path) -> str:
    """The dotted module name of a ``.py`` file under ``src``."""
    parts = list(path.relative_to(SRC).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


def tracked(path: Path) -> bool:
    return subprocess.run(["git", "ls-files", "--error-unmatch", str(path)], capture_output=True).returncode == 0


# ----------------------------------------------------------------------------------------------------------------
# 1. the plan of moves
def plan_moves() -> tuple[list[tuple[str, Path, Path]], list[str]]:
    """(old name, old path, new path) for each move still to do, and notes on those skipped."""
    moves, notes = [], []
    for old, new in MOVES.items():
        src, dst = module_file(old), module_file(new)
        if src is not None and dst is not None:
            raise SystemExit(f"restructure: both {src} and {dst} exist; merge them by hand, then run again")
        if src is None and dst is None:
            notes.append(f"{old}: neither {old} nor {new} exists here; skipped (the compat table keeps it only if "
                         f"{new} exists)")
            continue
        if src is None:
            continue  # already moved
        target = SRC.joinpath(*new.split("."))
        if src.suffix == ".py":
            target = target.with_suffix(".py")
        moves.append((old, src, target))
    return moves, notes


def relocation(moves) -> dict[Path, tuple[Path, str]]:
    """Every ``.py`` file under ``src/ehm`` now -> (its path after the moves, the dotted name of its OLD module:
    the name its relative imports were written against).  Files not moved keep their place and name."""
    out: dict[Path, tuple[Path, str]] = {}
    moved_dirs = {src: dst for _, src, dst in moves if src.is_dir()}
    moved_files = {src: dst for _, src, dst in moves if src.suffix == ".py"}
    for path in sorted(PKG.rglob("*.py")):
        if SKIP_DIRS & set(path.parts):
            continue
        new_path = moved_files.get(path)
        if new_path is None:
            for d, nd in moved_dirs.items():
                if d in path.parents:
                    new_path = nd / path.relative_to(d)
                    break
        out[path] = (new_path or path, dotted_of(path))
    return out


def modules_of(folder: str, after: set[Path]) -> set[str]:
    """The modules and packages directly in ``ehm.<folder>`` after the moves."""
    base = PKG / folder
    return {p.relative_to(base).parts[0].removesuffix(".py") for p in after
            if base in p.parents and p != base / "__init__.py"}


def check_placed(moves) -> list[str]:
    """What the data does not place: top-level children of ehm outside ``FOLDER_FLOORS``, modules of a folder
    without a floor.  Judged on the tree as it will be after the moves."""
    after = {new for new, _ in relocation(moves).values()}
    children = {p.relative_to(PKG).parts[0].removesuffix(".py") for p in after if p != PKG / "__init__.py"}
    named = {t.strip("() ") for floor in FOLDER_FLOORS for t in re.split(r"[|:]", _floor(floor))}
    problems = [f"ehm.{c} has no floor in FOLDER_FLOORS" for c in sorted(children - named)]
    for folder, spec in FOLDERS.items():
        if spec.get("floors") is None or spec.get("own_contract"):
            continue
        floors = {t.strip("() ") for floor in spec["floors"] for t in re.split(r"[|:]", _floor(floor))}
        problems += [f"ehm.{folder}.{m} has no floor in FOLDERS[{folder!r}]"
                     for m in sorted(modules_of(folder, after) - floors)]
    return problems


# ----------------------------------------------------------------------------------------------------------------
# 2. imports
def _package_of(old_module: str, is_init: bool) -> str:
    return old_module if is_init else old_module.rpartition(".")[0]


def _relative(from_package: str, target: str) -> str:
    """``target`` written relative to ``from_package`` (``..engine``, ``.``, ``...``)."""
    a, b = from_package.split("."), target.split(".")
    common = 0
    while common < min(len(a), len(b)) and a[common] == b[common]:
        common += 1
    return "." * (len(a) - common + 1) + ".".join(b[common:])


def _is_module(dotted: str, known: set[str]) -> bool:
    return dotted in known or any(dotted == k or dotted.startswith(k + ".") for k in MOVES)


def rewrite_imports(text: str, old_module: str | None, new_module: str | None, is_init: bool,
                    known: set[str]) -> str:
    """The ``from ... import`` statements of a Python file rewritten (relative ones against the file's old place
    and re-emitted against its new place; absolute ones stay absolute)."""
    try:
        tree = ast.parse(text)
    except SyntaxError:
        return text
    lines = text.splitlines(keepends=True)
    offsets = [0]
    for line in lines:
        offsets.append(offsets[-1] + len(line))

    def pos(lineno, col):  # col is in UTF-8 bytes
        line = lines[lineno - 1]
        return offsets[lineno - 1] + len(line.encode("utf-8")[:col].decode("utf-8", errors="ignore"))

    edits = []
    for node in ast.walk(tree):
        if not isinstance(node, ast.ImportFrom):
            continue
        if node.level:
            if old_module is None:
                continue
            pkg = _package_of(old_module, is_init).split(".")
            base_parts = pkg[:len(pkg) - node.level + 1]
            base = ".".join(base_parts + ([node.module] if node.module else []))
        else:
            base = node.module or ""
        if base != "ehm" and not base.startswith("ehm."):
            continue
        groups: dict[str, list[str]] = {}
        for alias in node.names:
            full = f"{base}.{alias.name}"
            if alias.name != "*" and _is_module(full, known) and new_name(full) != full:
                target, _, name = new_name(full).rpartition(".")
            else:
                target, name = new_name(base), alias.name
            local = alias.asname or (alias.name if name != alias.name else None)
            groups.setdefault(target, []).append(name if local in (None, name) else f"{name} as {local}")

        def emit(target: str, node=node) -> str:
            if node.level and new_module is not None:
                return _relative(_package_of(new_module, is_init), target)
            return target

        start, end = pos(node.lineno, node.col_offset), pos(node.end_lineno, node.end_col_offset)
        segment = text[start:end]
        if len(groups) == 1:
            (target, names), = groups.items()
            same_names = names == [a.name if a.asname is None else f"{a.name} as {a.asname}" for a in node.names]
            m = re.match(r"from\s+([.\w]+)\s+import", segment)
            if same_names and m:
                new_mod = emit(target)
                if new_mod != m.group(1):
                    edits.append((start + m.start(1), start + m.end(1), new_mod))
                continue
        indent = " " * node.col_offset
        statements = [f"from {emit(t)} import {', '.join(ns)}" for t, ns in groups.items()]
        edits.append((start, end, ("\n" + indent).join(statements)))
    for a, b, new in sorted(edits, reverse=True):
        text = text[:a] + new + text[b:]
    return text


# ----------------------------------------------------------------------------------------------------------------
# 3. dotted names and paths as text
_DOTTED = re.compile(r"(?<![\w.\\])ehm((?:\\?\.[A-Za-z_]\w*)+)")  # ehm.x.y, or ehm\.x\.y in a regular expression
_PATH = re.compile(r"(?<![\w/])((?:src/)?ehm/)((?:\w+/)*\w+)(\.py\b|/)")


def _sub_aligned(pattern: re.Pattern, repl, text: str) -> str:
    """``pattern.sub(repl, text)``, keeping columns: a replacement followed by a run of two or more spaces takes
    its growth out of that run (down to two spaces), so tables in docstrings and READMEs stay aligned."""
    out, last = [], 0
    for m in pattern.finditer(text):
        if m.start() < last:
            continue
        new = repl(m)
        out.append(text[last:m.start()] + new)
        last = m.end()
        run = re.match(r" {2,}", text[last:])
        if run and new != m.group(0):
            out.append(" " * max(2, len(run.group(0)) - (len(new) - len(m.group(0)))))
            last += len(run.group(0))
    out.append(text[last:])
    return "".join(out)


def rewrite_text(text: str) -> str:
    def dotted(m):
        if m.group(0) == "ehm.fmu" and text[m.end():m.end() + 1] in "\"'":
            return m.group(0)  # a file name ("ehm.fmu", the unit written by export-fmu), not the module
        escaped = m.group(1).startswith("\\")
        parts = re.split(r"\\?\.", m.group(1))[1:]
        for i in range(len(parts), 0, -1):
            head = "ehm." + ".".join(parts[:i])
            if head in MOVES:
                new = ".".join([MOVES[head], *parts[i:]])
                return new.replace(".", "\\.") if escaped else new
        return m.group(0)

    def path(m):
        mod = "ehm." + m.group(2).replace("/", ".")
        moved = new_name(mod)
        if moved == mod:
            return m.group(0)
        return m.group(1) + "/".join(moved.split(".")[1:]) + m.group(3)

    return _sub_aligned(_PATH, path, _sub_aligned(_DOTTED, dotted, text))


def fix_underlines(old: str, new: str) -> str:
    """reST titles whose text changed length get their underline re-measured."""
    old_lines, new_lines = old.splitlines(keepends=True), new.splitlines(keepends=True)
    if len(old_lines) != len(new_lines):
        return new
    for i in range(len(new_lines) - 1):
        title, under = new_lines[i].rstrip("\n"), new_lines[i + 1].rstrip("\n")
        if (title != old_lines[i].rstrip("\n") and re.fullmatch(r"([=\-~^\"'`#*+])\1{2,}", under)
                and len(under) == len(old_lines[i].rstrip("\n"))):
            new_lines[i + 1] = under[0] * len(title) + "\n"
    return "".join(new_lines)


LINE_LENGTH = 120


def _docstring_lines(text: str) -> set[int]:
    """Line numbers (1-based) inside triple-quoted strings, their first line included."""
    import io
    import tokenize

    inside = set()
    try:
        for tok in tokenize.generate_tokens(io.StringIO(text).readline):
            if tok.type == tokenize.STRING and tok.string.lstrip("rRbBuUfF").startswith(('"""', "'''")):
                inside.update(range(tok.start[0], tok.end[0] + 1))
    except (tokenize.TokenError, SyntaxError, IndentationError):
        pass
    return inside


def wrap_long_lines(old: str, new: str) -> tuple[str, list[int]]:
    """Lines the rewrite made longer than ``LINE_LENGTH`` wrapped where that is safe: an import (parenthesised), a
    comment, prose in a docstring (broken at a space, the rest on a new line with the same indent).  Returns the
    text and the numbers of the long lines left (code, tables: for a person to wrap)."""
    long_before = {line for line in old.splitlines() if len(line) > LINE_LENGTH}
    prose = _docstring_lines(new)
    out, left = [], []
    for number, line in enumerate(new.splitlines(keepends=True), 1):
        final = sum(piece.count("\n") for piece in out) + 1  # its number in the text returned
        body = line.rstrip("\n")
        if len(body) <= LINE_LENGTH or body in long_before:
            out.append(line)
            continue
        indent = body[:len(body) - len(body.lstrip())]
        m = re.fullmatch(r"(\s*from\s+[.\w]+\s+import\s+)([\w ,]+)", body)
        if m and number not in prose:
            names = [n.strip() for n in m.group(2).split(",")]
            head = m.group(1) + "("
            lines, current = [], head
            for i, n in enumerate(names):
                piece = n + ("," if i < len(names) - 1 else ")")
                if len(current) + len(piece) + 1 > LINE_LENGTH and current.strip() not in ("", head.strip()):
                    lines.append(current.rstrip())
                    current = " " * len(head)
                current += piece + " "
            lines.append(current.rstrip())
            out.append("\n".join(lines) + "\n")
            continue
        stripped = body.lstrip()
        comment = re.match(r"#:? ", stripped)
        table = re.search(r"={3,} +={3,}|^\s*[|+]", body)
        if (comment or number in prose) and not table:
            cut = body.rfind(" ", len(indent) + 1, LINE_LENGTH + 1)
            first, rest = body[:cut].rstrip(), body[cut + 1:].strip()
            quotes = rest.count('"""') + rest.count("'''")
            if (cut > len(indent) + 10 and rest and not first.endswith(("::", ":"))
                    and (quotes == 0 or quotes == 1 and rest.endswith(('"""', "'''")))):
                lead = indent + (comment.group(0) if comment else "")
                if not comment and re.match(r"[*-] ", stripped):
                    lead += "  "
                out.append(first + "\n" + lead + rest + "\n")
                continue
        out.append(line)
        left.append(final)
    return "".join(out), left


def text_files() -> list[Path]:
    out = set()
    for root in PY_ROOTS:
        if Path(root).is_dir():
            out |= {p for p in Path(root).rglob("*.py")}
    for pattern in TEXT_GLOBS:
        out |= {p for p in Path().glob(pattern) if p.is_file()}
    listed = subprocess.run(["git", "ls-files", "--cached", "--others", "--exclude-standard"], capture_output=True,
                            text=True, check=True).stdout.splitlines()  # not what git ignores (builds, caches)
    listed = {Path(p) for p in listed}
    return sorted(p for p in out if p in listed and p.as_posix() not in SKIP and not SKIP_DIRS & set(p.parts))


# ----------------------------------------------------------------------------------------------------------------
# 4. the compat table
COMPAT_TEMPLATE = '''"""Old import paths of ehm's modules, kept for one release.

ehm's modules moved into folders named after their layers (``docs/development.md``).  A module imported by its
old name, ``import ehm.{example_old}`` or ``from ehm.{example_old} import ...``, is the module at its new name,
the SAME object (monkeypatching through either name patches one module), and the import warns once with a
:class:`DeprecationWarning` naming the new path.  Names of ``ehm.__all__`` never warn: import them from ``ehm``.

The table is written by ``tools/restructure.py``; this module imports nothing of ehm.
"""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.util
import inspect
import sys
import warnings

#: Old dotted name -> new dotted name, modules and packages (a package's modules follow it).
MOVED: dict[str, str] = {{
{table}
}}


def new_name(name: str) -> str | None:
    """The new dotted name of an old one (``None``: not moved)."""
    parts = name.split(".")
    for i in range(len(parts), 1, -1):
        head = ".".join(parts[:i])
        if head in MOVED:
            return ".".join([MOVED[head], *parts[i:]])
    return None


def _caller_stacklevel() -> int:
    """The stack level, for ``warnings.warn`` in :meth:`_OldPaths.find_spec`, of the line that imported: frames of
    this module and of ``importlib`` are passed (``warnings`` itself passes the import system's frozen frames)."""
    def internal(frame):
        name = frame.f_code.co_filename
        return "importlib" in name and "_bootstrap" in name

    frame, level = inspect.currentframe().f_back, 1
    while frame is not None and frame.f_code.co_filename in (__file__, importlib.__file__):
        frame = frame.f_back
        while frame is not None and internal(frame):
            frame = frame.f_back
        level += 1
    return level


class _Alias(importlib.abc.Loader):
    """Loads an old name as the module at its new name (the same object)."""

    def __init__(self, new: str):
        self.new = new
        self.spec = None

    def create_module(self, spec):
        module = importlib.import_module(self.new)
        self.spec = module.__spec__
        return module

    def exec_module(self, module):
        module.__spec__ = self.spec  # the import system set the alias's spec on the module; the real one back

    def is_package(self, fullname) -> bool:
        """Whether the module at the new name is a package (``python -m`` of an old package name runs its
        ``__main__``)."""
        return importlib.util.find_spec(self.new).submodule_search_locations is not None

    def get_code(self, fullname):
        """The code of the module at the new name (``python -m`` with an old name runs it)."""
        spec = importlib.util.find_spec(self.new)
        return spec.loader.get_code(self.new)


class _OldPaths(importlib.abc.MetaPathFinder):
    """Finds old names of moved modules (first on ``sys.meta_path``, so a moved package's old name is never
    loaded a second time from its files)."""

    def find_spec(self, fullname, path=None, target=None):
        new = new_name(fullname)
        if new is None:
            return None
        warnings.warn(f"{{fullname}} is deprecated, import {{new}} (the old path goes in the next release)",
                      DeprecationWarning, stacklevel=_caller_stacklevel())
        return importlib.util.spec_from_loader(fullname, _Alias(new))


_FINDER = _OldPaths()


def install() -> None:
    """Put the finder first on ``sys.meta_path`` (once)."""
    if not any(isinstance(f, _OldPaths) for f in sys.meta_path):
        sys.meta_path.insert(0, _FINDER)


def old_attribute(name: str):
    """``ehm.<old module>`` as an attribute (``ehm.frf`` without importing it): the module, with the warning."""
    if f"ehm.{{name}}" in MOVED:
        return importlib.import_module(f"ehm.{{name}}")
    raise AttributeError(f"module 'ehm' has no attribute {{name!r}}")
'''

INIT_HOOK = """
from . import _compat

_compat.install()  # the modules' old paths keep working for one release, with a DeprecationWarning
__getattr__ = _compat.old_attribute
"""


def compat_text() -> str:
    live = {old: new for old, new in MOVES.items() if module_file(new) is not None}
    width = max(len(o) for o in live) + 3
    keys = {o: '"' + o + '":' for o in live}
    table = "\n".join(f'    {keys[o]:<{width}} "{new}",' for o, new in live.items())
    example = next(iter(k for k in live if k.count(".") == 1)).split(".", 1)[1]
    return COMPAT_TEMPLATE.format(table=table, example_old=example)


def add_init_hook(text: str) -> str:
    if "_compat.install()" in text:
        return text
    tree = ast.parse(text)
    after = 0
    for node in tree.body:  # after the docstring and the __future__ imports
        if (isinstance(node, ast.Expr) and isinstance(node.value, ast.Constant) and isinstance(node.value.value, str)
                or isinstance(node, ast.ImportFrom) and node.module == "__future__"):
            after = node.end_lineno
        else:
            break
    lines = text.splitlines(keepends=True)
    return "".join(lines[:after]) + INIT_HOOK + "".join(lines[after:])


# ----------------------------------------------------------------------------------------------------------------
# 5. the contracts
_BLOCK = re.compile(r"(?ms)^\[\[tool\.importlinter\.contracts\]\]\n.*?(?=^\[|\Z)")


def _floor(floor: str) -> str:
    """A floor's names, without its comment."""
    return floor.partition("#")[0].strip()


def _floor_lines(floors: list[str], indent: str = "    ") -> str:
    """The floors as TOML list items, their comments aligned."""
    items = [(f'"{_floor(f)}",', f.partition("#")[2].strip()) for f in floors]
    width = max(len(i) for i, _ in items)
    return "\n".join(f"{indent}{i:<{width}}  # {c}" if c else f"{indent}{i}" for i, c in items)


def top_contract() -> str:
    floors = []
    for floor in FOLDER_FLOORS:
        names = [n.strip() for n in _floor(floor).split("|")]
        present = " | ".join(n if (PKG / n).is_dir() or (PKG / f"{n}.py").is_file() else f"({n})" for n in names)
        comment = floor.partition("#")[2].strip()
        floors.append(f"{present}  # {comment}" if comment else present)
    return f'''[[tool.importlinter.contracts]]
id = "layers"
name = "ehm: its folders are its floors, imports only point down (no loops)"
type = "layers"
containers = ["ehm"]
exhaustive = true
layers = [  # top to bottom; "a | b": same floor, and neither imports the other; the floors of each folder below
{_floor_lines(floors)}
]

'''


def folder_contract(folder: str, floors: list[str]) -> str:
    return f'''[[tool.importlinter.contracts]]
id = "layers-{folder}"
name = "ehm.{folder}: its modules' floors"
type = "layers"
containers = ["ehm.{folder}"]
exhaustive = true
layers = [
{_floor_lines(floors)}
]

'''


def rewrite_contracts(text: str) -> str:
    blocks = list(_BLOCK.finditer(text))
    if not blocks:
        return text
    out, last = [], 0
    has_container = {}
    for b in blocks:
        m = re.search(r'(?m)^containers\s*=\s*\["([\w.]+)"\]', b.group(0))
        idm = re.search(r'(?m)^id\s*=\s*"([\w-]+)"', b.group(0))
        if m:
            has_container.setdefault(m.group(1), idm.group(1) if idm else "")
    generated = [top_contract()]
    for folder, spec in FOLDERS.items():
        if spec.get("floors") is None or not (PKG / folder).is_dir():
            continue
        mine = f"layers-{folder}"
        owner = has_container.get(f"ehm.{folder}")
        if owner is not None and owner != mine:
            continue  # the folder has a contract of its own
        if spec.get("own_contract"):
            floors = {t.strip("() ") for floor in spec["floors"] for t in re.split(r"[|:]", _floor(floor))}
            unknown = modules_of(folder, set(PKG.rglob("*.py"))) - floors
            if unknown:
                print(f"note: ehm.{folder} has modules this script does not know ({', '.join(sorted(unknown))}) "
                      f"and no contract of its own; give it one in pyproject.toml")
                continue
        generated.append(folder_contract(folder, spec["floors"]))
    for b in blocks:
        idm = re.search(r'(?m)^id\s*=\s*"([\w-]+)"', b.group(0))
        ident = idm.group(1) if idm else ""
        out.append(text[last:b.start()])
        if ident == "layers":
            out.append("".join(generated))
        elif not ident.startswith("layers-") or ident.removeprefix("layers-") not in FOLDERS:
            out.append(b.group(0))
        last = b.end()
    out.append(text[last:])
    return "".join(out)


# ----------------------------------------------------------------------------------------------------------------
def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--check", action="store_true", help="say what would be done; change nothing")
    args = parser.parse_args()
    if not PKG.is_dir() or not Path("pyproject.toml").is_file():
        raise SystemExit("restructure: run from the root of an ehm checkout (src/ehm and pyproject.toml)")

    moves, notes = plan_moves()
    problems = check_placed(moves)
    if problems:
        raise SystemExit("restructure: place these first (edit the data at the top of tools/restructure.py):\n  "
                         + "\n  ".join(problems))
    for n in notes:
        print("note:", n)
    where = relocation(moves)
    names = {new: old for new, old in where.values()}
    known = set(names.values()) | set(MOVES)
    pending = 0

    # 1. moves
    for _, src, dst in moves:
        print(f"move {src} -> {dst}")
        pending += 1
        if not args.check:
            dst.parent.mkdir(parents=True, exist_ok=True)
            subprocess.run(["git", "mv", str(src), str(dst)], check=True)
            if src.is_dir():  # what git did not move (caches)
                shutil.rmtree(src)
    for folder, spec in FOLDERS.items():
        init = PKG / folder / "__init__.py"
        if (PKG / folder).is_dir() or any(MOVES[o].startswith(f"ehm.{folder}.") for o, _, _ in moves):
            if not init.is_file() and init not in names:
                print(f"write {init}")
                pending += 1
                if not args.check:
                    init.parent.mkdir(parents=True, exist_ok=True)
                    init.write_text(f'"""{spec["doc"]}"""\n', encoding="utf-8")
                    subprocess.run(["git", "add", str(init)], check=True)

    # 2.-3. imports and text
    long_left: list[str] = []
    rewritten: list[Path] = []
    for path in text_files():
        here = where[path][0] if args.check and path in where else path  # --check: the place it will have
        text = path.read_text(encoding="utf-8")
        new = text
        if path.suffix == ".py":
            in_pkg = PKG in here.parents or here.parent == PKG
            old_mod = names.get(here) if in_pkg else None
            new_mod = dotted_of(here) if in_pkg else None
            new = rewrite_imports(new, old_mod, new_mod, here.name == "__init__.py", known)
        new = rewrite_text(new)
        for fix_path, a, b in TEXT_FIXES:
            if here.as_posix() == fix_path or path.as_posix() == fix_path:
                new = new.replace(a, b)
        if path.suffix == ".rst":
            new = fix_underlines(text, new)
        if path.suffix == ".py" and new != text:
            new, left = wrap_long_lines(text, new)
            long_left += [f"{here}:{n}" for n in left]
        if new != text:
            print(f"rewrite {here}")
            pending += 1
            if not args.check:
                path.write_text(new, encoding="utf-8")
                if path.suffix == ".py":
                    rewritten.append(path)

    # 4. compat
    compat = PKG / "_compat.py"
    if not args.check:
        text = compat_text()
        if not compat.is_file() or compat.read_text(encoding="utf-8") != text:
            print(f"write {compat}")
            pending += 1
            compat.write_text(text, encoding="utf-8")
            subprocess.run(["git", "add", str(compat)], check=True)
    elif not compat.is_file() or moves:
        print(f"write {compat}")
        pending += 1
    init = PKG / "__init__.py"
    text = init.read_text(encoding="utf-8")
    hooked = add_init_hook(text)
    if hooked != text:
        print(f"install the compat finder in {init}")
        pending += 1
        if not args.check:
            init.write_text(hooked, encoding="utf-8")

    # 5. contracts
    if not args.check:
        py = Path("pyproject.toml")
        text = py.read_text(encoding="utf-8")
        new = rewrite_contracts(text)
        if new != text:
            print("write the import-linter contracts in pyproject.toml")
            pending += 1
            py.write_text(new, encoding="utf-8")
    elif moves:
        print("write the import-linter contracts in pyproject.toml")
        pending += 1
    else:
        text = Path("pyproject.toml").read_text(encoding="utf-8")
        if rewrite_contracts(text) != text:
            print("write the import-linter contracts in pyproject.toml")
            pending += 1

    # import order: where the tree has a ruff configuration, its import sorting (I001) over the files rewritten
    if not args.check and rewritten and "[tool.ruff" in Path("pyproject.toml").read_text(encoding="utf-8"):
        ruff = shutil.which("ruff") or shutil.which("ruff", path=str(Path(sys.executable).parent))
        if ruff:
            run = subprocess.run([ruff, "check", "--fix", "--select", "I001", "--quiet", *map(str, rewritten)],
                                 capture_output=True, text=True)
            print(f"ruff: import order fixed in the rewritten files ({run.stdout.strip() or 'nothing left'})")
        else:
            print("note: pyproject.toml configures ruff but ruff is not installed: run `ruff check --fix --select "
                  "I001` on the rewritten files")
    if long_left:
        print(f"note: {len(long_left)} line(s) over {LINE_LENGTH} characters made by the new names, in code or "
              "tables, left for a person to wrap:\n  " + "\n  ".join(long_left))
    print(f"{'would do' if args.check else 'done'}: {pending} change(s)")
    return 1 if args.check and pending else 0


if __name__ == "__main__":
    sys.exit(main())
