// Exact verification (CollideOptions::exact_verification) on B-rep parts built here: the distance
// BrepSource::exact_distance reports is OCCT's BRepExtrema_DistShapeShape value bit for bit, the
// verified report is byte-identical for 1, 2 and 4 threads (the distances run in parallel), and a
// pair whose triangles touch but whose exact faces are apart gets its exact distance measured.
#include "built_parts.h"
#include "cadclash/collide.h"
#include "cadclash/import.h"
#include "cadclash/tessellate.h"

#include <BRepBuilderAPI_MakeVertex.hxx>
#include <BRepExtrema_DistShapeShape.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <BRepPrimAPI_MakeSphere.hxx>
#include <BRepPrimAPI_MakeTorus.hxx>
#include <TopLoc_Location.hxx>
#include <TopoDS_Shape.hxx>
#include <gp_Trsf.hxx>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace cadclash {
namespace {

Model build(const std::vector<TopoDS_Shape>& shapes, double deflection = 0.1) {
  TessellationOptions t;
  t.linear_deflection = deflection;
  testing::Built b = testing::build_parts(shapes, t, false);
  EXPECT_TRUE(b.complete);
  return std::move(b.model);
}

Pose placed(const Vec3& offset, double angle_z = 0.0, double angle_x = 0.0) {
  Pose p = Pose::Identity();
  p.translate(offset);
  p.rotate(Eigen::AngleAxisd(angle_z, Vec3::UnitZ()));
  p.rotate(Eigen::AngleAxisd(angle_x, Vec3::UnitX()));
  return p;
}

gp_Trsf trsf(const Pose& p) {
  const auto& m = p.matrix();
  gp_Trsf t;
  t.SetValues(m(0, 0), m(0, 1), m(0, 2), m(0, 3), m(1, 0), m(1, 1), m(1, 2), m(1, 3), m(2, 0), m(2, 1), m(2, 2), m(2, 3));
  return t;
}

std::uint64_t bits(double v) {
  std::uint64_t u = 0;
  std::memcpy(&u, &v, sizeof u);
  return u;
}

// Everything a report says except timings; doubles as bit patterns.
std::string serialize(const Report& r) {
  std::ostringstream s;
  for (const SurfacePairResult& p : r.pairs) {
    s << p.instance_a << ' ' << p.instance_b << ' ' << p.surface_a << ' ' << p.surface_b << ' '
      << contact_class_name(p.contact) << ' ' << p.intersecting << ' ' << std::hex << bits(p.distance) << ' '
      << bits(p.penetration) << ' ' << (p.exact_distance ? bits(*p.exact_distance) : 1) << std::dec << '\n';
  }
  s << r.complete << ' ' << r.unexamined_pairs.size() << ' ' << r.counters.surface_pairs << '\n';
  return s.str();
}

// Every face of part a against every face of part b, in several placements (touching, apart,
// turned, overlapping): the source's exact distance must be BRepExtrema_DistShapeShape's value, bit
// for bit (cadclash stops early only once the distance is 0, where nothing can change it).
TEST(ExactDistance, EqualsBRepExtremaDistShapeShapeBitForBit) {
  const std::vector<TopoDS_Shape> shapes{
      BRepPrimAPI_MakeBox(10, 10, 10).Shape(), BRepPrimAPI_MakeCylinder(3, 8).Shape(),
      BRepPrimAPI_MakeSphere(4).Shape(), BRepPrimAPI_MakeTorus(6, 1.5).Shape()};
  const Model m = build(shapes, 0.5);
  const std::vector<Pose> poses{placed(Vec3(10, 2, 1)), placed(Vec3(13, 5, 5), 0.3, 0.7), placed(Vec3(5, 5, 10)),
                                placed(Vec3(4, 6, 3), 1.1, -0.4)};
  const auto* box = dynamic_cast<const BrepSource*>(m.parts[0].source.get());
  ASSERT_NE(box, nullptr);
  int compared = 0, zero = 0;
  for (PartId other = 1; other < m.parts.size(); ++other) {
    const auto* src = dynamic_cast<const BrepSource*>(m.parts[other].source.get());
    ASSERT_NE(src, nullptr);
    for (const Pose& pose : poses)
      for (std::uint32_t fa = 0; fa < box->face_count(); ++fa)
        for (std::uint32_t fb = 0; fb < src->face_count(); ++fb) {
          const auto ours = box->exact_distance(fa, Pose::Identity(), *src, fb, pose, 1e9);
          BRepExtrema_DistShapeShape occt(box->face(fa), src->face(fb).Moved(TopLoc_Location(trsf(pose))),
                                          Extrema_ExtFlag_MIN);
          ASSERT_EQ(ours.has_value(), occt.IsDone()) << other << ' ' << fa << ' ' << fb;
          if (!ours) continue;
          EXPECT_EQ(bits(*ours), bits(occt.Value())) << "part " << other << " faces " << fa << ' ' << fb << ": "
                                                     << *ours << " vs " << occt.Value();
          ++compared;
          zero += *ours == 0.0;
        }
  }
  EXPECT_GT(compared, 100);
  EXPECT_GT(zero, 0);  // the early exit was taken
}

// With `enough`, the search may stop at the first two points within it: touching faces give a value
// <= enough (here the vertex or edge levels find it before the face–face level), apart faces the
// same minimum as without it.
TEST(ExactDistance, StopsAtTheFirstPointsWithinEnough) {
  const Model m = build({BRepPrimAPI_MakeBox(10, 10, 10).Shape(), BRepPrimAPI_MakeCylinder(3, 8).Shape()}, 0.5);
  const auto* box = dynamic_cast<const BrepSource*>(m.parts[0].source.get());
  const auto* cyl = dynamic_cast<const BrepSource*>(m.parts[1].source.get());
  ASSERT_TRUE(box && cyl);
  int touching = 0, apart = 0;
  for (const Pose& pose : {placed(Vec3(13, 5, 2)), placed(Vec3(10, 2, 1)), placed(Vec3(5, 5, 10)), placed(Vec3(16, 5, 2))})
    for (std::uint32_t fa = 0; fa < box->face_count(); ++fa)
      for (std::uint32_t fb = 0; fb < cyl->face_count(); ++fb) {
        const auto full = box->exact_distance(fa, Pose::Identity(), *cyl, fb, pose, 1e9);
        const auto early = box->exact_distance(fa, Pose::Identity(), *cyl, fb, pose, 1e9, 1e-3);
        ASSERT_EQ(full.has_value(), early.has_value());
        if (!full) continue;
        if (*full <= 1e-3) {
          EXPECT_LE(*early, 1e-3) << fa << ' ' << fb;
          ++touching;
        } else {
          EXPECT_EQ(bits(*early), bits(*full)) << fa << ' ' << fb;
          ++apart;
        }
      }
  EXPECT_GT(touching, 0);
  EXPECT_GT(apart, 10);
}

// edge_distance: a disk (a cylinder's top face, radius 3 at z = 8) and a box's side face whose top
// edge is the line x = 3, z = 8, tangent to the disk's circle at (3, 0, 8): the faces meet at that one
// point, edge to edge, where no vertex of either mesh lies. Newton on the two edge curves finds it
// from nearby outline points; moved 0.5 mm off, the bound is the true 0.5 (never below it).
TEST(EdgeDistance, FindsTheTangentPointOfTwoEdges) {
  const Model m = build({BRepPrimAPI_MakeCylinder(3, 8).Shape(), BRepPrimAPI_MakeBox(10, 10, 10).Shape()}, 0.1);
  const auto* cyl = dynamic_cast<const BrepSource*>(m.parts[0].source.get());
  const auto* box = dynamic_cast<const BrepSource*>(m.parts[1].source.get());
  ASSERT_TRUE(cyl && box);
  std::uint32_t disk = kInvalidId, side = kInvalidId;
  for (std::uint32_t i = 0; i < cyl->face_count(); ++i) {
    const Aabb& b = m.surfaces[m.parts[0].first_surface + i].aabb;
    if (b.min().z() > 7.9) disk = i;  // the top face
  }
  for (std::uint32_t i = 0; i < box->face_count(); ++i) {
    const Aabb& b = m.surfaces[m.parts[1].first_surface + i].aabb;
    if (b.max().x() < 0.1) side = i;  // the face x = 0 of the box
  }
  ASSERT_NE(disk, kInvalidId);
  ASSERT_NE(side, kInvalidId);
  const double angle = 0.2;  // an outline point of the disk near the tangent point, not on it
  const Vec3 near_disk(3.0 * std::cos(angle), 3.0 * std::sin(angle), 8.0);
  const Vec3 near_side(0.0, 5.4, 10.0);  // box frame: on its top edge x = 0, z = 10, off the tangent point
  for (double gap : {0.0, 0.5}) {
    const Pose pose = placed(Vec3(3.0 + gap, -5.0, -2.0));
    const auto d = cyl->edge_distance(disk, Pose::Identity(), *box, side, pose, near_disk, near_side);
    ASSERT_TRUE(d.has_value()) << gap;
    EXPECT_GE(*d, gap) << "an upper bound is never below the distance";
    EXPECT_LE(*d, gap + 1e-9) << gap;
  }
}

// point_distance answers the witness step: its value must never be below the exact distance to the
// face (a point of the face realises it), and it should be the distance itself wherever the
// nearest point is inside the face or on an edge. Points near as1's faces (B-spline cylinders and
// planes bounded by circles): the triangles' vertices moved along and off the face.
TEST(PointDistance, IsAnUpperBoundRealisedOnTheFace) {
  const std::string step = std::string(CADCLASH_DATA_DIR) + "/external/as1-tu-203.stp";
  if (!std::ifstream(step)) GTEST_SKIP() << "run scripts/setup.sh for " << step;
  ImportResult in = import_file(step);
  ASSERT_TRUE(in.complete);
  int asked = 0, tight = 0;
  for (const Part& part : in.model.parts) {
    const auto* src = dynamic_cast<const BrepSource*>(part.source.get());
    ASSERT_NE(src, nullptr);
    for (std::uint32_t f = 0; f < part.surface_count; ++f) {
      const Surface& s = in.model.surfaces[part.first_surface + f];
      for (std::size_t v = 0; v < s.mesh.vertices.size(); v += 3) {
        const Vec3 base = s.mesh.vertices[v];
        for (const Vec3& offset : {Vec3(0, 0, 0), Vec3(0.3, -0.2, 0.1), Vec3(-1.5, 0.4, 0.9)}) {
          const Vec3 p = base + offset;
          const auto ours = src->point_distance(f, p);
          BRepExtrema_DistShapeShape occt(BRepBuilderAPI_MakeVertex(gp_Pnt(p.x(), p.y(), p.z())).Vertex(),
                                          src->face(f), Extrema_ExtFlag_MIN);
          ASSERT_TRUE(occt.IsDone());
          ASSERT_TRUE(ours.has_value()) << part.name << " face " << f;
          EXPECT_GE(*ours, occt.Value() - 1e-9) << part.name << " face " << f << " point " << p.transpose();
          ++asked;
          tight += *ours <= occt.Value() + 1e-9;
        }
      }
    }
  }
  std::printf("[ witness  ] %d of %d point queries equal to OCCT's point-face distance (within 1e-9 mm)\n", tight, asked);
  EXPECT_GT(asked, 500);
  EXPECT_GE(tight, asked * 9 / 10) << tight << " of " << asked;
}

// A row of boxes touching face to face, cylinders standing on them, a sphere resting on one: many
// touching pairs, all verified; the report must not depend on the thread count.
TEST(ExactVerification, ReportIsIdenticalFor1_2And4Threads) {
  const std::vector<TopoDS_Shape> shapes{BRepPrimAPI_MakeBox(10, 10, 10).Shape(), BRepPrimAPI_MakeCylinder(3, 8).Shape(),
                                         BRepPrimAPI_MakeSphere(4).Shape()};
  Model m = build(shapes, 0.2);
  auto instance = [&](const std::string& path, PartId part, const Pose& pose) {
    Instance in;
    in.path = path;
    in.part = part;
    in.pose = pose;
    m.instances.push_back(in);
  };
  for (int i = 0; i < 4; ++i) instance("/box" + std::to_string(i), 0, placed(Vec3(10.0 * i, 0, 0)));
  instance("/cyl0", 1, placed(Vec3(5, 5, 10)));
  instance("/cyl1", 1, placed(Vec3(20, 0, 10), 0.4));  // stands on the edge between box 1 and 2
  instance("/ball", 2, placed(Vec3(35, 5, 14)));       // rests on box 3's top
  Scene scene(m);
  CollideOptions o;
  o.decision = DecisionMode::Exact;
  o.tolerance = 0.01;
  std::string reference;
  for (int threads : {1, 2, 4}) {
    o.threads = threads;
    const Report r = scene.check(o);
    ASSERT_TRUE(r.complete);
    std::size_t verified = 0;
    for (const SurfacePairResult& p : r.pairs) {
      if (p.contact == ContactClass::Penetrating || p.contact == ContactClass::Containment) continue;
      ASSERT_TRUE(p.exact_distance.has_value()) << threads << ": " << p.surface_a << ' ' << p.surface_b;
      EXPECT_LE(*p.exact_distance, 1e-6);  // everything here touches exactly
      ++verified;
    }
    EXPECT_GE(verified, 30u);
    const std::string s = serialize(r);
    if (reference.empty()) reference = s;
    else EXPECT_EQ(s, reference) << threads << " threads";
  }
}

// The same on the real assembly (the rod against everything: bracket holes, nuts), when present.
TEST(ExactVerification, As1ReportIsIdenticalFor1_2And4Threads) {
  const std::string step = std::string(CADCLASH_DATA_DIR) + "/external/as1-tu-203.stp";
  if (!std::ifstream(step)) GTEST_SKIP() << "run scripts/setup.sh for " << step;
  ImportResult in = import_file(step);
  ASSERT_TRUE(in.complete);
  SceneSelection sel;
  for (InstanceId i = 0; i < in.model.instances.size(); ++i)
    if (in.model.instances[i].path.find("/ROD-ASSEMBLY/") != std::string::npos) sel.set_a.push_back(i);
  ASSERT_FALSE(sel.set_a.empty());
  Scene scene(in.model, sel);
  CollideOptions o;
  o.decision = DecisionMode::Exact;
  std::string reference;
  for (int threads : {1, 2, 4}) {
    o.threads = threads;
    const Report r = scene.check(o);
    ASSERT_GE(r.pairs.size(), 10u);
    for (const SurfacePairResult& p : r.pairs) {
      if (p.contact == ContactClass::Penetrating) continue;
      EXPECT_TRUE(p.exact_distance.has_value()) << p.surface_a << ' ' << p.surface_b;
    }
    const std::string s = serialize(r);
    if (reference.empty()) reference = s;
    else EXPECT_EQ(s, reference) << threads << " threads";
  }
}

// A rod in a bore 0.05 mm wider: the faceted surfaces come within the touching bound (their chords
// cross), but the exact faces are 0.05 apart. Verification must measure that gap, so a consumer
// (bench_accuracy, a reviewer) can reject the contact; a skipped verification leaves no value.
TEST(ExactVerification, CoaxialGapIsMeasuredOnTheExactFaces) {
  const double gap = 0.05;
  const std::vector<TopoDS_Shape> shapes{BRepPrimAPI_MakeCylinder(5.0, 20).Shape(),
                                         BRepPrimAPI_MakeCylinder(5.0 + gap, 10).Shape()};
  Model m = build(shapes, 0.1);
  auto lateral = [&](PartId part) {  // the cylindrical face: the one whose box spans the full height
    for (SurfaceId s = m.parts[part].first_surface; s < m.parts[part].first_surface + m.parts[part].surface_count; ++s)
      if (m.surfaces[s].aabb.sizes().z() > 1.0) return s;
    return kInvalidId;
  };
  const SurfaceId rod = lateral(0), bore = lateral(1);
  ASSERT_NE(rod, kInvalidId);
  ASSERT_NE(bore, kInvalidId);
  for (const char* path : {"/rod", "/bore"}) {
    Instance in;
    in.path = path;
    in.part = m.instances.size() == 0 ? 0 : 1;
    in.pose = in.part == 0 ? placed(Vec3(0, 0, -5)) : Pose::Identity();
    m.instances.push_back(in);
  }
  ASSERT_GT(m.surfaces[rod].deflection + m.surfaces[bore].deflection, gap);  // the mesh cannot tell
  Scene scene(m);
  CollideOptions o;
  o.decision = DecisionMode::Fast;
  const Report mesh_only = scene.check(o);
  o.decision = DecisionMode::Exact;
  const Report verified = scene.check(o);
  o.decision = DecisionMode::Certified;
  const Report certified = scene.check(o);
  auto find = [&](const Report& r) -> const SurfacePairResult* {
    for (const SurfacePairResult& p : r.pairs)
      if ((p.surface_a == rod && p.surface_b == bore) || (p.surface_a == bore && p.surface_b == rod)) return &p;
    return nullptr;
  };
  const SurfacePairResult* p0 = find(mesh_only);
  ASSERT_NE(p0, nullptr);
  EXPECT_EQ(p0->contact, ContactClass::Touching);
  EXPECT_FALSE(p0->exact_distance.has_value());
  // Exact mode measures the gap and takes the pair out of the contacts (counted as dismissed).
  EXPECT_EQ(find(verified), nullptr);
  EXPECT_GE(verified.counters.dismissed_pairs, 1u);
  o.clearance = 0.1;
  o.decision = DecisionMode::Exact;
  const Report with_clearance = scene.check(o);
  const SurfacePairResult* p1 = find(with_clearance);
  ASSERT_NE(p1, nullptr);
  EXPECT_EQ(p1->contact, ContactClass::Clearance);
  EXPECT_EQ(p1->decided_by, DecidedBy::Exact);
  ASSERT_TRUE(p1->exact_distance.has_value());
  EXPECT_NEAR(*p1->exact_distance, gap, 1e-7);
  // The default proves it apart without the exact faces: the two cylinders' parameters (coaxial,
  // radii 0.05 apart) are a certificate.
  EXPECT_EQ(find(certified), nullptr);
  EXPECT_GE(certified.counters.decided_analytic, 1u);
}

// A face BRepMesh gives no triangles (data/cad/mesh_fail_degenerate.step: #132's B-spline surface
// collapses onto a segment) still takes part: its exact box reaches the square #39 through the OAABB
// levels and the pair is decided on the exact faces, in the default mode; fast mode cannot see it.
TEST(ExactVerification, FaceWithoutTrianglesIsDecidedOnTheExactGeometry) {
  ImportResult in = import_file(std::string(CADCLASH_DATA_DIR) + "/cad/mesh_fail_degenerate.step");
  Model& m = in.model;
  SurfaceId bad = kInvalidId, square = kInvalidId;
  for (SurfaceId s = 0; s < m.surfaces.size(); ++s) (m.surfaces[s].has_triangles ? square : bad) = s;
  ASSERT_NE(bad, kInvalidId);
  ASSERT_NE(square, kInvalidId);
  ASSERT_EQ(m.surfaces[bad].provenance.step_id, 132);
  InstanceId ibad = kInvalidId, isquare = kInvalidId;
  for (InstanceId i = 0; i < m.instances.size(); ++i)
    (m.instances[i].part == m.surfaces[bad].part ? ibad : isquare) = i;
  // The segment's midpoint onto the square's centre: it crosses the square there.
  const Aabb sq = m.surfaces[square].aabb.transformed(m.instances[isquare].pose);
  const Aabb seg = m.surfaces[bad].aabb;
  m.instances[ibad].pose = Pose::Identity();
  m.instances[ibad].pose.translation() = sq.center() - seg.center();
  auto find = [&](const Report& r) -> const SurfacePairResult* {
    for (const SurfacePairResult& p : r.pairs)
      if ((p.surface_a == bad && p.surface_b == square) || (p.surface_a == square && p.surface_b == bad)) return &p;
    return nullptr;
  };
  Scene scene(m);
  const SurfacePairResult* p = nullptr;
  const Report r = scene.check();
  p = find(r);
  ASSERT_NE(p, nullptr);
  EXPECT_EQ(p->contact, ContactClass::Touching);
  EXPECT_EQ(p->decided_by, DecidedBy::Exact);
  ASSERT_TRUE(p->exact_distance.has_value());
  EXPECT_EQ(*p->exact_distance, 0.0);
  CollideOptions fast;
  fast.decision = DecisionMode::Fast;
  EXPECT_EQ(find(scene.check(fast)), nullptr);  // no triangles, nothing the band can say
  // Lifted 1 mm off the square's plane (its thin box axis), it is proved apart: a clearance within 2.
  int thin = 0;
  sq.sizes().minCoeff(&thin);
  Pose lifted = m.instances[ibad].pose;
  lifted.translation()[thin] += 1.0;
  scene.set_pose(ibad, lifted);
  EXPECT_EQ(find(scene.check()), nullptr);
  CollideOptions near;
  near.clearance = 2.0;
  const Report rc = scene.check(near);
  p = find(rc);
  ASSERT_NE(p, nullptr);
  EXPECT_EQ(p->contact, ContactClass::Clearance);
  EXPECT_NEAR(p->distance_hi, 1.0, 1e-6);
}

// A face's model uncertainty comes from the model: OCCT's tolerances of the face, its edges and
// vertices (at least 1e-7 mm), and at least what the STEP file declares as its length uncertainty.
TEST(ModelUncertainty, FromTolerancesAndTheFilesDeclaredUncertainty) {
  const std::string path = std::string(CADCLASH_DATA_DIR) + "/cad/valid_two_solids.step";
  std::ifstream f(path, std::ios::binary);
  std::stringstream text;
  text << f.rdbuf();
  const std::string declared = "UNCERTAINTY_MEASURE_WITH_UNIT(LENGTH_MEASURE(1.E-07)";
  ASSERT_NE(text.str().find(declared), std::string::npos);
  ImportResult plain = import_file(path);
  ASSERT_FALSE(plain.model.surfaces.empty());
  for (const Surface& s : plain.model.surfaces) {
    EXPECT_GE(s.uncertainty, 1e-7);
    EXPECT_LT(s.uncertainty, 1e-3);
  }
  // The same file declaring 0.01 mm.
  std::string coarse = text.str();
  coarse.replace(coarse.find(declared), declared.size(), "UNCERTAINTY_MEASURE_WITH_UNIT(LENGTH_MEASURE(0.01)");
  const std::string tmp = ::testing::TempDir() + "/declared_uncertainty.step";
  std::ofstream(tmp, std::ios::binary) << coarse;
  ImportResult declared_in = import_file(tmp);
  ASSERT_EQ(declared_in.model.surfaces.size(), plain.model.surfaces.size());
  for (const Surface& s : declared_in.model.surfaces) {
    EXPECT_EQ(s.uncertainty, 0.01) << s.name;
    EXPECT_EQ(uncertainty_source(s), UncertaintySource::Declared) << s.name;
  }
  // The file's own 1e-7 is never above OCCT's tolerances (at least 1e-7): they stand.
  for (const Surface& s : plain.model.surfaces) EXPECT_EQ(uncertainty_source(s), UncertaintySource::OcctTolerance) << s.name;

  // ImportOptions::uncertainty chooses the source. Each face keeps its OCCT tolerance with `o`.
  auto keeps_tolerances = [&](const ImportOptions& o, const char* what) {
    const ImportResult in = import_file(tmp, o);
    ASSERT_EQ(in.model.surfaces.size(), plain.model.surfaces.size()) << what;
    for (std::size_t k = 0; k < in.model.surfaces.size(); ++k) {
      EXPECT_EQ(in.model.surfaces[k].uncertainty, plain.model.surfaces[k].uncertainty) << what;
      EXPECT_EQ(in.model.surfaces[k].tolerance, plain.model.surfaces[k].uncertainty) << what;
      EXPECT_EQ(uncertainty_source(in.model.surfaces[k]), UncertaintySource::OcctTolerance) << what;
    }
  };
  ImportOptions occt;  // OCCT's tolerances alone: the declared 0.01 ignored
  occt.uncertainty = UncertaintyChoice::OcctTolerance;
  keeps_tolerances(occt, "occt");
  ImportOptions below;  // never below a face's OCCT tolerance (at least 1e-7)
  below.uncertainty = UncertaintyChoice::Value;
  below.uncertainty_value = 1e-9;
  keeps_tolerances(below, "1e-9");
  // A value for every surface.
  ImportOptions given;
  given.uncertainty = UncertaintyChoice::Value;
  given.uncertainty_value = 0.25;
  for (const Surface& s : import_file(tmp, given).model.surfaces) {
    EXPECT_EQ(s.uncertainty, 0.25) << s.name;
    EXPECT_EQ(uncertainty_source(s), UncertaintySource::Given) << s.name;
  }
  // The import cache keeps the source, and keys it: the same file read with another choice is
  // read again, not taken from the entry of the first.
  ImportOptions cached;
  cached.cache_dir = ::testing::TempDir() + "/declared_uncertainty_cache";
  std::filesystem::remove_all(cached.cache_dir);
  ImportOptions cached_occt = cached;
  cached_occt.uncertainty = UncertaintyChoice::OcctTolerance;
  for (int run = 0; run < 2; ++run) {
    for (const Surface& s : import_file(tmp, cached).model.surfaces)
      EXPECT_EQ(uncertainty_source(s), UncertaintySource::Declared) << "run " << run << " " << s.name;
    for (const Surface& s : import_file(tmp, cached_occt).model.surfaces)
      EXPECT_EQ(uncertainty_source(s), UncertaintySource::OcctTolerance) << "run " << run << " " << s.name;
  }
}

// Mesh surfaces: ε derived from the coordinates unless the import gives one.
TEST(ModelUncertainty, MeshSurfacesFromTheirCoordinatesOrGiven) {
  const std::string path = std::string(CADCLASH_DATA_DIR) + "/collide/box_a.obj";
  const ImportResult plain = import_file(path);
  ASSERT_FALSE(plain.model.surfaces.empty());
  for (const Surface& s : plain.model.surfaces) {
    EXPECT_EQ(s.uncertainty, 0.0);
    EXPECT_EQ(uncertainty_source(s), UncertaintySource::Coordinates);
  }
  ImportOptions tol;
  tol.model_tolerance = 0.125;
  ImportOptions value;
  value.uncertainty = UncertaintyChoice::Value;
  value.uncertainty_value = 0.5;
  value.model_tolerance = 0.125;  // unused with a value
  ImportOptions occt;
  occt.uncertainty = UncertaintyChoice::OcctTolerance;  // B-rep faces only: meshes as by default
  for (const auto& [o, eps] : {std::pair{tol, 0.125}, std::pair{value, 0.5}, std::pair{occt, 0.0}}) {
    for (const Surface& s : import_file(path, o).model.surfaces) {
      EXPECT_EQ(s.uncertainty, eps);
      EXPECT_EQ(uncertainty_source(s), eps > 0.0 ? UncertaintySource::Given : UncertaintySource::Coordinates);
    }
  }
}

// The elementary surfaces are recognised in the part's frame: every vertex of a cylinder face's
// triangles lies on the recorded cylinder, of a plane face on the recorded plane.
TEST(ModelUncertainty, AnalyticSurfacesMatchTheirTriangles) {
  const std::vector<TopoDS_Shape> shapes{BRepPrimAPI_MakeCylinder(3, 8).Shape(), BRepPrimAPI_MakeBox(10, 10, 10).Shape()};
  Model m = build(shapes, 0.2);
  int cylinders = 0, planes = 0;
  for (const Surface& s : m.surfaces) {
    const AnalyticSurface& a = s.analytic;
    for (const Vec3& v : s.mesh.vertices) {
      if (a.shape == SurfaceShape::Cylinder) {
        const Vec3 w = v - a.origin;
        EXPECT_NEAR((w - w.dot(a.axis) * a.axis).norm(), a.radius, 1e-9);
      } else if (a.shape == SurfaceShape::Plane) {
        EXPECT_NEAR(a.axis.dot(v - a.origin), 0.0, 1e-9);
      }
    }
    cylinders += a.shape == SurfaceShape::Cylinder;
    planes += a.shape == SurfaceShape::Plane;
    if (s.exact_triangles) {
      EXPECT_EQ(a.shape, SurfaceShape::Plane);
      EXPECT_EQ(s.deflection, 0.0);
    }
  }
  EXPECT_EQ(cylinders, 1);
  EXPECT_EQ(planes, 2 + 6);  // the cylinder's caps and the box's sides
  std::size_t exact = 0;
  for (const Surface& s : m.surfaces) exact += s.exact_triangles;
  EXPECT_EQ(exact, 6u);  // the box's sides; the caps are bounded by circles
}

}  // namespace
}  // namespace cadclash
