// A lower bound on the distance between two faces from their surfaces' rational Bézier patches
// (SurfaceSource::bezier_patches), without OCCT: a rational Bézier patch with positive weights lies in
// the convex hull of its control points, so a plane with A's control points on one side and B's on
// the other, more than T apart, proves those pieces more than T apart. Pieces no plane separates are
// halved (de Casteljau at the middle, in homogeneous coordinates) where their control net bends most,
// until every pair of pieces is separated or the budget is spent. Internal to cadclash::collide.
#pragma once

#include "cadclash/model.h"

#include <optional>

namespace cadclash::detail {

struct PatchGapOptions {
  double threshold = 0.0;   // prove the surfaces farther apart than this (mm)
  double pose_magnitude = 0.0;  // |translation| of both poses that made t_ab: bounds t_ab's own rounding
  int budget = 16384;       // pairs of pieces looked at, at most (~0.25 us each)
  int max_depth = 40;       // halvings of one piece, at most
};

struct PatchGap {
  // A lower bound on the distance between the two patch sets' surfaces that exceeds the threshold,
  // every rounding (the patches' own, t_ab's and its application, the halvings', the planes')
  // already subtracted; nullopt when some pair of pieces is not separated by more than the threshold
  // within the budget (the surfaces may meet, or come closer than the budget can resolve).
  std::optional<double> gap;
  // Without a gap: a point of A's surface (A's frame, within rounding) in the pair of pieces the
  // search stopped at, where the surfaces come closest as far as it saw; a witness to try.
  std::optional<Vec3> near;
};

// A's patches (A's frame) and B's (B's frame, placed into A's by t_ab).
// Precondition: every patch has (degree_u + 1) * (degree_v + 1) points and positive weights.
PatchGap patch_gap(const SurfaceSource::BezierPatches& a, const SurfaceSource::BezierPatches& b, const Pose& t_ab,
                   const PatchGapOptions& options);

}  // namespace cadclash::detail
