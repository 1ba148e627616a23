// cadclash._cadclash.SceneCore, CollideOptions, collide() and replay(): every query runs with the
// GIL released and the model's lock held.
#include "convert.h"

#include <pybind11/stl.h>

#include <atomic>

namespace cadclash::py {
namespace {

// A prepared scene and the model state it points into (kept alive by the shared_ptr).
struct SceneCore {
  std::shared_ptr<ModelState> state;
  std::unique_ptr<Scene> scene;
  // True while check() or replay() runs on this scene (read without the GIL by design).
  std::atomic<bool> running{false};
};

InstanceId checked_instance(const ModelState& s, std::int64_t id) {
  if (id < 0 || static_cast<std::size_t>(id) >= s.model.instances.size())
    throw pyb::index_error("instance id " + std::to_string(id) + " out of range");
  return static_cast<InstanceId>(id);
}

void validate(const CollideOptions& o) {
  if (!(o.tolerance >= 0.0)) throw pyb::value_error("tolerance must be >= 0");
  if (!(o.clearance >= 0.0)) throw pyb::value_error("clearance must be >= 0");
  if (!(o.time_budget_seconds >= 0.0)) throw pyb::value_error("time_budget must be >= 0");
}

class Running {
 public:
  explicit Running(std::atomic<bool>& flag) : flag_(flag) { flag_.store(true); }
  ~Running() { flag_.store(false); }
  Running(const Running&) = delete;
  Running& operator=(const Running&) = delete;

