// Two-part scenes of built B-rep parts for the certified decision's tests: build, place, check.
#pragma once

#include "built_parts.h"
#include "cadclash/collide.h"

#include <gtest/gtest.h>

#include <string>
#include <utility>
#include <vector>

namespace cadclash::testing {

inline Model build(const std::vector<TopoDS_Shape>& shapes, double deflection) {
  TessellationOptions t;
  t.linear_deflection = deflection;
  Built b = build_parts(shapes, t, false);
  EXPECT_TRUE(b.complete);
  return std::move(b.model);
}

inline void place(Model& m, PartId part, const std::string& path, const Pose& pose) {
  Instance in;
  in.path = path;
  in.part = part;
  in.pose = pose;
  m.instances.push_back(in);
}

inline Pose moved(const Vec3& offset, double angle_z = 0.0) {
  Pose p = Pose::Identity();
  p.translate(offset);
  p.rotate(Eigen::AngleAxisd(angle_z, Vec3::UnitZ()));
  return p;
}

struct Outcome {
  Report report;
  bool contact = false;  // some pair of the two instances is reported touching or penetrating
};

// One certified check on one thread.
inline Outcome check_pair(Model& m, double tolerance) {
  Scene scene(m);
  CollideOptions o;
  o.tolerance = tolerance;
  o.threads = 1;
  Outcome out{scene.check(o)};
  for (const SurfacePairResult& p : out.report.pairs)
    out.contact |= p.contact == ContactClass::Touching || p.contact == ContactClass::Penetrating;
  return out;
}

}  // namespace cadclash::testing
