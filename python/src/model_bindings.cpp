// cadclash._cadclash.ModelCore: loading files, reading the model, NumPy views of its triangles.
#include "convert.h"

#include "cadclash/tessellate.h"

#include <pybind11/stl.h>

#include <omp.h>

#include <mutex>
#include <stdexcept>

namespace cadclash::py {
namespace {

static_assert(sizeof(Vec3) == 3 * sizeof(double), "vertices must be packed xyz doubles for the NumPy view");
static_assert(sizeof(std::array<std::uint32_t, 3>) == 3 * sizeof(std::uint32_t), "triangles must be packed");

// OCCT's readers keep process-wide settings (Interface_Static): loads run one at a time.
std::mutex g_import_mutex;

// A call's OpenMP thread count: omp_set_num_threads holds for the thread that sets it, so it is set
// for the call and put back after, leaving other Python threads and later calls as they were.
class CallThreads {
 public:
  explicit CallThreads(int threads) : saved_(omp_get_max_threads()), set_(threads > 0) {
    if (set_) omp_set_num_threads(threads);
  }
  ~CallThreads() {
    if (set_) omp_set_num_threads(saved_);
  }
  CallThreads(const CallThreads&) = delete;
  CallThreads& operator=(const CallThreads&) = delete;

 private:
  int saved_;
  bool set_;
};

int checked_threads(int threads) {
  if (threads < 0) throw pyb::value_error("threads must be >= 0 (0: every core)");
  return threads;
}

const Surface& surface_at(const ModelState& s, pyb::ssize_t id) {
  if (id < 0 || static_cast<std::size_t>(id) >= s.model.surfaces.size()) throw pyb::index_error("surface id out of range");
  return s.model.surfaces[static_cast<std::size_t>(id)];
}

struct LoadArgs {
  std::vector<std::string> paths;
  double deflection = 0.1;
  bool relative = false;
  double angular = 0.5;
  std::string preset;
  bool lazy = false;
  bool repair = false;
  bool fill_holes = false;
  bool segment = false;
  double sharp_angle = 60.0;
  bool planar = false;
  bool isolate = true;
  bool transfer_healing = true;
  double time_limit = 0.0;
  double model_tolerance = 0.0;
  std::string uncertainty = "auto";  // auto | occt | value (then uncertainty_value)
  double uncertainty_value = 0.0;
  std::string cache;  // ImportOptions::cache_dir; empty: none
  int threads = 0;    // the whole load on at most this many threads; 0: every core
};

// Same steps and defaults as the CLI's import_inputs(), without printing: (diagnostics, complete).
pyb::tuple load(ModelCore& core, const LoadArgs& a) {
  if (a.paths.empty()) throw pyb::value_error("load() needs at least one file");
  if (!(a.deflection > 0.0)) throw pyb::value_error("deflection must be > 0");
  if (!(a.angular > 0.0)) throw pyb::value_error("angular must be > 0");
  if (!(a.sharp_angle > 0.0 && a.sharp_angle < 180.0)) throw pyb::value_error("sharp_angle must be in (0, 180) degrees");
  ImportOptions options;
  options.tessellation.linear_deflection = a.deflection;
  options.tessellation.relative = a.relative;
  options.tessellation.angular_deflection = a.angular;
  if (!a.preset.empty()) {
    const auto preset = parse_tessellation_preset(a.preset);
    if (!preset) throw pyb::value_error("unknown preset '" + a.preset + "' (coarse, normal, fine, very-fine)");
    options.tessellation = apply_preset(options.tessellation, *preset);
  }
  options.lazy = a.lazy;
  options.isolate_cad_readers = a.isolate;
  options.transfer_healing = a.transfer_healing;
  if (!(a.time_limit >= 0.0)) throw pyb::value_error("time_limit must be >= 0 seconds (0: no limit)");
  options.reader_time_limit_seconds = a.time_limit;
  options.tessellation.time_limit_seconds = a.time_limit;
  if (!(a.model_tolerance >= 0.0)) throw pyb::value_error("model_tolerance must be >= 0 mm (0: from the coordinates)");
  options.model_tolerance = a.model_tolerance;
  if (a.uncertainty == "occt") options.uncertainty = UncertaintyChoice::OcctTolerance;
  else if (a.uncertainty == "value") {
    if (!(a.uncertainty_value > 0.0 && a.uncertainty_value <= kMaxLength))
      throw pyb::value_error("uncertainty must be 'auto', 'occt' or a length in (0, 2^128] mm");
    options.uncertainty = UncertaintyChoice::Value;
    options.uncertainty_value = a.uncertainty_value;
  } else if (a.uncertainty != "auto")
    throw pyb::value_error("uncertainty must be 'auto', 'occt' or a length in (0, 2^128] mm, not '" +
                           a.uncertainty + "'");
  options.cache_dir = a.cache;
  options.parallel_files = checked_threads(a.threads);

  ModelState& s = *core.state;
  std::vector<Diagnostic> diagnostics;
  bool complete = true;
  {
    pyb::gil_scoped_release release;
    std::lock_guard<std::mutex> import_lock(g_import_mutex);
    std::lock_guard<std::mutex> model_lock(s.mutex);
    if (s.loaded) throw std::logic_error("this model is already loaded; call cadclash.load() for a new one");
    // As `cadclash check --threads N`: cadclash's loops on N threads, OCCT's (BRepMesh meshing a
    // part's faces at once) held to N. That setting is process-wide, so every load makes it, under
    // the import lock: only loads mesh on OCCT's threads (lazy tessellation meshes a face on the
    // calling thread).
    const CallThreads call_threads(a.threads);
    hold_mesher_threads(a.threads);
    ImportResult r = import_files(a.paths, options);
    diagnostics = std::move(r.diagnostics);
    complete = r.complete;
    if (a.repair) {
      MeshRepairOptions ro;
      ro.fill_holes = a.fill_holes;
      MeshRepairReport rr = repair_meshes(r.model, ro);
      diagnostics.insert(diagnostics.end(), rr.diagnostics.begin(), rr.diagnostics.end());
    }
    if (a.segment) {
      SegmentOptions so;
      so.sharp_angle_degrees = a.sharp_angle;
      so.planar = a.planar;
      SegmentReport sr = segment_surfaces(r.model, so);
      diagnostics.insert(diagnostics.end(), sr.diagnostics.begin(), sr.diagnostics.end());
    }
    s.model = std::move(r.model);
    s.loaded = true;
    s.preset = a.preset;
    s.tessellation = options.tessellation;
    s.lazy = a.lazy;
  }
  return pyb::make_tuple(diagnostics_to_list(diagnostics), complete);
}

// A read-only view of `count` rows of `T` x 3 starting at `data`, kept alive by `owner`.
template <class T>
pyb::array view(const T* data, std::size_t count, const pyb::object& owner) {
  pyb::array out;
  if (count == 0) {
    out = pyb::array_t<T>(std::vector<pyb::ssize_t>{0, 3});
  } else {
    out = pyb::array(pyb::dtype::of<T>(), {static_cast<pyb::ssize_t>(count), pyb::ssize_t{3}},
                     {static_cast<pyb::ssize_t>(3 * sizeof(T)), static_cast<pyb::ssize_t>(sizeof(T))}, data, owner);
  }
  out.attr("setflags")(pyb::arg("write") = false);
  return out;
}

// Where a surface's triangles live, read under the model's lock. Empty unless the surface has
// triangles: only then is the storage stable once the lock is dropped (see state.h).
struct MeshSpan {
  const double* vertices = nullptr;
  std::size_t vertex_count = 0;
  const std::uint32_t* triangles = nullptr;
  std::size_t triangle_count = 0;
};

// With `tessellate`, first gives surface `id` triangles if it has none (lazy B-rep faces).
MeshSpan mesh_span(ModelState& s, pyb::ssize_t id, bool tessellate) {
  surface_at(s, id);
  MeshSpan out;
  ModelLock lock(s);
  Surface& surf = s.model.surfaces[static_cast<std::size_t>(id)];
  if (!surf.has_triangles && tessellate) {
    const SurfaceId sid = static_cast<SurfaceId>(id);
    require_triangles(s.model, std::span<const SurfaceId>(&sid, 1), 0.0);
  }
  if (surf.has_triangles && !surf.mesh.triangles.empty()) {
    out.vertices = surf.mesh.vertices.front().data();
    out.vertex_count = surf.mesh.vertices.size();
    out.triangles = surf.mesh.triangles.front().data();
    out.triangle_count = surf.mesh.triangles.size();
  }
  return out;
}

}  // namespace

void bind_model(pyb::module_& m) {
  pyb::class_<ModelCore>(m, "ModelCore", pyb::dynamic_attr(),
                         "The C++ model behind cadclash.Model. Create models with cadclash.load().")
      .def(pyb::init<>())
      .def(
          "_load",
          [](ModelCore& core, std::vector<std::string> paths, double deflection, bool relative, double angular,
             std::string preset, bool lazy, bool repair, bool fill_holes, bool segment, double sharp_angle,
             bool planar, bool isolate, bool transfer_healing, double time_limit, double model_tolerance,
             std::string uncertainty, double uncertainty_value, std::string cache, int threads) {
            return load(core, {std::move(paths), deflection, relative, angular, std::move(preset), lazy, repair,
                               fill_holes, segment, sharp_angle, planar, isolate, transfer_healing, time_limit,
                               model_tolerance,
                               std::move(uncertainty), uncertainty_value, std::move(cache), threads});
          },
          pyb::arg("paths"), pyb::arg("deflection"), pyb::arg("relative"), pyb::arg("angular"), pyb::arg("preset"),
          pyb::arg("lazy"), pyb::arg("repair"), pyb::arg("fill_holes"), pyb::arg("segment"), pyb::arg("sharp_angle"),
          pyb::arg("planar"), pyb::arg("isolate"), pyb::arg("transfer_healing"), pyb::arg("time_limit"), pyb::arg("model_tolerance"),
          pyb::arg("uncertainty"), pyb::arg("uncertainty_value"), pyb::arg("cache"), pyb::arg("threads"))
      .def("_counts",
           [](const ModelCore& c) {
             const Model& md = c.state->model;  // sizes never change after load
             return pyb::make_tuple(md.parts.size(), md.surfaces.size(), md.instances.size());
           })
      .def("_part",
           [](const ModelCore& c, pyb::ssize_t id) {
             const Model& md = c.state->model;
             if (id < 0 || static_cast<std::size_t>(id) >= md.parts.size()) throw pyb::index_error("part id out of range");
             const Part& p = md.parts[static_cast<std::size_t>(id)];
             return pyb::make_tuple(p.name, p.source_file, p.first_surface, p.surface_count, p.source != nullptr);
           })
      .def("_instance",
           [](const ModelCore& c, pyb::ssize_t id) {
             const Model& md = c.state->model;
             if (id < 0 || static_cast<std::size_t>(id) >= md.instances.size())
               throw pyb::index_error("instance id out of range");
             const Instance& i = md.instances[static_cast<std::size_t>(id)];
             return pyb::make_tuple(i.path, i.part, pose_to_array(i.pose));
           })
      .def("_surface",
           [](const ModelCore& c, pyb::ssize_t id) {
             const Surface& s = surface_at(*c.state, id);  // name, part, provenance: fixed after load
             const Provenance& p = s.provenance;
             pyb::object colour = p.colour ? pyb::object(pyb::make_tuple((*p.colour)[0], (*p.colour)[1], (*p.colour)[2]))
                                           : pyb::object(pyb::none());
             return pyb::make_tuple(s.name, s.part, source_kind_name(p.kind), p.source_file, p.step_id, p.face_index,
                                    p.source_name, p.parent == kInvalidId ? -1 : static_cast<std::int64_t>(p.parent),
                                    colour, p.healed, p.repaired, s.uncertainty,
                                    uncertainty_source_name(uncertainty_source(s)));
           })
      .def("_surface_state",
           [](ModelCore& c, pyb::ssize_t id) {
             ModelState& st = *c.state;
             surface_at(st, id);
             bool has = false;
             double deflection = 0.0;
             Aabb box;
             std::size_t vertices = 0, triangles = 0;
             {
               ModelLock lock(st);  // a running check may be tessellating this surface
               const Surface& s = st.model.surfaces[static_cast<std::size_t>(id)];
               has = s.has_triangles;
               deflection = s.deflection;
               box = s.aabb.isEmpty() ? mesh_aabb(s.mesh) : s.aabb;
               vertices = s.mesh.vertices.size();
               triangles = s.mesh.triangles.size();
             }
             pyb::object b = pyb::none();
             if (!box.isEmpty())
               b = pyb::make_tuple(pyb::make_tuple(box.min().x(), box.min().y(), box.min().z()),
                                   pyb::make_tuple(box.max().x(), box.max().y(), box.max().z()));
             return pyb::make_tuple(has, deflection, b, vertices, triangles);
           })
      .def(
          "_vertices",
          [](pyb::object self, pyb::ssize_t id, bool tessellate) {
            const MeshSpan span = mesh_span(*self.cast<ModelCore&>().state, id, tessellate);
            return view(span.vertices, span.vertex_count, self);
          },
          pyb::arg("id"), pyb::arg("tessellate") = true)
      .def(
          "_triangles",
          [](pyb::object self, pyb::ssize_t id, bool tessellate) {
            const MeshSpan span = mesh_span(*self.cast<ModelCore&>().state, id, tessellate);
            return view(span.triangles, span.triangle_count, self);
          },
          pyb::arg("id"), pyb::arg("tessellate") = true)
      .def("_tessellate",
           [](ModelCore& c, std::vector<std::int64_t> ids, double deflection, int threads) {
             ModelState& st = *c.state;
             checked_threads(threads);
             std::vector<SurfaceId> list;
             for (std::int64_t id : ids) {
               surface_at(st, id);
               list.push_back(static_cast<SurfaceId>(id));
             }
             std::vector<Diagnostic> ds;
             {
               ModelLock lock(st);
               ds = require_triangles(st.model, list, deflection, threads);
             }
             return diagnostics_to_list(ds);
           })
      .def("_triangle_count", [](ModelCore& c) {
        ModelLock lock(*c.state);
        return triangle_count(c.state->model);
      });
}

}  // namespace cadclash::py
