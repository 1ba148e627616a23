// B-rep tessellation on shapes built here: deflection honoured, outward winding, presets, lazy
// triangles, refinement, concurrent requests, exact distances.
#include "built_parts.h"
#include "cadclash/tessellate.h"

#include <BRepAlgoAPI_Cut.hxx>
#include <BRepBuilderAPI_MakeEdge.hxx>
#include <BRep_Builder.hxx>
#include <Geom_Plane.hxx>
#include <Precision.hxx>
#include <TopoDS_Compound.hxx>
#include <TopoDS_Wire.hxx>
#include <gp_Pln.hxx>
#include <BRepBuilderAPI_MakeVertex.hxx>
#include <BRepClass_FaceClassifier.hxx>
#include <BRepGProp.hxx>
#include <GProp_GProps.hxx>
#include <BRepExtrema_DistShapeShape.hxx>
#include <BRepExtrema_ExtPF.hxx>
#include <TopoDS_Vertex.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <BRepPrimAPI_MakeSphere.hxx>
#include <BRepPrimAPI_MakeTorus.hxx>
#include <TopExp.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Shape.hxx>
#include <gp_Ax2.hxx>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <optional>
#include <string>
#include <thread>

namespace cadclash {
namespace {

using testing::Built;

Built build(const std::vector<TopoDS_Shape>& shapes, const TessellationOptions& options, bool lazy) {
  return testing::build_parts(shapes, options, lazy);
}

// Distance from p to the face: the interior foot point from BRepExtrema_ExtPF when there is one,
// else the full BRepExtrema_DistShapeShape (boundary feet).
struct FaceDistance {
  explicit FaceDistance(const TopoDS_Face& f) : face(f) { ext.Initialize(face, Extrema_ExtFlag_MIN); }
  double operator()(const Vec3& p) {
    const TopoDS_Vertex v = BRepBuilderAPI_MakeVertex(gp_Pnt(p.x(), p.y(), p.z())).Vertex();
    ext.Perform(v, face);
    double best = 1e300;
    if (ext.IsDone())
      for (int i = 1; i <= ext.NbExt(); ++i) best = std::min(best, std::sqrt(ext.SquareDistance(i)));
    if (best < 1e300) return best;
    BRepExtrema_DistShapeShape dist(v, face);
    EXPECT_TRUE(dist.IsDone());
    return dist.Value();
  }
  TopoDS_Face face;
  BRepExtrema_ExtPF ext;
};

// Largest distance from the triangles' centroids (every `stride`-th triangle) and vertices to the face.
double measured_deflection(const Surface& s, const TopoDS_Face& face, std::size_t stride) {
  FaceDistance distance(face);
  double worst = 0.0;
  for (std::size_t t = 0; t < s.mesh.triangles.size(); t += stride) {
    const auto& tri = s.mesh.triangles[t];
    const Vec3 c = (s.mesh.vertices[tri[0]] + s.mesh.vertices[tri[1]] + s.mesh.vertices[tri[2]]) / 3.0;
    worst = std::max(worst, distance(c));
    worst = std::max(worst, distance(s.mesh.vertices[tri[0]]));
  }
  return worst;
}

// 6 x signed volume of the closed triangle soup: positive when every triangle faces outward.
double signed_volume(const Model& m) {
  double v = 0.0;
  for (const Surface& s : m.surfaces)
    for (const auto& t : s.mesh.triangles)
      v += s.mesh.vertices[t[0]].dot(s.mesh.vertices[t[1]].cross(s.mesh.vertices[t[2]]));
  return v / 6.0;
}

TopoDS_Shape torus() { return BRepPrimAPI_MakeTorus(gp_Ax2(gp_Pnt(1, 2, 3), gp_Dir(0, 0, 1)), 20.0, 6.0).Shape(); }
TopoDS_Shape cylinder() { return BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(0, 0, 0), gp_Dir(0, 1, 0)), 8.0, 30.0).Shape(); }
TopoDS_Shape sphere() { return BRepPrimAPI_MakeSphere(gp_Pnt(50, 0, 0), 12.0).Shape(); }

