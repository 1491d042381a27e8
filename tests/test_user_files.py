"""ehm never deletes a file it did not write: an output folder is replaced only when ehm's manifest lists every file
in it.  Every file here is SYNTHETIC (random bytes or short generated runs).
"""

from __future__ import annotations

import errno
import hashlib
import json
from pathlib import Path

import pytest

import ehm
from ehm import runfiles
from ehm.cli import main
from ehm.errors import InputError
from ehm.io import MANIFEST_NAME, read_manifest
from ehm.outdir import RunFolder


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
