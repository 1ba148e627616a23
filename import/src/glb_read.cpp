// Reading back a .glb that cadclash wrote (layout in cadclash/glb_layout.h): the exact parts, surfaces,
// names, ids, instances, poses.
// The file is untrusted: every index, offset and length is checked before use.
#include "mesh_common.h"
#include "readers.h"

#include "cadclash/glb_layout.h"
#include "cadclash/report.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstring>
#include <fstream>

namespace cadclash::detail {
namespace {

// The two chunks of a GLB file, as views into its bytes.
struct GlbChunks {
  std::string_view json;
  std::string_view bin;  // empty when the file has no BIN chunk
};

std::uint32_t get_u32(std::string_view bytes, std::size_t at) {
  std::uint32_t v = 0;
  std::memcpy(&v, bytes.data() + at, 4);
  return v;
}

// The bytes of bufferView `view`, checked against the BIN chunk.
std::string_view view_bytes(const nlohmann::json& doc, std::string_view bin, std::size_t view) {
  const nlohmann::json& v = doc.at("bufferViews").at(view);
  if (v.value("buffer", 0) != 0) throw std::runtime_error("bufferView " + std::to_string(view) + " is not in the BIN chunk");
  const auto offset = v.value<std::size_t>("byteOffset", 0);
  const auto length = v.at("byteLength").get<std::size_t>();
  if (offset > bin.size() || length > bin.size() - offset)
    throw std::runtime_error("bufferView " + std::to_string(view) + " runs past the end of the BIN chunk");
  if (v.contains("byteStride")) throw std::runtime_error("bufferView " + std::to_string(view) + " is strided");
  return bin.substr(offset, length);
}

// The elements of accessor `index`, as `components` numbers each, converted to T.
template <typename T>
std::vector<T> read_accessor(const nlohmann::json& doc, std::string_view bin, std::size_t index, int components) {
  const nlohmann::json& a = doc.at("accessors").at(index);
  const auto count = a.at("count").get<std::size_t>();
  const int type = a.at("componentType").get<int>();
  const std::size_t size = type == 5126 || type == 5125 ? 4 : type == 5123 ? 2 : type == 5121 ? 1 : 0;
  if (size == 0) throw std::runtime_error("accessor " + std::to_string(index) + " has an unsupported component type");
  const std::string_view bytes = view_bytes(doc, bin, a.at("bufferView").get<std::size_t>());
  const auto offset = a.value<std::size_t>("byteOffset", 0);
  const std::size_t n = count * static_cast<std::size_t>(components);
  if (count > bytes.size() || offset > bytes.size() || n * size > bytes.size() - offset)
    throw std::runtime_error("accessor " + std::to_string(index) + " runs past the end of its bufferView");
  std::vector<T> out(n);
  const char* p = bytes.data() + offset;
  for (std::size_t i = 0; i < n; ++i, p += size) {
    if (type == 5126) {
      float f;
      std::memcpy(&f, p, 4);
      out[i] = static_cast<T>(f);
    } else if (type == 5125) {
      std::uint32_t u;
      std::memcpy(&u, p, 4);
      out[i] = static_cast<T>(u);
    } else if (type == 5123) {
      std::uint16_t u;
      std::memcpy(&u, p, 2);
      out[i] = static_cast<T>(u);
    } else {
      out[i] = static_cast<T>(static_cast<unsigned char>(*p));
    }
  }
  return out;
}

// Splits a GLB file into its chunks, checking the header and every length. Returns false with a
// one-sentence `error` when the bytes are not a well-formed GLB.
bool split_glb(std::string_view bytes, GlbChunks& chunks, std::string& error) {
  if (bytes.size() < 20 || get_u32(bytes, 0) != kGlbMagic) {
    error = "not a binary glTF file (no 'glTF' magic)";
    return false;
  }
  if (get_u32(bytes, 4) != 2) {
    error = "unsupported binary glTF version " + std::to_string(get_u32(bytes, 4));
    return false;
  }
  const std::uint32_t total = get_u32(bytes, 8);
  if (total > bytes.size()) {
    error = "truncated: the header announces " + std::to_string(total) + " bytes, the file has " + std::to_string(bytes.size());
    return false;
  }
  bytes = bytes.substr(0, total);
  const std::uint32_t json_length = get_u32(bytes, 12);
  if (get_u32(bytes, 16) != kGlbChunkJson || json_length > bytes.size() - 20) {
    error = "the first chunk is not a complete JSON chunk";
    return false;
  }
  chunks.json = bytes.substr(20, json_length);
  chunks.bin = {};
  const std::size_t next = 20 + static_cast<std::size_t>(json_length);
  if (bytes.size() - next >= 8 && get_u32(bytes, next + 4) == kGlbChunkBin) {
    const std::uint32_t bin_length = get_u32(bytes, next);
    if (bin_length > bytes.size() - next - 8) {
      error = "truncated: the BIN chunk runs past the end of the file";
      return false;
    }
    chunks.bin = bytes.substr(next + 8, bin_length);
  }
  return true;
}

// A surface's name and provenance back from a primitive's extras (cadclash::report's
// provenance_from_json); throws, as the other checks of read_cadclash_glb do, on a bad value.
void surface_provenance_from_json(const nlohmann::json& j, Surface& s) {
  if (const std::optional<ReportError> e = provenance_from_json(j, s))
    throw nlohmann::json::other_error::create(501, "surface provenance " + format_report_error(*e), &j);
}

bool load_glb_json(const std::string& path, std::string& bytes, GlbChunks& chunks, nlohmann::json& doc, std::string& error) {
  if (!read_whole_file(path, bytes, error)) return false;
  if (!split_glb(bytes, chunks, error)) return false;
  doc = nlohmann::json::parse(chunks.json, nullptr, false);
  if (doc.is_discarded() || !doc.is_object()) {
    error = "the JSON chunk is not a JSON object";
    return false;
  }
  return true;
}

}  // namespace

bool is_cadclash_glb(const std::string& path) {
  // Only the first 20 bytes and the start of the JSON chunk are needed: our writer puts "asset"
  // first, so even a file cut short is recognised and gets our reader's precise messages.
  std::ifstream in(path, std::ios::binary);
  char header[20];
  if (!in.read(header, sizeof header)) return false;
  const std::string_view h(header, sizeof header);
  if (get_u32(h, 0) != kGlbMagic || get_u32(h, 16) != kGlbChunkJson) return false;
  std::string start(std::min<std::uint32_t>(get_u32(h, 12), 256), '\0');
  in.read(start.data(), static_cast<std::streamsize>(start.size()));
  start.resize(static_cast<std::size_t>(in.gcount()));
  const std::string_view json(start);
  return json.starts_with("{\"asset\":") && json.find("\"generator\":\"cadclash") != std::string_view::npos;
}

ImportResult read_cadclash_glb(const std::string& path, const ImportOptions&) {
  std::string bytes, error;
  GlbChunks chunks;
  nlohmann::json doc;
  if (!load_glb_json(path, bytes, chunks, doc, error)) return failed_import(path, error);

  ImportResult result;
  Model& model = result.model;
  try {
    const nlohmann::json& root = doc.at("extras").at("cadclash");
    if (root.at("format").get<int>() != kCadclashGlbFormat)
      return failed_import(path, "written by a cadclash with another .glb format (" + root.at("format").dump() + ")");
    const nlohmann::json& parts = root.at("parts");
    for (std::size_t pid = 0; pid < parts.size(); ++pid) {
      const nlohmann::json& jp = parts.at(pid);
      Part part;
      part.name = jp.at("name").get<std::string>();
      part.source_file = jp.at("source_file").get<std::string>();
      part.first_surface = static_cast<SurfaceId>(model.surfaces.size());
      const int mesh = jp.at("mesh").get<int>();
      if (mesh >= 0) {
        for (const nlohmann::json& prim : doc.at("meshes").at(static_cast<std::size_t>(mesh)).at("primitives")) {
          if (prim.value("mode", 4) != 4) throw std::runtime_error("a primitive is not made of triangles");
          Surface s;
          surface_provenance_from_json(prim.at("extras").at("cadclash"), s);
          s.part = static_cast<PartId>(pid);
          const nlohmann::json& extras = prim.at("extras").at("cadclash");
          const auto pos_accessor = prim.at("attributes").at("POSITION").get<std::size_t>();
          const auto count = doc.at("accessors").at(pos_accessor).at("count").get<std::size_t>();
          if (extras.contains("positions_f64")) {
            const std::string_view exact = view_bytes(doc, chunks.bin, extras.at("positions_f64").get<std::size_t>());
            if (exact.size() != count * sizeof(Vec3)) throw std::runtime_error("the float64 positions do not match POSITION");
            s.mesh.vertices.resize(count);
            std::memcpy(static_cast<void*>(s.mesh.vertices.data()), exact.data(), exact.size());
          } else {
            const std::vector<double> p = read_accessor<double>(doc, chunks.bin, pos_accessor, 3);
            for (std::size_t i = 0; i < count; ++i) s.mesh.vertices.emplace_back(p[3 * i], p[3 * i + 1], p[3 * i + 2]);
          }
          const std::vector<std::uint32_t> idx =
              read_accessor<std::uint32_t>(doc, chunks.bin, prim.at("indices").get<std::size_t>(), 1);
          if (idx.size() % 3 != 0) throw std::runtime_error("an index count is not a multiple of 3");
          for (std::size_t i = 0; i < idx.size(); i += 3) {
            if (idx[i] >= count || idx[i + 1] >= count || idx[i + 2] >= count)
              throw std::runtime_error("a triangle index is out of range");
            s.mesh.triangles.push_back({idx[i], idx[i + 1], idx[i + 2]});
          }
          for (const Vec3& v : s.mesh.vertices)
            if (!v.allFinite()) throw std::runtime_error("a position is not finite");
            else if (!(v.cwiseAbs().maxCoeff() <= kMaxLength))
              throw std::runtime_error("a position is " + kOutsideRange);
          s.has_triangles = true;
          if (s.aabb.isEmpty()) s.aabb = mesh_aabb(s.mesh);
          model.surfaces.push_back(std::move(s));
        }
      }
      part.surface_count = static_cast<std::uint32_t>(model.surfaces.size()) - part.first_surface;
      model.parts.push_back(std::move(part));
    }
    if (doc.contains("nodes")) {
      for (const nlohmann::json& node : doc.at("nodes")) {
        Instance instance;
        instance.path = node.at("name").get<std::string>();
        instance.part = node.at("extras").at("cadclash").at("part").get<PartId>();
        if (instance.part >= model.parts.size()) throw std::runtime_error("a node refers to a part that does not exist");
        if (node.contains("matrix")) {
          const auto m = node.at("matrix").get<std::vector<double>>();
          if (m.size() != 16) throw std::runtime_error("a node matrix does not have 16 numbers");
          Eigen::Matrix4d e;
          for (int c = 0; c < 4; ++c)
            for (int r = 0; r < 4; ++r) e(r, c) = m[static_cast<std::size_t>(4 * c + r)];
          if (!e.allFinite()) throw std::runtime_error("a node matrix is not finite");
          if (!(e.col(3).head<3>().cwiseAbs().maxCoeff() <= kMaxLength))
            throw std::runtime_error("a node matrix translates by a length " + kOutsideRange);
          instance.pose.matrix() = e;
        }
        model.instances.push_back(std::move(instance));
      }
    }
    for (const Surface& s : model.surfaces)
      if (s.provenance.parent != kInvalidId && s.provenance.parent >= model.surfaces.size())
        throw std::runtime_error("a surface's parent does not exist");
  } catch (const std::exception& e) {
    return failed_import(path, std::string("not a valid cadclash .glb: ") + e.what());
  }
  return result;
}

}  // namespace cadclash::detail