TEST(Presets, ParseAndOrder) {
  EXPECT_EQ(parse_tessellation_preset("coarse"), TessellationPreset::Coarse);
  EXPECT_EQ(parse_tessellation_preset("normal"), TessellationPreset::Normal);
  EXPECT_EQ(parse_tessellation_preset("fine"), TessellationPreset::Fine);
  EXPECT_EQ(parse_tessellation_preset("very-fine"), TessellationPreset::VeryFine);
  EXPECT_EQ(parse_tessellation_preset("very_fine"), TessellationPreset::VeryFine);
  EXPECT_FALSE(parse_tessellation_preset("ultra").has_value());
  EXPECT_STREQ(tessellation_preset_name(TessellationPreset::VeryFine), "very-fine");
  double previous = 1e9;
  for (auto p : {TessellationPreset::Coarse, TessellationPreset::Normal, TessellationPreset::Fine, TessellationPreset::VeryFine}) {
    const TessellationOptions o = tessellation_preset(p);
    EXPECT_LT(o.linear_deflection, previous);
    previous = o.linear_deflection;
    EXPECT_EQ(parse_tessellation_preset(tessellation_preset_name(p)), p);
  }
  EXPECT_DOUBLE_EQ(tessellation_preset(TessellationPreset::Normal).linear_deflection, TessellationOptions{}.linear_deflection);
}

TEST(BrepTessellate, OneSurfacePerFaceInMapShapesOrder) {
  const std::vector<TopoDS_Shape> shapes{BRepPrimAPI_MakeBox(10, 20, 30).Shape(), cylinder()};
  const Built b = build(shapes, {}, false);
  ASSERT_TRUE(b.complete);
  ASSERT_EQ(b.model.parts.size(), 2u);
  EXPECT_EQ(b.model.parts[0].surface_count, 6u);
  EXPECT_EQ(b.model.parts[1].surface_count, 3u);
  EXPECT_EQ(b.model.parts[1].first_surface, 6u);
  for (const Part& p : b.model.parts) {
    const auto* source = dynamic_cast<const BrepSource*>(p.source.get());
    ASSERT_NE(source, nullptr);
    EXPECT_EQ(source->face_count(), p.surface_count);
    for (std::uint32_t i = 0; i < p.surface_count; ++i) {
      const Surface& s = b.model.surfaces[p.first_surface + i];
      EXPECT_EQ(s.provenance.face_index, static_cast<std::int32_t>(i));
      EXPECT_EQ(s.provenance.kind, SourceKind::BrepFace);
      EXPECT_TRUE(s.has_triangles);
      EXPECT_FALSE(s.mesh.triangles.empty());
      EXPECT_FALSE(s.aabb.isEmpty());
      EXPECT_TRUE(s.aabb.contains(mesh_aabb(s.mesh)));
    }
  }
  // Box faces: the exact box of the 10 x 20 x 30 box's faces spans it.
  Aabb all;
  for (std::uint32_t i = 0; i < 6; ++i) all.extend(b.model.surfaces[i].aabb);
  EXPECT_NEAR(all.min().norm(), 0.0, 1e-6);
  EXPECT_NEAR((all.max() - Vec3(10, 20, 30)).norm(), 0.0, 1e-6);
}

