// Export to OBJ and .glb, import again: the same surfaces, names, ids, instances and poses.
#include "cadclash/export.h"
#include "readers.h"
#include "../import/test_mesh_util.h"

#include <gtest/gtest.h>
#include "../test_temp.h"
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>

namespace cadclash::test {
namespace {

std::string temp_path(const std::string& name) { return cadclash::testing::scratch_dir() + "/" + name; }

std::string read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::uint32_t u32(const std::string& b, std::size_t at) {
  std::uint32_t v = 0;
  std::memcpy(&v, b.data() + at, 4);
  return v;
}

// Two parts with every provenance field used, one placed twice, coordinates that float32 cannot hold.
Model sample_model() {
  Model m;
  Part a{"plate", "in/plate.step", 0, 2, nullptr};
  Part b{"bolt", "in/bolt.obj", 2, 1, nullptr};
  m.parts = {a, b};

  Surface s0;
  s0.name = "face-1";
  s0.part = 0;
  s0.provenance = {SourceKind::StepFace, "in/plate.step", 1234, 0, "top face", kInvalidId, std::array<float, 3>{0.25f, 0.5f, 1.0f},
                   true, false};
  s0.deflection = 0.05;
  s0.mesh.vertices = {{1000.123456789012, 0, 0}, {1001.5, 0, 0}, {1000.123456789012, 1.000000000001, 0}, {1001.5, 1, 0.1}};
  s0.mesh.triangles = {{0, 1, 2}, {1, 3, 2}};
  Surface s1;
  s1.name = "face 2";  // a space: OBJ group names must stay one word
  s1.part = 0;
  s1.provenance = {SourceKind::Segment, "in/plate.step", -1, 1, "", 0, std::nullopt, false, true};
  s1.mesh.vertices = {{0, 0, -1e-7}, {1e-9, 2, 3}, {4, 5, 6}};
  s1.mesh.triangles = {{0, 1, 2}};
  Surface s2;
  s2.name = "shank";
  s2.part = 1;
  s2.provenance = {SourceKind::ObjGroup, "in/bolt.obj", -1, 0, "shank", kInvalidId, std::nullopt, false, false};
  s2.mesh.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  s2.mesh.triangles = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}};
  for (Surface* s : {&s0, &s1, &s2}) {
    s->has_triangles = true;
    s->aabb = mesh_aabb(s->mesh);
  }
  s0.aabb.extend(Vec3(1000, -1, -1));  // as a B-rep face's box around its exact surface
  m.surfaces = {s0, s1, s2};

  Pose p1 = Pose::Identity();
  p1.rotate(Eigen::AngleAxisd(0.3, Vec3(1, 2, 3).normalized()));
  p1.pretranslate(Vec3(10.5, -20.25, 1e-3));
  Pose p2 = Pose::Identity();
  p2.translate(Vec3(0, 0, 100));
  m.instances = {{"/asm/plate", 0, Pose::Identity()}, {"/asm/bolt", 1, p1}, {"/asm/bolt::2", 1, p2}};
  return m;
}

void expect_same_model(const Model& a, const Model& b) {
  ASSERT_EQ(a.parts.size(), b.parts.size());
  for (std::size_t i = 0; i < a.parts.size(); ++i) {
    EXPECT_EQ(a.parts[i].name, b.parts[i].name);
    EXPECT_EQ(a.parts[i].source_file, b.parts[i].source_file);
    EXPECT_EQ(a.parts[i].first_surface, b.parts[i].first_surface);
    EXPECT_EQ(a.parts[i].surface_count, b.parts[i].surface_count);
  }
  ASSERT_EQ(a.surfaces.size(), b.surfaces.size());
  for (std::size_t i = 0; i < a.surfaces.size(); ++i) {
    const Surface &x = a.surfaces[i], &y = b.surfaces[i];
    SCOPED_TRACE(x.name);
    EXPECT_EQ(x.name, y.name);
    EXPECT_EQ(x.part, y.part);
    EXPECT_EQ(x.provenance.kind, y.provenance.kind);
    EXPECT_EQ(x.provenance.source_file, y.provenance.source_file);
    EXPECT_EQ(x.provenance.step_id, y.provenance.step_id);
    EXPECT_EQ(x.provenance.face_index, y.provenance.face_index);
    EXPECT_EQ(x.provenance.source_name, y.provenance.source_name);
    EXPECT_EQ(x.provenance.parent, y.provenance.parent);
    EXPECT_EQ(x.provenance.colour, y.provenance.colour);
    EXPECT_EQ(x.provenance.healed, y.provenance.healed);
    EXPECT_EQ(x.provenance.repaired, y.provenance.repaired);
    EXPECT_EQ(x.deflection, y.deflection);
    EXPECT_TRUE(y.has_triangles);
    EXPECT_EQ(x.mesh.vertices, y.mesh.vertices);  // exact: the .glb carries float64 positions too
    EXPECT_EQ(x.mesh.triangles, y.mesh.triangles);
    EXPECT_EQ(x.aabb.min(), y.aabb.min());
    EXPECT_EQ(x.aabb.max(), y.aabb.max());
  }
  ASSERT_EQ(a.instances.size(), b.instances.size());
  for (std::size_t i = 0; i < a.instances.size(); ++i) {
    EXPECT_EQ(a.instances[i].path, b.instances[i].path);
    EXPECT_EQ(a.instances[i].part, b.instances[i].part);
    EXPECT_EQ(a.instances[i].pose.matrix(), b.instances[i].pose.matrix());
  }
}

