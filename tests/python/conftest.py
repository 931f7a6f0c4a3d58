# Shared by the furrow module's tests: the CLI built beside the module, and a small plate scene
# (the plate_intrusion template at dx 20 mm in a 0.4 x 0.25 m box: ~800 points, ~2000 steps).
import os
import subprocess
import sys

import pytest

import furrow

CLI = os.environ.get("FURROW_CLI", "")

SMALL_PLATE = {
    "name": "small_plate",
    "domain.width_m": 0.4, "domain.height_m": 0.25, "domain.dx_m": 0.02,
    "beds.0.max_m": [0.4, 0.2],
    "bodies.0.start_m": [0.2, 0.215],
    "solver.end_displacement_m": 0.04, "solver.threads": 1,
    "outputs.frame_interval_s": 0.1, "outputs.points": True,
    "outputs.average_window.from_m": 0.02, "outputs.average_window.to_m": 0.035,
}


def cli(*args, check=True):
    """Runs the furrow CLI; returns the CompletedProcess (text)."""
    assert CLI, "FURROW_CLI is not set (ctest sets it to the furrow binary)"
    r = subprocess.run([CLI, *map(str, args)], capture_output=True, text=True)
    if check and r.returncode != 0:
        raise AssertionError(f"furrow {' '.join(map(str, args))} exited {r.returncode}:\n{r.stderr}")
    return r


def python(code, **kwargs):
    """Runs `code` in a new interpreter that imports the same furrow package."""
    return subprocess.Popen([sys.executable, "-c", code], env=dict(os.environ), text=True,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, **kwargs)


@pytest.fixture(scope="session")
def small_plate():
    return furrow.new_scene("plate_intrusion", set=SMALL_PLATE)


@pytest.fixture(scope="session")
def small_plate_file(small_plate, tmp_path_factory):
    path = tmp_path_factory.mktemp("scene") / "small_plate.json"
    small_plate.save(path)
    return path


@pytest.fixture(scope="session")
def plate_runs(small_plate, small_plate_file, tmp_path_factory):
    """The small plate run twice: by furrow.run and by `furrow run` ({"py": dir, "cli": dir})."""
    root = tmp_path_factory.mktemp("runs")
    furrow.run(small_plate, root / "py")
    cli("run", small_plate_file, "--out", root / "cli", "--no-movies", "--quiet")
    return {"py": root / "py", "cli": root / "cli"}