// A board-like plate drilled with `side` x `side` holes of two radii (planar faces with many holes:
// where BRepMesh's Watson triangulation is slow and planes are triangulated by Delabella).
TopoDS_Shape drilled_plate(int side) {
  TopTools_ListOfShape drills;
  for (int i = 0; i < side; ++i)
    for (int j = 0; j < side; ++j)
      drills.Append(BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(2.0 + 4.0 * i, 2.0 + 4.0 * j, -3), gp_Dir(0, 0, 1)),
                                             (i + j) % 2 ? 0.8 : 1.3, 5.0)
                        .Shape());
  TopTools_ListOfShape plate;
  plate.Append(BRepPrimAPI_MakeBox(gp_Pnt(0, 0, -1.6), gp_Pnt(4.0 * side, 4.0 * side, 0)).Shape());
  BRepAlgoAPI_Cut cut;
  cut.SetArguments(plate);
  cut.SetTools(drills);
  cut.Build();
  EXPECT_TRUE(cut.IsDone());
  return cut.Shape();
}

// The plate's faces are covered by their triangles and nothing else: every triangle lies inside its
// face (none fills a hole) and the triangles' area is the face's less at most a chord's sagitta
// along each boundary (the holes' outlines are polygons inscribed in their circles).
TEST(BrepTessellate, DrilledPlatesFacesAreCoveredByTheirTriangles) {
  const Built b = build({drilled_plate(8)}, {}, false);
  ASSERT_TRUE(b.complete);
  const auto* source = dynamic_cast<const BrepSource*>(b.model.parts[0].source.get());
  ASSERT_NE(source, nullptr);
  int drilled = 0;
  for (std::uint32_t i = 0; i < b.model.parts[0].surface_count; ++i) {
    const Surface& s = b.model.surfaces[i];
    const TopoDS_Face& face = source->face(i);
    GProp_GProps exact, boundary;
    BRepGProp::SurfaceProperties(face, exact);
    BRepGProp::LinearProperties(face, boundary);
    double area = 0.0;
    for (const auto& t : s.mesh.triangles) {
      const Vec3 &p = s.mesh.vertices[t[0]], &q = s.mesh.vertices[t[1]], &r = s.mesh.vertices[t[2]];
      area += 0.5 * (q - p).cross(r - p).norm();
      const Vec3 c = (p + q + r) / 3.0;
      BRepClass_FaceClassifier inside(face, gp_Pnt(c.x(), c.y(), c.z()), 1e-7);
      ASSERT_EQ(inside.State(), TopAbs_IN) << "face " << i << " triangle centroid " << c.transpose();
    }
    // Between the exact face and its triangles: at most the deflection along the whole boundary.
    EXPECT_NEAR(area, exact.Mass(), boundary.Mass() * TessellationOptions{}.linear_deflection) << "face " << i;
    drilled += s.mesh.triangles.size() > 500;
  }
  EXPECT_EQ(drilled, 2);  // the top and the bottom
}

// A square in z = `z` whose four edges each carry their own end vertices (coincident, not shared):
// BRepCheck rejects it, ShapeFix_Face heals it.
TopoDS_Face square_with_unshared_vertices(double z) {
  const gp_Pnt p[4] = {{0, 0, z}, {10, 0, z}, {10, 10, z}, {0, 10, z}};
  BRep_Builder builder;
  TopoDS_Wire wire;
  builder.MakeWire(wire);
  for (int i = 0; i < 4; ++i) builder.Add(wire, BRepBuilderAPI_MakeEdge(p[i], p[(i + 1) % 4]).Edge());
  TopoDS_Face face;
  builder.MakeFace(face, new Geom_Plane(gp_Pln(gp_Pnt(0, 0, z), gp::DZ())), Precision::Confusion());
  builder.Add(face, wire);
  return face;
}

