"""ehm never deletes a file it did not write: an output folder is replaced only when ehm's manifest lists every file
in it.  Every file here is SYNTHETIC (random bytes or short generated runs).
"""

from __future__ import annotations

import errno
import hashlib
import json
import os
import stat
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import ehm
from ehm.errors import InputError
from ehm.files import MANIFEST_NAME, read_manifest
from ehm.interfaces.cli import main
from ehm.outputs import runfiles
from ehm.outputs.outdir import RunFolder


def _tree(folder: Path) -> dict[str, str]:
    """Every file under ``folder`` with the SHA-256 of its bytes."""
    return {p.relative_to(folder).as_posix(): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(folder.rglob("*")) if p.is_file()}


def _one_error_line(err: str) -> str:
    lines = [ln for ln in err.replace("\r", "\n").splitlines() if ln.strip()]
    assert "Traceback" not in err
    assert lines[-1].startswith("ehm: error: "), err
    return lines[-1]


def _rerun_is_refused_and_keeps(out: Path, capsys) -> str:
    """Run simulate into ``out`` again: refused (exit 2) with one sentence, every file left byte-identical."""
    before = _tree(out)
    capsys.readouterr()
    assert main(["simulate", "--duration", "1", "--out", str(out)]) == 2
    err = _one_error_line(capsys.readouterr().err)
    assert _tree(out) == before
    return err


def _user_folder(tmp_path: Path, layout: str) -> Path:
    """The three folders a tester lost: own videos, files that happen to share ehm's names, videos one folder down."""
    rng = __import__("numpy").random.default_rng(0)
    files = {"videos": ["holiday.mp4", "clip.gif"],
             "ehm_names": ["report.html", "summary.json"],
             "nested": ["2024/wedding.mp4"]}[layout]
    folder = tmp_path / layout
    for name in files:
        (folder / name).parent.mkdir(parents=True, exist_ok=True)
        (folder / name).write_bytes(rng.bytes(100_000))
    return folder


@pytest.mark.parametrize("layout", ["videos", "ehm_names", "nested"])
@pytest.mark.parametrize("command", [["simulate", "--duration", "3"], ["demo", "--duration", "40"],
                                     ["assess", "--motion", "road"]])
def test_a_folder_of_the_users_files_is_refused_and_kept(tmp_path, capsys, layout, command):
    folder = _user_folder(tmp_path, layout)
    before = _tree(folder)
    assert main([*command, "--out", str(folder)]) == 2
    err = _one_error_line(capsys.readouterr().err)
    assert "ehm did not write" in err and "give a new or empty folder" in err
    assert _tree(folder) == before
    assert sorted(p.name for p in tmp_path.iterdir()) == [layout]  # no staging folder left beside it


def test_the_manifest_lists_the_command_version_and_every_file(tmp_path):
    out = tmp_path / "run"
    assert main(["simulate", "--duration", "1", "--plot", "--out", str(out)]) == 0
    manifest = read_manifest(out)
    assert manifest["written_by"] == "ehm" and manifest["state"] == "complete"
    assert manifest["ehm_version"] == ehm.__version__
    assert manifest["command"] == f"ehm simulate --duration 1 --plot --out {out}"
    files = {p.name: p.stat().st_size for p in out.iterdir() if p.name != MANIFEST_NAME}
    assert manifest["files"] == files and "time_histories.png" in files


def test_the_demos_nested_folders_are_listed(tmp_path):
    out = tmp_path / "demo"
    assert main(["demo", "--duration", "40", "--axes", "z", "--out", str(out)]) == 0
    listed = read_manifest(out)["files"]
    assert {"z/timeseries.csv", "z/animation.gif", "transmissibility.csv"} <= set(listed)
    assert set(listed) == {p.relative_to(out).as_posix() for p in out.rglob("*")
                           if p.is_file() and p.relative_to(out).as_posix() != MANIFEST_NAME}
    assert main(["demo", "--duration", "40", "--axes", "z", "--out", str(out)]) == 0  # its own folder: replaced


