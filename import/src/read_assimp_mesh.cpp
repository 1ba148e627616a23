// STL, PLY, glTF and the other formats assimp reads: one surface per mesh placement.
//
// Each mesh a node of the scene places becomes one surface, its vertices moved by the node's
// accumulated transform (so a glTF whose nodes place one mesh twice gives two surfaces). Vertices
// are merged where their positions are bit-identical: aiProcess_JoinIdenticalVertices would also
// compare normals, which an STL gives per facet, and so would merge nothing. Positions are float32
// as assimp stores them. No assimp post-processing runs: polygons are triangulated by
// triangulate_polygon and nothing is dropped for being small.
#include "mesh_common.h"
#include "mesh_polygon.h"
#include "readers.h"

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <array>
#include <bit>
#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <unordered_map>
#include <string_view>

namespace cadclash::detail {
namespace {

struct PositionKey {
  std::uint32_t x, y, z;
  bool operator==(const PositionKey&) const = default;
};
struct PositionHash {
  std::size_t operator()(const PositionKey& k) const {
    std::uint64_t h = k.x;
    h = h * 0x9E3779B97F4A7C15ull ^ k.y;
    h = h * 0x9E3779B97F4A7C15ull ^ k.z;
    return static_cast<std::size_t>(h ^ (h >> 29));
  }
};

std::uint32_t float_bits(float f) { return std::bit_cast<std::uint32_t>(f == 0.0f ? 0.0f : f); }  // -0 == +0

Eigen::Matrix4d to_eigen(const aiMatrix4x4& m) {
  Eigen::Matrix4d e;
  e << m.a1, m.a2, m.a3, m.a4, m.b1, m.b2, m.b3, m.b4, m.c1, m.c2, m.c3, m.c4, m.d1, m.d2, m.d3, m.d4;
  return e;
}

struct Walker {
  const aiScene* scene;
  DiagnosticCollector& diags;
  std::vector<Surface>& surfaces;
  std::unordered_map<std::string, std::size_t> name_uses;
  std::size_t dropped_faces = 0, skipped_primitives = 0, not_simple = 0;
  bool dropped = false;

  std::string unique_name(std::string name) {
    const std::size_t uses = ++name_uses[name];
    if (uses > 1) name += "::" + std::to_string(uses);
    return name;
  }