TEST(ExportGlb, RoundTripIsExact) {
  const Model m = sample_model();
  const std::string path = temp_path("sample.glb");
  const std::vector<Diagnostic> written = export_model(m, path);
  EXPECT_TRUE(written.empty()) << (written.empty() ? "" : format_diagnostic(written[0]));
  EXPECT_TRUE(detail::is_cadclash_glb(path));
  const ImportResult r = import_file(path);
  ASSERT_TRUE(r.complete) << all_messages(r);
  expect_well_formed(r.model);
  expect_same_model(m, r.model);
}

TEST(ExportGlb, RoundTripOfImportedFiles) {
  const std::vector<std::string> inputs{mesh_data("groups.obj"), mesh_data("colours.off"), mesh_data("cube_binary.stl")};
  const ImportResult in = import_files(inputs);
  ASSERT_TRUE(in.complete) << all_messages(in);
  const std::string path = temp_path("imported.glb");
  EXPECT_TRUE(export_model(in.model, path).empty());
  const ImportResult back = import_file(path);
  ASSERT_TRUE(back.complete) << all_messages(back);
  expect_same_model(in.model, back.model);
}

TEST(ExportGlb, StructureFollowsTheGltfSpec) {
  const Model m = sample_model();
  const std::string path = temp_path("structure.glb");
  ASSERT_TRUE(export_model(m, path).empty());
  const std::string b = read_bytes(path);
  ASSERT_GE(b.size(), 28u);
  EXPECT_EQ(b.substr(0, 4), "glTF");
  EXPECT_EQ(u32(b, 4), 2u);
  EXPECT_EQ(u32(b, 8), b.size());
  const std::uint32_t json_length = u32(b, 12);
  EXPECT_EQ(u32(b, 16), 0x4E4F534Au);  // JSON
  EXPECT_EQ(json_length % 4, 0u);
  ASSERT_LE(20 + json_length + 8, b.size());
  const std::uint32_t bin_length = u32(b, 20 + json_length);
  EXPECT_EQ(u32(b, 24 + json_length), 0x004E4942u);  // BIN
  EXPECT_EQ(bin_length % 4, 0u);
  EXPECT_EQ(28 + json_length + bin_length, b.size());

  const nlohmann::json doc = nlohmann::json::parse(b.substr(20, json_length));
  EXPECT_EQ(doc["asset"]["version"], "2.0");
  EXPECT_EQ(doc["asset"]["generator"], "cadclash 0.1.0");
  ASSERT_EQ(doc["buffers"].size(), 1u);
  EXPECT_EQ(doc["buffers"][0]["byteLength"], bin_length);
  EXPECT_FALSE(doc["buffers"][0].contains("uri"));
  for (const auto& v : doc["bufferViews"]) {
    EXPECT_LE(v["byteOffset"].get<std::size_t>() + v["byteLength"].get<std::size_t>(), bin_length);
    EXPECT_EQ(v["byteOffset"].get<std::size_t>() % 4, 0u);
  }
  // One mesh per part, one primitive per surface; one node per instance, in the scene.
  ASSERT_EQ(doc["meshes"].size(), 2u);
  EXPECT_EQ(doc["meshes"][0]["primitives"].size(), 2u);
  EXPECT_EQ(doc["meshes"][1]["primitives"].size(), 1u);
  ASSERT_EQ(doc["nodes"].size(), 3u);
  EXPECT_EQ(doc["scenes"][0]["nodes"].size(), 3u);
  EXPECT_EQ(doc["nodes"][1]["name"], "/asm/bolt");
  EXPECT_EQ(doc["nodes"][1]["mesh"], 1);
  ASSERT_EQ(doc["nodes"][1]["matrix"].size(), 16u);
  EXPECT_EQ(doc["nodes"][1]["matrix"][15], 1.0);
  EXPECT_EQ(doc["nodes"][1]["matrix"][12], 10.5);  // translation is in the last column
  for (const auto& mesh : doc["meshes"])
    for (const auto& prim : mesh["primitives"]) {
      EXPECT_EQ(prim["mode"], 4);
      const auto& pos = doc["accessors"][prim["attributes"]["POSITION"].get<std::size_t>()];
      EXPECT_EQ(pos["componentType"], 5126);
      EXPECT_EQ(pos["type"], "VEC3");
      ASSERT_TRUE(pos.contains("min") && pos.contains("max"));  // required for POSITION
      // min/max must be the true float bounds of the stored positions.
      const auto& view = doc["bufferViews"][pos["bufferView"].get<std::size_t>()];
      const std::size_t base = 28 + json_length + view["byteOffset"].get<std::size_t>();
      for (int c = 0; c < 3; ++c) {
        float lo = INFINITY, hi = -INFINITY;
        for (std::size_t i = 0; i < pos["count"].get<std::size_t>(); ++i) {
          float f;
          std::memcpy(&f, b.data() + base + 12 * i + 4 * static_cast<std::size_t>(c), 4);
          lo = std::min(lo, f);
          hi = std::max(hi, f);
        }
        EXPECT_EQ(pos["min"][c].get<float>(), lo);
        EXPECT_EQ(pos["max"][c].get<float>(), hi);
      }
      const auto& idx = doc["accessors"][prim["indices"].get<std::size_t>()];
      EXPECT_EQ(idx["componentType"], 5125);
      EXPECT_EQ(idx["count"].get<std::size_t>() % 3, 0u);
      EXPECT_LT(idx["max"][0].get<std::size_t>(), pos["count"].get<std::size_t>());
      const auto& extras = prim["extras"]["cadclash"];
      EXPECT_TRUE(extras.contains("kind") && extras.contains("step_id") && extras.contains("face_index") &&
                  extras.contains("source_name") && extras.contains("source_file") && extras.contains("deflection") &&
                  extras.contains("healed") && extras.contains("repaired"));
    }
  EXPECT_EQ(doc["meshes"][0]["primitives"][0]["extras"]["cadclash"]["step_id"], 1234);
}

