// glTF 2.0 binary export, written with nlohmann-json; layout in cadclash/glb_layout.h.
#include "writers.h"

#include "cadclash/glb_layout.h"
#include "cadclash/report.h"

#include <cstring>
#include <fstream>
#include <limits>
#include <optional>

namespace cadclash::detail {
namespace {

// The BIN chunk under construction: appends arrays, each bufferView aligned to 8 bytes.
struct BinWriter {
  std::string bytes;
  nlohmann::json views = nlohmann::json::array();

  std::size_t add_view(const void* data, std::size_t size, int target) {
    while (bytes.size() % 8 != 0) bytes.push_back('\0');
    nlohmann::json v{{"buffer", 0}, {"byteOffset", bytes.size()}, {"byteLength", size}};
    if (target != 0) v["target"] = target;
    bytes.append(static_cast<const char*>(data), size);
    views.push_back(std::move(v));
    return views.size() - 1;
  }
};

void put_u32(std::string& out, std::uint32_t v) {
  char b[4];
  std::memcpy(b, &v, 4);  // GLB is little-endian, as is every platform we build on
  out.append(b, 4);
}

// One surface as a TRIANGLES primitive: its float32 positions, their float64 copy and its indices
// appended to `bin`, the POSITION and index accessors to `accessors`, provenance in the extras.
nlohmann::json surface_primitive(const Surface& s, SurfaceId sid, BinWriter& bin, nlohmann::json& accessors) {
  std::vector<float> positions;
  positions.reserve(s.mesh.vertices.size() * 3);
  Eigen::Vector3f lo = Eigen::Vector3f::Constant(std::numeric_limits<float>::max());
  Eigen::Vector3f hi = -lo;
  for (const Vec3& v : s.mesh.vertices) {
    const Eigen::Vector3f f = v.cast<float>();
    lo = lo.cwiseMin(f);
    hi = hi.cwiseMax(f);
    positions.insert(positions.end(), {f.x(), f.y(), f.z()});
  }
  const std::size_t pos_view = bin.add_view(positions.data(), positions.size() * sizeof(float), 34962);
  const std::size_t f64_view = bin.add_view(s.mesh.vertices.data(), s.mesh.vertices.size() * sizeof(Vec3), 0);
  static_assert(sizeof(Vec3) == 3 * sizeof(double));
  const std::size_t index_view =
      bin.add_view(s.mesh.triangles.data(), s.mesh.triangles.size() * sizeof(s.mesh.triangles[0]), 34963);

  accessors.push_back({{"bufferView", pos_view},
                       {"componentType", 5126},
                       {"count", s.mesh.vertices.size()},
                       {"type", "VEC3"},
                       {"min", {lo.x(), lo.y(), lo.z()}},
                       {"max", {hi.x(), hi.y(), hi.z()}}});
  const std::size_t pos_accessor = accessors.size() - 1;
  std::uint32_t max_index = 0;
  for (const auto& t : s.mesh.triangles) max_index = std::max({max_index, t[0], t[1], t[2]});
  accessors.push_back({{"bufferView", index_view},
                       {"componentType", 5125},
                       {"count", s.mesh.triangles.size() * 3},
                       {"type", "SCALAR"},
                       {"min", {0}},
                       {"max", {max_index}}});
  const std::size_t index_accessor = accessors.size() - 1;
  std::uint32_t min_index = max_index;
  for (const auto& t : s.mesh.triangles) min_index = std::min({min_index, t[0], t[1], t[2]});
  accessors.back()["min"] = {min_index};

  nlohmann::json extras = provenance_json(s);
  extras["surface_id"] = sid;
  extras["positions_f64"] = f64_view;
  return {{"attributes", {{"POSITION", pos_accessor}}},
          {"indices", index_accessor},
          {"mode", 4},
          {"extras", {{"cadclash", std::move(extras)}}}};
}

// One node per instance (name = path, its part's mesh when it has one, a column-major matrix unless
// the pose is the identity), all in scene 0; nothing when the model has no instance.
void add_instance_nodes(const Model& model, const std::vector<int>& mesh_of_part, nlohmann::json& doc) {
  nlohmann::json nodes = nlohmann::json::array();
  nlohmann::json scene_nodes = nlohmann::json::array();
  for (InstanceId iid = 0; iid < model.instances.size(); ++iid) {
    const Instance& instance = model.instances[iid];
    const Eigen::Matrix4d m = instance.pose.matrix();
    nlohmann::json node{{"name", instance.path}, {"extras", {{"cadclash", {{"part", instance.part}}}}}};
    if (!instance.pose.matrix().isIdentity(0.0)) {
      nlohmann::json matrix = nlohmann::json::array();
      for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) matrix.push_back(m(r, c));  // glTF is column-major
      node["matrix"] = std::move(matrix);
    }
    if (mesh_of_part[instance.part] >= 0) node["mesh"] = mesh_of_part[instance.part];
    nodes.push_back(std::move(node));
    scene_nodes.push_back(iid);
  }
  if (!nodes.empty()) {
    doc["scene"] = 0;
    doc["scenes"] = {{{"nodes", std::move(scene_nodes)}}};
    doc["nodes"] = std::move(nodes);
  }
}

// The GLB file: header, the JSON chunk (`doc` after "asset") and the BIN chunk when `bin` is not
// empty (already padded to 4 bytes). Returns the error when the file could not be written.
std::optional<Diagnostic> write_container(const nlohmann::json& doc, const std::string& bin, const std::string& path) {
  // "asset" goes first so a reader can recognise the file from its first bytes, even when cut short.
  const nlohmann::json asset{{"version", "2.0"}, {"generator", kCadclashGenerator}};
  std::string json = "{\"asset\":" + asset.dump() + "," + doc.dump().substr(1);
  while (json.size() % 4 != 0) json.push_back(' ');
  const std::size_t total = 12 + 8 + json.size() + (bin.empty() ? 0 : 8 + bin.size());
  if (total > 0xFFFFFFFFu) return Diagnostic{Severity::Error, path, 0, -1, "the model is too large for one .glb (over 4 GiB)"};
  std::string header;
  put_u32(header, kGlbMagic);
  put_u32(header, 2);
  put_u32(header, static_cast<std::uint32_t>(total));
  put_u32(header, static_cast<std::uint32_t>(json.size()));
  put_u32(header, kGlbChunkJson);

  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) return Diagnostic{Severity::Error, path, 0, -1, "cannot open the file for writing"};
  out.write(header.data(), static_cast<std::streamsize>(header.size()));
  out.write(json.data(), static_cast<std::streamsize>(json.size()));
  if (!bin.empty()) {
    std::string chunk;
    put_u32(chunk, static_cast<std::uint32_t>(bin.size()));
    put_u32(chunk, kGlbChunkBin);
    out.write(chunk.data(), static_cast<std::streamsize>(chunk.size()));
    out.write(bin.data(), static_cast<std::streamsize>(bin.size()));
  }
  out.close();
  if (!out) return Diagnostic{Severity::Error, path, 0, -1, "write error"};
  return std::nullopt;
}

}  // namespace

