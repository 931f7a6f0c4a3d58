# Reading errors say what is missing and where.
import pytest

import furrow


def test_missing_run_directory(tmp_path):
    with pytest.raises(FileNotFoundError, match=f"{tmp_path / 'nope'}: no such run directory"):
        furrow.open_run(tmp_path / "nope")


def test_directory_without_run_json(tmp_path):
    with pytest.raises(FileNotFoundError, match="run.json: missing: not a finished run directory"):
        furrow.open_run(tmp_path)


def test_unknown_field_lists_the_stored_ones(plate_runs):
    f = furrow.open_run(plate_runs["py"]).frame(0)
    with pytest.raises(KeyError, match="no field 'temperature' in this frame; it holds .*pressure"):
        f["temperature"]
    assert "pressure" in f and "temperature" not in f


def test_frame_index_out_of_range(plate_runs):
    run = furrow.open_run(plate_runs["py"])
    n = run.frame_count
    with pytest.raises(IndexError, match=f"frame {n} out of range: the run stored {n} frame\\(s\\) \\(0..{n - 1}\\)"):
        run.frame(n)
    with pytest.raises(IndexError):
        run.particles(-n - 1)
    assert run.frame(-n).step == 0


def test_run_refuses_to_overwrite(plate_runs, small_plate):
    before = (plate_runs["py"] / "forces.csv").read_bytes()
    with pytest.raises(FileExistsError, match="already exists"):
        furrow.run(small_plate, plate_runs["py"])
    assert (plate_runs["py"] / "forces.csv").read_bytes() == before