@pytest.mark.parametrize("change", ["added", "added_below", "resized", "link"])
def test_an_ehm_folder_that_the_user_changed_is_refused(tmp_path, capsys, change):
    out = tmp_path / "run"
    assert main(["simulate", "--duration", "1", "--method", "nonlinear", "--out", str(out)]) == 0
    if change == "added":
        (out / "notes.txt").write_text("mine")
    elif change == "added_below":
        (out / "mine").mkdir()
        (out / "mine" / "summary.json").write_text("{}")
    elif change == "resized":
        with open(out / "summary.json", "a") as fh:
            fh.write("\n")
    else:
        (out / "link.csv").symlink_to(tmp_path)
    err = _rerun_is_refused_and_keeps(out, capsys)
    name = {"added": "notes.txt", "added_below": "mine/summary.json", "resized": "summary.json",
            "link": "link.csv"}[change]
    assert name in err and "give a new or empty folder" in err


def test_a_folder_without_a_manifest_is_refused_whatever_its_names(tmp_path, capsys):
    # a folder from an ehm without manifests, or a user's: names alone are no evidence
    out = tmp_path / "run"
    assert main(["simulate", "--duration", "1", "--method", "nonlinear", "--out", str(out)]) == 0
    (out / MANIFEST_NAME).unlink()
    assert "no ehm manifest" in _rerun_is_refused_and_keeps(out, capsys)


def test_an_animation_drawn_into_a_run_folder_joins_its_manifest(tmp_path):
    out = tmp_path / "run"
    assert main(["simulate", "--duration", "1", "--method", "nonlinear", "--out", str(out)]) == 0
    assert main(["animate", str(out), "--out", str(out / "a.gif"), "--max-frames", "3"]) == 0
    assert read_manifest(out)["files"]["a.gif"] == (out / "a.gif").stat().st_size
    assert main(["simulate", "--duration", "1", "--method", "nonlinear", "--out", str(out)]) == 0
    assert not (out / "a.gif").exists()


def test_a_file_added_while_the_run_goes_keeps_the_folder(tmp_path):
    out = tmp_path / "run"
    with RunFolder(out) as tmp:
        (tmp / "summary.json").write_text('{"run": 1}')
    with pytest.raises(InputError, match="added while the run went on") as info:
        with RunFolder(out) as tmp:
            (tmp / "summary.json").write_text('{"run": 2}')
            (out / "holiday.mp4").write_bytes(b"mine")  # the user saves a file there meanwhile
    assert (out / "holiday.mp4").read_bytes() == b"mine"
    assert json.loads((out / "summary.json").read_text()) == {"run": 1}
    kept = Path(str(info.value).rsplit(" is in ", 1)[1].rstrip("."))
    assert json.loads((kept / "summary.json").read_text()) == {"run": 2}


def test_a_full_disk_during_simulate_is_one_sentence(tmp_path, capsys, monkeypatch):
    # ENOSPC on a write, and again when the half-written files are closed (closing flushes)
    def full(*args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device")

    real_write, calls = runfiles._CsvStream.write, []

    def full_from_the_second_chunk(self, header, data):  # the poses' raw files are open by then
        calls.append(1)
        if len(calls) > 1:
            full()
        real_write(self, header, data)

    monkeypatch.setattr(runfiles._CsvStream, "write", full_from_the_second_chunk)
    real_remove_raw = runfiles._PoseStream.remove_raw

    class FullOnClose:  # closing flushes the buffer: on a full disk that fails again
        def __init__(self, fh):
            self.fh = fh

        def close(self):
            self.fh.close()
            full()

    def remove_raw_on_a_full_disk(self):
        self.fh = {k: FullOnClose(f) for k, f in self.fh.items()}
        real_remove_raw(self)

    monkeypatch.setattr(runfiles._PoseStream, "remove_raw", remove_raw_on_a_full_disk)
    out = tmp_path / "run"
    assert main(["simulate", "--duration", "30", "--out", str(out)]) == 2
    assert len(calls) == 2
    err = _one_error_line(capsys.readouterr().err)
    assert err == f"ehm: error: {out}: cannot write the run's files (No space left on device)."
    assert list(tmp_path.iterdir()) == []


def test_a_file_edited_in_place_at_the_same_size_is_the_users(tmp_path, capsys):
    out = tmp_path / "run"
    assert main(["simulate", "--duration", "1", "--method", "nonlinear", "--out", str(out)]) == 0
    text = (out / "summary.json").read_text()
    (out / "summary.json").write_text(text.replace("0", "1", 1))  # same length, other bytes, a later time
    assert "summary.json, which was changed after ehm wrote it" in _rerun_is_refused_and_keeps(out, capsys)


def test_a_picture_drawn_into_a_demos_run_folder_keeps_the_demo_replaceable(tmp_path):
    out = tmp_path / "demo"
    assert main(["demo", "--duration", "40", "--axes", "z", "--out", str(out)]) == 0
    assert main(["animate", str(out / "z"), "--out", str(out / "z" / "a.gif"), "--max-frames", "3"]) == 0
    assert read_manifest(out / "z")["files"]["a.gif"] == (out / "z" / "a.gif").stat().st_size
    assert read_manifest(out)["files"]["z/a.gif"] == (out / "z" / "a.gif").stat().st_size
    assert main(["demo", "--duration", "40", "--axes", "z", "--out", str(out)]) == 0  # still ehm's: replaced
    assert not (out / "z" / "a.gif").exists()


# ==================================================================================================================
# Batch folders as safe as run folders, and the output-folder cases users reported.  Every file here is SYNTHETIC
# (short generated runs, a few bytes of text, a generated drive log).  No test has a numerical tolerance: each
# checks the exit code, the sentence and the files' bytes exactly; the time limits are generous bounds on "before
# any work" (a refusal takes well under a second, the runs it would have started take seconds).
# ==================================================================================================================

#: The smallest study: one linear-model transmissibility run (a fraction of a second in its worker).
TINY_STUDY = '[study]\nname = "tiny"\ncompute = ["transmissibility"]\n[input]\naxes = ["z"]\n'




def _dead_pid() -> int:
    """The number of a process that has ended."""
    done = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True)
    return int(done.stdout)


