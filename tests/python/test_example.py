# The worked example (app/python/examples/plate_force_depth.py) end to end on the small plate: its
# run and its numbers are the CLI's run of the same scene, and its two Matplotlib figures are drawn.
import json
import os
import struct
import subprocess
import sys

import numpy as np

from conftest import SMALL_PLATE

EXAMPLE = os.path.join(os.path.dirname(__file__), "..", "..", "app", "python", "examples", "plate_force_depth.py")


def png_size(path):
    """(width, height) from a PNG's header."""
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", f"{path}: not a PNG"
    return struct.unpack(">II", data[16:24])


def test_worked_example(plate_runs, tmp_path):
    # the example's plots are part of what is tested: without Matplotlib this fails, not skips
    # (.ci/setup.sh installs Debian's python3-matplotlib)
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        raise AssertionError(f"{sys.executable} has no matplotlib: install python3-matplotlib (.ci/setup.sh does)")
    sets = [f"--set={k}={json.dumps(v)}" for k, v in SMALL_PLATE.items()]
    out = tmp_path / "example"
    r = subprocess.run([sys.executable, EXAMPLE, str(out), *sets], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    cli_dir = plate_runs["cli"]
    assert (out / "run" / "forces.csv").read_bytes() == (cli_dir / "forces.csv").read_bytes()
    table = np.loadtxt(out / "force_depth.csv", delimiter=",", skiprows=1)
    cli_forces = np.genfromtxt(cli_dir / "forces.csv", delimiter=",", names=True, dtype=None, encoding=None)
    np.testing.assert_array_equal(table[:, 1], cli_forces["Fy_N_per_m"])
    # depth of the plate's bottom: the bed's surface (0.2 m) less the bottom's height (centre - 0.01 m)
    np.testing.assert_allclose(table[:, 0], 0.2 - (cli_forces["y_m"] - 0.01), rtol=0, atol=1e-15)
    mean = json.loads((cli_dir / "run.json").read_text())["bodies"][0]["mean_force_N_per_m"][1]
    assert f"mean force over the averaging window: {mean:.17g} N/m" in r.stdout
    # the figures at the sizes the script asks for (inches x 150 dpi), with something drawn in them
    assert png_size(out / "force_depth.png") == (750, 525)
    assert png_size(out / "pressure.png") == (900, 525)
    for name in ("force_depth.png", "pressure.png"):
        assert (out / name).stat().st_size > 10000, name  # a blank 750 x 525 PNG is ~3 kB
