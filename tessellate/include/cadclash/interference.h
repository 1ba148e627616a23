// cadclash/interference.h — how much two placed B-rep parts overlap: the Boolean common of their
// solids (OCCT BRepAlgoAPI_Common), its volume and centroid (BRepGProp) and its depth.
//
// Contracts:
// - A part's solid is rebuilt from its faces (BrepSource::face, sewn by BRepBuilderAPI_Sewing at
//   the faces' own tolerance); a part whose sewn faces leave a free edge is "not a closed solid", a
//   mesh part "not a B-rep part": the result then says so in `note` and measures nothing.
// - depth is the smallest extent of the common's oriented bounding box (BRepBndLib::AddOBB): the
//   thickness of the overlap, for the thin slabs penetrating contacts give.
// - Never throws, never prints; OCCT failures become a note. Deterministic (OCCT runs serially here).
#pragma once

#include "cadclash/collide.h"

#include <string>

namespace cadclash {

struct InterferenceResult {
  bool measured = false;  // false: `note` says why nothing was measured
  std::string note;
  double volume = 0.0;    // mm^3
  double depth = 0.0;     // mm
  Vec3 centroid = Vec3::Zero();  // world coordinates; meaningful when volume > 0
};

// The interference of instances `a` and `b` at their poses in `model`.
// Precondition: a and b are valid instance ids of `model`.
InterferenceResult measure_interference(const Model& model, InstanceId a, InstanceId b);

}  // namespace cadclash
