"""Write the parameter table of the model page from the shipped ``default_params.toml``.

Called from ``conf.py`` at every build, so the table cannot drift from the file ehm reads. Writes
``_generated/default_params.csv`` (name, value, unit, grade, source) and ``_generated/param_sources.md``
(what each source key means, as the file states it).
"""

from __future__ import annotations

import csv
import tomllib
from pathlib import Path

META = {"grade", "source", "grades", "sources", "bounds"}
# Unit suffixes of the key names (longest first), as the file's header describes them.
UNITS = [
    ("_Nms_per_rad", "N m s/rad"), ("_Nm_per_rad", "N m/rad"), ("_Ns_per_m", "N s/m"),
    ("_N_per_m", "N/m"), ("_kg", "kg"), ("_deg", "deg"), ("_s", "s"), ("_m", "m"),
]


def unit_of(name: str) -> str:
    for suffix, unit in UNITS:
        if name.endswith(suffix):
            return unit
    return "1"  # a coefficient, a count or a list of names


def fmt(value) -> str:
    if isinstance(value, list):
        return ", ".join(str(v) for v in value)
    if isinstance(value, float):
        return f"{value:g}"
    return str(value)


def rows(data: dict):
    """(dotted name, value, unit, grade, source) of every entry, in file order."""
    def walk(node: dict, prefix: str):
        for key, entry in node.items():
            if key in META or key in ("about", "sources"):
                continue
            path = f"{prefix}.{key}" if prefix else key
            if not isinstance(entry, dict):
                continue
            if "grade" in entry:
                if "value" in entry:
                    yield path, fmt(entry["value"]), unit_of(key), entry["grade"], entry["source"]
                else:  # one entry holding several values, e.g. a joint's stiffness and damping
                    for sub, value in entry.items():
                        if sub not in META:
                            yield f"{path}.{sub}", fmt(value), unit_of(sub), entry["grade"], entry["source"]
            else:
                yield from walk(entry, path)
    yield from walk(data, "")


def write(toml_path: Path, out_dir: Path) -> int:
    data = tomllib.loads(Path(toml_path).read_text(encoding="utf-8"))
    out_dir.mkdir(parents=True, exist_ok=True)
    table = list(rows(data))
    with open(out_dir / "default_params.csv", "w", newline="", encoding="utf-8") as f:
        writer = csv.writer(f)
        for name, value, unit, grade, source in table:
            writer.writerow([f"``{name}``", value, unit, grade, source])
    lines = [f"- **{key}**: {text}" for key, text in data.get("sources", {}).items()]
    (out_dir / "param_sources.md").write_text("\n".join(lines) + "\n", encoding="utf-8")
    return len(table)
