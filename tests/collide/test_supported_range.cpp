// The supported range (model.h): verdicts at every scale a model may have, and queries outside it
// refused with errors instead of answered. Before the range was stated, two triangles crossing at a
// scale of 2^512 were reported as no pair at all, and at 2^260 or 2^-280 as touching.
#include "cadclash/collide.h"
#include "scene_fixtures.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

namespace cadclash {
namespace {

using testing::add_instance;
using testing::add_part;
using testing::translation;

Surface triangle(const std::string& name, const Vec3& a, const Vec3& b, const Vec3& c) {
  Surface s;
  s.name = name;
  s.mesh.vertices = {a, b, c};
  s.mesh.triangles = {{0, 1, 2}};
  return s;
}

// A: the unit right triangle in z = 0. B, by configuration: crossing A's interior half a unit deep
// each side, touching it with a vertex inside it, or a quarter unit above it. Each scaled by 2^e
// exactly and both placed by `pose` (exact: a permutation of axes with sign flips).
enum class Config { Cross, Touch, Apart };

Model scaled_pair(Config c, int e, const Pose& pose) {
  const double s = std::ldexp(1.0, e);
  Model m;
  add_part(m, "a", {triangle("a", Vec3(0, 0, 0) * s, Vec3(1, 0, 0) * s, Vec3(0, 1, 0) * s)});
  const double z0 = c == Config::Cross ? -0.5 : c == Config::Touch ? 0.0 : 0.25;
  add_part(m, "b", {triangle("b", Vec3(0.25, 0.25, z0) * s, Vec3(0.25, 0.25, 0.5 + (z0 > 0 ? 0.5 : 0)) * s, Vec3(1.5, 1.5, 0.5) * s)});
  add_instance(m, "/a", 0, pose);
  add_instance(m, "/b", 1, pose);
  return m;
}

// Exact rigid poses: the identity, a cyclic permutation of the axes, and a half turn about z.
Pose exact_pose(int k) {
  Pose p = Pose::Identity();
  if (k == 1) p.linear() << 0, 0, 1, 1, 0, 0, 0, 1, 0;
  if (k == 2) p.linear() << -1, 0, 0, 0, -1, 0, 0, 0, 1;
  return p;
}

std::string verdict(const Report& r) {
  if (!r.complete) return "refused: " + r.stopped_by;
  if (r.pairs.empty()) return "none";
  if (r.pairs.size() != 1) return "several";
  return contact_class_name(r.pairs[0].contact);
}

// Every scale from 2^-1000 to 2^126 (B reaches 1.5 x 2^e, within 2^128): crossing, touching and
// apart pairs get the verdict the contact rule gives. ε of a mesh part is 2^-24 of its largest
// coordinate, never below kMinUncertainty = 2^-128: at 2^-128 and below every pair here is within
// T = εa + εb of touching, so touching is the right answer; around 2^-125 the crossing depth and the
// gap meet T, where touching (or undecided, for the gap) is as right as the wider answers.
TEST(SupportedRange, VerdictsHoldAtEveryScale) {
  for (int k = 0; k < 3; ++k)
    for (int e = -1000; e <= 126; ++e) {
      const Pose pose = exact_pose(k);
      SCOPED_TRACE("scale 2^" + std::to_string(e) + ", pose " + std::to_string(k));
      Model cross = scaled_pair(Config::Cross, e, pose);
      Model touch = scaled_pair(Config::Touch, e, pose);
      Model apart = scaled_pair(Config::Apart, e, pose);
      const std::string vc = verdict(collide(cross, 0, 1));
      const std::string vt = verdict(collide(touch, 0, 1));
      const std::string va = verdict(collide(apart, 0, 1));
      EXPECT_EQ(vt, "touching");
      if (e >= -120) {
        EXPECT_EQ(vc, "penetrating");
        EXPECT_EQ(va, "none");
      } else if (e <= -129) {
        EXPECT_EQ(vc, "touching");
        EXPECT_EQ(va, "touching");
      } else {
        EXPECT_TRUE(vc == "penetrating" || vc == "touching") << vc;
        EXPECT_TRUE(va == "none" || va == "touching" || va == "undecided") << va;
      }
      if (::testing::Test::HasFailure()) return;  // one scale tells; thousands of lines would not
    }
}

bool refused_with(const Report& r, const std::string& text) {
  if (r.complete || r.stopped_by != "out of range" || !r.pairs.empty()) return false;
  for (const Diagnostic& d : r.diagnostics)
    if (d.severity == Severity::Error && d.message.find(text) != std::string::npos) return true;
  return false;
}

std::string messages(const Report& r) {
  std::string out;
  for (const Diagnostic& d : r.diagnostics) out += format_diagnostic(d) + "\n";
  return out;
}

TEST(SupportedRange, QueriesOutsideItAreRefusedNeverAnswered) {
  // Coordinates past 2^128 (B reaches 1.5 x 2^128).
  {
    Model m = scaled_pair(Config::Cross, 128, Pose::Identity());
    const Report r = collide(m, 0, 1);
    EXPECT_TRUE(refused_with(r, "instance '/b' not checked")) << messages(r);
    EXPECT_TRUE(refused_with(r, "nothing was checked")) << messages(r);
  }
  // A pose, a tolerance, a clearance, a rotation that is none.
  {
    Model m = scaled_pair(Config::Cross, 0, Pose::Identity());
    m.instances[1].pose = translation(0, std::ldexp(1.0, 129), 0);
    EXPECT_TRUE(refused_with(collide(m, 0, 1), "its pose translates by")) << messages(collide(m, 0, 1));
    m.instances[1].pose = translation(0, std::numeric_limits<double>::quiet_NaN(), 0);
    EXPECT_TRUE(refused_with(collide(m, 0, 1), "its pose translates by"));
    m.instances[1].pose = Pose::Identity();
    m.instances[1].pose.linear()(0, 0) = 1e300;
    EXPECT_TRUE(refused_with(collide(m, 0, 1), "not a rotation"));
    m.instances[1].pose = Pose::Identity();
    CollideOptions o;
    o.tolerance = 1e300;
    EXPECT_TRUE(refused_with(collide(m, 0, 1, o), "tolerance"));
    o.tolerance = 0.0;
    o.clearance = HUGE_VAL;
    EXPECT_TRUE(refused_with(collide(m, 0, 1, o), "clearance"));
    m.surfaces[1].uncertainty = 1e200;
    EXPECT_TRUE(refused_with(collide(m, 0, 1), "instance '/b' not checked"));
  }
  // A prepared scene moved out of the range and back: refused, then answered as before.
  {
    Model m = scaled_pair(Config::Cross, 0, Pose::Identity());
    Scene scene(m);
    const std::string before = verdict(scene.check());
    EXPECT_EQ(before, "penetrating");
    scene.set_pose(1, translation(std::ldexp(-1.0, 130), 0, 0));
    EXPECT_TRUE(refused_with(scene.check(), "instance '/b' not checked"));
    const CheckPlan plan = scene.plan({});
    EXPECT_TRUE(plan.pairs.empty());
    ASSERT_FALSE(plan.refused.empty());
    const PartialCheck part = scene.check_part({}, plan, {});
    EXPECT_FALSE(part.report.complete);
    EXPECT_EQ(part.report.stopped_by, "out of range");
    scene.set_pose(1, Pose::Identity());
    EXPECT_EQ(verdict(scene.check()), before);
  }
}

TEST(SupportedRange, TrajectoryTranslationsOutsideItAreErrors) {
  std::vector<Diagnostic> ds;
  const std::vector<TrajectoryRow> rows =
      parse_trajectory("0,/b,1,2,3,1,0,0,0\n1,/b,0,-1e200,0,1,0,0,0\n2,/b,0,0,0,1e300,1e300,0,0\n", "path.csv", ds);
  ASSERT_EQ(rows.size(), 1u);
  ASSERT_EQ(ds.size(), 2u);
  EXPECT_EQ(ds[0].line, 2);
  EXPECT_NE(ds[0].message.find("outside the supported range"), std::string::npos) << ds[0].message;
  EXPECT_NE(ds[0].message.find("-1e200"), std::string::npos) << ds[0].message;
  EXPECT_EQ(ds[1].line, 3);
}

}  // namespace
}  // namespace cadclash

