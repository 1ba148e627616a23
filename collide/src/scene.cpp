// The prepared scene: Scene::check runs the query's stages in order (scene_stages.h, stage_*.cpp).
#include "scene_stages.h"
#include "restricted_check.h"

#include <omp.h>

#include <cassert>

namespace cadclash {
namespace detail {

void set_schedule(Schedule s) {
  switch (s) {
    case Schedule::Guided: omp_set_schedule(omp_sched_guided, 1); break;
    case Schedule::Dynamic: omp_set_schedule(omp_sched_dynamic, 1); break;
    case Schedule::Static: omp_set_schedule(omp_sched_static, 0); break;
  }
}

SceneMemory scene_memory(const SceneData& s) {
  SceneMemory m = s.held;
  // Every surface has its slot (exact root box, sizes, pointers) and ready flag, built or not.
  m.hierarchies += s.bvh.size() * (sizeof(SurfaceBvh) + sizeof(s.bvh_ready[0]));
  m.instances = s.poses.size() * sizeof(Pose) + s.world_box.size() * sizeof(Aabb) + s.dirty.size() +
                s.in_a.size() + s.in_b.size() + s.instance_tree.bytes();
  return m;
}

void narrow_stages(SceneData& s, QueryState& q) {
  CollideTimings& time = q.report.timings;
  auto t = std::chrono::steady_clock::now();
  surface_level_stage(s, q);  // which of their surfaces can meet
  time.surface_level = seconds_since(t);
  if (q.note_refined)
    for (SurfaceId sid : q.needed) {
      q.refined_before.push_back(s.refined.surfaces[sid].attempted ? 1 : 0);
      q.regions_before.push_back(s.refined.regions_made[sid]);
    }
  t = std::chrono::steady_clock::now();
  tessellation_stage(s, q);  // triangles and BVHs for exactly those surfaces
  time.tessellation = seconds_since(t);
  t = std::chrono::steady_clock::now();
  if (decide_with_triangles(q)) {
    triangle_and_decision_stage(s, q);  // both, each task's decision right after its triangles
  } else {
    triangle_level_stage(s, q);  // what their triangles say
    decision_stage(s, q);        // what that proves about the exact faces
  }
  containment_stage(s, q);     // whole instances inside others
  time.triangle_level = seconds_since(t);
  results_stage(s, q);  // the kept prefix, in a fixed order
  q.report.model_memory = scene_memory(s);
  time.total = seconds_since(q.t0);
}

}  // namespace detail

Scene::Scene(Model& model, SceneSelection selection) : impl_(std::make_unique<Impl>(model, std::move(selection))) {}
Scene::~Scene() = default;

void Scene::set_pose(InstanceId instance, const Pose& pose) {
  assert(instance < impl_->poses.size());
  impl_->poses[instance] = pose;
  if (!impl_->dirty[instance]) impl_->dirty_list.push_back(instance);
  impl_->dirty[instance] = 1;
}

const Pose& Scene::pose(InstanceId instance) const {
  assert(instance < impl_->poses.size());
  return impl_->poses[instance];
}

InstanceId Scene::find_instance(const std::string& path) const {
  const auto it = impl_->by_path.find(path);
  return it == impl_->by_path.end() ? kInvalidId : it->second;
}

std::size_t Scene::build_hierarchies(int threads) {
  detail::SceneData& s = *impl_;
  std::vector<SurfaceId> all(s.model.surfaces.size());
  for (SurfaceId sid = 0; sid < all.size(); ++sid) all[sid] = sid;
  return detail::build_trees(s, all, threads > 0 ? threads : omp_get_max_threads(), detail::Deadline{}).size();
}

SceneMemory Scene::memory() const { return detail::scene_memory(*impl_); }

Report Scene::check(const CollideOptions& o) {
  assert(o.tolerance >= 0.0 && o.clearance >= 0.0 && o.time_budget_seconds >= 0.0);
  detail::SceneData& s = *impl_;
  detail::QueryState q(o, std::chrono::steady_clock::now());
  q.threads = o.threads > 0 ? o.threads : omp_get_max_threads();
  q.progress = &o.progress;
  if (std::vector<Diagnostic> e = detail::range_errors(s, o); !e.empty()) {
    detail::refuse(q.report, std::move(e));
    return std::move(q.report);
  }
  detail::set_schedule(o.schedule);
  detail::broad_phase_stage(s, q);  // which instance pairs can meet
  q.report.timings.broad = detail::seconds_since(q.t0);
  detail::narrow_stages(s, q);
  return std::move(q.report);
}

namespace detail {

struct SceneAccess {
  static SceneData& data(Scene& scene) { return *scene.impl_; }
};

Report restricted_check(Scene& scene, const CollideOptions& o, const CheckRestriction* only) {
  assert(o.tolerance >= 0.0 && o.clearance >= 0.0 && o.time_budget_seconds >= 0.0);
  SceneData& s = SceneAccess::data(scene);
  QueryState q(o, std::chrono::steady_clock::now());
  q.threads = o.threads > 0 ? o.threads : omp_get_max_threads();
  q.progress = &o.progress;
  q.only = only;
  q.depth = false;  // in contact or not is all its callers ask
  if (std::vector<Diagnostic> e = range_errors(s, o); !e.empty()) {
    refuse(q.report, std::move(e));
    return std::move(q.report);
  }
  set_schedule(o.schedule);
  broad_phase_stage(s, q);
  if (only) {
    std::erase_if(q.pairs, [&](const InstancePair& ip) { return !only->pairs.count({ip.a, ip.b}); });
    q.report.counters.instance_pairs = q.pairs.size();
  }
  q.report.timings.broad = seconds_since(q.t0);
  narrow_stages(s, q);
  return std::move(q.report);
}

}  // namespace detail

Report collide(Model& model, InstanceId a, InstanceId b, const CollideOptions& options) {
  assert(a < model.instances.size() && b < model.instances.size() && a != b);
  SceneSelection sel;
  sel.set_a = {a};
  sel.set_b = {b};
  Scene scene(model, std::move(sel));
  return scene.check(options);
}

}  // namespace cadclash
