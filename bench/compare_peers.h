// The other libraries bench_compare runs on the same triangles: FCL 0.7 mesh–mesh collide
// (OBBRSS and AABB trees), CGAL box_intersection_d + exact do_intersect, and OCCT
// BRepExtrema_ShapeProximity on the faces' own BRepMesh triangulation. Each answers, at every step
// of a workload, which surface pairs have intersecting triangles (OCCT: which face pairs overlap
// within its tolerance). Bench-only code.
#pragma once

#include "compare_workload.h"

#include <cstdint>
#include <memory>
#include <string>

namespace cadclash::bench {

// What one run of a method over a whole workload found and counted.
struct PeerRun {
  PairSet found;
  std::uint64_t triangle_tests = 0;  // triangle–triangle tests made (0 with has_tests false)
  bool has_tests = true;
};

class Peer {
 public:
  virtual ~Peer() = default;
  virtual std::string name() const = 0;
  // Builds the per-part structures the peer keeps across queries. Returns false with `error` set when
  // it cannot run on this model (e.g. OCCT without B-rep faces).
  virtual bool build(const Model& model, std::string& error) = 0;
  virtual double bytes_per_triangle() const = 0;  // of what build() kept; < 0 when it keeps nothing
  // Replays `w`, testing the broad-phase instance pairs of `subset`. Single-threaded.
  virtual PeerRun run(const Workload& w, const Subset& subset) = 0;
};

std::unique_ptr<Peer> make_fcl_obbrss_peer();
std::unique_ptr<Peer> make_fcl_aabb_peer();
std::unique_ptr<Peer> make_cgal_peer();
// `tolerance` is ShapeProximity's; 0 lists face pairs whose triangles intersect.
std::unique_ptr<Peer> make_occt_peer(double tolerance);

}  // namespace cadclash::bench
