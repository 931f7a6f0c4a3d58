"""Furrow from Python: load and run scenes, step a simulation by hand, read run directories.

Everything is computed by the same C++ engine as the `furrow` CLI (the extension furrow._furrow);
this file only arranges its results for notebooks. See app/python/README.md.
"""
import csv
import json
import os
import shutil
import warnings

import numpy as np

from . import _furrow

__version__ = _furrow.version
SceneError = _furrow.SceneError  # ValueError; .file, .path (JSON pointer), .value, .expected, .note


class StopRun(Exception):
    """Raise from a progress callback to stop a run: furrow.run then returns its summary with
    stopped=True (the checkpoint in summary["out_dir"] continues with resume=True or
    `furrow run --resume`). Stops a sweep or a study the same way."""


def templates():
    """The scene templates built in: {name: description}."""
    return dict(_furrow.templates())


def fields():
    """The fields a run can store: [{name, unit, label, vector}]."""
    return _furrow.fields()


def _overrides(set):
    """{key.path: value} -> the CLI's --set strings (values written as JSON)."""
    if set is None:
        return []
    if isinstance(set, dict):
        return [f"{k}={json.dumps(v)}" for k, v in set.items()]
    return list(set)  # already "key=value" strings


class Scene:
    """A validated scene (immutable). Build one with load_scene, new_scene or scene_from_dict."""

    def __init__(self, native):
        self._s = native

    name = property(lambda self: self._s.name)
    source = property(lambda self: self._s.source, doc="the file or template it came from")

    def to_dict(self):
        """The resolved scene, every default filled in."""
        return json.loads(self._s.to_json())

    def text(self):
        """The resolved scene as the CLI writes scene.json."""
        return self._s.text()

    def save(self, path):
        """Writes the resolved scene to `path`, which must not exist (written beside it, then linked
        into place: never half a file, never over another)."""
        path = os.fspath(path)
        tmp = f"{path}.tmp-{os.getpid()}"
        with open(tmp, "w") as f:
            f.write(self.text())
        try:
            os.link(tmp, path)  # fails if path exists
        finally:
            os.unlink(tmp)

    def with_set(self, set):
        """A new scene with `set` overrides applied (errors name the override)."""
        return Scene(_furrow.parse_scene(self._s.to_json(), self.source, _overrides(set), True))

    def validate(self, allow_large=False):
        """Validates again (including the size limits unless allow_large); raises SceneError."""
        _furrow.parse_scene(self._s.to_json(), self.source, [], allow_large)
        return self

    def estimate(self):
        """particles, steps, time_step_s, end_time_s, particle_steps, threads, and predicted_wall_s
        from this machine's `furrow bench` calibration (None without one; predicted_how says why)."""
        return self._s.estimate()

    def hash(self):
        """run.json's scene_hash for a run of this scene."""
        return self._s.hash()

    def __repr__(self):
        return f"<furrow.Scene {self.name!r} from {self.source}>"


def load_scene(path, set=None, allow_large=False):
    """A scene file, with `set` = {"domain.dx_m": 0.005, ...} applied as --set would.
    Raises SceneError with the CLI's message (file, JSON path, value, expectation)."""
    return Scene(_furrow.load_scene(os.fspath(path), _overrides(set), allow_large))


def new_scene(template, set=None, allow_large=False):
    """A scene from a built-in template (furrow.templates()), as `furrow new`."""
    text = _furrow.template_text(template)
    if text is None:
        raise ValueError(f"unknown template '{template}'; available: {', '.join(templates())}")
    return Scene(_furrow.parse_scene(text, "template " + template, _overrides(set), allow_large))


def scene_from_dict(d, set=None, allow_large=False, source="<dict>"):
    """A scene from a dict as a scene file would hold it."""
    return Scene(_furrow.parse_scene(json.dumps(d), source, _overrides(set), allow_large))