def _run(out: Path, *extra: str) -> int:
    return main(["simulate", "--duration", "1", *extra, "--out", str(out)])


# --- ehm batch --out replaces the user's own results.csv --------------------------------------------------------------

@pytest.mark.requires_dask
@pytest.mark.requires_pyarrow
def test_batch_refuses_a_folder_holding_the_users_results_csv_before_any_work(tmp_path, capsys):
    """User case: `ehm batch --out` replaced the user's own results.csv (rc 0, no word).  --out takes a folder only
    (a file there is refused as before); a folder holding a results.csv ehm did not write, or one it wrote that was
    edited since, is now refused before any run, the file byte-identical."""
    study = tmp_path / "study.toml"
    study.write_text(TINY_STUDY)
    res = tmp_path / "res"
    res.mkdir()
    (res / "results.csv").write_text("my,own,table\n1,2,3\n")
    before = _tree(res)
    assert main(["batch", str(study), "--out", str(res), "--csv", "--workers", "1"]) == 2
    err = _one_error_line(capsys.readouterr().err)
    assert "results.csv, which ehm did not write" in err and "give a new or empty folder" in err
    assert _tree(res) == before and sorted(p.name for p in res.iterdir()) == ["results.csv"]  # no runs/ started
    # --out naming the user's file itself: refused too (a folder is asked for)
    assert main(["batch", str(study), "--out", str(res / "results.csv"), "--csv", "--workers", "1"]) == 2
    assert "is a file; give a folder" in _one_error_line(capsys.readouterr().err)
    # ehm's own study folder: its files are listed, so it resumes; a table edited since is the user's
    own = tmp_path / "own"
    assert main(["batch", str(study), "--out", str(own), "--csv", "--workers", "1"]) == 0
    assert set(read_manifest(own)["files"]) == {f"runs/{p.name}" for p in (own / "runs").iterdir()} | {
        "results.parquet", "results.csv"}
    assert main(["batch", str(study), "--out", str(own), "--csv", "--workers", "1"]) == 0  # resumes
    (own / "results.csv").write_text((own / "results.csv").read_text() + "my,note\n")
    before = _tree(own)
    capsys.readouterr()
    assert main(["batch", str(study), "--out", str(own), "--csv", "--workers", "1"]) == 2
    assert "results.csv, which was changed after ehm wrote it" in _one_error_line(capsys.readouterr().err)
    assert _tree(own) == before


# --- a folder named like ehm's staging folders ----------------------------------------------------------------------

