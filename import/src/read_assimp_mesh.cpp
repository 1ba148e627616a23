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

#include <bit>
#include <cmath>
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
    std::vector<bool> finite(mesh.mNumVertices, true);
    for (unsigned v = 0; v < mesh.mNumVertices; ++v) {
      const aiVector3D& p = mesh.mVertices[v];
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
        finite[v] = false;
        continue;
      }
      auto [it, inserted] = merged.try_emplace(PositionKey{float_bits(p.x), float_bits(p.y), float_bits(p.z)},
                                                static_cast<std::uint32_t>(surface.mesh.vertices.size()));
      if (inserted) {
        const Eigen::Vector4d w = to_world * Eigen::Vector4d(p.x, p.y, p.z, 1.0);
        surface.mesh.vertices.emplace_back(w.x(), w.y(), w.z());
      }
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
                  "face " + std::to_string(f) + " of mesh '" + surface.name +
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

}  // namespace

ImportResult read_assimp_mesh(const std::string& path, const ImportOptions&) {
  Assimp::Importer importer;
  // Only structure checks: every other post-process step would change or drop geometry.
  const aiScene* scene = importer.ReadFile(path, aiProcess_ValidateDataStructure);
  if (scene == nullptr || scene->mRootNode == nullptr)
    return failed_import(path, std::string("cannot read the file: ") + importer.GetErrorString());

  ImportResult result;
  DiagnosticCollector diags(path);
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
