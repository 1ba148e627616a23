// STEP import on the real sample files: assembly tree, shared parts, STEP ids traced to the file,
// face counts against OCCT's own, deflection honoured, lazy mode, exact distances.
#include "cadclash/import.h"

#include <BRepBuilderAPI_MakeVertex.hxx>
#include <BRepExtrema_DistShapeShape.hxx>
#include <BRepExtrema_ExtPF.hxx>
#include <STEPControl_Reader.hxx>
#include <TopExp.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Vertex.hxx>

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <thread>

namespace cadclash {
namespace {

const std::string kExternal = std::string(CADCLASH_DATA_DIR) + "/external/";

#define REQUIRE_FILE(path)                                                              \
  do {                                                                                  \
    if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " missing: run scripts/setup.sh"; \
  } while (0)

// Entity ids of every ADVANCED_FACE in the file, read from its text (entities may span lines).
std::set<std::int64_t> advanced_face_ids(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  const std::string s = text.str();
  std::set<std::int64_t> ids;
  const std::regex entity(R"(#(\d+)\s*=\s*ADVANCED_FACE\s*\()");
  for (auto it = std::sregex_iterator(s.begin(), s.end(), entity); it != std::sregex_iterator(); ++it)
    ids.insert(std::stoll((*it)[1].str()));
  return ids;
}

// Faces OCCT itself finds in the file (plain STEPControl_Reader, all roots, unique faces).
int occt_face_count(const std::string& path) {
  STEPControl_Reader reader;
  if (reader.ReadFile(path.c_str()) != IFSelect_RetDone) return -1;
  reader.TransferRoots();
  TopTools_IndexedMapOfShape faces;
  TopExp::MapShapes(reader.OneShape(), TopAbs_FACE, faces);
  return faces.Extent();
}

std::size_t instance_face_count(const Model& m) {
  std::size_t n = 0;
  for (const Instance& i : m.instances) n += m.parts[i.part].surface_count;
  return n;
}

Aabb world_box(const Model& m) {
  Aabb box;
  for (const Instance& i : m.instances) {
    const Part& p = m.parts[i.part];
    for (SurfaceId s = p.first_surface; s < p.first_surface + p.surface_count; ++s)
      for (const Vec3& v : m.surfaces[s].mesh.vertices) box.extend(i.pose * v);
  }
  return box;
}

TEST(CadStep, As1AssemblyTreeAndStepIds) {
  const std::string path = kExternal + "as1-tu-203.stp";
  REQUIRE_FILE(path);
  const ImportResult r = import_file(path);
  for (const Diagnostic& d : r.diagnostics) ADD_FAILURE() << format_diagnostic(d);
  EXPECT_TRUE(r.complete);
  const Model& m = r.model;
  EXPECT_EQ(m.instances.size(), 18u);
  EXPECT_EQ(instance_face_count(m), 160u);
  // Shared parts are one Part each: nut, rod, bolt, l-bracket, plate.
  EXPECT_EQ(m.parts.size(), 5u);
  EXPECT_EQ(m.surfaces.size(), 53u);

  std::set<std::string> paths;
  for (const Instance& i : m.instances) EXPECT_TRUE(paths.insert(i.path).second) << "duplicate path " << i.path;
  EXPECT_TRUE(paths.count("/as1/L-BRACKET-ASSEMBLY::2/NUT-BOLT-ASSEMBLY::1/BOLT"));
  EXPECT_TRUE(paths.count("/as1/PLATE"));
  EXPECT_TRUE(paths.count("/as1/ROD-ASSEMBLY/NUT::2"));

  const std::set<std::int64_t> faces_in_file = advanced_face_ids(path);
  ASSERT_EQ(faces_in_file.size(), 53u);
  std::set<std::int64_t> seen;
  for (const Surface& s : m.surfaces) {
    EXPECT_EQ(s.provenance.kind, SourceKind::StepFace);
    EXPECT_TRUE(faces_in_file.count(s.provenance.step_id)) << s.name << " #" << s.provenance.step_id;
    EXPECT_TRUE(seen.insert(s.provenance.step_id).second) << "two surfaces claim #" << s.provenance.step_id;
    EXPECT_TRUE(s.has_triangles);
    EXPECT_FALSE(s.mesh.triangles.empty());
    EXPECT_GT(s.deflection, -1e-12);
    EXPECT_LE(s.deflection, 0.1 * (1 + 1e-9));
  }
  // The file is in millimetres (#4 SI_UNIT(.MILLI.,.METRE.)): the plate is a few hundred mm across.
  const Aabb box = world_box(m);
  EXPECT_GT(box.diagonal().norm(), 100.0);
  EXPECT_LT(box.diagonal().norm(), 2000.0);
}

TEST(CadStep, As1InstancesOfOnePartShareItAndArePlacedApart) {
  const std::string path = kExternal + "as1-tu-203.stp";
  REQUIRE_FILE(path);
  const ImportResult r = import_file(path);
  const Model& m = r.model;
  std::vector<const Instance*> bolts;
  for (const Instance& i : m.instances)
    if (i.path.ends_with("/BOLT")) bolts.push_back(&i);
  ASSERT_EQ(bolts.size(), 6u);
  std::set<std::pair<long, long>> positions;
  for (const Instance* b : bolts) {
    EXPECT_EQ(b->part, bolts[0]->part);
    EXPECT_TRUE(b->pose.linear().isUnitary(1e-9));
    positions.insert({std::lround(b->pose.translation().x()), std::lround(b->pose.translation().y() * 1000 + b->pose.translation().z())});
  }
  EXPECT_EQ(positions.size(), 6u) << "six bolts at six places";
}

struct FaceCountCase {
  const char* file;
};

class CadStepFaceCounts : public ::testing::TestWithParam<FaceCountCase> {};

TEST_P(CadStepFaceCounts, MatchOcctAndEveryFaceIsMeshedOrReported) {
  const std::string path = kExternal + GetParam().file;
  REQUIRE_FILE(path);
  const ImportResult r = import_file(path);
  const int expected = occt_face_count(path);
  ASSERT_GT(expected, 0);
  EXPECT_EQ(r.model.surfaces.size(), static_cast<std::size_t>(expected));
  const std::set<std::int64_t> faces_in_file = advanced_face_ids(path);
  std::set<std::int64_t> reported;
  for (const Diagnostic& d : r.diagnostics) {
    if (d.severity == Severity::Error) reported.insert(d.step_id);
  }
  for (const Surface& s : r.model.surfaces) {
    EXPECT_TRUE(s.has_triangles || reported.count(s.provenance.step_id)) << s.name;
    if (s.provenance.step_id >= 0) {
      EXPECT_TRUE(faces_in_file.count(s.provenance.step_id)) << s.provenance.step_id;
    }
  }
  EXPECT_EQ(r.complete, !has_error(r.diagnostics));
  EXPECT_FALSE(r.model.instances.empty());
}

INSTANTIATE_TEST_SUITE_P(RealFiles, CadStepFaceCounts,
                         ::testing::Values(FaceCountCase{"linkrods.step"}, FaceCountCase{"screw.step"},
                                           FaceCountCase{"frame.step"}, FaceCountCase{"component8.step"}),
                         [](const auto& param_info) {
                           std::string n = param_info.param.file;
                           return n.substr(0, n.find('.'));
                         });

// Distance from p to the face: interior foot point (ExtPF), else the boundary (DistShapeShape).
double face_distance(BRepExtrema_ExtPF& ext, const TopoDS_Face& face, const Vec3& p) {
  const TopoDS_Vertex v = BRepBuilderAPI_MakeVertex(gp_Pnt(p.x(), p.y(), p.z())).Vertex();
  ext.Perform(v, face);
  double best = 1e300;
  if (ext.IsDone())
    for (int i = 1; i <= ext.NbExt(); ++i) best = std::min(best, std::sqrt(ext.SquareDistance(i)));
  if (best < 1e300) return best;
  BRepExtrema_DistShapeShape dist(v, face);
  return dist.IsDone() ? dist.Value() : 1e300;
}

TEST(CadStep, DeflectionIsHonouredOnSampledRealFaces) {
  for (const char* file : {"linkrods.step", "as1-tu-203.stp"}) {
    const std::string path = kExternal + file;
    REQUIRE_FILE(path);
    for (double deflection : {0.05, 0.005}) {
      ImportOptions o;
      o.tessellation.linear_deflection = deflection;
      const ImportResult r = import_file(path, o);
      ASSERT_TRUE(r.complete) << file;
      const Model& m = r.model;
      int sampled = 0;
      for (const Part& p : m.parts) {
        const auto* source = dynamic_cast<const BrepSource*>(p.source.get());
        ASSERT_NE(source, nullptr);
        for (std::uint32_t i = 0; i < p.surface_count; i += 3) {  // every third face
          const Surface& s = m.surfaces[p.first_surface + i];
          ASSERT_TRUE(s.has_triangles);
          EXPECT_LE(s.deflection, deflection * (1 + 1e-9));
          const TopoDS_Face& face = source->face(i);
          BRepExtrema_ExtPF ext;
          ext.Initialize(face, Extrema_ExtFlag_MIN);
          const std::size_t stride = std::max<std::size_t>(1, s.mesh.triangles.size() / 12);
          double worst = 0.0;
          for (std::size_t t = 0; t < s.mesh.triangles.size(); t += stride) {
            const auto& tri = s.mesh.triangles[t];
            const Vec3 c = (s.mesh.vertices[tri[0]] + s.mesh.vertices[tri[1]] + s.mesh.vertices[tri[2]]) / 3.0;
            worst = std::max({worst, face_distance(ext, face, c), face_distance(ext, face, s.mesh.vertices[tri[1]])});
          }
          EXPECT_LE(worst, deflection + 1e-6) << file << " " << p.name << " face " << i;
          ++sampled;
        }
      }
      EXPECT_GT(sampled, 10);
    }
  }
}

TEST(CadStep, LazyImportHasBoxesAndMeshesOnRequest) {
  const std::string path = kExternal + "as1-tu-203.stp";
  REQUIRE_FILE(path);
  ImportOptions o;
  o.lazy = true;
  ImportResult lazy = import_file(path, o);
  ASSERT_TRUE(lazy.complete);
  Model& m = lazy.model;
  ASSERT_EQ(m.surfaces.size(), 53u);
  for (const Surface& s : m.surfaces) {
    EXPECT_FALSE(s.has_triangles);
    EXPECT_TRUE(s.mesh.triangles.empty());
    EXPECT_FALSE(s.aabb.isEmpty());
  }
  EXPECT_EQ(triangle_count(m), 0u);

  // Concurrent requests, one thread per part.
  std::vector<std::thread> threads;
  std::vector<std::vector<Diagnostic>> errors(m.parts.size());
  for (PartId p = 0; p < m.parts.size(); ++p) {
    threads.emplace_back([&, p] {
      std::vector<SurfaceId> ids;
      for (std::uint32_t i = 0; i < m.parts[p].surface_count; ++i) ids.push_back(m.parts[p].first_surface + i);
      for (SurfaceId s : ids) {
        Surface& surf = m.surfaces[s];
        Diagnostic e;
        if (m.parts[p].source->triangulate(s - m.parts[p].first_surface, 0.0, surf.mesh, surf.deflection, e))
          surf.has_triangles = true;
        else
          errors[p].push_back(e);
      }
    });
  }
  for (auto& t : threads) t.join();
  for (const auto& e : errors) EXPECT_TRUE(e.empty());
  const ImportResult eager = import_file(path);
  for (SurfaceId s = 0; s < m.surfaces.size(); ++s) {
    EXPECT_TRUE(m.surfaces[s].has_triangles);
    EXPECT_FALSE(m.surfaces[s].mesh.triangles.empty());
    EXPECT_LE(m.surfaces[s].deflection, 0.1 * (1 + 1e-9));
    EXPECT_TRUE(m.surfaces[s].aabb.contains(mesh_aabb(m.surfaces[s].mesh)));
    // The lazy exact boxes agree with the eager ones (both come from the B-rep).
    EXPECT_TRUE(m.surfaces[s].aabb.isApprox(eager.model.surfaces[s].aabb, 1e-6) ||
                eager.model.surfaces[s].aabb.contains(m.surfaces[s].aabb));
  }

  // require_triangles through the model API as well.
  ImportResult again = import_file(path, o);
  std::vector<SurfaceId> all(again.model.surfaces.size());
  for (SurfaceId s = 0; s < all.size(); ++s) all[s] = s;
  EXPECT_TRUE(require_triangles(again.model, all).empty());
  for (const Surface& s : again.model.surfaces) EXPECT_TRUE(s.has_triangles);
}

TEST(CadStep, ExactDistanceOfTouchingAs1Faces) {
  const std::string path = kExternal + "as1-tu-203.stp";
  REQUIRE_FILE(path);
  ImportOptions o;
  o.lazy = true;
  const ImportResult r = import_file(path, o);
  const Model& m = r.model;
  const Instance* plate = nullptr;
  const Instance* bracket = nullptr;
  for (const Instance& i : m.instances) {
    if (i.path == "/as1/PLATE") plate = &i;
    if (i.path == "/as1/L-BRACKET-ASSEMBLY::1/L-BRACKET") bracket = &i;
  }
  ASSERT_TRUE(plate && bracket);
  const Part& pp = m.parts[plate->part];
  const Part& bp = m.parts[bracket->part];
  // The bracket stands on the plate: some pair of their faces touches; most pairs are far apart.
  double closest = 1e300;
  int far = 0;
  for (std::uint32_t a = 0; a < pp.surface_count; ++a) {
    for (std::uint32_t b = 0; b < bp.surface_count; ++b) {
      const auto d = pp.source->exact_distance(a, plate->pose, *bp.source, b, bracket->pose, 1.0);
      ASSERT_TRUE(d.has_value());
      EXPECT_GE(*d, 0.0);
      closest = std::min(closest, *d);
      if (*d > 1.0) ++far;
    }
  }
  EXPECT_LT(closest, 1e-6);
  EXPECT_GT(far, 0);
}

TEST(CadStep, PresetsAndRelativeDeflection) {
  const std::string path = kExternal + "linkrods.step";
  REQUIRE_FILE(path);
  std::size_t previous = 0;
  for (auto p : {TessellationPreset::Coarse, TessellationPreset::Normal, TessellationPreset::Fine}) {
    ImportOptions o;
    o.tessellation = tessellation_preset(p);
    const ImportResult r = import_file(path, o);
    ASSERT_TRUE(r.complete);
    EXPECT_GT(triangle_count(r.model), previous) << tessellation_preset_name(p);
    previous = triangle_count(r.model);
  }
  ImportOptions rel;
  rel.tessellation.relative = true;
  rel.tessellation.linear_deflection = 0.001;
  const ImportResult r = import_file(path, rel);
  ASSERT_TRUE(r.complete);
  const auto* source = dynamic_cast<const BrepSource*>(r.model.parts[0].source.get());
  Aabb box;
  for (const Surface& s : r.model.surfaces) box.extend(s.aabb);
  EXPECT_NEAR(source->default_deflection(), 0.001 * box.diagonal().norm(), 1e-9);
}

}  // namespace
}  // namespace cadclash