// A part holding a drilled face has its faces checked one by one; alone (a re-run whose one
// changed part is a board plate) they are checked on threads: the same faces healed, the same
// warnings in face order, as on one thread.
TEST(BrepTessellate, APartsFacesCheckedOnThreadsAreHealedAsOnOne) {
  TopoDS_Compound part;
  BRep_Builder builder;
  builder.MakeCompound(part);
  builder.Add(part, drilled_plate(8));
  for (int k = 0; k < 5; ++k) builder.Add(part, square_with_unshared_vertices(20.0 + 5.0 * k));
  std::vector<std::vector<std::string>> warnings;
  std::vector<std::vector<bool>> healed;
  for (const bool parallel : {false, true}) {
    BrepPartInput in;
    const TopoDS_Shape shape = part;
    in.shape = &shape;
    in.name = "plate and squares";
    TessellationOptions options;
    options.parallel = parallel;
    Model m;
    std::vector<Diagnostic> ds;
    bool complete = true;
    add_brep_parts(m, std::span<const BrepPartInput>(&in, 1), options, true, ds, complete);
    warnings.emplace_back();
    for (const Diagnostic& d : ds) warnings.back().push_back(d.message);
    healed.emplace_back();
    for (const Surface& s : m.surfaces) healed.back().push_back(s.provenance.healed);
  }
  EXPECT_EQ(warnings[1], warnings[0]);
  EXPECT_EQ(healed[1], healed[0]);
  EXPECT_EQ(std::count(healed[0].begin(), healed[0].end(), true), 5);
  EXPECT_EQ(warnings[0].size(), 5u);
}

// OCCT picks its default triangulation from the CSF_MeshAlgo environment variable; cadclash names
// its own, so the same file gives the same triangles (and reports) in any environment.
TEST(BrepTessellate, MeshesDoNotDependOnOcctsMeshAlgorithmVariable) {
  const char* before = std::getenv("CSF_MeshAlgo");
  const std::optional<std::string> saved = before ? std::optional<std::string>(before) : std::nullopt;
  std::vector<Model> models;
  for (const char* algorithm : {"watson", "delabella"}) {
    setenv("CSF_MeshAlgo", algorithm, 1);
    models.push_back(build({drilled_plate(6)}, {}, false).model);  // a new shape: BRepMesh keeps its triangles
  }
  if (saved) setenv("CSF_MeshAlgo", saved->c_str(), 1);
  else unsetenv("CSF_MeshAlgo");
  ASSERT_EQ(models[0].surfaces.size(), models[1].surfaces.size());
  for (std::size_t i = 0; i < models[0].surfaces.size(); ++i) {
    EXPECT_EQ(models[0].surfaces[i].mesh.triangles, models[1].surfaces[i].mesh.triangles) << "face " << i;
    EXPECT_EQ(models[0].surfaces[i].mesh.vertices, models[1].surfaces[i].mesh.vertices) << "face " << i;
  }
}

TEST(BrepTessellate, WindingIsOutwardIncludingReversedFaces) {
  // The box, cylinder and torus all have faces stored REVERSED in their shells.
  for (const TopoDS_Shape& shape : {BRepPrimAPI_MakeBox(10, 20, 30).Shape(), cylinder(), torus()}) {
    const Built b = build({shape}, {}, false);
    EXPECT_GT(signed_volume(b.model), 0.0);
  }
  const Built box = build({BRepPrimAPI_MakeBox(10, 20, 30).Shape()}, {}, false);
  EXPECT_NEAR(signed_volume(box.model), 6000.0, 1e-6);
}

TEST(BrepTessellate, DeflectionIsHonoured) {
  const std::vector<TopoDS_Shape> shapes{torus(), cylinder(), sphere()};
  for (double d : {0.5, 0.05, 0.01}) {
    TessellationOptions o;
    o.linear_deflection = d;
    const Built b = build(shapes, o, false);
    ASSERT_TRUE(b.complete);
    for (const Part& p : b.model.parts) {
      const auto* source = dynamic_cast<const BrepSource*>(p.source.get());
      for (std::uint32_t i = 0; i < p.surface_count; ++i) {
        const Surface& s = b.model.surfaces[p.first_surface + i];
        EXPECT_LE(s.deflection, d * (1 + 1e-9)) << p.name << " face " << i;
        const std::size_t stride = std::max<std::size_t>(1, s.mesh.triangles.size() / 25);
        EXPECT_LE(measured_deflection(s, source->face(i), stride), d + 1e-7) << p.name << " face " << i << " d=" << d;
      }
    }
  }
}