def test_a_folder_named_like_a_staging_folder_is_kept_with_what_the_user_put_in_it(tmp_path, capsys):
    """User case: a folder beside the output named like ehm's staging folders (`.NAME.partial-PID-...`) was deleted
    whole with the user's files.  Here it is an ehm run folder the user made under that name (so it carries a
    manifest, of a finished run) and added notes to; only ehm's own staging mark, naming the folder, counts."""
    pid = _dead_pid()
    lookalike = tmp_path / f".run.partial-{pid}-mine"
    assert _run(lookalike) == 0
    (lookalike / "notes.txt").write_text("keep me")
    before = _tree(lookalike)
    assert _run(tmp_path / "run") == 0
    assert _run(tmp_path / "run") == 0  # the staging folders of ehm's own runs are looked for each time
    assert _tree(lookalike) == before
    assert sorted(p.name for p in tmp_path.iterdir()) == [lookalike.name, "run"]


# --- a read-only folder, and the hidden copies of earlier runs --------------------------------------------------------

@pytest.mark.parametrize("what", ["folder", "file"])
def test_a_read_only_folder_is_refused_before_any_work(tmp_path, capsys, what):
    """User case: a folder the user made read-only was replaced anyway.  Judged by the mode bits (these tests run
    as root, whom the permission would not stop), the folder or anything in it."""
    out = tmp_path / "run"
    assert _run(out, "--method", "nonlinear") == 0
    locked = out if what == "folder" else out / "summary.json"
    mode = stat.S_IMODE(locked.stat().st_mode) & ~0o222
    os.chmod(locked, mode)
    try:
        before = _tree(out)
        capsys.readouterr()
        assert _run(out, "--method", "nonlinear", "--duration", "600") == 2  # 600 s: refused before running it
        err = _one_error_line(capsys.readouterr().err)
        assert "read-only" in err and "chmod -R u+w" in err
        assert _tree(out) == before and stat.S_IMODE(locked.stat().st_mode) == mode
        assert sorted(p.name for p in tmp_path.iterdir()) == ["run"]
    finally:
        os.chmod(locked, mode | stat.S_IWUSR)


def test_no_hidden_copy_of_an_earlier_run_is_left_beside_it(tmp_path, capsys, monkeypatch):
    """User case: each run left a hidden read-only copy of the earlier run beside it (the earlier folder was
    read-only, its new copy too, and the removal of the swapped-out folder failed without a word).  Root may remove
    anything, so removal is made to fail as it does for a user: no entry may be removed from a folder whose owner
    may not write it."""
    def as_a_user(real):
        def remove(path, *, dir_fd=None):
            parent = os.fstat(dir_fd) if dir_fd is not None else os.stat(os.path.dirname(os.path.abspath(path)))
            if not parent.st_mode & stat.S_IWUSR:
                raise PermissionError(errno.EACCES, os.strerror(errno.EACCES), path)
            return real(path, dir_fd=dir_fd)
        return remove

    monkeypatch.setattr(os, "unlink", as_a_user(os.unlink))
    monkeypatch.setattr(os, "rmdir", as_a_user(os.rmdir))
    out = tmp_path / "run"
    assert _run(out) == 0
    os.chmod(out, 0o555)
    try:
        _run(out)
        assert sorted(p.name for p in tmp_path.iterdir()) == ["run"]  # nothing hidden beside it
    finally:
        os.chmod(out, 0o755)
    for _ in range(2):
        assert _run(out) == 0
        assert sorted(p.name for p in tmp_path.iterdir()) == ["run"]


# --- single files written into a folder ehm manages -------------------------------------------------------------------

@pytest.mark.parametrize("command", [["drive", "city", "--duration", "12", "--out"], ["params", "--export"]])
def test_a_single_file_is_not_written_into_a_run_folder(tmp_path, capsys, command):
    """User case: `ehm params --export FILE` or `ehm drive --out FILE` into a run folder joined the folder's manifest
    and was deleted by the next run.  Now refused before any work, with another place named."""
    out = tmp_path / "run"
    assert _run(out) == 0
    before = _tree(out)
    name = "drive.csv" if command[0] == "drive" else "p.toml"
    capsys.readouterr()
    assert main([*command, str(out / name)]) == 2
    err = _one_error_line(capsys.readouterr().err)
    assert f"{out} is an output folder of ehm's" in err and f"e.g. {tmp_path / name}." in err
    assert _tree(out) == before