  void add_mesh(unsigned mesh_index, const aiNode& node, const Eigen::Matrix4d& to_world) {
    const aiMesh& mesh = *scene->mMeshes[mesh_index];
    Surface surface;
    std::string name = mesh.mName.length > 0 ? mesh.mName.C_Str() : node.mName.C_Str();
    if (name.empty()) name = "mesh-" + std::to_string(mesh_index);
    surface.name = unique_name(name);
    surface.provenance.kind = SourceKind::MeshFile;
    surface.provenance.source_name = mesh.mName.C_Str();
    surface.provenance.face_index = static_cast<std::int32_t>(mesh_index);
    // A colour only from a material the file defines: assimp invents a white "DefaultMaterial" (or an
    // unnamed one) for formats without materials, such as STL.
    if (scene->mMaterials != nullptr && mesh.mMaterialIndex < scene->mNumMaterials) {
      const aiMaterial& material = *scene->mMaterials[mesh.mMaterialIndex];
      aiString material_name;
      aiColor4D c;
      if (material.Get(AI_MATKEY_NAME, material_name) == AI_SUCCESS && material_name.length > 0 &&
          std::string_view(material_name.C_Str()) != AI_DEFAULT_MATERIAL_NAME &&
          material.Get(AI_MATKEY_COLOR_DIFFUSE, c) == AI_SUCCESS)
        surface.provenance.colour = std::array<float, 3>{c.r, c.g, c.b};
    }

    std::unordered_map<PositionKey, std::uint32_t, PositionHash> merged;
    std::vector<std::uint32_t> local(mesh.mNumVertices, kInvalidId);
    std::vector<bool> finite(mesh.mNumVertices, true);  // finite and within the supported range
    bool reported_range = false;
    for (unsigned v = 0; v < mesh.mNumVertices; ++v) {
      const aiVector3D& p = mesh.mVertices[v];
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
        finite[v] = false;
        continue;
      }
      const Eigen::Vector4d w = to_world * Eigen::Vector4d(p.x, p.y, p.z, 1.0);
      if (!in_supported_range(w.x()) || !in_supported_range(w.y()) || !in_supported_range(w.z())) {
        finite[v] = false;
        if (!reported_range)
          diags.add(Severity::Error, 0, "bad vertices",
                    "mesh '" + printable_text(surface.name) + "': vertex " + std::to_string(v) + " placed at (" +
                        printable_number(w.x()) + ", " + printable_number(w.y()) + ", " + printable_number(w.z()) +
                        ") has a coordinate " + kOutsideRange);
        reported_range = true;
        continue;
      }
      auto [it, inserted] = merged.try_emplace(PositionKey{float_bits(p.x), float_bits(p.y), float_bits(p.z)},
                                                static_cast<std::uint32_t>(surface.mesh.vertices.size()));
      if (inserted) surface.mesh.vertices.emplace_back(w.x(), w.y(), w.z());
      local[v] = it->second;
    }
    std::vector<std::uint32_t> corners;
    for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
      const aiFace& face = mesh.mFaces[f];
      if (face.mNumIndices < 3) {
        ++skipped_primitives;
        continue;
      }
      corners.clear();
      bool ok = true;
      for (unsigned k = 0; k < face.mNumIndices && ok; ++k) {
        const unsigned v = face.mIndices[k];
        if (v >= mesh.mNumVertices || !finite[v]) ok = false;
        else corners.push_back(local[v]);
      }
      if (!ok) {
        diags.add(Severity::Error, 0, "faces dropped",
                  "face " + std::to_string(f) + " of mesh '" + printable_text(surface.name) +
                      "' dropped: it uses a vertex that is out of range or not finite");
        dropped = true;
        continue;
      }
      if (!triangulate_polygon(surface.mesh.vertices, corners, surface.mesh.triangles)) ++not_simple;
    }
    if (surface.mesh.triangles.empty()) return;
    surfaces.push_back(std::move(surface));
  }

  void walk(const aiNode& node, const Eigen::Matrix4d& parent) {
    const Eigen::Matrix4d to_world = parent * to_eigen(node.mTransformation);
    for (unsigned i = 0; i < node.mNumMeshes; ++i)
      if (node.mMeshes[i] < scene->mNumMeshes) add_mesh(node.mMeshes[i], node, to_world);
    for (unsigned c = 0; c < node.mNumChildren; ++c) walk(*node.mChildren[c], to_world);
  }
};

// STL is checked by our own scan before assimp reads it: assimp's messages name neither a line nor a
// byte offset. A structurally broken STL (cut short, a bad token) is rejected as a whole, as assimp
// would: its facets form one surface, and a surface with a missing piece is not what anyone drew.
// Exactly degenerate facets are kept, with a warning naming the line (ASCII) or the facet and its
// byte offset (binary). Returns false after adding an error when the file must not be read.
bool iequals(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (std::tolower(static_cast<unsigned char>(a[i])) != std::tolower(static_cast<unsigned char>(b[i]))) return false;
  return true;
}

void warn_degenerate_facet(DiagnosticCollector& diags, std::int64_t line, std::uint64_t facet, std::int64_t offset,
                           std::span<const Vec3> corners) {
  for (const Vec3& p : corners)
    if (!p.allFinite()) return;  // the walker reports non-finite vertices
  const std::string why = degenerate_face(corners);
  if (why.empty()) return;
  std::string where = "facet " + std::to_string(facet);
  if (offset >= 0) where += " (byte offset " + std::to_string(offset) + ")";
  diags.add(Severity::Warning, line, "degenerate facets kept", where + " " + why + "; kept");
}