TEST(ExportGlb, OtherGltfReadersSeeTheSameGeometry) {
  // assimp's own glTF reader (not ours) must read what we wrote: one mesh per primitive and placement.
  const Model m = sample_model();
  const std::string path = temp_path("assimp.glb");
  ASSERT_TRUE(export_model(m, path).empty());
  const ImportResult r = detail::read_assimp_mesh(path, {});
  ASSERT_TRUE(r.complete) << all_messages(r);
  ASSERT_EQ(r.model.surfaces.size(), 2u + 1u + 1u);  // plate's two surfaces, bolt placed twice
  // World positions agree within float precision.
  const TriangleMesh& bolt = r.model.surfaces[2].mesh;
  EXPECT_EQ(bolt.triangles.size(), 4u);
  Aabb expected;
  for (const Vec3& v : m.surfaces[2].mesh.vertices) expected.extend(m.instances[1].pose * v);
  EXPECT_TRUE(r.model.surfaces[2].aabb.min().isApprox(expected.min(), 1e-5));
  EXPECT_TRUE(r.model.surfaces[2].aabb.max().isApprox(expected.max(), 1e-5));
}

TEST(ExportGlb, DamagedGlbIsAnErrorNotACrash) {
  const std::string good = temp_path("good.glb");
  ASSERT_TRUE(export_model(sample_model(), good).empty());
  const std::string b = read_bytes(good);
  const std::string cut = temp_path("cut.glb");
  std::ofstream(cut, std::ios::binary) << b.substr(0, b.size() / 2);
  const ImportResult r = import_file(cut);
  EXPECT_FALSE(r.complete);
  EXPECT_TRUE(r.model.surfaces.empty());
  EXPECT_NE(all_messages(r).find("truncated"), std::string::npos) << all_messages(r);
  // A BIN chunk shorter than the views it must hold.
  std::string shrunk = b;
  const std::uint32_t json_length = u32(b, 12);
  const std::uint32_t small = 8;
  std::memcpy(shrunk.data() + 20 + json_length, &small, 4);
  const std::string bad = temp_path("bad_views.glb");
  std::ofstream(bad, std::ios::binary) << shrunk;
  const ImportResult r2 = import_file(bad);
  EXPECT_FALSE(r2.complete);
  EXPECT_TRUE(r2.model.surfaces.empty());
  EXPECT_NE(all_messages(r2).find("past the end"), std::string::npos) << all_messages(r2);
}