def test_the_next_run_never_deletes_a_file_it_reads_or_a_file_written_there_from_python(tmp_path, capsys):
    """User case, continued: the drive the next run read was deleted with the folder.  A file written into a run
    folder from Python (where no command line checks first) is not listed, so the next run refuses the folder; an
    input listed there by an earlier ehm (which adopted every file written into a run folder) is refused as an
    input of the run that would replace it."""
    from ehm.inputs.drives import city_drive, write_drive_csv

    out = tmp_path / "run"
    assert _run(out) == 0
    write_drive_csv(city_drive(12.0), out / "drive.csv")
    assert "drive.csv" not in read_manifest(out)["files"]
    before = _tree(out)
    capsys.readouterr()
    assert main(["simulate", "--motion", str(out / "drive.csv"), "--out", str(out)]) == 2
    assert "drive.csv" in _one_error_line(capsys.readouterr().err)
    assert _tree(out) == before
    from ehm.outputs.outdir import record_in_manifest

    record_in_manifest(out / "drive.csv", out)  # as the earlier ehm listed it
    before = _tree(out)
    assert main(["simulate", "--motion", str(out / "drive.csv"), "--out", str(out)]) == 2
    err = _one_error_line(capsys.readouterr().err)
    assert f"holds {out / 'drive.csv'}, which this command reads" in err
    assert _tree(out) == before


# --- the corrupt-manifest sentence ----------------------------------------------------------------------------------

def test_a_damaged_manifest_is_named_as_such(tmp_path, capsys):
    """User case: the corrupt-manifest sentence contradicted itself ("holds .ehm-manifest.json, which ehm did not
    write (the folder has no ehm manifest, .ehm-manifest.json)").  Now it says the manifest is damaged and what to
    do."""
    out = tmp_path / "run"
    assert _run(out) == 0
    (out / MANIFEST_NAME).write_text('{"written_by": "ehm", "files": {')
    before = _tree(out)
    capsys.readouterr()
    assert _run(out) == 2
    err = _one_error_line(capsys.readouterr().err)
    assert err == (f"ehm: error: {out} has a manifest, {MANIFEST_NAME}, that is damaged (not valid JSON), so ehm "
                   "cannot tell the files it wrote there from any others; give a new or empty folder for the output: "
                   "ehm replaces only a folder that it wrote and that holds nothing else.")
    assert _tree(out) == before


# --- batch warnings --------------------------------------------------------------------------------------------------

def _drive_with_a_gap(path: Path) -> None:
    """A SYNTHETIC 4 s seat log at 100 Hz with 0.1 s of rows missing."""
    t = np.delete(np.arange(0, 4, 0.01), range(150, 160))
    acc = np.random.default_rng(0).normal(0.0, [0.1, 0.1, 0.3], (t.size, 3))
    path.write_text("time_s,ax_mps2,ay_mps2,az_mps2\n" + "".join(
        f"{ti:.3f},{a:.4f},{b:.4f},{c:.4f}\n" for ti, (a, b, c) in zip(t, acc)))


@pytest.mark.filterwarnings("always::ehm.errors.EhmWarning")  # the command line prints them: read on stderr
@pytest.mark.requires_dask
@pytest.mark.requires_pyarrow
def test_batch_warnings_are_ehm_warnings_on_their_own_lines(tmp_path, capfd):
    """User case: batch warnings printed raw Python with file and line (the workers' default format), glued to the
    progress line.  Two runs on one worker process, each warning that its drive's gap was bridged: the warnings
    come back with the runs' records and are printed once, as `ehm: warning: ...` on a line of their own."""
    _drive_with_a_gap(tmp_path / "drive.csv")
    study = tmp_path / "study.toml"
    study.write_text('[study]\ncompute = ["comfort"]\n[grid]\n"joints.t12.z.stiffness_N_per_m" = [14000.0, 16000.0]\n'
                     '[input]\ndrive = "drive.csv"\nfill_gaps = true\nduration_s = 3.0\nroute = "linear"\n')
    assert main(["batch", str(study), "--out", str(tmp_path / "res"), "--workers", "1"]) == 0
    err = capfd.readouterr().err  # the file descriptor: what worker processes print is seen too
    assert "Warning:" not in err and ".py:" not in err, err
    lines = err.split("\n")
    assert all(ln.startswith("ehm: warning: ") for ln in lines if "warning" in ln.lower()), err
    assert sum("is bridged with a straight line (fill_gaps)" in ln for ln in lines) == 1, err
    records = [json.loads(p.read_text()) for p in (tmp_path / "res" / "runs").iterdir()]
    assert all(any("fill_gaps" in text for _, text in r["warnings"]) for r in records)


# --- the gyro file of a batch study ----------------------------------------------------------------------------------

