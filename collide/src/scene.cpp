// The prepared scene: broad phase, object and surface levels, and the parallel triangle level.
#include "box_util.h"
#include "narrow_phase.h"
#include "surface_bvh.h"

#include <omp.h>

#include <algorithm>
#include <cassert>
#include <chrono>
#include <limits>
#include <set>
#include <tuple>
#include <unordered_map>

namespace cadclash {
namespace {

using detail::PairOutcome;
using detail::PreparedPair;

// Work blocks of Version 2: this many of A's surviving triangles per item.
constexpr std::size_t kV2Block = 64;
// Fewer work items than this run on the calling thread: waking a team costs more than they do.
constexpr std::ptrdiff_t kMinParallel = 4;
// The object and surface levels of one instance pair take microseconds: only many pairs pay a team.
constexpr std::ptrdiff_t kMinParallelPairs = 64;

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

void add(CollideCounters& into, const CollideCounters& c) {
  into.instance_pairs += c.instance_pairs;
  into.aabb_tests += c.aabb_tests;
  into.aabb_updates += c.aabb_updates;
  into.surfaces_a += c.surfaces_a;
  into.surfaces_b += c.surfaces_b;
  into.surface_pairs += c.surface_pairs;
  into.triangles_a += c.triangles_a;
  into.triangles_b += c.triangles_b;
  into.triangle_tests += c.triangle_tests;
  into.exact_fallbacks += c.exact_fallbacks;
  into.distance_tests += c.distance_tests;
  into.intersecting_pairs += c.intersecting_pairs;
  into.tessellated_surfaces += c.tessellated_surfaces;
}

void set_schedule(Schedule s) {
  switch (s) {
    case Schedule::Guided: omp_set_schedule(omp_sched_guided, 1); break;
    case Schedule::Dynamic: omp_set_schedule(omp_sched_dynamic, 1); break;
    case Schedule::Static: omp_set_schedule(omp_sched_static, 0); break;
  }
}

bool under(const std::string& path, const std::string& prefix) {
  if (prefix.empty() || path.size() < prefix.size() || path.compare(0, prefix.size(), prefix) != 0) return false;
  return path.size() == prefix.size() || path[prefix.size()] == '/' || prefix.back() == '/';
}

// One overlapping instance pair: what the object and surface levels found.
struct InstancePair {
  InstanceId a = kInvalidId, b = kInvalidId;
  Pose t_ab = Pose::Identity(), t_ba = Pose::Identity();  // B → A and A → B
  std::vector<std::array<SurfaceId, 2>> candidates;
  int containment = 0;  // 1: B's box inside A's (test B inside A); 2: the reverse; 0: neither
  CollideCounters counters;
};

struct Task {
  std::uint32_t pair = 0;  // index into the instance pairs
  SurfaceId sa = kInvalidId, sb = kInvalidId;
};

}  // namespace

struct Scene::Impl {
  Model& model;
  SceneSelection selection;
  std::vector<Pose> poses;
  std::vector<Aabb> part_box;   // part-local union of its surfaces' boxes
  std::vector<Aabb> world_box;  // per instance
  std::vector<char> dirty;
  std::vector<detail::SurfaceBvh> bvh;
  std::vector<char> bvh_ready;
  std::vector<char> in_a, in_b;
  std::set<std::pair<InstanceId, InstanceId>> excluded;
  std::unordered_map<std::string, InstanceId> by_path;

  Impl(Model& m, SceneSelection sel) : model(m), selection(std::move(sel)) {
    const std::size_t n = model.instances.size();
    poses.resize(n);
    world_box.resize(n);
    dirty.assign(n, 1);
    for (InstanceId i = 0; i < n; ++i) {
      assert(model.instances[i].part < model.parts.size());
      poses[i] = model.instances[i].pose;
      by_path.emplace(model.instances[i].path, i);
    }
    part_box.resize(model.parts.size());
    for (PartId p = 0; p < model.parts.size(); ++p)
      for (SurfaceId s = first(p); s < end(p); ++s) part_box[p].extend(surface_box(s));
    bvh.resize(model.surfaces.size());
    bvh_ready.assign(model.surfaces.size(), 0);
    in_a.assign(n, selection.set_a.empty() ? 1 : 0);
    in_b.assign(n, selection.set_b.empty() ? 1 : 0);
    for (InstanceId i : selection.set_a) {
      assert(i < n);
      in_a[i] = 1;
    }
    for (InstanceId i : selection.set_b) {
      assert(i < n);
      in_b[i] = 1;
    }
    for (const auto& [pa, pb] : selection.excluded_pairs) {
      const auto ia = by_path.find(pa), ib = by_path.find(pb);
      if (ia == by_path.end() || ib == by_path.end()) continue;
      excluded.emplace(std::min(ia->second, ib->second), std::max(ia->second, ib->second));
    }
  }

