// The dense reference of continuous_bench (issue 40, Goals): which pairs of exact B-rep faces are in
// contact at evenly spaced poses of a motion, measured with OCCT alone (BRepExtrema_DistShapeShape
// on the placed TopoDS faces), independently of cadclash's checks. Bench-only code.
//
// Contact of faces fa, fb at a pose: their exact distance <= tolerance + ε_a + ε_b, ε the faces'
// model uncertainty (Surface::uncertainty; as a static check defines contact). Between two poses a
// part moves along interpolate_pose (cadclash's motion: the screw of the displacement, each point on
// a helix about its axis).
//
// Samples are s_j = j / N, j = 0..N, of one stretch. A face pair is measured exactly at a sample
// unless a lower bound already proves it out of contact there: the distance of the faces' placed
// OCCT bounding boxes (BRepBndLib::AddOptimal, part-local, corners mapped), or a lower bound carried
// from the last sample where the pair was measured: d(s) >= d(s') - v |s - s'| with v the pair's
// largest point speed, per side the arc its origin runs, |t_b - t_a| * (angle / 2) / sin(angle / 2) (a
// helix is at most that much longer than its chord), + angle * (largest |p| over the face's box),
// taken 5 % larger plus 1e-9 mm. Containment (one part inside another without faces in contact) is not seen.
#pragma once

#include "cadclash/collide.h"

#include <cstdint>
#include <map>
#include <memory>
#include <utility>
#include <vector>

namespace cadclash::bench {

struct ReferenceSamples {
  std::vector<char> contact;  // per sample j = 0..N: some face pair in contact
  // Per face pair (surface of the first instance, surface of the second) that is in contact at some
  // sample: per sample, in contact.
  std::map<std::pair<SurfaceId, SurfaceId>, std::vector<char>> surfaces;
  std::vector<double> distance;       // per sample: smallest exact distance measured (inf when none was)
  std::uint64_t exact_calls = 0;      // BRepExtrema_DistShapeShape runs
  std::uint64_t failures = 0;         // runs that were not done (counted as in contact)
};

class ContinuousReference {
 public:
  // Faces of every B-rep part of `model` (parts without a BrepSource have none: never in contact).
  explicit ContinuousReference(const Model& model);
  ~ContinuousReference();
  ContinuousReference(const ContinuousReference&) = delete;
  ContinuousReference& operator=(const ContinuousReference&) = delete;

  // Instances a and b over one stretch: a from pose a0 to a1, b from b0 to b1 (equal when it stays),
  // N + 1 samples, `threads` OpenMP threads over the face pairs.
  ReferenceSamples sample(InstanceId a, const Pose& a0, const Pose& a1, InstanceId b, const Pose& b0,
                          const Pose& b1, double tolerance, int samples, int threads) const;

  // The smallest and largest ε over the model's faces.
  std::pair<double, double> uncertainty_range() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace cadclash::bench