def run(scene, out, threads=None, progress=None, progress_interval_s=0.5, force=False, paraview=True,
        checkpoint_every_min=30, resume=False, resume_any_build=False):
    """Runs `scene` into the run directory `out` (what `furrow run` writes, without movies: render
    them with `furrow render`). The solver runs with the GIL released; `progress(dict)` is called
    every progress_interval_s with fraction, time_s, steps, wall_s, eta_s, particles, dt_s.
    Ctrl-C, or an exception in `progress`, stops the run after the current step with a checkpoint
    (resume=True continues it bit-identically) and is raised again; furrow.StopRun instead returns
    the summary with stopped=True. Checkpoints also every checkpoint_every_min minutes of wall time
    (0: never), as the CLI's --checkpoint-every. Returns {run_json, bodies, out_dir, stopped,
    resumed_from_step}."""
    if isinstance(scene, (str, os.PathLike)):
        scene = load_scene(scene)
    if threads is not None:
        scene = scene.with_set({"solver.threads": int(threads)})
    out = os.fspath(out)
    if os.path.exists(out) and not force:
        raise FileExistsError(f"{out}: already exists; pass another out= for a new run or force=True to replace it")
    summary, error = _furrow.run(scene._s, out, force, paraview, progress, float(progress_interval_s),
                                 60.0 * checkpoint_every_min, resume, resume_any_build)
    if error is None or isinstance(error, StopRun):
        return summary
    if summary["stopped"] and isinstance(error, KeyboardInterrupt):
        raise KeyboardInterrupt(f"{scene.name}: stopped at step {summary['run_json']['steps']}; checkpoint in "
                                f"{summary['out_dir']}/checkpoint (furrow.run(..., resume=True) continues)") from error
    raise error


class Simulation:
    """A simulation stepped by hand: step(n), particles() (NumPy copies), bodies() (forces).
    Writes nothing; use run() for a run directory."""

    def __init__(self, scene):
        if isinstance(scene, (str, os.PathLike)):
            scene = load_scene(scene)
        self.scene = scene
        self._sim = _furrow.Simulation(scene._s)

    def step(self, n=1):
        """Advances n steps (fewer if the run's end comes first), the GIL released."""
        self._sim.step(int(n))
        return self

    finished = property(lambda self: self._sim.finished)
    time_s = property(lambda self: self._sim.time_s)
    steps = property(lambda self: self._sim.steps)
    dt_s = property(lambda self: self._sim.dt_s, doc="the last step's time step")
    total_mass_kg_per_m = property(lambda self: self._sim.total_mass_kg_per_m)
    kinetic_energy_J_per_m = property(lambda self: self._sim.kinetic_energy_J_per_m)

    def particles(self):
        """Copies of the material points' arrays: x_m, y_m, vx_m_s, vy_m_s, mass_kg_per_m,
        volume_m2, pressure_Pa, sxx_Pa, syy_Pa, sxy_Pa, szz_Pa (deviatoric), material, and
        phi_d, plastic_strain, strain_rate_1_s when the solver tracks them."""
        return self._sim.particles()

    def bodies(self):
        """[{name, position_m, velocity_m_s, force_N_per_m}]: the media's force on each body in the
        last step, N per metre out of plane."""
        return self._sim.bodies()

    def wall_forces(self):
        """Reaction force on the left, right, bottom and top walls in the last step (N/m)."""
        return self._sim.wall_forces()


class Frame:
    """One stored frame: frame[field] is an (ny, nx) array (velocity: (ny, nx, 2)); cell (j, i)
    is centred at origin_m + ((i + 1/2) dx_m, (j + 1/2) dx_m); `active` marks cells with material."""

    def __init__(self, path):
        d = _furrow.read_frame(path)
        self.path = path
        self._fields = d["fields"]
        self.active = d["active"]
        self.scene, self.step, self.time_s, self.dt_s = d["scene"], d["step"], d["time_s"], d["dt_s"]
        self.dx_m, self.origin_m, self.bodies = d["dx_m"], d["origin_m"], d["bodies"]
        self.ny, self.nx = self.active.shape

    @property
    def fields(self):
        return sorted(self._fields)

    def __getitem__(self, field):
        if field not in self._fields:
            raise KeyError(f"{self.path}: no field '{field}' in this frame; it holds {', '.join(self.fields)}")
        return self._fields[field]

    def __contains__(self, field):
        return field in self._fields

    def cell_centres_m(self):
        """(x, y): 1-D arrays of the cell centres along each axis."""
        x = self.origin_m[0] + (np.arange(self.nx) + 0.5) * self.dx_m
        y = self.origin_m[1] + (np.arange(self.ny) + 0.5) * self.dx_m
        return x, y

    def extent_m(self):
        """(left, right, bottom, top) for matplotlib's imshow(..., origin="lower", extent=...)."""
        x0, y0 = self.origin_m
        return (x0, x0 + self.nx * self.dx_m, y0, y0 + self.ny * self.dx_m)