// TessellationOptions::time_limit_seconds: a limit that has run out before meshing starts leaves every
// face without triangles, each named with the limit; a limit not reached changes nothing.
TEST(BrepTessellate, TimeLimitLeavesFacesUnmeshedAndNamed) {
  const std::vector<TopoDS_Shape> shapes{torus(), cylinder(), sphere()};
  TessellationOptions o;
  o.time_limit_seconds = 1e-9;
  const Built cut = build(shapes, o, false);
  EXPECT_FALSE(cut.complete);
  ASSERT_EQ(cut.diagnostics.size(), cut.model.surfaces.size());
  for (const Surface& s : cut.model.surfaces) {
    EXPECT_FALSE(s.has_triangles) << s.name;
    EXPECT_TRUE(s.mesh.triangles.empty()) << s.name;
  }
  for (const Diagnostic& d : cut.diagnostics) {
    EXPECT_EQ(d.severity, Severity::Error);
    EXPECT_NE(d.message.find("could not be tessellated (the tessellation time limit of 1e-09 s ran out)"),
              std::string::npos)
        << d.message;
  }
  o.time_limit_seconds = 3600;
  const Built limited = build(shapes, o, false);
  const Built unlimited = build(shapes, TessellationOptions{}, false);
  EXPECT_TRUE(limited.complete);
  ASSERT_EQ(limited.model.surfaces.size(), unlimited.model.surfaces.size());
  for (std::size_t i = 0; i < limited.model.surfaces.size(); ++i) {
    EXPECT_EQ(limited.model.surfaces[i].mesh.triangles, unlimited.model.surfaces[i].mesh.triangles);
    EXPECT_EQ(limited.model.surfaces[i].deflection, unlimited.model.surfaces[i].deflection);
  }
}

TEST(BrepTessellate, FinerDeflectionGivesMoreTriangles) {
  std::size_t previous = 0;
  for (double d : {1.0, 0.1, 0.01}) {
    TessellationOptions o;
    o.linear_deflection = d;
    const Built b = build({torus()}, o, false);
    const std::size_t n = triangle_count(b.model);
    EXPECT_GT(n, previous);
    previous = n;
  }
}

TEST(BrepTessellate, RelativeDeflectionScalesWithPartSize) {
  TessellationOptions o;
  o.linear_deflection = 0.001;
  o.relative = true;
  const Built b = build({torus()}, o, false);
  const auto* source = dynamic_cast<const BrepSource*>(b.model.parts[0].source.get());
  // Torus box: 52 x 52 x 12 (plus tolerance) → diagonal ≈ 74.5.
  EXPECT_NEAR(source->default_deflection(), 0.001 * std::sqrt(52.0 * 52 * 2 + 12.0 * 12), 1e-3);
  for (const Surface& s : b.model.surfaces) EXPECT_LE(s.deflection, source->default_deflection() * (1 + 1e-9));
}

TEST(BrepTessellate, LazyHasBoxesButNoTrianglesUntilRequired) {
  const std::vector<TopoDS_Shape> shapes{torus(), cylinder()};
  Built b = build(shapes, {}, true);
  ASSERT_TRUE(b.complete);
  for (const Surface& s : b.model.surfaces) {
    EXPECT_FALSE(s.has_triangles);
    EXPECT_TRUE(s.mesh.triangles.empty());
    EXPECT_FALSE(s.aabb.isEmpty());
  }
  EXPECT_EQ(triangle_count(b.model), 0u);
  const std::vector<SurfaceId> some{0, 2};
  EXPECT_TRUE(require_triangles(b.model, some).empty());
  EXPECT_TRUE(b.model.surfaces[0].has_triangles);
  EXPECT_FALSE(b.model.surfaces[1].has_triangles);
  EXPECT_TRUE(b.model.surfaces[2].has_triangles);
  for (SurfaceId s : some) {
    EXPECT_GT(b.model.surfaces[s].mesh.triangles.size(), 0u);
    EXPECT_LE(b.model.surfaces[s].deflection, 0.1 * (1 + 1e-9));
    // The exact box encloses the triangles it was computed without.
    EXPECT_TRUE(b.model.surfaces[s].aabb.contains(mesh_aabb(b.model.surfaces[s].mesh)));
  }
}

