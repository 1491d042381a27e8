"""Write the validation page's table and figure of every condition (``ehm validate --all``) at every build.

Called from ``conf.py``, so the page shows what this version of ehm computes, never figures copied by hand.
Writes into ``_generated/``: ``validation_all_counts.csv`` (condition, checks passing, checks, the failing ones),
``validation_all.csv`` (a row per check: condition, check, the model's figure, unit, where it was taken, band,
verdict, what it is) and ``validation_all.png`` (the grid of :func:`ehm.outputs.plotting.plot_validation_grid`).
"""

from __future__ import annotations

import csv
import math
from pathlib import Path


def _number(value: float) -> str:
    return "" if isinstance(value, float) and math.isnan(value) else f"{value:.3g}"


def write(out_dir: Path) -> int:
    """Evaluate the default person on every posture and back support and write the three files; the number of
    checks."""
    from ehm.analysis.validation import band_text, validate
    from ehm.outputs.plotting import plot_validation_grid

    out_dir.mkdir(parents=True, exist_ok=True)
    v = validate(every_condition=True)
    with open(out_dir / "validation_all_counts.csv", "w", newline="", encoding="utf-8") as f:
        writer = csv.writer(f)
        for condition, (passing, n) in v.counts().items():
            failing = dict.fromkeys(c.name for c in v.checks if c.condition == condition and not c.passed)
            writer.writerow([condition, passing, n, ", ".join(f"``{name}``" for name in failing)])
    with open(out_dir / "validation_all.csv", "w", newline="", encoding="utf-8") as f:
        writer = csv.writer(f)
        for c in v.checks:
            writer.writerow([c.condition, f"``{c.name}``", _number(c.value), c.unit, _number(c.at_hz), band_text(c),
                             "pass" if c.passed else "**FAIL**", c.what])
    plot_validation_grid(v, out_dir / "validation_all.png")
    return len(v.checks)