class Points:
    """One frame's material points (runs with outputs.points): points[name] is an array."""

    def __init__(self, path):
        d = _furrow.read_points(path)
        self.path = path
        self.arrays = d["arrays"]
        self.scene, self.step, self.time_s, self.dt_s = d["scene"], d["step"], d["time_s"], d["dt_s"]
        self.dx_m, self.bodies = d["dx_m"], d["bodies"]

    def __getitem__(self, name):
        if name not in self.arrays:
            raise KeyError(f"{self.path}: no point attribute '{name}'; it holds {', '.join(sorted(self.arrays))}")
        return self.arrays[name]

    def __len__(self):
        return len(self.arrays["x_m"])


class Run:
    """A finished run directory (see open_run)."""

    def __init__(self, path):
        self.path = os.fspath(path)
        if not os.path.isdir(self.path):
            raise FileNotFoundError(f"{self.path}: no such run directory")
        run_json = os.path.join(self.path, "run.json")
        if not os.path.isfile(run_json):
            partial = _furrow.checkpoint_dirs(self.path)
            hint = f" (a stopped run's checkpoint is in {partial[0]})" if partial else ""
            raise FileNotFoundError(f"{run_json}: missing: not a finished run directory{hint}")
        with open(run_json) as f:
            self.run_json = json.load(f)
        self.scene = load_scene(os.path.join(self.path, "scene.json"), allow_large=True)
        self._forces = None
        self._frames = None
        self._times = {}

    @property
    def forces(self):
        """{body: {t_s, x_m, y_m, Fx_N_per_m, Fy_N_per_m}} from forces.csv (N per metre out of plane)."""
        if self._forces is None:
            self._forces = _furrow.read_forces(os.path.join(self.path, "forces.csv"), self.scene._s)
        return self._forces

    def forces_dataframe(self):
        """forces.csv as a pandas DataFrame (needs pandas), columns as in the file."""
        import pandas as pd

        parts = [pd.DataFrame(dict(t_s=c["t_s"], body=name, x_m=c["x_m"], y_m=c["y_m"], Fx_N_per_m=c["Fx_N_per_m"],
                                   Fy_N_per_m=c["Fy_N_per_m"])) for name, c in self.forces.items()]
        return pd.concat(parts, ignore_index=True).sort_values(["t_s"], kind="stable", ignore_index=True)

    @property
    def frame_paths(self):
        if self._frames is None:
            self._frames = _furrow.list_frames(self.path) if os.path.isdir(os.path.join(self.path, "frames")) else []
        return self._frames

    @property
    def frame_count(self):
        return len(self.frame_paths)

    def _index(self, i):
        n = self.frame_count
        if not isinstance(i, (int, np.integer)):
            raise TypeError(f"frame index must be an integer, got {type(i).__name__}")
        if not -n <= i < n:
            raise IndexError(f"{self.path}: frame {i} out of range: the run stored {n} frame(s) (0..{n - 1})")
        return int(i) % n

    def frame(self, i):
        """Frame i (negative counts from the end)."""
        frame = Frame(self.frame_paths[self._index(i)])
        self._times[self._index(i)] = frame.time_s
        return frame

    def frame_times_s(self):
        """Every frame's time (reads each frame file once)."""
        return np.array([self._times[k] if k in self._times else self.frame(k).time_s for k in range(self.frame_count)])

    def particles(self, i):
        """The material points of frame i (the scene must store outputs.points)."""
        k = self._index(i)
        number = int(os.path.basename(self.frame_paths[k])[len("frame_"):-len(".vdb")])
        path = _furrow.points_path(self.path, number)
        if not os.path.isfile(path):
            raise FileNotFoundError(f"{path}: no points stored for frame {i} (the scene's outputs.points is false)")
        return Points(path)

    def __repr__(self):
        return f"<furrow.Run {self.path!r}: {self.frame_count} frames, bodies {list(self.forces)}>"