@pytest.mark.requires_dask
@pytest.mark.requires_pyarrow
def test_a_missing_gyro_file_is_named_as_the_gyro(tmp_path, capsys):
    """User case: a batch study's missing gyro file was reported as `[input] drive`."""
    _drive_with_a_gap(tmp_path / "drive.csv")
    study = tmp_path / "study.toml"
    study.write_text('[study]\ncompute = ["comfort"]\n[input]\ndrive = "drive.csv"\ngyro = "gyro.csv"\n'
                     'fill_gaps = true\nduration_s = 3.0\n')
    assert main(["batch", str(study), "--out", str(tmp_path / "res")]) == 2
    err = _one_error_line(capsys.readouterr().err)
    assert err == (f"ehm: error: {study}: [input] gyro 'gyro.csv' (no file {tmp_path / 'gyro.csv'}): give the gyro "
                   "file's path (relative paths start from the study file's folder).")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["drive.csv", "study.toml"]


# --- review of issue 31: batch bookkeeping, a killed study, a study folder of an earlier ehm -------------------

def _manifest_writes(monkeypatch) -> list:
    """Count the writes of a manifest made through the atomic JSON writer of ehm.outputs.outdir (how it rewrites a
    folder's
    manifest, before this change and after)."""
    import ehm.outputs.outdir as outdir

    writes, real = [], outdir.write_json_atomic

    def counted(path, obj):
        if Path(path).name == MANIFEST_NAME:
            writes.append(path)
        real(path, obj)

    monkeypatch.setattr(outdir, "write_json_atomic", counted)
    return writes


@pytest.mark.requires_dask
@pytest.mark.requires_pyarrow
def test_a_study_writes_its_manifest_at_most_about_once_a_second(tmp_path, monkeypatch):
    """Review case: batch bookkeeping grew quadratically with the number of runs (every finished run re-read,
    re-wrote and fsynced the whole manifest: 4000 records took 43 s, the runs' results waiting behind it).  300
    SYNTHETIC runs that take no time (a stand-in for run_one, on an in-process Dask cluster) end within a few
    seconds: the manifest is written on entering, for the results table, on leaving, and at most once per second
    between (the bound: 3 + the seconds it took; it was written once per run, 300 times).  It lists every record."""
    import time

    from dask.distributed import Client

    import ehm.interfaces.batch as batch

    def no_time_run(spec):
        return {"inputs": spec.inputs(), "outputs": {"x.peak_hz": 1.0}, "error": None, "simulated_s": 0.0,
                "wall_s": 0.0, "warnings": []}

    import contextlib

    @contextlib.contextmanager
    def in_process(scheduler, workers):
        with Client(processes=False, n_workers=1, threads_per_worker=1, dashboard_address=None,
                    scheduler_kwargs={"dashboard_address": ":0"}) as client:
            yield client

    monkeypatch.setattr(batch, "run_one", no_time_run)
    monkeypatch.setattr(batch, "dask_client", in_process)
    specs = [batch.RunSpec(f"{i:012x}", {}, {"k": float(i)}, (), ("transmissibility",), {}, f"{i:012x}", {"f": "1"})
             for i in range(300)]
    out = tmp_path / "res"
    writes = _manifest_writes(monkeypatch)
    t0 = time.monotonic()
    assert batch.run_study(specs, out)["ran"] == 300
    elapsed = time.monotonic() - t0
    assert len(writes) <= 3 + elapsed, (len(writes), elapsed)
    listed = read_manifest(out)
    assert set(listed["files"]) == {f"runs/{s.point_id}.json" for s in specs} | {"results.parquet"}
    assert listed["open"] is False


_KILLED_STUDY = '''
import os, signal, sys
import ehm.interfaces.batch as batch
import ehm.outputs.outdir as outdir

outdir.FLUSH_INTERVAL_S = 1e9  # no record listed before the kill: every record is one written since the last listing


def killed(*args, **kwargs):  # the runs are recorded (and the cluster closed): killed before the results table
    os.kill(os.getpid(), signal.SIGKILL)


batch.write_table = killed
if __name__ == "__main__":
    name, specs = batch.load_study(sys.argv[1])
    batch.run_study(specs, batch.Path(sys.argv[2]), workers=1)
'''


