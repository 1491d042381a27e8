"""Tests for ehm.files: atomic text, CSV and JSON writers."""

from __future__ import annotations

import json
import os
import stat

import numpy as np
import pytest

from ehm.errors import InputError
from ehm.files import write_csv_atomic, write_json_atomic, write_text_atomic


def listing(directory) -> list[str]:
    return sorted(p.name for p in directory.iterdir())


def test_text_written_and_parent_created(tmp_path):
    path = tmp_path / "a" / "b" / "note.txt"
    write_text_atomic(path, "hello\nworld\n")
    assert path.read_text(encoding="utf-8") == "hello\nworld\n"
    assert listing(path.parent) == ["note.txt"]


def test_text_replaces_existing_and_keeps_mode(tmp_path):
    path = tmp_path / "note.txt"
    path.write_text("old")
    os.chmod(path, 0o640)
    write_text_atomic(str(path), "new")
    assert path.read_text() == "new"
    assert stat.S_IMODE(path.stat().st_mode) == 0o640
    assert listing(tmp_path) == ["note.txt"]


def test_text_new_file_has_umask_permissions(tmp_path):
    path = tmp_path / "note.txt"
    write_text_atomic(path, "x")
    mask = os.umask(0o022)
    os.umask(mask)
    assert stat.S_IMODE(path.stat().st_mode) == 0o666 & ~mask


def test_text_failure_leaves_no_temp_and_target_untouched(tmp_path):
    target = tmp_path / "sub"
    target.mkdir()  # a directory where the file should go: os.replace fails
    with pytest.raises(InputError, match=r"sub: cannot write file"):
        write_text_atomic(target, "text")
    assert target.is_dir()
    assert listing(tmp_path) == ["sub"]


def test_text_rejects_non_str(tmp_path):
    with pytest.raises(InputError, match=r"must be a str, got bytes"):
        write_text_atomic(tmp_path / "x.txt", b"bytes")
    assert listing(tmp_path) == []


def test_text_parent_is_a_file(tmp_path):
    (tmp_path / "plain").write_text("")
    with pytest.raises(InputError, match=r"cannot create directory"):
        write_text_atomic(tmp_path / "plain" / "x.txt", "text")


def test_csv_content_and_precision(tmp_path):
    path = tmp_path / "out" / "table.csv"
    data = np.array([[0.0, 1.0 / 3.0, -2.5e-7], [0.001, 123456.789, 7.0]])
    write_csv_atomic(path, ["time_s", "a_mps2", "b"], data)
    lines = path.read_text().splitlines()
    assert lines[0] == "time_s,a_mps2,b"
    assert lines[1] == "0,0.333333333,-2.5e-07"
    assert lines[2] == "0.001,123456.789,7"
    back = np.loadtxt(path, delimiter=",", skiprows=1)
    # 9 significant digits: |x - read back| <= half a unit in the 9th digit <= 5e-9 |x| (1/3 is off by exactly
    # 1e-9 of itself, which rtol=1e-9 passed only by round-off in the comparison)
    np.testing.assert_allclose(back, data, rtol=5e-9)
    assert listing(path.parent) == ["table.csv"]


def test_csv_custom_format_full_precision(tmp_path):
    path = tmp_path / "t.csv"
    data = np.array([[np.pi, np.e]])
    write_csv_atomic(path, ["a", "b"], data, fmt="%.17g")
    back = np.loadtxt(path, delimiter=",", skiprows=1)
    np.testing.assert_array_equal(back, data[0])


def test_csv_header_only(tmp_path):
    path = tmp_path / "empty.csv"
    write_csv_atomic(path, ["a", "b"], np.empty((0, 2)))
    assert path.read_text() == "a,b\n"


@pytest.mark.parametrize(
    ("header", "data", "pattern"),
    [
        (["a", "b"], np.zeros((2, 3)), r"header has 2 column\(s\) but the data has 3"),
        (["a"], np.zeros(3), r"must be a 2-D array"),
        (["a", "b"], [[0.0, np.nan]], r"row 0, column b is nan"),
        (["a", "b"], [[0.0, 1.0], [np.inf, 1.0]], r"row 1, column a is inf"),
        (["a", "b"], [["x", "y"]], r"numeric 2-D array"),
        (["a", "b,c"], np.zeros((1, 2)), r"must not contain a comma"),
        ("ab", np.zeros((1, 2)), r"must be a list of column names"),
    ],
)
def test_csv_errors_leave_nothing(tmp_path, header, data, pattern):
    path = tmp_path / "bad.csv"
    with pytest.raises(InputError, match=pattern):
        write_csv_atomic(path, header, data)
    assert listing(tmp_path) == []


