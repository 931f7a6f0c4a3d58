// furrow._furrow: the engine and app core seen from Python. Thin on purpose: every result comes from
// the same functions the CLI calls (scene_io, run_scene, read_forces_csv, read_frame, read_points,
// and the sweep and study drivers of app/drivers.hpp); furrow/__init__.py arranges them for notebooks.
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <optional>
#include <sstream>
#include <thread>

#include "app/calibration.hpp"
#include "app/commands.hpp"
#include "app/drivers.hpp"
#include "app/sweep.hpp"
#include "engine/io/field_store.hpp"
#include "engine/io/point_store.hpp"
#include "engine/run.hpp"
#include "engine/scene/scene_io.hpp"
#include "engine/simulation.hpp"

namespace py = pybind11;
using namespace furrow;

namespace {

// A copy of `v` as a NumPy array of `shape` (C order); float or double as stored.
template <class T>
py::array_t<T> to_numpy(const std::vector<T>& v, std::vector<py::ssize_t> shape = {}) {
  if (shape.empty()) shape = {py::ssize_t(v.size())};
  py::array_t<T> a(shape);
  if (!v.empty()) std::copy(v.begin(), v.end(), a.mutable_data());
  return a;
}

py::object json_to_python(const nlohmann::json& j) {
  return py::module_::import("json").attr("loads")(j.dump());
}

py::dict vec2(const Vec2& v) { return py::dict(py::arg("x") = v.x(), py::arg("y") = v.y()); }

// A validated scene and the name it was read under (errors and summaries say it).
struct PyScene {
  Scene scene;
  std::string source;
};

PyScene parse_text(const std::string& text, const std::string& source, const std::vector<std::string>& overrides,
                   bool allow_large) {
  ValidationOptions v;
  v.allow_large = allow_large;
  return {parse_scene_text(text, source, overrides, v), source};
}

py::dict estimate(const PyScene& s) {
  py::dict d;
  d["particles"] = estimate_particle_count(s.scene);
  d["steps"] = estimate_step_count(s.scene);
  d["time_step_s"] = estimate_time_step_s(s.scene);
  d["end_time_s"] = estimate_end_time_s(s.scene);
  d["particle_steps"] = estimate_particle_steps(s.scene);
  d["threads"] = cli::run_threads(s.scene);
  // the solver's wall time from this machine's `furrow bench` calibration; None without one
  std::string why, how;
  const auto calibration = cli::load_calibration(&why);
  const double predicted_s = calibration ? cli::predict_run_wall_s(*calibration, s.scene, &how) : NAN;
  d["predicted_wall_s"] = std::isfinite(predicted_s) ? py::object(py::float_(predicted_s)) : py::object(py::none());
  d["predicted_how"] = std::isfinite(predicted_s) ? how : (calibration ? how : why);
  return d;
}

py::dict progress_dict(const RunProgress& p) {
  py::dict d;
  d["fraction"] = p.fraction;
  d["time_s"] = p.time_s;
  d["steps"] = p.steps;
  d["wall_s"] = p.wall_s;
  d["eta_s"] = p.eta_s < 0 ? py::object(py::none()) : py::object(py::float_(p.eta_s));
  d["particles"] = p.particles;
  d["dt_s"] = p.dt_s;
  d["particle_steps_per_s"] = p.particle_steps_per_s;
  return d;
}

py::dict summary_dict(const RunSummary& s) {
  py::dict d;
  d["run_json"] = json_to_python(s.run_json);
  py::list bodies;
  for (const auto& b : s.bodies)
    bodies.append(py::dict(py::arg("name") = b.name, py::arg("mean_force_N_per_m") = vec2(b.mean_N_per_m),
                           py::arg("peak_force_N_per_m") = vec2(b.peak_N_per_m),
                           py::arg("window_samples") = b.window_samples));
  d["bodies"] = bodies;
  d["out_dir"] = s.out_dir;
  d["stopped"] = s.stopped;
  d["resumed_from_step"] = s.resumed_from_step >= 0 ? py::object(py::int_(s.resumed_from_step)) : py::object(py::none());
  return d;
}

// Runs the scene with the GIL released. The progress callback (and a check for Ctrl-C) runs with
// the GIL every progress_interval_s; an exception there stops the run after the current step with
// a checkpoint. Returns (summary, the exception or None): furrow/__init__.py decides what to raise.
py::tuple run(const PyScene& s, const std::string& out_dir, bool force, bool paraview, py::object progress,
              double progress_interval_s, double checkpoint_interval_s, bool resume, bool resume_any_build) {
  RunOptions opt;
  opt.out_dir = out_dir;
  opt.force = force;
  opt.write_paraview = paraview;
  opt.resume = resume || resume_any_build;
  opt.resume_any_build = resume_any_build;
  opt.checkpoint_interval_s = checkpoint_interval_s;
  // without a callback still poll for Ctrl-C, a few times a second
  opt.progress_interval_s = progress.is_none() ? std::min(progress_interval_s, 0.2) : progress_interval_s;
  std::atomic<bool> stop{false};
  std::optional<py::object> error;  // touched with the GIL held only
  opt.progress = [&](const RunProgress& p) {
    py::gil_scoped_acquire gil;
    if (error) return;
    try {
      if (PyErr_CheckSignals() != 0) throw py::error_already_set();
      if (!progress.is_none()) progress(progress_dict(p));
    } catch (py::error_already_set& e) {
      error = e.value();
      stop = true;
    }
  };
  opt.stop_requested = [&] { return stop.load(); };
  RunSummary summary;
  {
    py::gil_scoped_release released;
    summary = run_scene(s.scene, opt);
  }
  return py::make_tuple(summary_dict(summary), error ? *error : py::object(py::none()));
}

// `furrow sweep` / `furrow study` with the command line `args` (after the command name), run by the
// CLI's own driver on a thread of its own: a sweep's runs go on worker threads, where Python sees no
// signals, so the calling thread waits and asks Python about Ctrl-C every 0.1 s. `progress(dict)`
// gets the driver's events and its runs' progress. Returns (exit status, what the driver wrote as
// errors, the exception that stopped it or None).
py::tuple drive(const std::string& command, const std::vector<std::string>& args, py::object progress,
                double progress_interval_s, const std::string& furrow_exe) {
  const cli::Command cmd = command == "sweep" ? cli::command_sweep() : cli::command_study();
  const cli::Parsed parsed = cli::parse(cmd, args);
  std::ostringstream err;
  cli::DriverHooks hooks;
  hooks.err = &err;
  hooks.throw_scene_errors = true;
  hooks.furrow_exe = furrow_exe;
  hooks.run_progress_interval_s = progress_interval_s;
  std::atomic<bool> stop{false};
  std::optional<py::object> error;  // touched with the GIL held only
  // with the GIL held: run `f`, turning a Python exception into a stop
  auto guarded = [&](auto&& f) {
    if (error) return;
    try {
      f();
    } catch (py::error_already_set& e) {
      error = e.value();
      stop = true;
    }
  };
  hooks.stop_requested = [&] { return stop.load(); };
  if (!progress.is_none()) {
    hooks.on_event = [&](const nlohmann::json& e) {
      py::gil_scoped_acquire gil;
      guarded([&] { progress(json_to_python(e)); });
    };
    hooks.on_run_progress = [&](const std::string& dir, const RunProgress& p) {
      py::gil_scoped_acquire gil;
      guarded([&] {
        py::dict d = progress_dict(p);
        d["event"] = "run_progress";
        d["dir"] = dir;
        progress(d);
      });
    };
  }
  int status = 0;
  std::exception_ptr failure;
  std::mutex m;
  std::condition_variable finished;
  bool done = false;
  std::thread driver([&] {
    try {
      status = command == "sweep" ? cli::sweep_main(parsed, hooks) : cli::study_main(parsed, hooks);
    } catch (...) {
      failure = std::current_exception();
    }
    std::lock_guard<std::mutex> lock(m);
    done = true;
    finished.notify_all();
  });
  for (bool over = false; !over;) {
    {
      py::gil_scoped_release released;
      std::unique_lock<std::mutex> lock(m);
      over = finished.wait_for(lock, std::chrono::milliseconds(100), [&] { return done; });
    }
    guarded([] {
      if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    });
  }
  driver.join();
  if (failure) std::rethrow_exception(failure);
  return py::make_tuple(status, err.str(), error ? *error : py::object(py::none()));
}

// A Simulation stepped by hand (no run directory).
struct PySimulation {
  explicit PySimulation(const PyScene& s) : scene(s), sim(std::make_unique<Simulation>(s.scene)) {}
  PyScene scene;
  std::unique_ptr<Simulation> sim;
};

py::dict particles_dict(const Simulation& sim) {
  const Particles& p = sim.particles();
  py::dict d;
  d["x_m"] = to_numpy(p.x);
  d["y_m"] = to_numpy(p.y);
  d["vx_m_s"] = to_numpy(p.vx);
  d["vy_m_s"] = to_numpy(p.vy);
  d["mass_kg_per_m"] = to_numpy(p.mass);
  d["volume_m2"] = to_numpy(p.volume);
  d["pressure_Pa"] = to_numpy(p.pressure);
  d["sxx_Pa"] = to_numpy(p.sxx);
  d["syy_Pa"] = to_numpy(p.syy);
  d["sxy_Pa"] = to_numpy(p.sxy);
  d["szz_Pa"] = to_numpy(p.szz);
  if (!p.phi_d.empty()) d["phi_d"] = to_numpy(p.phi_d);
  if (!p.plastic_strain.empty()) d["plastic_strain"] = to_numpy(p.plastic_strain);
  if (!p.strain_rate.empty()) d["strain_rate_1_s"] = to_numpy(p.strain_rate);
  d["material"] = to_numpy(p.material);
  return d;
}

py::list bodies_list(const Simulation& sim) {
  py::list out;
  const auto& bodies = sim.bodies();
  for (size_t b = 0; b < bodies.size(); ++b)
    out.append(py::dict(py::arg("name") = sim.scene().bodies[b].name,
                        py::arg("position_m") = vec2(bodies[b].position_m),
                        py::arg("velocity_m_s") = vec2(bodies[b].velocity_m_s),
                        py::arg("force_N_per_m") = vec2(bodies[b].force_N_per_m)));
  return out;
}

py::list outlines_list(const std::vector<BodyOutline>& bodies) {
  py::list out;
  for (const auto& b : bodies) {
    std::vector<double> xy;
    for (const auto& p : b.outline_m) xy.push_back(p.x()), xy.push_back(p.y());
    out.append(py::dict(py::arg("name") = b.name, py::arg("outline_m") = to_numpy(xy, {py::ssize_t(b.outline_m.size()), 2}),
                        py::arg("position_m") = vec2(b.position_m), py::arg("force_N_per_m") = vec2(b.force_N_per_m)));
  }
  return out;
}

// A frame file: every field as an (ny, nx) array (row j holds y = origin_y + (j + 1/2) dx), the
// velocity as (ny, nx, 2), the cells holding material as `active`.
py::dict frame_dict(const std::string& path) {
  const FieldFrame f = read_frame(path);
  const std::vector<py::ssize_t> shape{f.ny, f.nx};
  py::dict fields;
  for (const auto& [name, values] : f.scalars) fields[py::str(name)] = to_numpy(values, shape);
  if (!f.velocity_x.empty()) {
    std::vector<float> v(2 * f.velocity_x.size());
    for (size_t k = 0; k < f.velocity_x.size(); ++k) v[2 * k] = f.velocity_x[k], v[2 * k + 1] = f.velocity_y[k];
    fields["velocity"] = to_numpy(v, {f.ny, f.nx, 2});
  }
  std::vector<uint8_t> active = f.active;
  py::dict d;
  d["fields"] = fields;
  d["active"] = to_numpy(active, shape).attr("astype")("bool");
  d["scene"] = f.scene_name;
  d["step"] = f.step;
  d["time_s"] = f.time_s;
  d["dt_s"] = f.dt_s;
  d["dx_m"] = f.dx_m;
  d["origin_m"] = py::make_tuple(f.origin_m.x(), f.origin_m.y());
  d["bodies"] = outlines_list(f.bodies);
  return d;
}

py::dict points_dict(const std::string& path) {
  const PointFrame f = read_points(path);
  py::dict a;
  a["x_m"] = to_numpy(f.x_m);
  a["y_m"] = to_numpy(f.y_m);
  a["vx_m_s"] = to_numpy(f.vx_m_s);
  a["vy_m_s"] = to_numpy(f.vy_m_s);
  a["volume_m2"] = to_numpy(f.volume_m2);
  auto optional = [&](const char* name, const std::vector<float>& v) {
    if (!v.empty()) a[name] = to_numpy(v);
  };
  optional("pressure_Pa", f.pressure_Pa);
  optional("packing_fraction", f.packing_fraction);
  optional("strain_rate_1_s", f.strain_rate_1_s);
  optional("plastic_strain", f.plastic_strain);
  optional("phi_d", f.phi_d);
  py::dict d;
  d["arrays"] = a;
  d["scene"] = f.scene_name;
  d["step"] = f.step;
  d["time_s"] = f.time_s;
  d["dt_s"] = f.dt_s;
  d["dx_m"] = f.dx_m;
  d["bodies"] = outlines_list(f.bodies);
  return d;
}

// forces.csv, one dict of arrays per body of the scene (read by the function sweeps use).
py::dict forces_dict(const std::string& csv_path, const PyScene& s) {
  const auto samples = sweep::read_forces_csv(csv_path, s.scene);
  py::dict out;
  for (size_t b = 0; b < samples.size(); ++b) {
    const size_t n = samples[b].size();
    std::vector<double> t(n), x(n), y(n), fx(n), fy(n);
    for (size_t k = 0; k < n; ++k) {
      const auto& q = samples[b][k];
      t[k] = q.t_s, x[k] = q.position_m.x(), y[k] = q.position_m.y();
      fx[k] = q.force_N_per_m.x(), fy[k] = q.force_N_per_m.y();
    }
    out[py::str(s.scene.bodies[b].name)] =
        py::dict(py::arg("t_s") = to_numpy(t), py::arg("x_m") = to_numpy(x), py::arg("y_m") = to_numpy(y),
                 py::arg("Fx_N_per_m") = to_numpy(fx), py::arg("Fy_N_per_m") = to_numpy(fy));
  }
  return out;
}

}  // namespace