@pytest.mark.requires_dask
@pytest.mark.requires_pyarrow
def test_a_study_killed_before_its_manifest_listed_its_records_resumes(tmp_path, capsys):
    """Review case: the manifest is now written at most about once a second, so a study killed in between (SIGKILL,
    a power cut) leaves records that it does not list.  The next `ehm batch` must neither refuse them (ehm wrote
    them) nor take a file of the user's as ehm's: the records name the folder's id (their content, not their
    names), and only while the manifest says the killed command did not end.  Three SYNTHETIC linear-model runs;
    no tolerance: exit codes, sentences and bytes are checked exactly."""
    study = tmp_path / "study.toml"
    study.write_text(TINY_STUDY + '[grid]\n"joints.t12.z.stiffness_N_per_m" = [14000.0, 15000.0, 16000.0]\n')
    script = tmp_path / "killed.py"
    script.write_text(_KILLED_STUDY)
    res = tmp_path / "res"
    done = subprocess.run([sys.executable, str(script), str(study), str(res)], capture_output=True, text=True,
                          env={**os.environ, "PYTHONPATH": str(Path(__import__("ehm").__file__).parents[1])})
    assert done.returncode == -9, done.stderr
    records = sorted(p.relative_to(res).as_posix() for p in (res / "runs").iterdir())
    killed = read_manifest(res)
    assert len(records) == 3 and killed["open"] is True and killed["files"] == {}  # the case: none listed
    # a file of the user's among them, a record without the folder's id: refused, nothing touched
    mine = res / "runs" / "mine.json"
    rec = json.loads((res / records[0]).read_text())
    mine.write_text(json.dumps({k: v for k, v in rec.items() if k != "ehm_folder_id"}))
    before = _tree(res)
    assert main(["batch", str(study), "--out", str(res), "--workers", "1"]) == 2
    assert _one_error_line(capsys.readouterr().err) == (
        f"ehm: error: {res} holds runs/mine.json, which ehm did not write; give a new or empty folder for the "
        "study's results: ehm adds only to a folder that it wrote and that holds nothing else.")
    assert _tree(res) == before
    mine.unlink()
    # the study resumes: nothing is run again, the records are listed, the manifest closed
    assert main(["batch", str(study), "--out", str(res), "--workers", "1"]) == 0
    assert "ran 0 runs (3 already done" in capsys.readouterr().out
    resumed = read_manifest(res)
    assert set(resumed["files"]) == {*records, "results.parquet"} and resumed["open"] is False
    # after a study that ended, a copy of a record (the folder's id and all) is the user's
    (res / "runs" / "copy.json").write_text((res / records[0]).read_text())
    before = _tree(res)
    assert main(["batch", str(study), "--out", str(res), "--workers", "1"]) == 2
    assert "holds runs/copy.json, which ehm did not write" in _one_error_line(capsys.readouterr().err)
    assert _tree(res) == before


def test_sigterm_writes_the_manifest_of_a_folder_being_added_to(tmp_path):
    """Review case, continued: the manifest is written once more when the command ends, also on SIGTERM where ehm is
    used from Python (SIGTERM left to its default: the process still ends by it).  Records written within the
    second after the last writing, then SIGTERM: all listed, the manifest closed.  SYNTHETIC records."""
    code = ("import os, signal, sys\nfrom pathlib import Path\n"
            "from ehm.outputs.outdir import added_folder, write_owned_json\n"
            "out = Path(sys.argv[1])\nwith added_folder(out, 'results'):\n"
            "    for i in range(3):\n        write_owned_json(out / 'runs' / f'{i}.json', {'i': i}, out)\n"
            "    os.kill(os.getpid(), signal.SIGTERM)\n    print('not ended')\n")
    out = tmp_path / "res"
    done = subprocess.run([sys.executable, "-c", code, str(out)], capture_output=True, text=True,
                          env={**os.environ, "PYTHONPATH": str(Path(__import__("ehm").__file__).parents[1])})
    assert done.returncode == -15 and "not ended" not in done.stdout, done.stderr
    listed = read_manifest(out)
    assert set(listed["files"]) == {"runs/0.json", "runs/1.json", "runs/2.json"} and listed["open"] is False