namespace cadclash {
namespace {

// Two one-triangle faces with ε = 0.01 mm each: B's lowest vertex `gap` above A's interior (a
// negative gap crosses A).
Model banded_pair(double gap) {
  Model m;
  add_part(m, "a", {triangle("a", Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0))});
  add_part(m, "b", {triangle("b", Vec3(0.25, 0.25, gap), Vec3(0.25, 0.25, 1), Vec3(1.5, 1.5, 1))});
  for (Surface& s : m.surfaces) s.uncertainty = 0.01;
  add_instance(m, "/a", 0);
  add_instance(m, "/b", 1);
  return m;
}

// A contact says whether the tolerance alone holds it or only the model uncertainty does
// (collide.h, ContactWithin), with the ε each side used.
TEST(ContactWithin, ToleranceAloneOrOnlyTheModelUncertainty) {
  CollideOptions o;
  auto only = [&](double gap, double tolerance) {
    Model m = banded_pair(gap);
    o.tolerance = tolerance;
    const Report r = collide(m, 0, 1, o);
    EXPECT_EQ(r.pairs.size(), 1u) << gap << " " << tolerance;
    return r.pairs.empty() ? SurfacePairResult{} : r.pairs[0];
  };
  SurfacePairResult p = only(0.015, 0.0);  // 0.015 > tolerance 0, <= T = 0.02
  EXPECT_EQ(p.contact, ContactClass::Touching);
  EXPECT_EQ(p.within, ContactWithin::ModelUncertainty);
  EXPECT_EQ(p.uncertainty_a, 0.01);
  EXPECT_EQ(p.uncertainty_b, 0.01);
  p = only(0.015, 0.016);  // within the tolerance itself
  EXPECT_EQ(p.contact, ContactClass::Touching);
  EXPECT_EQ(p.within, ContactWithin::Tolerance);
  p = only(0.0, 0.001);  // exact contact: d* within the rounding r of 0
  EXPECT_EQ(p.within, ContactWithin::Tolerance);
  p = only(0.0, 0.0);  // ... which tolerance 0 cannot be shown to hold: either
  EXPECT_EQ(p.contact, ContactClass::Touching);
  EXPECT_EQ(p.within, ContactWithin::Unknown);
  p = only(-0.5, 0.0);  // crossing
  EXPECT_EQ(p.contact, ContactClass::Penetrating);
  EXPECT_EQ(p.within, ContactWithin::Tolerance);
  o.decision = DecisionMode::Fast;  // the triangles' band: ε plays no part
  p = only(0.0, 0.0);
  EXPECT_EQ(p.within, ContactWithin::Unknown);
  o.decision = DecisionMode::Certified;
  Model apart = banded_pair(0.03);
  EXPECT_TRUE(collide(apart, 0, 1).pairs.empty());
}

}  // namespace
}  // namespace cadclash
