// The prepared scene: broad phase, object and surface levels, and the parallel triangle level.
#include "box_util.h"
#include "budget.h"
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
// Surfaces tessellated per round under a memory budget: a constant, so the rounds, and so what the
// budget keeps, do not depend on the thread count.
constexpr std::size_t kBudgetRound = 64;

std::uint64_t mesh_bytes(const TriangleMesh& m) {
  return m.vertices.size() * sizeof(Vec3) + m.triangles.size() * sizeof(m.triangles[0]);
}

std::uint64_t bvh_bytes(const detail::SurfaceBvh& b) {
  return b.nodes.size() * sizeof(b.nodes[0]) + b.order.size() * sizeof(b.order[0]) +
         b.triangle_boxes.size() * sizeof(Aabb);
}

std::uint64_t result_bytes(const SurfacePairResult& r) {
  return sizeof(r) + r.triangle_pairs.size() * sizeof(r.triangle_pairs[0]);
}

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
  bool cut = false;  // the time budget ran out before its surface level
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
  assert(o.tolerance >= 0.0 && o.clearance >= 0.0 && o.time_budget_seconds >= 0.0);
  Impl& s = *impl_;
  Model& model = s.model;
  Report report;
  CollideCounters& total = report.counters;
  const auto t0 = std::chrono::steady_clock::now();
  const detail::Deadline deadline(t0, o.time_budget_seconds);
  const std::uint64_t budget = o.memory_budget_bytes;
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
  for (std::ptrdiff_t k = 0; k < npairs; ++k) {
    InstancePair& ip = pairs[static_cast<std::size_t>(k)];
    if (deadline.expired()) ip.cut = true;
    else s.surface_level(ip, o);
  }
  // The memory budget's ledger: per instance pair, the bytes it makes this query build. Each
  // surface is charged to the first pair (in pair order) that needs it, so the prefix of pairs that
  // fits the budget does not depend on how the work was spread over threads.
  std::vector<std::uint64_t> charge(pairs.size(), 0);
  std::vector<Task> tasks;
  std::vector<std::size_t> first_task(pairs.size() + 1, 0);  // tasks of pair k: [first_task[k], first_task[k+1])
  std::vector<SurfaceId> needed;                              // in order of first need
  std::vector<std::uint32_t> first_need(model.surfaces.size(), kInvalidId);
  for (std::uint32_t k = 0; k < pairs.size(); ++k) {
    const InstancePair& ip = pairs[k];
    first_task[k] = tasks.size();
    charge[k] += ip.candidates.size() * sizeof(ip.candidates[0]);
    auto need = [&](SurfaceId sid) {
      if (first_need[sid] != kInvalidId) return;
      first_need[sid] = k;
      needed.push_back(sid);
    };
    for (const auto& c : ip.candidates) {
      tasks.push_back({k, c[0], c[1]});
      need(c[0]);
      need(c[1]);
    }
    if (ip.containment) {
      for (InstanceId i : {ip.a, ip.b}) {
        const PartId p = model.instances[i].part;
        for (SurfaceId sid = s.first(p); sid < s.end(p); ++sid) need(sid);
      }
    }
  }
  first_task[pairs.size()] = tasks.size();
  report.timings.surface_level = seconds_since(t1);

  // Instance pairs from `cutoff` on do not fit the memory budget. Charges only grow, so the first
  // pair whose running sum exceeds the budget can only move earlier as more is charged.
  auto cutoff = static_cast<std::uint32_t>(pairs.size());
  auto apply_memory_budget = [&] {
    if (budget == 0) return;
    std::uint64_t sum = 0;
    for (std::uint32_t k = 0; k < cutoff; ++k) {
      sum += charge[k];
      if (sum > budget) {
        cutoff = k;
        return;
      }
    }
  };
  apply_memory_budget();

  // 3. Lazy tessellation of exactly the surviving surfaces, then their BVHs (built once per surface).
  // Under a memory budget in rounds of a fixed number of surfaces in order of first need, checking
  // the budget between rounds, so a small budget does not tessellate the whole scene first.
  const auto t2 = std::chrono::steady_clock::now();
  std::vector<SurfaceId> asked, tessellated, built;
  std::vector<double> old_deflection;  // parallel to `tessellated`: restored if released
  const std::size_t round = budget > 0 ? kBudgetRound : std::max<std::size_t>(needed.size(), 1);
  for (std::size_t r = 0; r < needed.size(); r += round) {
    if (first_need[needed[r]] >= cutoff || deadline.expired()) break;
    const std::span<const SurfaceId> wave(needed.data() + r, std::min(round, needed.size() - r));
    std::vector<SurfaceId> missing;
    std::vector<double> before;
    for (SurfaceId sid : wave)
      if (!model.surfaces[sid].has_triangles) {
        missing.push_back(sid);
        before.push_back(model.surfaces[sid].deflection);
      }
    if (!missing.empty()) {
      std::vector<Diagnostic> ds = detail::require_triangles(model, missing, o.tessellation_deflection, deadline);
      report.diagnostics.insert(report.diagnostics.end(), ds.begin(), ds.end());
      asked.insert(asked.end(), missing.begin(), missing.end());
    }
    for (std::size_t i = 0; i < missing.size(); ++i) {
      const Surface& surf = model.surfaces[missing[i]];
      if (!surf.has_triangles) continue;
      tessellated.push_back(missing[i]);
      old_deflection.push_back(before[i]);
      charge[first_need[missing[i]]] += mesh_bytes(surf.mesh);
    }
    std::vector<SurfaceId> to_build;
    for (SurfaceId sid : wave)
      if (!s.bvh_ready[sid] && model.surfaces[sid].has_triangles) to_build.push_back(sid);
    std::vector<char> done(to_build.size(), 0);
    const auto nbuild = static_cast<std::ptrdiff_t>(to_build.size());
#pragma omp parallel for num_threads(threads) schedule(dynamic, 1) if (nbuild >= kMinParallel)
    for (std::ptrdiff_t k = 0; k < nbuild; ++k) {
      if (deadline.expired()) continue;
      const SurfaceId sid = to_build[static_cast<std::size_t>(k)];
      s.bvh[sid] = detail::build_surface_bvh(model.surfaces[sid].mesh);
      done[static_cast<std::size_t>(k)] = 1;
    }
    for (std::size_t k = 0; k < to_build.size(); ++k) {
      if (!done[k]) continue;
      s.bvh_ready[to_build[k]] = 1;
      built.push_back(to_build[k]);
      charge[first_need[to_build[k]]] += bvh_bytes(s.bvh[to_build[k]]);
    }
    apply_memory_budget();
  }
  report.timings.tessellation = seconds_since(t2);

  // 4. Triangle level: Version 1 (one item per surface pair) or 2 (surface pair × block of A's
  // triangles), over the tasks of the pairs within the memory budget. With the time budget out,
  // remaining items are skipped and marked cut (an OpenMP loop cannot break).
  const auto t3 = std::chrono::steady_clock::now();
  std::vector<PreparedPair> prepared(tasks.size());
  std::vector<PairOutcome> outcomes(tasks.size());
  std::vector<CollideCounters> task_counters(tasks.size());
  std::vector<char> task_cut(tasks.size(), 0);
  std::vector<std::uint64_t> task_bytes(tasks.size(), 0);
  auto usable = [&](const Task& t) {
    return model.surfaces[t.sa].has_triangles && model.surfaces[t.sb].has_triangles;
  };
  auto prepare = [&](std::size_t k) {
    const Task& t = tasks[k];
    if (!usable(t)) return;
    const InstancePair& ip = pairs[t.pair];
    detail::prepare_pair(model.surfaces[t.sa], s.bvh[t.sa], model.surfaces[t.sb], s.bvh[t.sb], ip.t_ab, ip.t_ba, o,
                         prepared[k], task_counters[k]);
    task_bytes[k] = detail::prepared_bytes(prepared[k]);
  };
  auto charge_prepared = [&](std::size_t end_task) {
    for (std::size_t k = 0; k < end_task; ++k) charge[tasks[k].pair] += task_bytes[k];
    apply_memory_budget();
  };
  if (o.version == ParallelVersion::V1) {
    const auto ntasks = static_cast<std::ptrdiff_t>(first_task[cutoff]);
#pragma omp parallel for num_threads(threads) schedule(runtime) if (ntasks >= kMinParallel)
    for (std::ptrdiff_t k = 0; k < ntasks; ++k) {
      const auto ku = static_cast<std::size_t>(k);
      if (deadline.expired()) {
        task_cut[ku] = 1;
        continue;
      }
      prepare(ku);
      detail::run_pair(model.surfaces[tasks[ku].sa], prepared[ku], 0, prepared[ku].la.size(), o, outcomes[ku],
                       task_counters[ku], &deadline);
      const double tau = prepared[ku].tau;  // keep tau only; free the survivors
      prepared[ku] = PreparedPair{};
      prepared[ku].tau = tau;
    }
    charge_prepared(static_cast<std::size_t>(ntasks));
  } else {
    const auto ntasks = static_cast<std::ptrdiff_t>(first_task[cutoff]);
#pragma omp parallel for num_threads(threads) schedule(runtime) if (ntasks >= kMinParallel)
    for (std::ptrdiff_t k = 0; k < ntasks; ++k) {
      if (deadline.expired()) task_cut[static_cast<std::size_t>(k)] = 1;
      else prepare(static_cast<std::size_t>(k));
    }
    charge_prepared(static_cast<std::size_t>(ntasks));  // all survivor lists are held at once here
    for (std::size_t k = first_task[cutoff]; k < static_cast<std::size_t>(ntasks); ++k) prepared[k] = PreparedPair{};
    struct Item {
      std::size_t task, begin, end;
    };
    std::vector<Item> items;
    for (std::size_t k = 0; k < first_task[cutoff]; ++k)
      for (std::size_t b = 0; b < prepared[k].la.size(); b += kV2Block)
        items.push_back({k, b, std::min(prepared[k].la.size(), b + kV2Block)});
    std::vector<PairOutcome> item_out(items.size());
    std::vector<CollideCounters> item_counters(items.size());
    const auto nitems = static_cast<std::ptrdiff_t>(items.size());
#pragma omp parallel for num_threads(threads) schedule(runtime) if (nitems >= kMinParallel)
    for (std::ptrdiff_t i = 0; i < nitems; ++i) {
      const auto iu = static_cast<std::size_t>(i);
      const Item& it = items[iu];
      if (deadline.expired()) item_out[iu].cut = true;
      else detail::run_pair(model.surfaces[tasks[it.task].sa], prepared[it.task], it.begin, it.end, o, item_out[iu],
                            item_counters[iu], &deadline);
    }
    for (std::size_t i = 0; i < items.size(); ++i) {  // fixed order: independent of the thread count
      detail::merge_outcome(outcomes[items[i].task], std::move(item_out[i]));
      add(task_counters[items[i].task], item_counters[i]);
    }
  }
  for (std::size_t k = 0; k < first_task[cutoff]; ++k)
    if (outcomes[k].cut) task_cut[k] = 1;

  // 5. Classes, in task order. A cut surface pair reports nothing: its class could be wrong.
  std::vector<char> pair_cut(pairs.size(), 0);
  for (std::size_t k = 0; k < pairs.size(); ++k) pair_cut[k] = pairs[k].cut;
  std::vector<char> pair_intersects(pairs.size(), 0);
  std::vector<double> pair_distance(pairs.size(), std::numeric_limits<double>::infinity());
  std::vector<std::vector<SurfacePairResult>> pair_results(pairs.size());
  struct Classified {
    std::size_t task = 0;
    SurfacePairResult result;
    bool cut = false;  // the time budget ran out before its exact verification
  };
  std::vector<Classified> classified;
  for (std::size_t k = 0; k < first_task[cutoff]; ++k) {
    const Task& t = tasks[k];
    if (task_cut[k]) {
      pair_cut[t.pair] = 1;
      continue;
    }
    const PairOutcome& out = outcomes[k];
    if (out.intersecting) pair_intersects[t.pair] = 1;
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
    classified.push_back({k, std::move(r)});
  }
  // Exact verification of every pair that is not penetrating, touching pairs whose triangles cross
  // included: faceted coaxial cylinders with a small radial gap cross each other although the exact
  // faces are apart. One exact distance takes milliseconds, so the pairs go to the threads one at a
  // time; each answer depends on its pair alone and the merge below keeps task order, so the report
  // is the same for any thread count (only which pairs a time budget cuts depends on it).
  if (o.exact_verification) {
    std::vector<std::size_t> verify;
    for (std::size_t i = 0; i < classified.size(); ++i)
      if (classified[i].result.contact != ContactClass::Penetrating) verify.push_back(i);
    const auto nverify = static_cast<std::ptrdiff_t>(verify.size());
#pragma omp parallel for num_threads(threads) schedule(dynamic, 1) if (nverify >= 2)
    for (std::ptrdiff_t v = 0; v < nverify; ++v) {
      Classified& c = classified[verify[static_cast<std::size_t>(v)]];
      if (deadline.expired()) {
        c.cut = true;
        continue;
      }
      SurfacePairResult& r = c.result;
      const Part& pa = model.parts[model.surfaces[r.surface_a].part];
      const Part& pb = model.parts[model.surfaces[r.surface_b].part];
      if (pa.source && pb.source)
        r.exact_distance = pa.source->exact_distance(r.surface_a - pa.first_surface, s.poses[r.instance_a], *pb.source,
                                                     r.surface_b - pb.first_surface, s.poses[r.instance_b],
                                                     std::max(prepared[c.task].tau, o.clearance));
    }
  }
  for (Classified& c : classified) {
    const std::size_t pair = tasks[c.task].pair;
    if (c.cut) {
      task_cut[c.task] = 1;
      pair_cut[pair] = 1;
      continue;
    }
    charge[pair] += result_bytes(c.result);
    pair_results[pair].push_back(std::move(c.result));
  }

  // 6. Containment: instance pairs whose boxes nest and whose surfaces do not cross (not decidable
  // for a pair with a cut surface pair).
  std::vector<char> contained(pairs.size(), 0);
  const auto ncontain = static_cast<std::ptrdiff_t>(cutoff);
