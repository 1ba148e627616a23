// CGAL: box_intersection_d over all triangles of the two instances, then the exact do_intersect
// (Epick: filtered exact predicates) on every box pair. Both instances are tested in A's frame, with
// B's vertices mapped by pose_a⁻¹·pose_b exactly as cadclash maps them, so both answer for the same
// doubles and must agree pair for pair.
#include "compare_peers.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Intersections_3/Triangle_3_Triangle_3.h>
#include <CGAL/box_intersection_d.h>

#include <algorithm>
#include <vector>

namespace cadclash::bench {
namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Box = CGAL::Box_intersection_d::Box_with_info_d<double, 3, std::uint32_t>;

struct Tri {
  K::Triangle_3 t;
  SurfaceId surface;
};

void gather(const Model& model, PartId part, const Pose* map, std::vector<Tri>& tris, std::vector<Box>& boxes) {
  tris.clear();
  boxes.clear();
  const Part& p = model.parts[part];
  for (SurfaceId s = p.first_surface; s < p.first_surface + p.surface_count; ++s) {
    const TriangleMesh& mesh = model.surfaces[s].mesh;
    for (const auto& t : mesh.triangles) {
      K::Point_3 q[3];
      double lo[3], hi[3];
      for (int k = 0; k < 3; ++k) {
        const Vec3 v = map ? Vec3(*map * mesh.vertices[t[k]]) : mesh.vertices[t[k]];
        q[k] = K::Point_3(v.x(), v.y(), v.z());
        for (int c = 0; c < 3; ++c) {
          lo[c] = k == 0 ? v[c] : std::min(lo[c], v[c]);
          hi[c] = k == 0 ? v[c] : std::max(hi[c], v[c]);
        }
      }
      boxes.emplace_back(lo, hi, static_cast<std::uint32_t>(tris.size()));
      tris.push_back({K::Triangle_3(q[0], q[1], q[2]), s});
    }
  }
}

class CgalPeer final : public Peer {
 public:
  std::string name() const override { return "CGAL box_intersection_d + do_intersect"; }
  bool build(const Model&, std::string&) override { return true; }
  double bytes_per_triangle() const override { return -1.0; }

  PeerRun run(const Workload& w, const Subset& subset) override {
    PeerRun out;
    const Model& model = *w.model;
    std::vector<Tri> ta, tb;
    std::vector<Box> ba, bb;
    for_each_step_pair(w, subset, [&](std::uint32_t step, InstanceId a, InstanceId b, const Pose& pa, const Pose& pb) {
      const Pose t_ab = pa.inverse(Eigen::Isometry) * pb;
      gather(model, model.instances[a].part, nullptr, ta, ba);
      gather(model, model.instances[b].part, &t_ab, tb, bb);
      CGAL::box_intersection_d(ba.begin(), ba.end(), bb.begin(), bb.end(), [&](const Box& x, const Box& y) {
        const Tri& p = ta[x.info()];
        const Tri& q = tb[y.info()];
        ++out.triangle_tests;
        // CGAL's triangle–triangle test requires proper triangles; BRepMesh gives none degenerate
        // here, and a degenerate one is counted as not intersecting rather than aborting.
        if (p.t.is_degenerate() || q.t.is_degenerate()) return;
        if (CGAL::do_intersect(p.t, q.t)) out.found.insert({step, a, b, p.surface, q.surface});
      });
    });
    return out;
  }
};

}  // namespace

std::unique_ptr<Peer> make_cgal_peer() { return std::make_unique<CgalPeer>(); }

}  // namespace cadclash::bench