TEST(ExportObj, RoundTripKeepsNamesIdsAndWorldCoordinates) {
  const Model m = sample_model();
  const std::string path = temp_path("sample.obj");
  EXPECT_TRUE(export_model(m, path).empty());
  const ImportResult r = import_file(path);
  ASSERT_TRUE(r.complete) << all_messages(r);
  // One group per surface and instance, in instance order, named "<instance path>/<surface name>".
  std::vector<std::pair<InstanceId, SurfaceId>> written;
  for (InstanceId i = 0; i < m.instances.size(); ++i)
    for (SurfaceId s = m.parts[m.instances[i].part].first_surface;
         s < m.parts[m.instances[i].part].first_surface + m.parts[m.instances[i].part].surface_count; ++s)
      written.emplace_back(i, s);
  ASSERT_EQ(r.model.surfaces.size(), written.size());
  for (std::size_t k = 0; k < written.size(); ++k) {
    const auto [i, s] = written[k];
    const Surface& back = r.model.surfaces[k];
    std::string name = m.instances[i].path + "/" + m.surfaces[s].name;
    std::replace(name.begin(), name.end(), ' ', '_');
    EXPECT_EQ(back.name, name);
    EXPECT_EQ(back.provenance.face_index, static_cast<int>(k));
    ASSERT_EQ(back.mesh.triangles.size(), m.surfaces[s].mesh.triangles.size());
    ASSERT_EQ(back.mesh.vertices.size(), m.surfaces[s].mesh.vertices.size());
    for (std::size_t v = 0; v < back.mesh.vertices.size(); ++v)
      EXPECT_EQ(back.mesh.vertices[v], m.instances[i].pose * m.surfaces[s].mesh.vertices[v]);  // exact
    EXPECT_EQ(back.mesh.triangles, m.surfaces[s].mesh.triangles);
  }
  // The comment before each group gives back the exact names and ids.
  std::ifstream in(path);
  std::string line;
  std::size_t k = 0;
  while (std::getline(in, line)) {
    if (line.rfind("# cadclash-surface ", 0) != 0) continue;
    const nlohmann::json j = nlohmann::json::parse(line.substr(19));
    ASSERT_LT(k, written.size());
    const auto [i, s] = written[k++];
    EXPECT_EQ(j["instance"], m.instances[i].path);
    EXPECT_EQ(j["part"], m.parts[m.instances[i].part].name);
    EXPECT_EQ(j["surface_id"], s);
    EXPECT_EQ(j["name"], m.surfaces[s].name);
    EXPECT_EQ(j["step_id"], m.surfaces[s].provenance.step_id);
    EXPECT_EQ(j["kind"], source_kind_name(m.surfaces[s].provenance.kind));
  }
  EXPECT_EQ(k, written.size());
}

TEST(Export, SurfacesWithoutTrianglesAreListedAndUnknownFormatsRefused) {
  Model m = sample_model();
  m.surfaces[1].has_triangles = false;
  m.surfaces[1].mesh = {};
  for (const char* ext : {".obj", ".glb"}) {
    const std::vector<Diagnostic> d = export_model(m, temp_path(std::string("lazy") + ext));
    EXPECT_FALSE(has_error(d));
    ASSERT_FALSE(d.empty()) << ext;
    EXPECT_NE(d[0].message.find("'face 2' has no triangles"), std::string::npos) << d[0].message;
  }
  const std::vector<Diagnostic> d = export_model(m, temp_path("x.stl"));
  ASSERT_TRUE(has_error(d));
  EXPECT_EQ(export_model(m, "/nonexistent-dir/x.glb").at(0).severity, Severity::Error);
}

}  // namespace
}  // namespace cadclash::test
