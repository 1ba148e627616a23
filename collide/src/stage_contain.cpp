// Stage 6: containment — instance pairs whose boxes nest and whose surfaces do not cross (not
// decidable for a pair with a cut surface pair).
#include "scene_stages.h"
#include "team_loop.h"

#include <cmath>

namespace cadclash::detail {
namespace {

constexpr std::ptrdiff_t kMinParallel = 2;

// True when every surface of instance `inner` has its first vertex inside `outer`'s triangles.
bool inside(const SceneData& s, InstanceId inner, InstanceId outer, const Pose& inner_to_outer) {
  const Model& model = s.model;
  std::vector<const Surface*> outer_surfaces;
  const PartId po = model.instances[outer].part, pi = model.instances[inner].part;
  for (SurfaceId sid = s.first(po); sid < s.end(po); ++sid)
    if (model.surfaces[sid].has_triangles) outer_surfaces.push_back(&model.surfaces[sid]);
  if (outer_surfaces.empty()) return false;
  bool any = false;
  for (SurfaceId sid = s.first(pi); sid < s.end(pi); ++sid) {
    const Surface& surf = model.surfaces[sid];
    if (!surf.has_triangles || surf.mesh.triangles.empty()) continue;
    const Vec3 p = inner_to_outer * surf.mesh.vertices[surf.mesh.triangles[0][0]];
    if (std::abs(winding_number(p, outer_surfaces)) < 0.5) return false;
    any = true;
  }
  return any;
}

}  // namespace

void containment_stage(const SceneData& s, QueryState& q) {
  q.contained.assign(q.pairs.size(), 0);
  // The pairs whose boxes nest and whose surfaces do not cross: usually none, so no team for them.
  std::vector<std::uint32_t> nested;
  for (std::uint32_t k = 0; k < q.cutoff; ++k)
    if (q.pairs[k].containment && !q.pair_intersects[k] && !q.pair_cut[k]) nested.push_back(k);
  const auto n = static_cast<std::ptrdiff_t>(nested.size());
  dynamic_loop(n, q.threads, n >= kMinParallel, [&](std::ptrdiff_t i) {
    const std::uint32_t ku = nested[static_cast<std::size_t>(i)];
    const InstancePair& ip = q.pairs[ku];
    if (q.deadline.expired()) {
      q.pair_cut[ku] = 1;
      return;
    }
    q.contained[ku] = ip.containment == 1 ? inside(s, ip.b, ip.a, ip.t_ab) : inside(s, ip.a, ip.b, ip.t_ba);
  });
  for (std::size_t k = 0; k < q.cutoff; ++k) {
    if (!q.contained[k]) continue;
    SurfacePairResult r;
    r.instance_a = q.pairs[k].a;
    r.instance_b = q.pairs[k].b;
    r.contact = ContactClass::Containment;
    r.distance = q.pair_distance[k];
    r.distance_lo = r.distance_hi = r.distance;
    q.charge[k] += result_bytes(r);
    q.results.push_back(std::move(r));
    q.result_pair.push_back(static_cast<std::uint32_t>(k));
  }
  q.apply_memory_budget();
}

}  // namespace cadclash::detail