 private:
  std::atomic<bool>& flag_;
};

// The options of a query: their enums, CollideOptions, and the pose helpers.
void bind_options(pyb::module_& m) {
  pyb::enum_<CollideMode>(m, "CollideMode")
      .value("EarlyExit", CollideMode::EarlyExit)
      .value("AllTrianglePairs", CollideMode::AllTrianglePairs);
  pyb::enum_<ParallelVersion>(m, "ParallelVersion").value("V1", ParallelVersion::V1).value("V2", ParallelVersion::V2);
  pyb::enum_<Schedule>(m, "Schedule")
      .value("Guided", Schedule::Guided)
      .value("Dynamic", Schedule::Dynamic)
      .value("Static", Schedule::Static);
  pyb::enum_<DecisionMode>(m, "DecisionMode")
      .value("Certified", DecisionMode::Certified)
      .value("Fast", DecisionMode::Fast)
      .value("Exact", DecisionMode::Exact);
  pyb::enum_<TriangleLevel>(m, "TriangleLevel")
      .value("Auto", TriangleLevel::Auto)
      .value("Flat", TriangleLevel::Flat)
      .value("Bvh", TriangleLevel::Bvh);

  pyb::class_<CollideOptions>(m, "CollideOptionsCore", "cadclash::CollideOptions; see cadclash.CollideOptions")
      .def(pyb::init<>())
      .def_readwrite("tolerance", &CollideOptions::tolerance)
      .def_readwrite("clearance", &CollideOptions::clearance)
      .def_readwrite("mode", &CollideOptions::mode)
      .def_readwrite("threads", &CollideOptions::threads)
      .def_readwrite("version", &CollideOptions::version)
      .def_readwrite("schedule", &CollideOptions::schedule)
      .def_readwrite("use_oaabb", &CollideOptions::use_oaabb)
      .def_readwrite("triangle_level", &CollideOptions::triangle_level)
      .def_readwrite("flat_limit", &CollideOptions::flat_limit)
      .def_readwrite("detect_containment", &CollideOptions::detect_containment)
      .def_readwrite("decision", &CollideOptions::decision)
      .def_readwrite("time_budget_seconds", &CollideOptions::time_budget_seconds)
      .def_readwrite("memory_budget_bytes", &CollideOptions::memory_budget_bytes);

  m.def("pose_from_matrix", [](const pyb::handle& h) { return pose_to_array(pose_from_matrix(h)); },
        "Validates a rigid 4x4 pose; returns it as a new float64 array. ValueError if it is not rigid.");
  m.def(
      "pose_from_translation_quaternion",
      [](const pyb::handle& t, const pyb::handle& q) { return pose_to_array(pose_from_translation_quaternion(t, q)); },
      "4x4 pose from (tx, ty, tz) and (qw, qx, qy, qz) (normalised). ValueError for a zero quaternion.");

}

// The prepared scene (check, replay) and the one-off collide().
void bind_scene_core(pyb::module_& m) {
  pyb::class_<SceneCore>(m, "SceneCore", pyb::dynamic_attr(), "The C++ prepared scene behind cadclash.Scene.")
      .def(pyb::init([](ModelCore& model, std::vector<std::int64_t> set_a, std::vector<std::int64_t> set_b,
                        std::vector<std::array<std::string, 2>> excluded_pairs,
                        std::vector<std::string> excluded_subassemblies) {
             auto core = std::make_unique<SceneCore>();
             core->state = model.state;
             ModelState& st = *core->state;
             SceneSelection sel;
             for (std::int64_t i : set_a) sel.set_a.push_back(checked_instance(st, i));
             for (std::int64_t i : set_b) sel.set_b.push_back(checked_instance(st, i));
             sel.excluded_pairs = std::move(excluded_pairs);
             sel.excluded_subassemblies = std::move(excluded_subassemblies);
             {
               ModelLock lock(st);  // builds boxes from the surfaces a running check may tessellate
               core->scene = std::make_unique<Scene>(st.model, std::move(sel));
             }
             return core;
           }),
           pyb::arg("model"), pyb::arg("set_a"), pyb::arg("set_b"), pyb::arg("excluded_pairs"),
           pyb::arg("excluded_subassemblies"))
      .def("set_pose",
           [](SceneCore& c, std::int64_t id, const pyb::handle& matrix) {
             const InstanceId i = checked_instance(*c.state, id);
             const Pose p = pose_from_matrix(matrix);
             ModelLock lock(*c.state);
             c.scene->set_pose(i, p);
           })
      .def("pose",
           [](SceneCore& c, std::int64_t id) {
             const InstanceId i = checked_instance(*c.state, id);
             Pose p;
             {
               ModelLock lock(*c.state);
               p = c.scene->pose(i);
             }
             return pose_to_array(p);
           })
      .def_property_readonly("running", [](const SceneCore& c) { return c.running.load(); },
                             "True while check() or replay() of this scene runs (in another thread).")
      .def("check",
           [](SceneCore& c, const CollideOptions& o) {
             validate(o);
             Report r;
             QueryReport record;
             {
               ModelLock lock(*c.state);
               Running running(c.running);
               r = c.scene->check(o);
               record = query_report(c.state->model, r);
             }
             return report_to_tuple(r, std::move(record));
           })
      .def("replay", [](SceneCore& c, const std::string& csv_text, const std::string& file, const CollideOptions& o,
                        bool continuous, double resolution, std::size_t max_checks) {
        validate(o);
        if (continuous && !(resolution > 0.0 && resolution <= 1.0))
          throw pyb::value_error("time_resolution must be in (0, 1]");
        if (continuous && max_checks == 0) throw pyb::value_error("motion_checks must be positive");
        std::vector<Diagnostic> parse_diags, run_diags;
        std::vector<StepResult> steps;
        std::vector<QueryReport> records;
        std::optional<ReportTimeline> timeline;
        std::size_t distinct_steps = 0;  // of the rows: steps_not_checked = distinct_steps - steps
        {
          ModelLock lock(*c.state);
          const std::vector<TrajectoryRow> rows = parse_trajectory(csv_text, file, parse_diags);
          for (std::size_t k = 0; k < rows.size(); ++k) distinct_steps += (k == 0 || rows[k].step != rows[k - 1].step);
          if (!has_error(parse_diags)) {  // like `cadclash check --path`: a bad row means nothing is run
            Running running(c.running);
            if (continuous) {
              MotionOptions mo;
              mo.resolution = resolution;
              mo.max_checks = max_checks;
              PathResult path = replay_continuous(*c.scene, c.state->model, rows, o, mo, run_diags, file);
              timeline = timeline_report(c.state->model, path, resolution);
              steps = std::move(path.steps);
            } else {
              steps = replay_trajectory(*c.scene, rows, o, run_diags, file);
            }
            for (const StepResult& s : steps) records.push_back(query_report(c.state->model, s.report));
          }
        }
        pyb::list out;
        for (std::size_t k = 0; k < steps.size(); ++k)
          out.append(pyb::make_tuple(steps[k].step, report_to_tuple(steps[k].report, std::move(records[k]))));
        pyb::object t = timeline ? pyb::cast(std::move(*timeline)) : pyb::object(pyb::none());
        return pyb::make_tuple(diagnostics_to_list(parse_diags), out, diagnostics_to_list(run_diags), distinct_steps, t);
      });

  m.def("collide", [](ModelCore& model, std::int64_t a, std::int64_t b, const CollideOptions& o) {
    ModelState& st = *model.state;
    const InstanceId ia = checked_instance(st, a), ib = checked_instance(st, b);
    if (ia == ib) throw pyb::value_error("collide() needs two different instances");
    validate(o);
    Report r;
    QueryReport record;
    {
      ModelLock lock(st);
      r = collide(st.model, ia, ib, o);
      record = query_report(st.model, r);
    }
    return report_to_tuple(r, std::move(record));
  });
}

}  // namespace

void bind_scene(pyb::module_& m) {
  bind_options(m);
  bind_scene_core(m);
}

}  // namespace cadclash::py