@pytest.mark.requires_dask
@pytest.mark.requires_pyarrow
def test_a_study_folder_of_an_earlier_ehm_says_it_cannot_be_resumed_and_what_to_do(tmp_path, capsys):
    """Review case: a study folder written by an earlier ehm (no manifest) was refused with "give a new or empty
    folder" only, with no word of why a study folder of ehm's own could not be resumed.  It is known by its
    content (a run record in runs/), and the sentence says what to do; nothing in it is touched.  A SYNTHETIC
    one-run study whose manifest is taken away, as an earlier ehm left it."""
    study = tmp_path / "study.toml"
    study.write_text(TINY_STUDY)
    res = tmp_path / "res"
    assert main(["batch", str(study), "--out", str(res), "--workers", "1"]) == 0
    (res / MANIFEST_NAME).unlink()
    for rec in (res / "runs").iterdir():  # an earlier ehm's record: no folder id
        rec.write_text(json.dumps({k: v for k, v in json.loads(rec.read_text()).items() if k != "ehm_folder_id"}))
    before = _tree(res)
    capsys.readouterr()
    assert main(["batch", str(study), "--out", str(res), "--workers", "1"]) == 2
    assert _one_error_line(capsys.readouterr().err) == (
        f"ehm: error: {res} is a study folder of an earlier ehm, written before study folders carried a manifest "
        f"({MANIFEST_NAME}), so it cannot be resumed: ehm cannot tell the files it wrote there from any others; run "
        f"the study into a new folder, e.g. {tmp_path / 'res-new'} (the earlier results stay where they are).")
    assert _tree(res) == before
    # a folder of the user's own JSON files under runs/ is not taken for one
    (tmp_path / "mine" / "runs").mkdir(parents=True)
    (tmp_path / "mine" / "runs" / "a.json").write_text('{"my": "notes"}')
    assert main(["batch", str(study), "--out", str(tmp_path / "mine"), "--workers", "1"]) == 2
    assert "holds runs, which ehm did not write" in _one_error_line(capsys.readouterr().err)


def _hold_lock(folder, tmp_path):
    """A subprocess that holds ``folder_lock(folder)`` until killed (started once it holds it)."""
    import subprocess
    import sys

    import ehm

    code = ("import sys, time; from ehm.outputs.outdir import folder_lock\n"
            "with folder_lock(sys.argv[1]):\n    print('held', flush=True); time.sleep(60)\n")
    env = {**os.environ, "PYTHONPATH": str(Path(ehm.__file__).parents[1])}
    proc = subprocess.Popen([sys.executable, "-c", code, str(folder)], stdout=subprocess.PIPE, text=True, env=env)
    assert proc.stdout.readline().strip() == "held"
    return proc


def test_a_folder_held_by_another_process_is_refused_and_a_dead_holders_lock_is_taken_over(tmp_path):
    # issue 38: two 'ehm batch' studies into one folder both exited 0, the second's table replacing the first's
    import signal

    from ehm.outputs.outdir import folder_lock

    folder = tmp_path / "study"
    proc = _hold_lock(folder, tmp_path)
    try:
        with pytest.raises(InputError, match=rf"study is being written by another ehm command \(process {proc.pid} "):
            with folder_lock(folder):
                pass
    finally:
        proc.send_signal(signal.SIGKILL)  # dies holding it: its lock file stays, its lock goes with it
        proc.wait()
        proc.stdout.close()
    assert (tmp_path / ".study.ehm-lock").exists()
    with folder_lock(folder), folder_lock(folder):  # a stale lock is no lock; one process may nest
        assert str(os.getpid()) in (tmp_path / ".study.ehm-lock").read_text()
    assert not (tmp_path / ".study.ehm-lock").exists()  # removed on leaving


@pytest.mark.parametrize("command, out", [(["simulate", "--duration", "0.1"], "loop"),
                                          (["simulate", "--duration", "0.1"], "loop/run"),
                                          (["frf", "--method", "linear"], "loop/frf.csv")])
def test_an_output_path_through_a_symlink_loop_is_one_sentence(tmp_path, capsys, monkeypatch, command, out):
    """Issue 38: 'an --out that is a symlink loop' ended in pathlib's RuntimeError; one sentence now, before any
    work, naming the path, the loop and what to do."""
    monkeypatch.chdir(tmp_path)
    os.symlink("other", "loop")
    os.symlink("loop", "other")
    assert main([*command, "--out", out]) != 0
    err = capsys.readouterr().err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1, err
    assert f"ehm: error: {out}: " in err and "symbolic link loop" in err and "another output path" in err
    with pytest.raises(InputError, match="symbolic link loop"):
        ehm.RunResult.write(ehm.SeatedHuman().simulate(ehm.sine("z", 0.01, 0.1, 2.0)), "loop/run")