TEST(BrepTessellate, RefinementRemeshesFiner) {
  Built b = build({torus()}, {}, true);
  auto& source = *b.model.parts[0].source;
  TriangleMesh coarse, fine, again;
  double d_coarse = 0, d_fine = 0, d_again = 0;
  Diagnostic error;
  ASSERT_TRUE(source.triangulate(0, 0.5, coarse, d_coarse, error));
  ASSERT_TRUE(source.triangulate(0, 0.01, fine, d_fine, error));
  EXPECT_LE(d_coarse, 0.5);
  EXPECT_LE(d_fine, 0.01);
  EXPECT_GT(fine.triangles.size(), 4 * coarse.triangles.size());
  // Finer than the part's deflection is a refinement, meshed on a copy of the face: the face keeps
  // its own triangulation, so a coarser request afterwards reads that one again.
  ASSERT_TRUE(source.triangulate(0, 0.5, again, d_again, error));
  EXPECT_EQ(again.triangles.size(), coarse.triangles.size());
  // A request only slightly finer than the current one still re-meshes (BRepMesh alone would not).
  TriangleMesh slightly;
  double d_slightly = 0;
  ASSERT_TRUE(source.triangulate(0, d_fine * 0.95, slightly, d_slightly, error));
  EXPECT_LE(d_slightly, d_fine * 0.95);
}

TEST(BrepTessellate, ConcurrentRequestsOnDifferentPartsMatchSerialOnes) {
  const std::vector<TopoDS_Shape> shapes{torus(), cylinder(), sphere(), BRepPrimAPI_MakeBox(5, 6, 7).Shape()};
  Built serial = build(shapes, {}, true);
  Built parallel = build(shapes, {}, true);
  std::vector<SurfaceId> all(serial.model.surfaces.size());
  for (SurfaceId s = 0; s < all.size(); ++s) all[s] = s;
  for (SurfaceId s : all) ASSERT_TRUE(require_triangles(serial.model, std::span<const SurfaceId>(&s, 1)).empty());
  std::vector<std::thread> threads;
  std::vector<int> failures(parallel.model.parts.size(), 0);
  for (PartId p = 0; p < parallel.model.parts.size(); ++p) {
    threads.emplace_back([&, p] {
      const Part& part = parallel.model.parts[p];
      for (std::uint32_t i = 0; i < part.surface_count; ++i) {
        Surface& s = parallel.model.surfaces[part.first_surface + i];
        Diagnostic error;
        if (!part.source->triangulate(i, 0.0, s.mesh, s.deflection, error)) ++failures[p];
        s.has_triangles = true;
      }
    });
  }
  for (auto& t : threads) t.join();
  for (int f : failures) EXPECT_EQ(f, 0);
  for (SurfaceId s : all) {
    EXPECT_EQ(parallel.model.surfaces[s].mesh.triangles, serial.model.surfaces[s].mesh.triangles) << s;
    EXPECT_EQ(parallel.model.surfaces[s].mesh.vertices, serial.model.surfaces[s].mesh.vertices) << s;
  }
}

