# furrow.sweep and furrow.study run the CLI's own drivers: on the same small scene they write the
# same run directories and the same tables as `furrow sweep` / `furrow study`, cell for cell apart
# from the columns that measure the machine (wall time, peak memory).
import csv
import json
import signal

import numpy as np
import pytest

import furrow
from conftest import cli, python

DX_M = ["0.02", "0.01"]  # two cheap rungs of the small plate
MACHINE_COLUMNS = {"wall_s", "predicted_wall_s", "peak_memory_MB"}


def cells(path):
    """The CSV's rows as text cells, the machine-dependent columns left out."""
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    keep = [k for k, name in enumerate(rows[0]) if name not in MACHINE_COLUMNS]
    return [[row[k] for k in keep] for row in rows]


def test_sweep_equals_the_cli(small_plate_file, tmp_path):
    events = []
    first = {"stop": True}

    def stop_once(e):  # the first run stops with a checkpoint; the same call again continues it
        events.append(e)
        if first["stop"] and e["event"] == "run_progress" and e["steps"] > 100:
            first["stop"] = False
            raise furrow.StopRun()

    out = tmp_path / "py"
    stopped = furrow.sweep(small_plate_file, vary={"domain.dx_m": [0.02, 0.01]}, out=out, progress=stop_once,
                           progress_interval_s=0)
    assert stopped.stopped and stopped.table is None
    assert "stopped" in [r["status"] for r in stopped.json["runs"]]
    py = furrow.sweep(small_plate_file, vary={"domain.dx_m": [0.02, 0.01]}, out=out, progress=events.append)
    assert py.status == 0 and not py.stopped and not py.failed
    assert {e["event"] for e in events} == {"run_progress", "run_done"}

    cli("sweep", small_plate_file, "--vary", "domain.dx_m=" + ",".join(DX_M), "--out", tmp_path / "cli", "--quiet")
    # the table, cell for cell (the wall time aside), and every run's forces byte for byte
    assert cells(out / "sweep.csv") == cells(tmp_path / "cli" / "sweep.csv")
    assert (out / "sweep.csv").read_bytes().split(b"\n")[0] == (tmp_path / "cli" / "sweep.csv").read_bytes().split(b"\n")[0]
    for run in py.json["runs"]:
        assert (out / run["dir"] / "forces.csv").read_bytes() == (tmp_path / "cli" / run["dir"] / "forces.csv").read_bytes()
    # the table as arrays: the swept values as numbers, one row per run
    np.testing.assert_array_equal(py.table["domain.dx_m"], [0.02, 0.01])
    assert list(py.table["status"]) == ["ok", "ok"]
    assert py.run(1).scene.to_dict()["domain"]["dx_m"] == 0.01


def test_study_equals_the_cli(small_plate_file, tmp_path):
    events = []
    py = furrow.study(small_plate_file, ladder={"domain.dx_m": [0.02, 0.01]}, out=tmp_path / "py",
                      progress=events.append)
    assert py.status == 0
    assert [e["event"] for e in events] == ["rung_start", "rung_done"] * 2
    cli("study", small_plate_file, "--ladder", "domain.dx_m=" + ",".join(DX_M), "--out", tmp_path / "cli", "--quiet")
    assert cells(tmp_path / "py" / "study.csv") == cells(tmp_path / "cli" / "study.csv")
    column = "drag_mean_N_per_m"
    assert column in py.table and np.all(np.isfinite(py.table[column]))
    assert (tmp_path / "py" / "study.md").is_file() and not (tmp_path / "py" / "study.png").exists()


def test_a_bad_vary_key_raises_with_its_json_path(small_plate_file, tmp_path):
    with pytest.raises(furrow.SceneError) as e:
        furrow.sweep(small_plate_file, vary={"domain.dxx_m": [0.02, 0.01]}, out=tmp_path / "bad")
    assert e.value.path == "/domain/dxx_m", str(e.value)
    assert "--vary domain.dxx_m=0.02,0.01" in str(e.value)
    assert not (tmp_path / "bad").exists()
    with pytest.raises(ValueError, match="--vary"):
        furrow.sweep(small_plate_file, vary=["domain.dx_m=0.02:0.01"], out=tmp_path / "bad")
    with pytest.raises(ValueError, match="quantity"):
        furrow.study(small_plate_file, ladder={"domain.dx_m": [0.02, 0.01]}, out=tmp_path / "bad", quantity="nope")


def test_ctrl_c_stops_a_sweep_with_checkpoints(small_plate_file, tmp_path):
    out = tmp_path / "sweep"
    p = python(f"import furrow\n"
               f"def progress(e):\n"
               f"    if e['event'] == 'run_progress': print('running', flush=True)\n"
               f"try:\n"
               f"    furrow.sweep(r'{small_plate_file}', vary={{'domain.dx_m': [0.02, 0.01]}}, out=r'{out}',\n"
               f"                 set={{'solver.end_time_s': 1.5, 'solver.end_displacement_m': None}},\n"
               f"                 progress=progress, progress_interval_s=0.05)\n"
               f"except KeyboardInterrupt as e:\n"
               f"    print('interrupted', e)\n")
    line = p.stdout.readline().strip()
    assert line == "running", p.communicate()[1]  # a run is in the solver's loop
    p.send_signal(signal.SIGINT)
    stdout, stderr = p.communicate(timeout=120)
    assert p.returncode == 0, stderr
    assert any(l.startswith("interrupted furrow sweep stopped") for l in stdout.splitlines()), stdout
    runs = json.loads((out / "sweep.json").read_text())["runs"]
    assert {r["status"] for r in runs} <= {"stopped", "ok"} and "stopped" in {r["status"] for r in runs}
    assert not (out / "sweep.csv").exists()
    assert any((out / (r["dir"] + ".partial-" + str(p.pid)) / "checkpoint").is_dir() for r in runs)
