"""Progress of the command line (ehm.interfaces.cli.progress): a bar on a terminal, a few lines on a pipe, nothing with
--quiet, and nothing from library calls unless asked.

Every drive here is SYNTHETIC (ehm.random_vibration)."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

import ehm
from ehm.errors import EhmWarning
from ehm.interfaces.cli import main
from ehm.interfaces.cli import progress as cli_progress
from ehm.interfaces.cli.parser import build_parser


def _write_drive(path, motion):
    pd.DataFrame({"time_s": motion.time_s, "ax_mps2": motion.acc_mps2[:, 0], "ay_mps2": motion.acc_mps2[:, 1],
                  "az_mps2": motion.acc_mps2[:, 2]}).to_csv(path, index=False)


@pytest.mark.filterwarnings("always::ehm.errors.EhmWarning")  # the command line prints them: read on stderr
def test_piped_assess_prints_no_carriage_returns(tmp_path, capsys):
    """Issue 32: piped into a file or a CI log (stderr not a terminal, as here), ehm assess printed its progress
    updates joined by carriage returns on one line."""
    log = tmp_path / "drive.csv"
    _write_drive(log, ehm.random_vibration("xyz", 12.0, 0.3, seed=3, dt_s=0.01))
    assert main(["assess", "--motion", str(log), "--out", str(tmp_path / "a")]) == 0
    out, err = capsys.readouterr()
    assert "\r" not in out + err and "a_v" in out
    assert "ehm: warning: from drive.csv" in err and "not all of the Wk band" in err  # 12 s at 100 Hz


def test_progress_on_a_pipe_is_a_few_lines(monkeypatch, capsys):
    """Issue 32: a 342 s assessment's ~60 progress updates, piped: at most a line every 10 s of wall time, at a new
    tenth of the drive (here the updates come every 5 s: at most one line per 10 s and per tenth, 10 or fewer)."""
    clock = iter(np.arange(0.0, 1000.0, 5.0))
    monkeypatch.setattr(cli_progress.time, "monotonic", lambda: float(next(clock)))
    show = cli_progress.progress_bar("assess")
    for done in np.linspace(342 / 60, 342, 60):
        show(done, 342.0)
    err = capsys.readouterr().err
    lines = err.splitlines()
    assert "\r" not in err and 3 <= len(lines) <= 10
    assert lines[-1] == "assess: 100 % (342 / 342 s of the drive)"


def test_progress_on_a_terminal_is_a_bar(monkeypatch, capsys):
    """Issue 32: on a terminal the bar stays (rewritten in place)."""
    monkeypatch.setattr(cli_progress.sys.stderr, "isatty", lambda: True, raising=False)
    show = cli_progress.progress_bar("simulate")
    show(5.0, 10.0)
    show(10.0, 10.0)
    err = capsys.readouterr().err
    assert err.count("\r") == 2 and err.endswith("10 / 10 s\n")


def test_quiet_prints_no_progress_and_a_short_pipe_run_none(tmp_path, capsys):
    """Issue 32: --quiet on the commands that print progress; a run shorter than a progress interval prints no
    progress line on a pipe either."""
    assert cli_progress.progress_bar("simulate", quiet=True) is None
    for args in (["simulate", "--duration", "2", "--quiet"], ["simulate", "--duration", "2"]):
        assert main([*args, "--out", str(tmp_path / "run")]) == 0
        assert capsys.readouterr().err == ""
    parser = build_parser()
    for command in (["assess", "--motion", "city", "--out", "x", "-q"], ["batch", "s.toml", "--out", "x", "-q"],
                    ["fit", "--data", "d.csv", "--out", "f.toml", "--quiet"]):
        assert parser.parse_args(command).quiet


def test_library_calls_print_nothing_unless_asked(human, capsys):
    """Issue 32: library calls print nothing unless given progress=."""
    motion = ehm.random_vibration("z", 2.0, 0.3, seed=0)
    with pytest.warns(EhmWarning, match="not all of the Wf band"):  # 2 s: no motion-sickness band
        ehm.assess(motion, human)
    assert capsys.readouterr() == ("", "")
    seen = []
    human.simulate(motion, progress=lambda done, total: seen.append(done))
    assert seen and seen[-1] == pytest.approx(2.0)