def open_run(path):
    """A finished run directory: .run_json, .scene, .forces, .frame(i)[field], .particles(i)."""
    return Run(path)


# ---- sweeps and studies: the CLI's drivers, given the CLI's command line ----

class Table:
    """A sweep.csv or study.csv as columns: table[column] is a float array (empty cells NaN) when
    every cell is a number, else an array of str. Column names carry the units, as in the file."""

    def __init__(self, path):
        self.path = os.fspath(path)
        with open(self.path, newline="") as f:
            rows = list(csv.reader(f))
        self.columns = rows[0] if rows else []
        self._columns = {}
        for k, name in enumerate(self.columns):
            cells = [r[k] if k < len(r) else "" for r in rows[1:]]
            try:
                self._columns[name] = np.array([float(c) if c != "" else np.nan for c in cells], dtype=float)
            except ValueError:
                self._columns[name] = np.array(cells, dtype=str)
        self.rows = len(rows) - 1 if rows else 0

    def __getitem__(self, column):
        if column not in self._columns:
            raise KeyError(f"{self.path}: no column '{column}'; it has {', '.join(self.columns)}")
        return self._columns[column]

    def __contains__(self, column):
        return column in self._columns

    def __len__(self):
        return self.rows

    def keys(self):
        return list(self.columns)

    def dataframe(self):
        """The table as a pandas DataFrame (needs pandas), columns in the file's order."""
        import pandas as pd

        return pd.DataFrame({c: self._columns[c] for c in self.columns})

    def __repr__(self):
        return f"<furrow.Table {self.path!r}: {self.rows} rows, {len(self.columns)} columns>"


def _vary_args(option, varies):
    """{key: [values] or "a:b:step"} or ["KEYS=VALUES", ...] -> the CLI's --vary/--ladder arguments."""
    if isinstance(varies, str):
        varies = [varies]
    if isinstance(varies, dict):
        specs = []
        for key, values in varies.items():
            if not isinstance(values, str):
                values = ",".join(v if isinstance(v, str) else json.dumps(v) for v in values)
            specs.append(f"{key}={values}")
        varies = specs
    args = []
    for spec in varies:
        args += [option, spec]
    return args


def _scene_args(scene, set, threads, yes, quiet):
    if not isinstance(scene, (str, os.PathLike)):
        raise TypeError("sweep and study read the scene from its file (they load it again per run, as the CLI): "
                        "pass a path; a Scene object can be written with scene.save(path)")
    args = [os.fspath(scene)]
    for s in _overrides(set):
        args += ["--set", s]
    if threads is not None:
        args += ["--threads", str(int(threads))]
    if yes:
        args.append("--yes")
    if quiet:
        args.append("--quiet")
    return args


def _drive(command, args, progress, progress_interval_s=0.5, exe=""):
    status, errors, error = _furrow.drive(command, args, progress, float(progress_interval_s), exe)
    if error is not None and not isinstance(error, StopRun):
        if isinstance(error, KeyboardInterrupt):
            raise KeyboardInterrupt(f"furrow {command} stopped; what finished is kept (run it again to finish the "
                                    f"rest)") from error
        raise error
    if errors.strip():
        if status != 0:
            raise RuntimeError(errors.strip())
        warnings.warn(errors.strip())
    return status


class SweepResult:
    """A sweep directory: .table (sweep.csv; None when the sweep was stopped before its end),
    .json (sweep.json), .status (the CLI's exit status: 0, 1 when runs failed, 130 stopped),
    .stopped, .failed (rows that failed), .run(i) (open_run of row i's directory)."""

    def __init__(self, path, status):
        self.path = os.fspath(path)
        self.status = status
        self.stopped = status == 130
        with open(os.path.join(self.path, "sweep.json")) as f:
            self.json = json.load(f)
        csv_path = os.path.join(self.path, "sweep.csv")
        self.table = Table(csv_path) if not self.stopped and os.path.isfile(csv_path) else None
        self.failed = [r for r in self.json.get("runs", []) if r.get("status") == "failed"]

    def dataframe(self):
        return self.table.dataframe()

    def run(self, i):
        return open_run(os.path.join(self.path, self.json["runs"][i]["dir"]))

    def __repr__(self):
        return f"<furrow.SweepResult {self.path!r}: {len(self.json.get('runs', []))} runs, status {self.status}>"