std::vector<Diagnostic> write_glb(const Model& model, const std::string& path) {
  std::vector<Diagnostic> diags;
  BinWriter bin;
  nlohmann::json accessors = nlohmann::json::array();
  nlohmann::json meshes = nlohmann::json::array();
  nlohmann::json parts = nlohmann::json::array();
  std::vector<int> mesh_of_part(model.parts.size(), -1);

  for (PartId pid = 0; pid < model.parts.size(); ++pid) {
    const Part& part = model.parts[pid];
    nlohmann::json primitives = nlohmann::json::array();
    for (SurfaceId sid = part.first_surface; sid < part.first_surface + part.surface_count; ++sid) {
      const Surface& s = model.surfaces[sid];
      if (!s.has_triangles || s.mesh.triangles.empty() || s.mesh.vertices.empty()) {
        // glTF accessors cannot be empty; the surface is listed instead of written.
        diags.push_back({Severity::Warning, path, 0, -1,
                         "surface " + std::to_string(sid) + " '" + s.name + "' has no triangles; not written"});
        continue;
      }
      primitives.push_back(surface_primitive(s, sid, bin, accessors));
    }
    if (!primitives.empty()) {
      mesh_of_part[pid] = static_cast<int>(meshes.size());
      meshes.push_back({{"name", part.name}, {"primitives", std::move(primitives)}});
    }
    parts.push_back({{"name", part.name}, {"source_file", part.source_file}, {"mesh", mesh_of_part[pid]}});
  }

  nlohmann::json doc{{"extras", {{"cadclash", {{"format", kCadclashGlbFormat}, {"parts", std::move(parts)}}}}}};
  add_instance_nodes(model, mesh_of_part, doc);
  const bool wrote_any = !meshes.empty();
  if (wrote_any) doc["meshes"] = std::move(meshes);
  if (!accessors.empty()) doc["accessors"] = std::move(accessors);
  while (bin.bytes.size() % 4 != 0) bin.bytes.push_back('\0');
  if (!bin.bytes.empty()) {
    doc["bufferViews"] = std::move(bin.views);
    doc["buffers"] = {{{"byteLength", bin.bytes.size()}}};
  }
  if (const std::optional<Diagnostic> error = write_container(doc, bin.bytes, path)) return {*error};
  if (!wrote_any) diags.push_back({Severity::Error, path, 0, -1, "nothing to write: no surface has triangles"});
  return diags;
}

}  // namespace cadclash::detail
