// OBJ: one surface per `g` group / `o` object, read through assimp.
//
// assimp 5.2.5 alone is not enough for a tagged model, so the file goes through two steps:
// 1. Our own scan validates every line (it is the only place that knows line numbers), keeps the
//    vertices in double precision, resolves relative indices, and decides the surface of each face:
//    the latest `g` or `o` name; a name that recurs is the same surface. Bad elements are listed and
//    dropped here, so the rest of the file survives.
// 2. assimp parses a normalised copy: one `g s<k>` per surface k, faces with absolute vertex
//    indices, and no materials. That sidesteps its quirks: it splits a group's mesh at every `usemtl`
//    and names the pieces after the material, keeps a recurring group as a second node, calls faces
//    before any group "defaultobject", accepts faces with two corners, and rejects the whole file for
//    one index out of range. Its positions are float32, so the normalised copy carries each vertex's
//    number in x and y (exact in float) and the coordinates come from the scan.
// Polygons are triangulated by triangulate_polygon (fan when convex, ear clipping otherwise) on the
// double coordinates: aiProcess_Triangulate handles concave polygons too, but it only sees the vertex
// numbers here.
// Nothing is filtered by area: a degenerate triangle stays, as no tolerance here would fit all units;
// an exactly degenerate face (repeated point, collinear corners) gets a warning naming its line.
#include "mesh_common.h"
#include "mesh_polygon.h"
#include "readers.h"

#include <assimp/Importer.hpp>
#include <assimp/scene.h>

#include <algorithm>
#include <string_view>
#include <tuple>
#include <unordered_map>