#pragma omp parallel for num_threads(threads) schedule(dynamic, 1) if (ncontain >= kMinParallel)
  for (std::ptrdiff_t k = 0; k < ncontain; ++k) {
    const auto ku = static_cast<std::size_t>(k);
    const InstancePair& ip = pairs[ku];
    if (!ip.containment || pair_intersects[ku] || pair_cut[ku]) continue;
    if (deadline.expired()) {
      pair_cut[ku] = 1;
      continue;
    }
    contained[ku] = ip.containment == 1 ? s.inside(ip.b, ip.a, ip.t_ab) : s.inside(ip.a, ip.b, ip.t_ba);
  }
  for (std::size_t k = 0; k < cutoff; ++k) {
    if (!contained[k]) continue;
    SurfacePairResult r;
    r.instance_a = pairs[k].a;
    r.instance_b = pairs[k].b;
    r.contact = ContactClass::Containment;
    r.distance = pair_distance[k];
    charge[k] += result_bytes(r);
    pair_results[k].push_back(std::move(r));
  }
  apply_memory_budget();
  report.timings.triangle_level = seconds_since(t3);

  // 7. The kept prefix of instance pairs: its results, counters and charge; the rest is listed.
  for (std::uint32_t k = 0; k < pairs.size(); ++k) {
    if (k >= cutoff || pair_cut[k]) report.unexamined_pairs.push_back({pairs[k].a, pairs[k].b});
    if (k >= cutoff) continue;
    add(total, pairs[k].counters);
    report.memory_charged += charge[k];
    for (std::size_t t = first_task[k]; t < first_task[k + 1]; ++t) {
      if (task_cut[t]) continue;
      add(total, task_counters[t]);
      if (outcomes[t].intersecting) ++total.intersecting_pairs;
    }
    for (SurfacePairResult& r : pair_results[k]) report.pairs.push_back(std::move(r));
  }
  for (SurfaceId sid : asked) total.tessellated_surfaces += first_need[sid] < cutoff;
  const bool memory_cut = cutoff < pairs.size();
  const bool time_cut = std::any_of(pair_cut.begin(), pair_cut.begin() + cutoff, [](char c) { return c != 0; });
  report.complete = !memory_cut && !time_cut;
  if (memory_cut && time_cut) report.stopped_by = "time and memory budget";
  else if (memory_cut) report.stopped_by = "memory budget";
  else if (time_cut) report.stopped_by = "time budget";
  std::sort(report.unexamined_pairs.begin(), report.unexamined_pairs.end());

  // Give back what was built only for pairs past the memory budget, leaving the model and the scene
  // as if the query had stopped there.
  if (memory_cut) {
    for (std::size_t i = 0; i < tessellated.size(); ++i) {
      if (first_need[tessellated[i]] < cutoff) continue;
      Surface& surf = model.surfaces[tessellated[i]];
      surf.mesh = TriangleMesh{};
      surf.has_triangles = false;
      surf.deflection = old_deflection[i];
    }
    for (SurfaceId sid : built) {
      if (first_need[sid] < cutoff) continue;
      s.bvh[sid] = detail::SurfaceBvh{};
      s.bvh_ready[sid] = 0;
    }
  }

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
