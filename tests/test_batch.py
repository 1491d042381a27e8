"""Batch studies on Dask: a tidy table, recorded failures, resuming."""

from __future__ import annotations

import json

import pytest

pytest.importorskip("dask.distributed")
pq = pytest.importorskip("pyarrow.parquet")

from ehm.batch import load_study, run_study  # noqa: E402
from ehm.cli import main  # noqa: E402
from ehm.errors import InputError  # noqa: E402

STUDY = """
[study]
name = "small"
compute = ["transmissibility"]
[people]
stature_m = [1.60, 1.85]
mass_kg = [55.0, 90.0]
[grid]
"joints.t12.z.stiffness_N_per_m" = [15000.0, -1.0]
[input]
axes = ["z"]
"""


def test_study_runs_records_failures_and_resumes(tmp_path, capsys):
    path = tmp_path / "study.toml"
    path.write_text(STUDY)
    name, specs = load_study(path)
    assert name == "small" and len(specs) == 4 and len({s.run_id for s in specs}) == 4
    out = tmp_path / "res"
    res = run_study(specs, out, workers=2)
    assert res["ran"] == 4 and res["failed"] == 2  # the negative stiffness fails, the study goes on
    table = pq.read_table(out / "results.parquet").to_pylist()
    errors = [r for r in table if r["output"] == "error"]
    assert len(errors) == 2 and all("must not be negative" in r["error"] for r in errors)
    ok = [r for r in table if r["output"] == "seat_z->head_z.peak_hz"]
    assert len(ok) == 2 and {r["stature_m"] for r in ok} == {1.60, 1.85}
    # the taller person's vertical mode is lower (Hof scaling: f ~ 1 / sqrt(L))
    by_height = {r["stature_m"]: r["value"] for r in ok}
    assert by_height[1.85] < by_height[1.60]
    # resume: nothing is redone; a lost record is redone alone
    assert run_study(specs, out, workers=1)["ran"] == 0
    (out / "runs" / f"{specs[0].point_id}.json").unlink()
    assert run_study(specs, out, workers=1)["ran"] == 1
    assert len(pq.read_table(out / "results.parquet").to_pylist()) == len(table)
    # failures are kept on resume unless retried; a lost worker's run is always redone
    res = run_study(specs, out, workers=1, retry_failed=True)
    assert res["ran"] == 2 and res["failed"] == 2
    failed = next(s for s in specs if s.run_id == errors[0]["run_id"])
    rec_path = out / "runs" / f"{failed.point_id}.json"
    rec = json.loads(rec_path.read_text())
    rec_path.write_text(json.dumps({**rec, "error": "worker failed: connection lost"}))
    assert run_study(specs, out, workers=1)["ran"] == 1
    assert "must not be negative" in json.loads(rec_path.read_text())["error"]


def test_bad_study_files(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text("[study]\ncompute = ['dance']\n")
    with pytest.raises(InputError, match="compute names 'dance'"):
        load_study(bad)
    bad.write_text("[people]\nstature_m = [1.6, 1.7]\nmass_kg = [60.0]\n")
    with pytest.raises(InputError, match="equal length"):
        load_study(bad)
    bad.write_text('[grid]\n"joints.t12.q" = [1.0]\n')  # refused before any cluster starts
    with pytest.raises(InputError, match="not a parameter"):
        load_study(bad)
    for text, words in (('[study]\ncompute = "comfort"\n', "compute must be a list"),
                        ('[input]\nmethod = "tim"\n', "method 'tim'"),
                        ('[input]\naxes = ["x", "w"]\n', "axes"),
                        ('[input]\ndrive = "nowhere.csv"\n', "drive 'nowhere.csv'"),
                        ('[input]\nduration_s = -2\n', "duration_s -2")):
        bad.write_text(text)
        with pytest.raises(InputError, match=words):
            load_study(bad)
    bad.write_text("[input]\nduration = 3\n")
    with pytest.raises(InputError, match="unknown key 'duration'"):
        load_study(bad)


def test_cli_batch(tmp_path, capsys):
    path = tmp_path / "study.toml"
    path.write_text(STUDY.replace(", -1.0", ""))
    assert main(["batch", str(path), "--out", str(tmp_path / "r"), "--workers", "1", "--csv"]) == 0
    lines = (tmp_path / "r" / "results.csv").read_text().splitlines()
    assert lines[0].startswith("\"run_id\",\"output\",\"value\",\"error\"")
    # 2 people x 1 parameter value x 6 outputs (peak frequency and gain of pelvis, trunk, head on seat z)
    assert len(lines) == 1 + 2 * 6 and not any("error" in ln.split(",")[1] for ln in lines[1:])


def test_fit_evaluates_candidates_on_a_dask_cluster():
    # The transfer-function fit takes an executor: here a local Dask cluster's.  SYNTHETIC gains made by
    # the model with the T12 compression stiffness at 21 kN/m are fitted from the default 15 kN/m.
    import numpy as np
    from dask.distributed import Client, LocalCluster

    import ehm
    from ehm.fit import fit
    from ehm.frf import FrfTable, linear_frf
    from ehm.params import Parameters

    human = ehm.SeatedHuman(params=Parameters.load().with_values({"joints.t12.z.stiffness_N_per_m": 21000.0}))
    human.settle()
    table = linear_frf(human, "z", freq_hz=np.arange(0.5, 12.01, 0.5))
    data = FrfTable({k: v for k, v in table.curves.items() if k[2] in ("z", "pitch")}, method="measured")
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, \
            Client(cluster) as client:
        result = fit(data, free=["joints.t12.z.stiffness_N_per_m"], time_check=False,
                     executor=client.get_executor())
    assert result.final["joints.t12.z.stiffness_N_per_m"] == pytest.approx(21000.0, rel=0.01)
