# Scenes from Python: the CLI's templates, validation errors with the CLI's message, estimates.
import json

import pytest

import furrow
from conftest import SMALL_PLATE, cli


def test_templates_are_the_clis():
    names = [line.split()[0] for line in cli("templates").stdout.splitlines() if line.strip()]
    assert list(furrow.templates()) == names
    assert "plate_intrusion" in names


def test_bad_scene_raises_with_the_json_path_and_the_clis_message(tmp_path):
    scene = json.loads(furrow.new_scene("hydrostatic_bed").text())
    scene["domain"]["dx_m"] = -0.01
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(scene))
    with pytest.raises(furrow.SceneError) as e:
        furrow.load_scene(path)
    assert e.value.path == "/domain/dx_m"
    assert e.value.file == str(path)
    assert isinstance(e.value, ValueError)
    r = cli("validate", path, check=False)
    assert r.returncode == 1
    assert r.stderr == f"furrow validate: error: {e.value}\n"


def test_an_override_error_names_the_override():
    with pytest.raises(furrow.SceneError) as e:
        furrow.new_scene("hydrostatic_bed", set={"solver.cfl": 7})
    assert e.value.path == "/solver/cfl"
    assert "solver.cfl=7" in e.value.note
    r = cli("new", "hydrostatic_bed", "-o", "-", "--set", "solver.cfl=7", check=False)
    assert r.returncode == 1
    assert r.stderr == f"furrow new: error: {e.value}\n"


def test_unknown_key_and_template():
    with pytest.raises(furrow.SceneError) as e:
        furrow.scene_from_dict({"schema_version": 1, "domian": {}})
    assert e.value.path == "/domian"
    with pytest.raises(ValueError, match="unknown template 'plate'; available: .*plate_intrusion"):
        furrow.new_scene("plate")


def test_scene_round_trip_and_estimate(small_plate):
    d = small_plate.to_dict()
    assert d["domain"]["dx_m"] == SMALL_PLATE["domain.dx_m"]
    again = furrow.scene_from_dict(d)
    assert again.hash() == small_plate.hash()
    e = small_plate.estimate()
    # a bed of 0.4 x 0.2 m at dx 0.02 m with 2 x 2 points per cell
    assert e["particles"] == round(0.4 * 0.2 / 0.02**2) * 4
    # steps: the time to travel 0.04 m at 0.1 m/s over the CFL time step
    assert e["end_time_s"] == pytest.approx(0.04 / 0.1, rel=1e-9)
    assert e["steps"] == pytest.approx(e["end_time_s"] / e["time_step_s"], abs=1)
    assert e["predicted_wall_s"] is None or e["predicted_wall_s"] > 0


def test_validate_applies_the_size_limits():
    huge = furrow.new_scene("hydrostatic_bed", set={"domain.dx_m": 2e-5}, allow_large=True)
    with pytest.raises(furrow.SceneError):
        huge.validate()
    assert huge.validate(allow_large=True) is huge
