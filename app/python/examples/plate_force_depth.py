"""Worked example: the paper's case 2 (a plate pushed into glass beads) at the template's preview
dx, from Python: run it, plot the force against depth, show the last frame's pressure.

    PYTHONPATH=build/python python3 app/python/examples/plate_force_depth.py OUT [--set KEY=VALUE ...]

Writes OUT/run (the run directory, as `furrow run` writes it), OUT/force_depth.csv and, when
Matplotlib is installed, OUT/force_depth.png and OUT/pressure.png. 34 s on a shared 2-core
machine (2026-12-05).
"""
import argparse
import os
import sys

import numpy as np

import furrow


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("out", help="output directory (must not exist)")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", help="scene override, as furrow run --set")
    args = ap.parse_args()

    scene = furrow.new_scene("plate_intrusion", set=args.set)
    e = scene.estimate()
    print(f"{scene.name}: {e['particles']} points, {e['steps']} steps")
    os.makedirs(args.out)
    summary = furrow.run(scene, os.path.join(args.out, "run"),
                         progress=lambda p: print(f"\r{100 * p['fraction']:5.1f} %", end="", file=sys.stderr))
    print(file=sys.stderr)

    run = furrow.open_run(summary["out_dir"])
    plate = run.forces["plate"]
    s = scene.to_dict()
    surface_m = s["beds"][0]["max_m"][1]
    half_height_m = s["bodies"][0]["shape"]["size_m"][1] / 2
    depth_m = surface_m - (plate["y_m"] - half_height_m)  # of the plate's bottom face
    force = plate["Fy_N_per_m"]
    np.savetxt(os.path.join(args.out, "force_depth.csv"), np.column_stack([depth_m, force]), delimiter=",",
               header="depth_m,Fy_N_per_m", comments="", fmt="%.17g")
    mean = run.run_json["bodies"][0]["mean_force_N_per_m"][1]
    print(f"mean force over the averaging window: {mean:.17g} N/m; at the deepest point {force[-1]:.4g} N/m "
          f"({depth_m[-1] * 1e3:.1f} mm)")

    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("no Matplotlib (apt install python3-matplotlib): plots skipped")
        return
    fig, ax = plt.subplots(figsize=(5, 3.5))
    ax.plot(depth_m * 1e3, force, lw=0.8)
    ax.set_xlabel("depth of the plate's bottom (mm)")
    ax.set_ylabel("vertical force (N/m)")
    fig.tight_layout()
    fig.savefig(os.path.join(args.out, "force_depth.png"), dpi=150)

    frame = run.frame(-1)
    fig, ax = plt.subplots(figsize=(6, 3.5))
    im = ax.imshow(np.where(frame.active, frame["pressure"], np.nan), origin="lower", extent=frame.extent_m())
    for b in frame.bodies:
        ax.fill(b["outline_m"][:, 0], b["outline_m"][:, 1], color="0.3")
    fig.colorbar(im, label="pressure (Pa)")
    ax.set_title(f"t = {frame.time_s:.2f} s")
    fig.tight_layout()
    fig.savefig(os.path.join(args.out, "pressure.png"), dpi=150)
    print(f"plots in {args.out}")


if __name__ == "__main__":
    main()