def sweep(scene, vary, out, set=None, jobs=1, threads=None, force=False, paraview=True, movies=False, yes=False,
          progress=None, progress_interval_s=0.5, quiet=True):
    """`furrow sweep SCENE --vary ... --out OUT`, run by the CLI's own code: every combination of
    `vary` ({"key.path": [v1, v2] or "a:b:step"} or ["KEYS=VALUES", ...], as --vary) into OUT, the
    same run directories, sweep.json and sweep.csv (sweep.png only from the CLI, which draws it:
    `furrow sweep` again with the same arguments reuses every run and adds it). The runs go with
    the GIL released; `progress(dict)` gets {"event": "run_progress", "dir", "fraction", ...} (every
    progress_interval_s per run) and {"event": "run_done", "dir", "status", ...}. Ctrl-C or an exception in `progress` stops the
    runs with a checkpoint and is raised again; furrow.StopRun returns the result with
    stopped=True; the same call again finishes the rest. A bad scene or --vary key raises
    SceneError (JSON path), a bad --vary ValueError. Returns a SweepResult."""
    args = _scene_args(scene, set, threads, yes, quiet) + _vary_args("--vary", vary)
    args += ["--out", os.fspath(out), "--jobs", str(int(jobs))]
    if force:
        args.append("--force")
    if not paraview:
        args.append("--no-paraview")
    if movies:
        args.append("--movies")
    status = _drive("sweep", args, progress, progress_interval_s)
    return SweepResult(out, status)


def cli_path():
    """The furrow CLI a study runs its rungs with: $FURROW_CLI, else the one built beside this
    module, else `furrow` on PATH."""
    for candidate in (os.environ.get("FURROW_CLI"), _furrow.cli_path, shutil.which("furrow")):
        if candidate and os.access(candidate, os.X_OK):
            return candidate
    raise FileNotFoundError(f"no furrow CLI to run a study's rungs: not at {_furrow.cli_path}, not on PATH; set "
                            "FURROW_CLI to its path")


class StudyResult:
    """A study directory: .table (study.csv), .json (study.json), .markdown (study.md),
    .reference (the converged estimate, None without one), .status (0, 1 failed rungs, 130 stopped)."""

    def __init__(self, path, status):
        self.path = os.fspath(path)
        self.status = status
        self.stopped = status == 130
        with open(os.path.join(self.path, "study.json")) as f:
            self.json = json.load(f)
        self.table = Table(os.path.join(self.path, "study.csv"))
        with open(os.path.join(self.path, "study.md")) as f:
            self.markdown = f.read()
        self.reference = self.json.get("reference")

    def dataframe(self):
        return self.table.dataframe()

    def __repr__(self):
        return f"<furrow.StudyResult {self.path!r}: {len(self.table)} rungs, reference {self.reference}>"


def study(scene, ladder, out, quantity="drag_mean", body=None, set=None, jobs=1, threads=None, yes=False,
          progress=None, quiet=True, cli=None):
    """`furrow study SCENE --ladder ... --out OUT`, run by the CLI's own code: each rung a child
    `furrow run` (cli_path(), or `cli`), cheapest first; writes study.csv, study.md, study.json
    (study.png only from the CLI). `ladder` as sweep's `vary`. `progress(dict)` gets
    {"event": "rung_start" | "rung_done", ...}. Ctrl-C stops it (the rungs running get SIGTERM and
    keep a checkpoint) and is raised again; the same call finishes the rest. Returns a StudyResult."""
    args = _scene_args(scene, set, threads, yes, quiet) + _vary_args("--ladder", ladder)
    args += ["--out", os.fspath(out), "--jobs", str(int(jobs)), "--quantity", quantity]
    if body:
        args += ["--body", body]
    status = _drive("study", args, progress, exe=os.fspath(cli) if cli else cli_path())
    return StudyResult(out, status)
