# A run stopped from Python leaves a checkpoint that resumes bit-identically, in Python or with
# `furrow run --resume`: the CLI and the module name the same build (a hash of the engine library
# both link), so the CLI takes the module's checkpoint as its own.
import json
import os
import signal

import pytest

import furrow
from conftest import cli, python

STOP_AT_STEP = 300


def stop_at(step):
    def progress(p):
        if p["steps"] >= step:
            raise furrow.StopRun()
    return progress


def test_stop_and_resume_in_python(small_plate, plate_runs, tmp_path):
    out = tmp_path / "run"
    s = furrow.run(small_plate, out, progress=stop_at(STOP_AT_STEP), progress_interval_s=0)
    assert s["stopped"] and s["run_json"]["steps"] == STOP_AT_STEP
    assert not out.exists() and os.path.isdir(os.path.join(s["out_dir"], "checkpoint"))
    s = furrow.run(small_plate, out, resume=True)
    assert s["resumed_from_step"] == STOP_AT_STEP and not s["stopped"]
    assert (out / "forces.csv").read_bytes() == (plate_runs["cli"] / "forces.csv").read_bytes()


def test_stopped_in_python_resumed_by_the_cli(small_plate_file, plate_runs, tmp_path):
    out = tmp_path / "run"
    # another process, so the CLI does not take the checkpoint for one still being written
    p = python(f"import furrow\n"
               f"def progress(p):\n"
               f"    if p['steps'] >= {STOP_AT_STEP}: raise furrow.StopRun()\n"
               f"s = furrow.run(r'{small_plate_file}', r'{out}', progress=progress, progress_interval_s=0)\n"
               f"print(s['stopped'], s['run_json']['steps'])\n")
    stdout, stderr = p.communicate(timeout=120)
    assert p.returncode == 0, stderr
    assert stdout.split() == ["True", str(STOP_AT_STEP)]
    r = cli("run", small_plate_file, "--out", out, "--resume", "--no-movies")
    assert f"resumed from the checkpoint at step {STOP_AT_STEP}" in r.stderr
    assert (out / "forces.csv").read_bytes() == (plate_runs["cli"] / "forces.csv").read_bytes()
    run_json = json.loads((out / "run.json").read_text())
    assert "resumed_across_builds" not in run_json


def test_the_cli_and_the_module_are_one_build(plate_runs):
    py, cli_run = (json.loads((plate_runs[k] / "run.json").read_text())["build"] for k in ("py", "cli"))
    assert py == cli_run and py.startswith(furrow.__version__ + "-")


def test_ctrl_c_stops_with_a_checkpoint(small_plate_file, tmp_path):
    out = tmp_path / "run"
    p = python(f"import furrow, sys\n"
               f"def progress(p):\n"
               f"    print('running', flush=True)\n"
               f"try:\n"
               f"    furrow.run(furrow.load_scene(r'{small_plate_file}', set={{'solver.end_time_s': 1.5,\n"
               f"               'solver.end_displacement_m': None}}), r'{out}', progress=progress, progress_interval_s=0.05)\n"
               f"except KeyboardInterrupt as e:\n"
               f"    print('interrupted', e)\n")
    line = p.stdout.readline().strip()
    assert line == "running", p.communicate()[1]  # the solver is in its loop (~10 s of it)
    p.send_signal(signal.SIGINT)
    stdout, stderr = p.communicate(timeout=120)
    assert p.returncode == 0, stderr
    line = [l for l in stdout.splitlines() if l.startswith("interrupted")][0]
    assert "checkpoint in" in line and "resume=True" in line
    partial = line.split("checkpoint in ")[1].split("/checkpoint")[0]
    assert os.path.isdir(os.path.join(partial, "checkpoint"))
    assert not out.exists()