  SurfaceId first(PartId p) const { return model.parts[p].first_surface; }
  SurfaceId end(PartId p) const { return model.parts[p].first_surface + model.parts[p].surface_count; }

  Aabb surface_box(SurfaceId s) const {
    const Surface& surf = model.surfaces[s];
    if (!surf.aabb.isEmpty()) return surf.aabb;
    return mesh_aabb(surf.mesh);
  }

  double deflection(SurfaceId s, const CollideOptions& o) const {
    const Surface& surf = model.surfaces[s];
    return surf.has_triangles ? surf.deflection : std::max(surf.deflection, o.deflection_hint);
  }

  double part_deflection(PartId p, const CollideOptions& o) const {
    double d = 0.0;
    for (SurfaceId s = first(p); s < end(p); ++s) d = std::max(d, deflection(s, o));
    return d;
  }

  bool selected(InstanceId i, InstanceId j) const {
    if (!((in_a[i] && in_b[j]) || (in_a[j] && in_b[i]))) return false;
    if (excluded.count({std::min(i, j), std::max(i, j)})) return false;
    for (const std::string& prefix : selection.excluded_subassemblies)
      if (under(model.instances[i].path, prefix) && under(model.instances[j].path, prefix)) return false;
    return true;
  }

  // Sweep-and-prune over x of the instance world boxes grown by half the search margin each.
  std::vector<std::array<InstanceId, 2>> broad_phase(double margin, CollideCounters& c) const {
    std::vector<InstanceId> ids;
    std::vector<Aabb> boxes(world_box.size());
    for (InstanceId i = 0; i < world_box.size(); ++i) {
      if (!(in_a[i] || in_b[i]) || world_box[i].isEmpty()) continue;
      ids.push_back(i);
      boxes[i] = detail::pad_box(world_box[i], 0.5 * margin);
    }
    std::sort(ids.begin(), ids.end(), [&](InstanceId x, InstanceId y) {
      return boxes[x].min().x() < boxes[y].min().x() || (boxes[x].min().x() == boxes[y].min().x() && x < y);
    });
    std::vector<std::array<InstanceId, 2>> out;
    for (std::size_t k = 0; k < ids.size(); ++k) {
      const Aabb& bk = boxes[ids[k]];
      for (std::size_t l = k + 1; l < ids.size() && boxes[ids[l]].min().x() <= bk.max().x(); ++l) {
        ++c.aabb_tests;
        const InstanceId i = std::min(ids[k], ids[l]), j = std::max(ids[k], ids[l]);
        if (detail::boxes_overlap(bk, boxes[ids[l]]) && selected(i, j)) out.push_back({i, j});
      }
    }
    std::sort(out.begin(), out.end());
    return out;
  }

  // Object and surface levels of one instance pair.
  void surface_level(InstancePair& ip, const CollideOptions& o) const {
    const Instance& ia = model.instances[ip.a];
    const Instance& ib = model.instances[ip.b];
    ip.t_ab = poses[ip.a].inverse(Eigen::Isometry) * poses[ip.b];
    ip.t_ba = ip.t_ab.inverse(Eigen::Isometry);
    CollideCounters& c = ip.counters;
    if (o.detect_containment) {
      const Aabb& wa = world_box[ip.a];
      const Aabb& wb = world_box[ip.b];
      if (!wa.isEmpty() && !wb.isEmpty()) {
        if (wa.contains(wb)) ip.containment = 1;
        else if (wb.contains(wa)) ip.containment = 2;
      }
    }
    if (!o.use_oaabb) {
      for (SurfaceId sa = first(ia.part); sa < end(ia.part); ++sa)
        for (SurfaceId sb = first(ib.part); sb < end(ib.part); ++sb) ip.candidates.push_back({sa, sb});
      c.surface_pairs += ip.candidates.size();
      return;
    }
    const double tol_margin = std::max(o.tolerance + part_deflection(ia.part, o) + part_deflection(ib.part, o),
                                       o.clearance);
    // The OAABB in A's frame, then its single update into B's frame.
    const Aabb oaabb = detail::pad_box(part_box[ia.part], tol_margin)
                           .intersection(detail::transform_box(detail::pad_box(part_box[ib.part], tol_margin), ip.t_ab));
    ++c.aabb_updates;
    if (oaabb.isEmpty()) return;
    const Aabb oaabb_b = detail::transform_box(oaabb, ip.t_ba);
    ++c.aabb_updates;
    std::vector<SurfaceId> surv_a, surv_b;
    for (SurfaceId s = first(ia.part); s < end(ia.part); ++s) {
      ++c.aabb_tests;
      if (detail::boxes_overlap(surface_box(s), oaabb)) surv_a.push_back(s);
    }
    for (SurfaceId s = first(ib.part); s < end(ib.part); ++s) {
      ++c.aabb_tests;
      if (detail::boxes_overlap(surface_box(s), oaabb_b)) surv_b.push_back(s);
    }
    c.surfaces_a += surv_a.size();
    c.surfaces_b += surv_b.size();
    std::vector<Aabb> box_b(surv_b.size());
    for (std::size_t k = 0; k < surv_b.size(); ++k) {
      box_b[k] = detail::transform_box(surface_box(surv_b[k]), ip.t_ab);
      ++c.aabb_updates;
    }
    for (SurfaceId sa : surv_a) {
      const Aabb box_a = surface_box(sa);
      for (std::size_t k = 0; k < surv_b.size(); ++k) {
        const double m = std::max(o.tolerance + deflection(sa, o) + deflection(surv_b[k], o), o.clearance);
        ++c.aabb_tests;
        if (detail::boxes_within(box_a, box_b[k], m + detail::kRelativePad * (1.0 + detail::box_magnitude(box_b[k]))))
          ip.candidates.push_back({sa, surv_b[k]});
      }
    }
    c.surface_pairs += ip.candidates.size();
  }

