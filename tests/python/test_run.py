# Runs from Python and reading run directories: the same results as the CLI, and physics in them.
import csv
import math

import numpy as np
import pytest

import furrow


def test_python_run_equals_cli_run(plate_runs):
    py, cl = plate_runs["py"], plate_runs["cli"]
    assert (py / "forces.csv").read_bytes() == (cl / "forces.csv").read_bytes()
    a, b = furrow.open_run(py), furrow.open_run(cl)
    assert a.run_json["steps"] == b.run_json["steps"]
    assert a.run_json["scene_hash"] == b.run_json["scene_hash"]
    assert a.frame_count == b.frame_count >= 4
    for i in (0, a.frame_count // 2, -1):
        fa, fb = a.frame(i), b.frame(i)
        assert fa.time_s == fb.time_s
        assert fa.fields == fb.fields
        for name in fa.fields:
            np.testing.assert_array_equal(fa[name], fb[name])
        np.testing.assert_array_equal(fa.active, fb.active)


def test_forces_are_forces_csv(plate_runs):
    run = furrow.open_run(plate_runs["cli"])
    with open(plate_runs["cli"] / "forces.csv") as f:
        rows = list(csv.DictReader(f))
    plate = run.forces["plate"]
    assert list(run.forces) == ["plate"]
    for col in ("t_s", "x_m", "y_m", "Fx_N_per_m", "Fy_N_per_m"):
        np.testing.assert_array_equal(plate[col], np.array([float(r[col]) for r in rows]))
    # the window mean run.json reports comes from the same samples: the plate's force lies between
    # the smallest and largest sample in the averaging window (travel 0.02..0.035 m)
    travel = plate["y_m"][0] - plate["y_m"]
    mean_fy = run.run_json["bodies"][0]["mean_force_N_per_m"][1]
    window = (travel >= 0.02) & (travel <= 0.035)
    assert window.sum() > 10
    assert plate["Fy_N_per_m"][window].min() <= mean_fy <= plate["Fy_N_per_m"][window].max()
    assert mean_fy > 0  # the bed pushes the descending plate up


def test_frames_carry_their_grid(plate_runs, small_plate):
    run = furrow.open_run(plate_runs["py"])
    f = run.frame(0)
    d = small_plate.to_dict()["domain"]
    assert f.dx_m == d["dx_m"]
    cells = lambda length_m: math.ceil(length_m / d["dx_m"] - 1e-9)  # the domain's cells, as the solver's grid
    assert f["pressure"].shape == (f.ny, f.nx) == (cells(d["height_m"]), cells(d["width_m"]))
    x, y = f.cell_centres_m()
    assert x[0] == pytest.approx(f.origin_m[0] + f.dx_m / 2)
    # the bed fills y < 0.2 m: material in every cell below, none above
    assert f.active[y < 0.2].all() and not f.active[y > 0.2].any()
    # a frame is written at the first step at or past each multiple of frame_interval_s
    times = run.frame_times_s()
    k = np.arange(len(times))
    assert np.all((times >= 0.1 * k - 1e-12) & (times < 0.1 * k + run.run_json["dt_max_s"]))


def test_stored_points_conserve_mass(plate_runs, small_plate):
    """Every frame's points carry the bed's mass, rho_g phi A (float storage: ~1e-7 per point)."""
    run = furrow.open_run(plate_runs["py"])
    rho_g, phi, area_m2 = 2520.0, 0.6, 0.4 * 0.2
    for i in (0, -1):
        p = run.particles(i)
        mass = np.sum(p["packing_fraction"].astype(float) * rho_g * p["volume_m2"].astype(float))
        assert mass == pytest.approx(rho_g * phi * area_m2, rel=1e-5)
    assert len(run.particles(-1)) == 4 * 20 * 10


def test_simulation_by_hand_matches_the_run(small_plate, plate_runs):
    """Stepping a Simulation gives the forces the run wrote, step for step (force_interval 0)."""
    sim = furrow.Simulation(small_plate)
    plate = furrow.open_run(plate_runs["py"]).forces["plate"]
    fy = []
    for k in range(700):  # the plate reaches the bed after ~400 steps
        sim.step()
        assert sim.time_s == pytest.approx(plate["t_s"][k], rel=1e-8)  # forces.csv's 9 digits
        fy.append(sim.bodies()[0]["force_N_per_m"]["y"])
    assert sim.bodies()[0]["name"] == "plate"
    assert np.count_nonzero(fy) > 100
    np.testing.assert_allclose(fy, plate["Fy_N_per_m"][:700], rtol=1e-8, atol=1e-12)


def test_hydrostatic_stress_of_a_settled_bed():
    """A settled bed carries its weight: above the floor's cell (whose points see the wall's half
    stencil) a point's vertical stress is rho g depth within half a cell's weight of material
    (where in its cell the point sits), and the floor holds the bed's weight."""
    dx, surface_m = 0.01, 0.1
    scene = furrow.new_scene("hydrostatic_bed", set={"domain.dx_m": dx, "solver.threads": 1})
    sim = furrow.Simulation(scene)
    rho, g = 2520.0 * 0.6, 9.81
    sim.step(1000)  # 60 ms: ~40 crossings of the bed by the elastic wave
    p = sim.particles()
    sigma_yy = -p["pressure_Pa"].astype(float) + p["syy_Pa"]
    above_floor_cell = p["y_m"] > dx
    depth = surface_m - p["y_m"][above_floor_cell]
    assert np.abs(sigma_yy[above_floor_cell] + rho * g * depth).max() < rho * g * dx / 2
    # the floor: the bed's weight, to the 3% of the engine's own test (the bed still rings a little)
    weight = sim.total_mass_kg_per_m * g
    assert weight == pytest.approx(rho * 0.2 * surface_m * g, rel=1e-6)
    assert -sim.wall_forces()[2]["y"] == pytest.approx(weight, rel=0.03)