namespace cadclash::detail {
namespace {

constexpr std::uint32_t kNoGroup = ~std::uint32_t{0};

struct ObjFace {
  std::uint32_t group = 0;     // index into ObjScan::group_names
  std::int64_t line = 0;
  std::uint32_t first = 0;     // into ObjScan::corners
  std::uint32_t count = 0;
};

struct ObjScan {
  std::vector<Vec3> vertices;
  std::vector<std::int64_t> bad_vertex_line;  // per vertex: 0 if good, else the line that made it bad
  std::vector<std::string> group_names;
  std::vector<std::int64_t> corners;          // 0-based; may be out of range until checked
  std::vector<ObjFace> faces;
  std::size_t ignored_lines_points = 0;
};

std::string_view trim(std::string_view s) {
  const auto is_space = [](char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; };
  while (!s.empty() && is_space(s.front())) s.remove_prefix(1);
  while (!s.empty() && is_space(s.back())) s.remove_suffix(1);
  return s;
}

// Tokens up to an inline comment.
void statement_tokens(std::string_view line, std::vector<std::string_view>& tokens) {
  split_tokens(line, tokens);
  for (std::size_t i = 0; i < tokens.size(); ++i)
    if (tokens[i].front() == '#') {
      tokens.resize(i);
      break;
    }
}

bool is_ignored_keyword(std::string_view k) {
  static constexpr std::string_view kIgnored[] = {"vt", "vn", "vp", "s", "usemtl", "mtllib", "usemap", "maplib",
                                                  "lod", "bevel", "c_interp", "d_interp", "shadow_obj",
                                                  "trace_obj", "mg"};
  for (std::string_view i : kIgnored)
    if (k == i) return true;
  return false;
}

bool is_freeform_keyword(std::string_view k) {
  static constexpr std::string_view kFreeform[] = {"cstype", "deg", "bmat", "step", "curv", "curv2", "surf",
                                                   "parm", "trim", "hole", "scrv", "sp", "end", "con", "ctech", "stech"};
  for (std::string_view i : kFreeform)
    if (k == i) return true;
  return false;
}

void scan_obj(std::string_view text, ObjScan& scan, DiagnosticCollector& diags, bool& dropped) {
  std::unordered_map<std::string, std::uint32_t> group_ids;
  std::uint32_t current_group = kNoGroup;
  std::string current_name = "default";
  std::vector<std::string_view> tokens;
  std::string joined;  // a statement continued over several lines with a trailing backslash
  LineReader lines(text);
  std::string_view raw;
  while (lines.next(raw)) {
    const std::int64_t line_no = lines.line_number();
    std::string_view line = trim(raw);
    if (!line.empty() && line.back() == '\\') {
      joined.clear();
      while (!line.empty() && line.back() == '\\') {
        joined.append(line.substr(0, line.size() - 1));
        joined.push_back(' ');
        if (!lines.next(raw)) break;
        line = trim(raw);
      }
      if (line.empty() || line.back() != '\\') joined.append(line);
      line = joined;
    }
    if (line.empty() || line.front() == '#') continue;
    const std::size_t key_end = line.find_first_of(" \t");
    const std::string_view key = line.substr(0, key_end);
    const std::string_view rest = key_end == std::string_view::npos ? std::string_view{} : trim(line.substr(key_end));

    if (key == "v") {
      statement_tokens(rest, tokens);
      Vec3 p = Vec3::Zero();
      std::int64_t bad = 0;
      if (tokens.size() < 3) {
        diags.add(Severity::Error, line_no, "bad vertices",
                  "malformed vertex " + std::to_string(scan.vertices.size() + 1) + ": expected 3 coordinates, found " +
                      std::to_string(tokens.size()));
        bad = line_no;
      } else {
        for (int c = 0; c < 3 && bad == 0; ++c) {
          const NumberStatus st = parse_double(tokens[static_cast<std::size_t>(c)], p[c]);
          if (st == NumberStatus::Invalid) {
            diags.add(Severity::Error, line_no, "bad vertices",
                      "malformed vertex " + std::to_string(scan.vertices.size() + 1) + ": '" +
                          printable_token(tokens[static_cast<std::size_t>(c)]) + "' is not a number");
            bad = line_no;
          } else if (st == NumberStatus::NotFinite) {
            diags.add(Severity::Error, line_no, "bad vertices",
                      "vertex " + std::to_string(scan.vertices.size() + 1) + " has a coordinate that is not finite ('" +
                          printable_token(tokens[static_cast<std::size_t>(c)]) + "')");
            bad = line_no;
          } else if (!in_supported_range(p[c])) {
            diags.add(Severity::Error, line_no, "bad vertices",
                      "vertex " + std::to_string(scan.vertices.size() + 1) + " has a coordinate " + kOutsideRange + " ('" +
                          printable_token(tokens[static_cast<std::size_t>(c)]) + "')");
            bad = line_no;
          }
        }
      }
      scan.vertices.push_back(bad ? Vec3::Zero() : p);
      scan.bad_vertex_line.push_back(bad);
    } else if (key == "f" || key == "fo") {
      statement_tokens(rest, tokens);
      const auto first = static_cast<std::uint32_t>(scan.corners.size());
      std::string problem;
      for (std::string_view t : tokens) {
        const std::string_view index_text = t.substr(0, t.find('/'));
        std::int64_t index = 0;
        if (!parse_int(index_text, index)) {
          // Appended piece by piece: GCC 12 warns falsely (-Wrestrict) on "literal" + std::string.
          problem = "'";
          problem += printable_token(t);
          problem += "' is not a vertex reference";
          break;
        }
        if (index == 0) {
          problem = "vertex index 0 is invalid (OBJ indices start at 1)";
          break;
        }
        // Negative indices count back from the latest vertex; positive ones are checked at the end,
        // since a file may refer forward.
        const auto nv = static_cast<std::int64_t>(scan.vertices.size());
        const std::int64_t resolved = index > 0 ? index - 1 : nv + index;
        if (resolved < 0) {
          problem = "vertex index " + std::to_string(index) + " is out of range (" + std::to_string(nv) +
                    " vertices defined so far)";
          break;
        }
        scan.corners.push_back(resolved);
      }
      if (problem.empty() && tokens.size() < 3)
        problem = "a face needs at least 3 vertices, found " + std::to_string(tokens.size());
      if (!problem.empty()) {
        scan.corners.resize(first);
        diags.add(Severity::Error, line_no, "faces dropped", "face dropped: " + problem);
        dropped = true;
        continue;
      }
      if (current_group == kNoGroup) {
        auto [it, inserted] = group_ids.try_emplace(current_name, static_cast<std::uint32_t>(scan.group_names.size()));
        if (inserted) scan.group_names.push_back(current_name);
        current_group = it->second;
      }
      scan.faces.push_back({current_group, line_no, first, static_cast<std::uint32_t>(tokens.size())});
    } else if (key == "g" || key == "o") {
      // The whole rest of the line is the name: "g a b" (a face in two groups) cannot be two surfaces.
      current_name = rest.empty() ? "default" : std::string(rest);
      current_group = kNoGroup;
    } else if (key == "l" || key == "p") {
      ++scan.ignored_lines_points;
    } else if (is_freeform_keyword(key)) {
      diags.add(Severity::Warning, line_no, "free-form statements ignored",
                "free-form geometry ('" + printable_token(key) + "') is not supported; ignored");
      dropped = true;
    } else if (!is_ignored_keyword(key)) {
      diags.add(Severity::Warning, line_no, "unknown statements ignored",
                "unknown statement '" + printable_token(key) + "' ignored");
    }
  }
}

// Faces that repeat an earlier face of the same surface (the same corners, in any order), as
// (line, message) in line order: a group that recurs with the same faces doubles them. They are kept
// (as degenerate faces are) and named with both lines. Sorting (surface, hash) keys keeps this cheap.
std::vector<std::pair<std::int64_t, std::string>> repeated_faces(const ObjScan& scan,
                                                                 const std::vector<std::uint32_t>& kept_face,
                                                                 const std::vector<std::uint32_t>& kept_surface,
                                                                 const std::vector<std::string>& surface_names) {
  auto sorted_corners = [&](std::uint32_t f) {
    const ObjFace& face = scan.faces[f];
    std::vector<std::int64_t> c(scan.corners.begin() + face.first, scan.corners.begin() + face.first + face.count);
    std::sort(c.begin(), c.end());
    return c;
  };
  struct Key {
    std::uint32_t surface;
    std::uint64_t hash;
    std::uint32_t face;
  };
  std::vector<Key> keys(kept_face.size());
  for (std::size_t k = 0; k < kept_face.size(); ++k) {
    std::uint64_t h = 1469598103934665603ull;
    for (const std::int64_t v : sorted_corners(kept_face[k])) h = (h ^ static_cast<std::uint64_t>(v)) * 1099511628211ull;
    keys[k] = {kept_surface[k], h, kept_face[k]};
  }
  std::sort(keys.begin(), keys.end(), [](const Key& a, const Key& b) {
    return std::tie(a.surface, a.hash, a.face) < std::tie(b.surface, b.hash, b.face);
  });
  std::vector<std::pair<std::int64_t, std::string>> out;
  for (std::size_t i = 1; i < keys.size(); ++i) {
    for (std::size_t j = i; j-- > 0 && keys[j].surface == keys[i].surface && keys[j].hash == keys[i].hash;) {
      if (sorted_corners(keys[j].face) != sorted_corners(keys[i].face)) continue;
      out.emplace_back(scan.faces[keys[i].face].line,
                       "face repeats the face at line " + std::to_string(scan.faces[keys[j].face].line) +
                           " of surface '" + printable_token(surface_names[keys[i].surface]) +
                           "' (a group that appears twice?); kept");
      break;
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

// The faces that survive the check against the final vertex list, as the normalised OBJ text assimp
// reads (vertex i written as its number, groups renamed s<k>), with one surface per group in order
// of its first good face; bad faces are listed and dropped, degenerate and repeated ones listed.
struct KeptFaces {
  std::string normalised;
  std::vector<std::string> surface_names;
  std::size_t count = 0;
};

KeptFaces keep_faces(const ObjScan& scan, DiagnosticCollector& diags, bool& dropped) {
  KeptFaces kept;
  std::string& normalised = kept.normalised;
  std::vector<std::string>& surface_names = kept.surface_names;
  std::size_t& kept_faces = kept.count;
  const auto nv = static_cast<std::int64_t>(scan.vertices.size());
  std::vector<std::uint32_t> surface_of_group(scan.group_names.size(), kNoGroup);
  normalised.reserve(scan.vertices.size() * 16 + scan.corners.size() * 8);
  for (std::int64_t i = 0; i < nv; ++i) {
    normalised += "v " + std::to_string(i & 0xFFFFFF) + ' ' + std::to_string(i >> 24) + " 0\n";
  }
  std::uint32_t last_surface = kNoGroup;
  std::vector<Vec3> face_points;
  std::vector<std::uint32_t> kept_face, kept_surface;  // scan.faces index and surface of each kept face
  for (const ObjFace& f : scan.faces) {
    std::string problem;
    for (std::uint32_t c = f.first; c < f.first + f.count && problem.empty(); ++c) {
      const std::int64_t v = scan.corners[c];
      if (v >= nv)
        problem = "vertex index " + std::to_string(v + 1) + " is out of range (the file has " + std::to_string(nv) +
                  " vertices)";
      else if (scan.bad_vertex_line[static_cast<std::size_t>(v)] != 0)
        problem = "it uses vertex " + std::to_string(v + 1) + ", which is bad (line " +
                  std::to_string(scan.bad_vertex_line[static_cast<std::size_t>(v)]) + ")";
    }
    if (!problem.empty()) {
      diags.add(Severity::Error, f.line, "faces dropped", "face dropped: " + problem);
      dropped = true;
      continue;
    }
    face_points.clear();
    for (std::uint32_t c = f.first; c < f.first + f.count; ++c)
      face_points.push_back(scan.vertices[static_cast<std::size_t>(scan.corners[c])]);
    if (const std::string why = degenerate_face(face_points); !why.empty())
      diags.add(Severity::Warning, f.line, "degenerate faces kept", "face " + why + "; kept");
    std::uint32_t& s = surface_of_group[f.group];
    if (s == kNoGroup) {
      s = static_cast<std::uint32_t>(surface_names.size());
      surface_names.push_back(scan.group_names[f.group]);
    }
    kept_face.push_back(static_cast<std::uint32_t>(&f - scan.faces.data()));
    kept_surface.push_back(s);
    if (s != last_surface) {
      normalised += "g s" + std::to_string(s) + '\n';
      last_surface = s;
    }
    normalised += 'f';
    for (std::uint32_t c = f.first; c < f.first + f.count; ++c) normalised += ' ' + std::to_string(scan.corners[c] + 1);
    normalised += '\n';
    ++kept_faces;
  }
  for (auto& [line, message] : repeated_faces(scan, kept_face, kept_surface, surface_names))
    diags.add(Severity::Warning, line, "repeated faces kept", std::move(message));
  return kept;
}

}  // namespace

ImportResult read_obj(const std::string& path, const ImportOptions&) {
  std::string text, error;
  if (!read_whole_file(path, text, error)) return failed_import(path, error);
  if (text.empty()) return failed_import(path, "empty file: no vertices or faces");
  if (std::int64_t line = 0; find_binary_byte(text, line)) {
    ImportResult r = failed_import(path, "binary data: not a text OBJ file");
    r.diagnostics.back().line = line;
    return r;
  }

  ImportResult result;
  DiagnosticCollector diags(path);
  bool dropped = false;
  ObjScan scan;
  scan_obj(text, scan, diags, dropped);
  text.clear();
  text.shrink_to_fit();

  KeptFaces kept = keep_faces(scan, diags, dropped);
  const std::vector<std::string>& surface_names = kept.surface_names;
  const std::size_t kept_faces = kept.count;
  std::string& normalised = kept.normalised;
  if (scan.ignored_lines_points > 0)
    diags.add(Severity::Warning, 0, "line and point elements ignored",
              std::to_string(scan.ignored_lines_points) + " line/point elements (l, p) ignored: they bound no surface");

  if (kept_faces == 0) {
    diags.add(Severity::Error, 0, "files without faces", "no usable faces: nothing to import");
    diags.flush_into(result.diagnostics);
    result.complete = false;
    return result;
  }

  Assimp::Importer importer;
  const aiScene* scene = importer.ReadFileFromMemory(normalised.data(), normalised.size(), 0, "obj");
  if (scene == nullptr || scene->mRootNode == nullptr) {
    diags.add(Severity::Error, 0, "assimp failures", std::string("assimp could not parse the file: ") + importer.GetErrorString());
    diags.flush_into(result.diagnostics);
    result.complete = false;
    return result;
  }

  // Vertex numbers come back exactly: x holds the low 24 bits, y the rest.
  const auto vertex_number = [](const aiVector3D& p) {
    return static_cast<std::uint32_t>(p.x) | (static_cast<std::uint32_t>(p.y) << 24);
  };
  std::vector<Surface>& surfaces = result.model.surfaces;
  surfaces.resize(surface_names.size());
  std::vector<std::unordered_map<std::uint32_t, std::uint32_t>> local_index(surface_names.size());
  std::vector<std::vector<std::uint64_t>> source_of_local(surface_names.size());
  std::vector<std::uint32_t> corners;
  std::size_t assimp_faces = 0, not_simple = 0;
  const auto visit = [&](const aiNode* node) {
    const std::string_view name = node->mName.C_Str();
    std::uint32_t s = kNoGroup;
    if (name.size() > 1 && name.front() == 's') {
      std::int64_t k = 0;
      if (parse_int(name.substr(1), k) && k >= 0 && static_cast<std::size_t>(k) < surfaces.size())
        s = static_cast<std::uint32_t>(k);
    }
    if (s == kNoGroup) return;
    Surface& surface = surfaces[s];
    for (unsigned mi = 0; mi < node->mNumMeshes; ++mi) {
      const aiMesh* mesh = scene->mMeshes[node->mMeshes[mi]];
      for (unsigned fi = 0; fi < mesh->mNumFaces; ++fi) {
        const aiFace& face = mesh->mFaces[fi];
        ++assimp_faces;
        corners.clear();
        for (unsigned k = 0; k < face.mNumIndices; ++k) {
          const std::uint32_t global = vertex_number(mesh->mVertices[face.mIndices[k]]);
          auto [it, inserted] =
              local_index[s].try_emplace(global, static_cast<std::uint32_t>(surface.mesh.vertices.size()));
          if (inserted) {
            surface.mesh.vertices.push_back(scan.vertices[global]);
            source_of_local[s].push_back(global);
          }
          corners.push_back(it->second);
        }
        if (corners.size() < 3) continue;  // cannot happen: the scan passed only faces with >= 3 corners
        if (!triangulate_polygon(surface.mesh.vertices, corners, surface.mesh.triangles)) ++not_simple;
      }
    }
  };
  for (unsigned c = 0; c < scene->mRootNode->mNumChildren; ++c) visit(scene->mRootNode->mChildren[c]);
  visit(scene->mRootNode);

  if (assimp_faces != kept_faces) {
    diags.add(Severity::Error, 0, "assimp failures",
              "assimp returned " + std::to_string(assimp_faces) + " faces where the file has " +
                  std::to_string(kept_faces) + " good ones");
    dropped = true;
  }
  if (not_simple > 0)
    diags.add(Severity::Warning, 0, "polygons not simple",
              std::to_string(not_simple) + " polygons are self-intersecting or without area; triangulated as well as possible");

  for (std::uint32_t s = 0; s < surfaces.size(); ++s) {
    renumber_in_source_order(surfaces[s].mesh, source_of_local[s]);
    surfaces[s].name = surface_names[s];
    surfaces[s].provenance.kind = SourceKind::ObjGroup;
    surfaces[s].provenance.source_name = surface_names[s];
    surfaces[s].provenance.face_index = static_cast<std::int32_t>(s);
  }
  finish_single_part_model(result.model, path);
  diags.flush_into(result.diagnostics);
  result.complete = !dropped && !has_error(result.diagnostics);
  return result;
}

}  // namespace cadclash::detail