bool scan_binary_stl(std::string_view bytes, DiagnosticCollector& diags) {
  if (bytes.size() < 84) {
    diags.add(Severity::Error, 0, "broken files",
              "binary STL shorter than its 84-byte header (" + std::to_string(bytes.size()) + " bytes)");
    return false;
  }
  std::uint32_t count = 0;
  std::memcpy(&count, bytes.data() + 80, 4);
  const std::uint64_t needed = 84 + 50 * std::uint64_t{count};
  if (bytes.size() < needed) {
    const std::uint64_t whole = (bytes.size() - 84) / 50;
    diags.add(Severity::Error, 0, "broken files",
              "binary STL too short (truncated, or not an STL): the header (bytes 80-83) announces " +
                  std::to_string(count) + " facets, " + std::to_string(needed) + " bytes, but the file has " +
                  std::to_string(bytes.size()) + "; facet " + std::to_string(whole) + " (from byte offset " +
                  std::to_string(84 + 50 * whole) + ") is missing or cut short");
    return false;
  }
  if (bytes.size() > needed)
    diags.add(Severity::Warning, 0, "trailing data",
              std::to_string(bytes.size() - needed) + " bytes after the last announced facet (byte offset " +
                  std::to_string(needed) + ") ignored");
  std::array<Vec3, 3> corners;
  for (std::uint64_t f = 0; f < count; ++f) {
    const char* p = bytes.data() + 84 + 50 * f + 12;  // after the facet normal
    for (int k = 0; k < 3; ++k) {
      float xyz[3];
      std::memcpy(xyz, p + 12 * k, 12);
      corners[static_cast<std::size_t>(k)] = Vec3(xyz[0], xyz[1], xyz[2]);
    }
    warn_degenerate_facet(diags, 0, f, static_cast<std::int64_t>(84 + 50 * f), corners);
  }
  return true;
}

bool scan_ascii_stl(std::string_view text, DiagnosticCollector& diags) {
  enum class At { Outside, Solid, Facet, Loop, EndLoop };
  At at = At::Outside;
  LineReader lines(text);
  std::string_view line;
  std::vector<std::string_view> tokens;
  std::vector<Vec3> corners;
  std::uint64_t facets = 0;
  std::int64_t facet_line = 0;
  auto fail = [&](std::int64_t line_no, const std::string& message) {
    diags.add(Severity::Error, line_no, "broken files", message);
    return false;
  };
  auto expected = [&](std::string_view what) {
    return fail(lines.line_number(), "expected " + std::string(what) + ", found '" + printable_token(tokens[0]) + "'");
  };
  while (lines.next(line)) {
    split_tokens(line, tokens);
    if (tokens.empty()) continue;
    const std::string_view key = tokens[0];
    switch (at) {
      case At::Outside:
        if (!iequals(key, "solid")) return expected("'solid'");
        at = At::Solid;
        break;
      case At::Solid:
        if (iequals(key, "endsolid")) {
          at = At::Outside;
        } else if (iequals(key, "facet")) {
          at = At::Facet;
          facet_line = lines.line_number();
          corners.clear();
        } else {
          return expected("'facet' or 'endsolid'");
        }
        break;
      case At::Facet:
        if (!(iequals(key, "outer") && tokens.size() >= 2 && iequals(tokens[1], "loop"))) return expected("'outer loop'");
        at = At::Loop;
        break;
      case At::Loop:
        if (iequals(key, "endloop")) {
          if (corners.size() < 3)
            return fail(lines.line_number(), "facet " + std::to_string(facets) + " (line " + std::to_string(facet_line) +
                                                 ") has " + std::to_string(corners.size()) + " vertices; 3 needed");
          at = At::EndLoop;
        } else if (iequals(key, "vertex")) {
          if (tokens.size() != 4)
            return fail(lines.line_number(), "malformed vertex: expected 3 coordinates, found " +
                                                 std::to_string(tokens.size() - 1));
          Vec3 p;
          for (int c = 0; c < 3; ++c)
            if (parse_double(tokens[static_cast<std::size_t>(c) + 1], p[c]) == NumberStatus::Invalid)
              return fail(lines.line_number(), "malformed vertex: '" +
                                                   printable_token(tokens[static_cast<std::size_t>(c) + 1]) +
                                                   "' is not a number");
          corners.push_back(p);
        } else {
          return expected("'vertex' or 'endloop'");
        }
        break;
      case At::EndLoop:
        if (!iequals(key, "endfacet")) return expected("'endfacet'");
        warn_degenerate_facet(diags, facet_line, facets, -1, corners);
        ++facets;
        at = At::Solid;
        break;
    }
  }
  if (at == At::Facet || at == At::Loop || at == At::EndLoop)
    return fail(lines.line_number(), "truncated: the file ends inside facet " + std::to_string(facets) + " (line " +
                                         std::to_string(facet_line) + ")");
  if (at == At::Solid)
    diags.add(Severity::Warning, lines.line_number(), "truncated files", "the file ends without 'endsolid'");
  return true;
}