def test_csv_failure_keeps_previous_file(tmp_path):
    path = tmp_path / "keep.csv"
    write_csv_atomic(path, ["a"], [[1.0]])
    with pytest.raises(InputError):
        write_csv_atomic(path, ["a"], [[np.nan]])
    assert path.read_text() == "a\n1\n"
    assert listing(tmp_path) == ["keep.csv"]


def test_json_numpy_conversion(tmp_path):
    path = tmp_path / "deep" / "r.json"
    obj = {
        "n": np.int64(3),
        "x": np.float32(0.5),
        "flag": np.bool_(True),
        "arr": np.arange(3.0),
        "matrix": np.eye(2, dtype=int),
        "tuple": (1, "two"),
        "nested": {"list": [np.float64(1.25), None]},
        7: "int key",
    }
    write_json_atomic(path, obj)
    text = path.read_text()
    assert text.endswith("\n")
    assert '\n  "n": 3' in text  # indent=2
    back = json.loads(text)
    assert back == {
        "n": 3,
        "x": 0.5,
        "flag": True,
        "arr": [0.0, 1.0, 2.0],
        "matrix": [[1, 0], [0, 1]],
        "tuple": [1, "two"],
        "nested": {"list": [1.25, None]},
        "7": "int key",
    }
    assert listing(path.parent) == ["r.json"]


@pytest.mark.parametrize(
    ("obj", "pattern"),
    [
        ({"a": float("nan")}, r"value at obj\['a'\] is nan; JSON allows only finite numbers"),
        ({"a": [1.0, np.float64("inf")]}, r"value at obj\['a'\]\[1\] is inf"),
        ({"a": np.array([0.0, np.nan])}, r"value at obj\['a'\]\[1\] is nan"),
        ({"a": {1, 2}}, r"value at obj\['a'\] has type set"),
        ({"a": 1j}, r"has type complex"),
        ({(1, 2): 0}, r"key \(1, 2\)"),
    ],
)
def test_json_serialisation_failure_leaves_nothing(tmp_path, obj, pattern):
    path = tmp_path / "bad.json"
    with pytest.raises(InputError, match=pattern):
        write_json_atomic(path, obj)
    assert listing(tmp_path) == []


def test_json_failure_keeps_previous_file(tmp_path):
    path = tmp_path / "r.json"
    write_json_atomic(path, {"ok": 1})
    with pytest.raises(ValueError):  # InputError is a ValueError
        write_json_atomic(path, {"ok": float("nan")})
    assert json.loads(path.read_text()) == {"ok": 1}
    assert listing(tmp_path) == ["r.json"]


def test_json_self_reference(tmp_path):
    obj: list = []
    obj.append(obj)
    with pytest.raises(InputError, match=r"refers to itself"):
        write_json_atomic(tmp_path / "loop.json", obj)
    assert listing(tmp_path) == []


def test_figures_and_run_folders_get_umask_permissions(tmp_path):
    # Figures (plotting) go through replace_atomically, run folders through outdir.RunFolder: new files and
    # folders get the permissions any new file or folder gets (0o666 / 0o777 minus the umask), not the private
    # 0o600 / 0o700 of temporary files and folders.
    import matplotlib.pyplot as plt

    from ehm.outputs.outdir import RunFolder
    from ehm.outputs.plotting import _save

    old = os.umask(0o022)
    try:
        fig = plt.figure()
        _save(fig, tmp_path / "f.png")
        with RunFolder(tmp_path / "run") as tmp:
            np.savez_compressed(tmp / "poses.npz", a=np.arange(3))
    finally:
        os.umask(old)
    assert stat.S_IMODE((tmp_path / "f.png").stat().st_mode) == 0o644
    assert stat.S_IMODE((tmp_path / "run").stat().st_mode) == 0o755
    assert stat.S_IMODE((tmp_path / "run" / "poses.npz").stat().st_mode) == 0o644
    assert np.load(tmp_path / "run" / "poses.npz")["a"].tolist() == [0, 1, 2]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["f.png", "run"]


def test_replace_atomically_failure_leaves_nothing(tmp_path):
    from ehm.files import replace_atomically

    def fail(tmp):
        with open(tmp, "w") as fh:
            fh.write("half")
        raise OSError(28, "No space left on device")

    with pytest.raises(InputError, match=r"out\.bin: cannot write the table \(No space left on device\)"):
        replace_atomically(tmp_path / "out.bin", fail, "the table")
    assert list(tmp_path.iterdir()) == []