  // True when every surface of instance `inner` has its first vertex inside `outer`'s triangles.
  bool inside(InstanceId inner, InstanceId outer, const Pose& inner_to_outer) const {
    std::vector<const Surface*> outer_surfaces;
    const PartId po = model.instances[outer].part, pi = model.instances[inner].part;
    for (SurfaceId s = first(po); s < end(po); ++s)
      if (model.surfaces[s].has_triangles) outer_surfaces.push_back(&model.surfaces[s]);
    if (outer_surfaces.empty()) return false;
    bool any = false;
    for (SurfaceId s = first(pi); s < end(pi); ++s) {
      const Surface& surf = model.surfaces[s];
      if (!surf.has_triangles || surf.mesh.triangles.empty()) continue;
      const Vec3 p = inner_to_outer * surf.mesh.vertices[surf.mesh.triangles[0][0]];
      if (std::abs(detail::winding_number(p, outer_surfaces)) < 0.5) return false;
      any = true;
    }
    return any;
  }
};

Scene::Scene(Model& model, SceneSelection selection) : impl_(std::make_unique<Impl>(model, std::move(selection))) {}
Scene::~Scene() = default;

void Scene::set_pose(InstanceId instance, const Pose& pose) {
  assert(instance < impl_->poses.size());
  impl_->poses[instance] = pose;
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

Report Scene::check(const CollideOptions& o) {
  assert(o.tolerance >= 0.0 && o.clearance >= 0.0);
  Impl& s = *impl_;
  Model& model = s.model;
  Report report;
  CollideCounters& total = report.counters;
  const auto t0 = std::chrono::steady_clock::now();
  const int threads = o.threads > 0 ? o.threads : omp_get_max_threads();
  set_schedule(o.schedule);

  // Only moved instances get new world boxes.
  for (InstanceId i = 0; i < s.poses.size(); ++i) {
    if (!s.dirty[i]) continue;
    s.world_box[i] = detail::transform_box(s.part_box[model.instances[i].part], s.poses[i]);
    ++total.aabb_updates;
    s.dirty[i] = 0;
  }

  // 1. Broad phase (brute force: every selected pair).
  std::vector<InstancePair> pairs;
  {
    std::vector<std::array<InstanceId, 2>> ids;
    if (o.use_oaabb) {
      double max_defl = 0.0;
      for (PartId p = 0; p < model.parts.size(); ++p) max_defl = std::max(max_defl, s.part_deflection(p, o));
      ids = s.broad_phase(std::max(o.tolerance + 2.0 * max_defl, o.clearance), total);
    } else {
      for (InstanceId i = 0; i < s.poses.size(); ++i)
        for (InstanceId j = i + 1; j < s.poses.size(); ++j)
          if (s.selected(i, j)) ids.push_back({i, j});
    }
    pairs.resize(ids.size());
    for (std::size_t k = 0; k < ids.size(); ++k) {
      pairs[k].a = ids[k][0];
      pairs[k].b = ids[k][1];
    }
    total.instance_pairs = pairs.size();
  }
  report.timings.broad = seconds_since(t0);

  // 2. Object and surface levels, parallel over instance pairs.
  const auto t1 = std::chrono::steady_clock::now();
  const auto npairs = static_cast<std::ptrdiff_t>(pairs.size());
#pragma omp parallel for num_threads(threads) schedule(runtime) if (npairs >= kMinParallelPairs)
  for (std::ptrdiff_t k = 0; k < npairs; ++k) s.surface_level(pairs[static_cast<std::size_t>(k)], o);
  std::vector<Task> tasks;
  std::vector<SurfaceId> needed;
  for (std::uint32_t k = 0; k < pairs.size(); ++k) {
    const InstancePair& ip = pairs[k];
    add(total, ip.counters);
    for (const auto& c : ip.candidates) {
      tasks.push_back({k, c[0], c[1]});
      needed.push_back(c[0]);
      needed.push_back(c[1]);
    }
    if (ip.containment) {
      for (InstanceId i : {ip.a, ip.b}) {
        const PartId p = model.instances[i].part;
        for (SurfaceId sid = s.first(p); sid < s.end(p); ++sid) needed.push_back(sid);
      }
    }
  }
  std::sort(needed.begin(), needed.end());
  needed.erase(std::unique(needed.begin(), needed.end()), needed.end());
  report.timings.surface_level = seconds_since(t1);

  // 3. Lazy tessellation of exactly the surviving surfaces, then their BVHs (built once per surface).
  const auto t2 = std::chrono::steady_clock::now();
  std::vector<SurfaceId> missing;
  for (SurfaceId sid : needed)
    if (!model.surfaces[sid].has_triangles) missing.push_back(sid);
  total.tessellated_surfaces = missing.size();
  if (!missing.empty()) report.diagnostics = require_triangles(model, missing, o.tessellation_deflection);
  std::vector<SurfaceId> to_build;
  for (SurfaceId sid : needed)
    if (!s.bvh_ready[sid] && model.surfaces[sid].has_triangles) to_build.push_back(sid);
  const auto nbuild = static_cast<std::ptrdiff_t>(to_build.size());
#pragma omp parallel for num_threads(threads) schedule(dynamic, 1) if (nbuild >= kMinParallel)
  for (std::ptrdiff_t k = 0; k < nbuild; ++k) {
    const SurfaceId sid = to_build[static_cast<std::size_t>(k)];
    s.bvh[sid] = detail::build_surface_bvh(model.surfaces[sid].mesh);
  }
  for (SurfaceId sid : to_build) s.bvh_ready[sid] = 1;
  report.timings.tessellation = seconds_since(t2);

  // 4. Triangle level: Version 1 (one item per surface pair) or 2 (surface pair × block of A's triangles).
  const auto t3 = std::chrono::steady_clock::now();
  const auto ntasks = static_cast<std::ptrdiff_t>(tasks.size());
  std::vector<PreparedPair> prepared(tasks.size());
  std::vector<PairOutcome> outcomes(tasks.size());
  std::vector<CollideCounters> task_counters(tasks.size());
  auto usable = [&](const Task& t) {
    return model.surfaces[t.sa].has_triangles && model.surfaces[t.sb].has_triangles;
  };
  auto prepare = [&](std::size_t k) {
    const Task& t = tasks[k];
    if (!usable(t)) return;
    const InstancePair& ip = pairs[t.pair];
    detail::prepare_pair(model.surfaces[t.sa], s.bvh[t.sa], model.surfaces[t.sb], s.bvh[t.sb], ip.t_ab, ip.t_ba, o,
                         prepared[k], task_counters[k]);
  };
  if (o.version == ParallelVersion::V1) {
#pragma omp parallel for num_threads(threads) schedule(runtime) if (ntasks >= kMinParallel)
    for (std::ptrdiff_t k = 0; k < ntasks; ++k) {
      const auto ku = static_cast<std::size_t>(k);
      prepare(ku);
      detail::run_pair(model.surfaces[tasks[ku].sa], prepared[ku], 0, prepared[ku].la.size(), o, outcomes[ku],
                       task_counters[ku]);
      const double tau = prepared[ku].tau;  // keep tau only; free the survivors
      prepared[ku] = PreparedPair{};
      prepared[ku].tau = tau;
    }
  } else {
#pragma omp parallel for num_threads(threads) schedule(runtime) if (ntasks >= kMinParallel)
    for (std::ptrdiff_t k = 0; k < ntasks; ++k) prepare(static_cast<std::size_t>(k));
    struct Item {
      std::size_t task, begin, end;
    };
    std::vector<Item> items;
    for (std::size_t k = 0; k < tasks.size(); ++k)
      for (std::size_t b = 0; b < prepared[k].la.size(); b += kV2Block)
        items.push_back({k, b, std::min(prepared[k].la.size(), b + kV2Block)});
    std::vector<PairOutcome> item_out(items.size());
    std::vector<CollideCounters> item_counters(items.size());
    const auto nitems = static_cast<std::ptrdiff_t>(items.size());
#pragma omp parallel for num_threads(threads) schedule(runtime) if (nitems >= kMinParallel)
    for (std::ptrdiff_t i = 0; i < nitems; ++i) {
      const Item& it = items[static_cast<std::size_t>(i)];
      detail::run_pair(model.surfaces[tasks[it.task].sa], prepared[it.task], it.begin, it.end, o,
                       item_out[static_cast<std::size_t>(i)], item_counters[static_cast<std::size_t>(i)]);
    }
    for (std::size_t i = 0; i < items.size(); ++i) {  // fixed order: independent of the thread count
      detail::merge_outcome(outcomes[items[i].task], std::move(item_out[i]));
      add(task_counters[items[i].task], item_counters[i]);
    }
  }

  // 5. Classes, in task order.
  std::vector<char> pair_intersects(pairs.size(), 0);
  std::vector<double> pair_distance(pairs.size(), std::numeric_limits<double>::infinity());
  for (std::size_t k = 0; k < tasks.size(); ++k) {
    add(total, task_counters[k]);
    const Task& t = tasks[k];
    const PairOutcome& out = outcomes[k];
    if (out.intersecting) {
      ++total.intersecting_pairs;
      pair_intersects[t.pair] = 1;
    }
    const auto cls = detail::classify(out, prepared[k].tau, o.clearance);
    if (!cls) continue;
    SurfacePairResult r;
    r.instance_a = pairs[t.pair].a;
    r.instance_b = pairs[t.pair].b;
    r.surface_a = t.sa;
    r.surface_b = t.sb;
    r.contact = *cls;
    r.intersecting = out.intersecting;
    r.distance = out.intersecting ? 0.0 : out.distance;
    r.penetration = out.penetration;
    r.triangle_pairs = out.triangle_pairs;
    pair_distance[t.pair] = std::min(pair_distance[t.pair], r.distance);
    if (o.exact_verification && !out.intersecting) {
      const Part& pa = model.parts[model.surfaces[t.sa].part];
      const Part& pb = model.parts[model.surfaces[t.sb].part];
      if (pa.source && pb.source)
        r.exact_distance = pa.source->exact_distance(t.sa - pa.first_surface, s.poses[r.instance_a], *pb.source,
                                                     t.sb - pb.first_surface, s.poses[r.instance_b],
                                                     std::max(prepared[k].tau, o.clearance));
    }
    report.pairs.push_back(std::move(r));
  }

  // 6. Containment: instance pairs whose boxes nest and whose surfaces do not cross.
  std::vector<char> contained(pairs.size(), 0);
#pragma omp parallel for num_threads(threads) schedule(dynamic, 1) if (npairs >= kMinParallel)
  for (std::ptrdiff_t k = 0; k < npairs; ++k) {
    const InstancePair& ip = pairs[static_cast<std::size_t>(k)];
    if (!ip.containment || pair_intersects[static_cast<std::size_t>(k)]) continue;
    contained[static_cast<std::size_t>(k)] =
        ip.containment == 1 ? s.inside(ip.b, ip.a, ip.t_ab) : s.inside(ip.a, ip.b, ip.t_ba);
  }
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    if (!contained[k]) continue;
    SurfacePairResult r;
    r.instance_a = pairs[k].a;
    r.instance_b = pairs[k].b;
    r.contact = ContactClass::Containment;
    r.distance = pair_distance[k];
    report.pairs.push_back(std::move(r));
  }
  report.timings.triangle_level = seconds_since(t3);

  std::sort(report.pairs.begin(), report.pairs.end(), [](const SurfacePairResult& x, const SurfacePairResult& y) {
    return std::tie(x.instance_a, x.instance_b, x.surface_a, x.surface_b) <
           std::tie(y.instance_a, y.instance_b, y.surface_a, y.surface_b);
  });
  report.timings.total = seconds_since(t0);
  return report;
}

Report collide(Model& model, InstanceId a, InstanceId b, const CollideOptions& options) {
  assert(a < model.instances.size() && b < model.instances.size() && a != b);
  SceneSelection sel;
  sel.set_a = {a};
  sel.set_b = {b};
  Scene scene(model, std::move(sel));
  return scene.check(options);
}

}  // namespace cadclash