PYBIND11_MODULE(_furrow, m) {
  m.doc() = "Furrow's engine from Python (use the package furrow, not this module)";
  m.attr("version") = FURROW_VERSION;

  // SceneError carries the CLI's message and its parts (file, JSON path, value, expectation, note)
  static py::handle scene_error = PyErr_NewException("furrow.SceneError", PyExc_ValueError, nullptr);
  m.attr("SceneError") = scene_error;
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const cli::UsageError& e) {  // a bad sweep/study argument, worded as the CLI's
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const SceneError& e) {
      py::object exc = py::reinterpret_borrow<py::object>(scene_error)(e.what());
      exc.attr("file") = e.file;
      exc.attr("path") = e.path;
      exc.attr("value") = e.value;
      exc.attr("expected") = e.expected;
      exc.attr("note") = e.note;
      PyErr_SetObject(scene_error.ptr(), exc.ptr());
    }
  });

  m.def("templates", [] {
    std::vector<std::pair<std::string, std::string>> out;
    for (const auto& t : scene_templates()) out.emplace_back(t.name, t.description);
    return out;
  });
  m.def("template_text", [](const std::string& name) -> py::object {
    const SceneTemplate* t = find_scene_template(name);
    return t ? py::object(py::str(t->text)) : py::object(py::none());
  });
  m.def("fields", [] {
    py::list out;
    for (const auto& f : field_registry())
      out.append(py::dict(py::arg("name") = f.name, py::arg("unit") = f.unit, py::arg("label") = f.label,
                          py::arg("vector") = f.vector));
    return out;
  });

  py::class_<PyScene>(m, "Scene")
      .def_property_readonly("name", [](const PyScene& s) { return s.scene.name; })
      .def_property_readonly("source", [](const PyScene& s) { return s.source; })
      .def("text", [](const PyScene& s) { return format_scene(s.scene); })
      .def("to_json", [](const PyScene& s) { return scene_to_json(s.scene).dump(); })
      .def("hash", [](const PyScene& s) { return scene_hash(s.scene); })
      .def("estimate", &estimate);
  m.def("load_scene", [](const std::string& path, const std::vector<std::string>& overrides, bool allow_large) {
    ValidationOptions v;
    v.allow_large = allow_large;
    return PyScene{load_scene(path, overrides, v), path};
  });
  m.def("parse_scene", &parse_text);

  m.def("run", &run);
  m.def("drive", &drive);
  m.attr("cli_path") = FURROW_CLI_PATH;
  m.def("checkpoint_dirs", &checkpoint_dirs);

  py::class_<PySimulation>(m, "Simulation")
      .def(py::init<const PyScene&>())
      .def("step",
           [](PySimulation& s, int64_t n) {
             py::gil_scoped_release released;
             for (int64_t k = 0; k < n && !s.sim->finished(); ++k) s.sim->step();
           })
      .def_property_readonly("finished", [](const PySimulation& s) { return s.sim->finished(); })
      .def_property_readonly("time_s", [](const PySimulation& s) { return s.sim->time_s(); })
      .def_property_readonly("steps", [](const PySimulation& s) { return s.sim->step_count(); })
      .def_property_readonly("dt_s", [](const PySimulation& s) { return s.sim->last_dt_s(); })
      .def_property_readonly("total_mass_kg_per_m", [](const PySimulation& s) { return s.sim->total_mass(); })
      .def_property_readonly("kinetic_energy_J_per_m", [](const PySimulation& s) { return s.sim->kinetic_energy(); })
      .def("particles", [](const PySimulation& s) { return particles_dict(*s.sim); })
      .def("bodies", [](const PySimulation& s) { return bodies_list(*s.sim); })
      .def("wall_forces", [](const PySimulation& s) {
        py::list out;
        // zero before the first step (the engine sets them in its first step)
        for (const auto& f : s.sim->wall_forces()) out.append(vec2(s.sim->step_count() ? f : Vec2(0, 0)));
        return out;
      });

  m.def("read_forces", &forces_dict);
  m.def("list_frames", &list_frames);
  m.def("read_frame", &frame_dict);
  m.def("read_points", &points_dict);
  m.def("points_path", &points_path);
}