TEST(BrepTessellate, ExactDistanceBetweenPlacedFaces) {
  const std::vector<TopoDS_Shape> shapes{BRepPrimAPI_MakeBox(10, 10, 10).Shape(), BRepPrimAPI_MakeBox(10, 10, 10).Shape()};
  const Built b = build(shapes, {}, true);
  const SurfaceSource& a = *b.model.parts[0].source;
  const SurfaceSource& c = *b.model.parts[1].source;
  // Find the faces x = 10 of box a and x = 0 of box c from their exact boxes.
  std::uint32_t a_right = kInvalidId, c_left = kInvalidId;
  for (std::uint32_t i = 0; i < 6; ++i) {
    if (std::abs(b.model.surfaces[i].aabb.min().x() - 10) < 1e-5) a_right = i;
    if (std::abs(b.model.surfaces[6 + i].aabb.max().x()) < 1e-5) c_left = i;
  }
  ASSERT_NE(a_right, kInvalidId);
  ASSERT_NE(c_left, kInvalidId);
  Pose touching = Pose::Identity();
  touching.translate(Vec3(10, 3, 0));
  auto d = a.exact_distance(a_right, Pose::Identity(), c, c_left, touching, 1.0);
  ASSERT_TRUE(d.has_value());
  EXPECT_NEAR(*d, 0.0, 1e-7);

  Pose apart = Pose::Identity();
  apart.translate(Vec3(12.5, 0, 0));
  d = a.exact_distance(a_right, Pose::Identity(), c, c_left, apart, 5.0);
  ASSERT_TRUE(d.has_value());
  EXPECT_NEAR(*d, 2.5, 1e-7);
  // Beyond max_distance: some value above it.
  d = a.exact_distance(a_right, Pose::Identity(), c, c_left, apart, 1.0);
  ASSERT_TRUE(d.has_value());
  EXPECT_GT(*d, 1.0);
  // Rotated placement: box c turned 90° about z around the origin lies in x ∈ [-10, 0]: its face
  // that was x = 0 is now y = 0, x ∈ [-10, 0]; box a's face x = 10 is 10 away.
  Pose turned = Pose::Identity();
  turned.rotate(Eigen::AngleAxisd(M_PI / 2, Vec3::UnitZ()));
  d = a.exact_distance(a_right, Pose::Identity(), c, c_left, turned, 100.0);
  ASSERT_TRUE(d.has_value());
  EXPECT_NEAR(*d, 10.0, 1e-7);
}

TEST(BrepTessellate, TagsBecomeProvenance) {
  const std::vector<TopoDS_Shape> shapes{BRepPrimAPI_MakeBox(1, 2, 3).Shape()};
  BrepPartInput in;
  in.shape = &shapes[0];
  in.name = "box";
  in.source_file = "box.step";
  in.kind = SourceKind::StepFace;
  in.tags.resize(2);
  in.tags[1].entity_id = 42;
  in.tags[1].name = "top";
  in.tags[1].colour = std::array<float, 3>{1.0f, 0.5f, 0.0f};
  Model m;
  std::vector<Diagnostic> ds;
  bool complete = true;
  const auto ids = add_brep_parts(m, std::span<const BrepPartInput>(&in, 1), {}, false, ds, complete);
  ASSERT_EQ(ids.size(), 1u);
  EXPECT_EQ(m.parts[0].name, "box");
  EXPECT_EQ(m.surfaces[0].provenance.step_id, -1);
  EXPECT_EQ(m.surfaces[1].provenance.step_id, 42);
  EXPECT_EQ(m.surfaces[1].provenance.source_name, "top");
  ASSERT_TRUE(m.surfaces[1].provenance.colour.has_value());
  EXPECT_FLOAT_EQ((*m.surfaces[1].provenance.colour)[1], 0.5f);
  EXPECT_EQ(m.surfaces[5].provenance.kind, SourceKind::StepFace);
  EXPECT_EQ(m.surfaces[5].provenance.source_file, "box.step");
  for (const Surface& s : m.surfaces) EXPECT_FALSE(s.provenance.healed);
}

}  // namespace
}  // namespace cadclash