bool scan_stl(const std::string& path, DiagnosticCollector& diags) {
  std::string bytes, error;
  if (!read_whole_file(path, bytes, error) || bytes.empty()) return true;  // assimp says what is wrong
  // A binary header may begin with "solid" as well: the size settles it, then binary bytes do.
  bool binary = true;
  const std::size_t start = bytes.find_first_not_of(" \t\r\n");
  if (start != std::string::npos && bytes.size() >= start + 5 && iequals(std::string_view(bytes).substr(start, 5), "solid")) {
    std::uint32_t count = 0;
    if (bytes.size() >= 84) std::memcpy(&count, bytes.data() + 80, 4);
    std::int64_t line = 0;
    binary = (bytes.size() >= 84 && bytes.size() == 84 + 50 * std::uint64_t{count}) || find_binary_byte(bytes, line);
  }
  return binary ? scan_binary_stl(bytes, diags) : scan_ascii_stl(bytes, diags);
}

}  // namespace

ImportResult read_assimp_mesh(const std::string& path, const ImportOptions&) {
  DiagnosticCollector stl_diags(path);
  std::string extension = std::filesystem::path(path).extension().string();
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (extension == ".stl" && !scan_stl(path, stl_diags)) {
    ImportResult failed;
    stl_diags.flush_into(failed.diagnostics);
    failed.complete = false;
    return failed;
  }
  Assimp::Importer importer;
  // Only structure checks: every other post-process step would change or drop geometry.
  const aiScene* scene = importer.ReadFile(path, aiProcess_ValidateDataStructure);
  if (scene == nullptr || scene->mRootNode == nullptr)
    // assimp's message may quote a name from the file (a binary STL's header) byte for byte.
    return failed_import(path, "cannot read the file: " + printable_text(importer.GetErrorString()));

  ImportResult result;
  DiagnosticCollector& diags = stl_diags;
  Walker walker{scene, diags, result.model.surfaces, {}};
  walker.walk(*scene->mRootNode, Eigen::Matrix4d::Identity());
  if (walker.skipped_primitives > 0)
    diags.add(Severity::Warning, 0, "line and point elements ignored",
              std::to_string(walker.skipped_primitives) + " line/point primitives ignored: they bound no surface");
  if (walker.not_simple > 0)
    diags.add(Severity::Warning, 0, "polygons not simple",
              std::to_string(walker.not_simple) +
                  " polygons are self-intersecting or without area; triangulated as well as possible");
  if (result.model.surfaces.empty()) {
    diags.add(Severity::Error, 0, "files without faces", "no triangles or polygons: nothing to import");
    diags.flush_into(result.diagnostics);
    result.complete = false;
    return result;
  }
  finish_single_part_model(result.model, path);
  diags.flush_into(result.diagnostics);
  result.complete = !walker.dropped && !has_error(result.diagnostics);
  return result;
}

}  // namespace cadclash::detail
