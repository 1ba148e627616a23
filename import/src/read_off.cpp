// OFF: one surface per distinct face colour, read through CGAL.
//
// CGAL::IO::read_OFF reports only true/false, sizes its arrays from the header before reading (a
// damaged header count can ask for any amount of memory), drops the colour of faces that have none
// (so colours no longer line up with faces), and guesses 0..1 versus 0..255 colours from the values.
// So our scan goes first: it checks the header counts against the content, gives line numbers,
// parses each face's colour from its text (a '.' or exponent means floats in 0..1, otherwise integers
// in 0..255, as Geomview defines), and drops bad faces. CGAL then reads a normalised copy holding the
// good vertices (round-trip exact decimal text) and faces, into a polygon soup in double precision.
#include "mesh_common.h"
#include "mesh_polygon.h"
#include "readers.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/IO/OFF.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <optional>
#include <sstream>
#include <unordered_map>

namespace cadclash::detail {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;

struct OffHeader {
  bool texture = false, colour = false, normals = false, homogeneous = false;
};

// "[ST][C][N][4][n]OFF"; false if `word` is not an OFF keyword.
bool parse_off_keyword(std::string_view word, OffHeader& h, bool& n_dimension) {
  if (word.size() < 3 || word.substr(word.size() - 3) != "OFF") return false;
  word.remove_suffix(3);
  n_dimension = false;
  if (word.starts_with("ST")) h.texture = true, word.remove_prefix(2);
  if (word.starts_with("C")) h.colour = true, word.remove_prefix(1);
  if (word.starts_with("N")) h.normals = true, word.remove_prefix(1);
  if (word.starts_with("4")) h.homogeneous = true, word.remove_prefix(1);
  if (word.starts_with("n")) n_dimension = true, word.remove_prefix(1);
  return word.empty();
}

bool looks_like_float(std::string_view t) { return t.find_first_of(".eE") != std::string_view::npos; }

std::string hex_byte(int v) {
  static constexpr char kDigits[] = "0123456789ABCDEF";
  return {kDigits[(v >> 4) & 15], kDigits[v & 15]};
}

void append_double(std::string& out, double v) {
  char buf[32];
  const auto [ptr, ec] = std::to_chars(buf, buf + sizeof buf, v);
  (void)ec;
  out.append(buf, ptr);
}

// The face colour key and value parsed from the tokens after the indices. Empty key: no colour.
struct FaceColour {
  std::string key;
  std::optional<std::array<float, 3>> rgb;
};

bool parse_face_colour(std::span<const std::string_view> t, FaceColour& out, std::string& problem) {
  if (t.empty()) return true;
  if (t.size() == 1) {
    std::int64_t index = 0;
    if (!parse_int(t[0], index) || index < 0) {
      problem = "colour map index '" + printable_token(t[0]) + "' is not a non-negative integer";
      return false;
    }
    out.key = "colour-index-" + std::to_string(index);
    return true;
  }
  if (t.size() != 3 && t.size() != 4) {
    problem = "a face colour has 1, 3 or 4 components, found " + std::to_string(t.size());
    return false;
  }
  const bool floats = looks_like_float(t[0]) || looks_like_float(t[1]) || looks_like_float(t[2]);
  std::array<float, 3> rgb{};
  std::string key = "colour-";
  for (std::size_t c = 0; c < 3; ++c) {
    double v = 0;
    if (parse_double(t[c], v) != NumberStatus::Ok) {
      problem = "colour component '" + printable_token(t[c]) + "' is not a finite number";
      return false;
    }
    const double unit = std::clamp(floats ? v : v / 255.0, 0.0, 1.0);
    rgb[c] = static_cast<float>(unit);
    key += hex_byte(static_cast<int>(std::lround(unit * 255.0)));
  }
  out.key = std::move(key);
  out.rgb = rgb;
  return true;
}

struct OffFace {
  std::int64_t line;
  std::vector<std::uint32_t> corners;
  std::uint32_t group;
};

// The file's content lines as tokens (comments removed), and failures naming a line.
struct OffScanner {
  const std::string& path;
  LineReader lines;
  std::string_view raw;
  std::vector<std::string_view> tokens;

  // Next line with content; false at the end.
  bool next_tokens() {
    while (lines.next(raw)) {
      split_tokens(raw.substr(0, raw.find('#')), tokens);
      if (!tokens.empty()) return true;
    }
    return false;
  }
  ImportResult fail_at(std::int64_t line, std::string message) const {
    ImportResult r = failed_import(path, std::move(message));
    r.diagnostics.back().line = line;
    return r;
  }
};

// The `nv` vertices the header announced (`counts_line`): a bad one is kept as a placeholder with its
// line in `bad_vertex_line` (faces using it are dropped); a file that ends early or turns to faces
// fails the import (the returned result).
std::optional<ImportResult> read_vertices(OffScanner& sc, const OffHeader& header, std::int64_t nv,
                                          std::int64_t counts_line, DiagnosticCollector& diags,
                                          std::vector<Vec3>& vertices, std::vector<std::int64_t>& bad_vertex_line) {
  const std::vector<std::string_view>& tokens = sc.tokens;
  const std::size_t coords = header.homogeneous ? 4 : 3;
  std::size_t first_vertex_tokens = 0;
  for (std::int64_t i = 0; i < nv; ++i) {
    if (!sc.next_tokens())
      return sc.fail_at(sc.lines.line_number(), "truncated: the header (line " + std::to_string(counts_line) + ") announces " +
                                              std::to_string(nv) + " vertices but the file ends after " +
                                              std::to_string(i));
    if (i == 0) first_vertex_tokens = tokens.size();
    const std::int64_t line_no = sc.lines.line_number();
    // A line of integers that reads as "n i1 .. in [colour]" where a vertex is expected means the
    // header announced more vertices than the file has.
    if (i > 0 && tokens.size() != first_vertex_tokens) {
      std::int64_t n = 0, dummy = 0;
      const bool integers = std::all_of(tokens.begin(), tokens.end(), [&](std::string_view t) { return parse_int(t, dummy); });
      if (integers && parse_int(tokens[0], n) && n >= 1 && static_cast<std::size_t>(n) + 1 <= tokens.size())
        return sc.fail_at(line_no, "expected vertex " + std::to_string(i + 1) + " of " + std::to_string(nv) +
                                    " but found a face: the vertex count in the header (line " +
                                    std::to_string(counts_line) + ") is larger than the file's");
    }
    Vec3 p = Vec3::Zero();
    std::int64_t bad = 0;
    if (tokens.size() < coords) {
      diags.add(Severity::Error, line_no, "bad vertices",
                "malformed vertex " + std::to_string(i) + ": expected " + std::to_string(coords) + " coordinates, found " +
                    std::to_string(tokens.size()));
      bad = line_no;
    } else {
      double w = 1.0;
      for (std::size_t c = 0; c < coords && bad == 0; ++c) {
        double v = 0;
        const NumberStatus st = parse_double(tokens[c], v);
        if (st != NumberStatus::Ok) {
          diags.add(Severity::Error, line_no, "bad vertices",
                    "vertex " + std::to_string(i) +
                        (st == NumberStatus::NotFinite ? " has a coordinate that is not finite ('" : ": '") +
                        printable_token(tokens[c]) + (st == NumberStatus::NotFinite ? "')" : "' is not a number"));
          bad = line_no;
        } else if (c < 3) {
          p[static_cast<int>(c)] = v;
        } else {
          w = v;
        }
      }
      if (bad == 0 && header.homogeneous) {
        if (w == 0.0 || !std::isfinite((p / w).squaredNorm())) {
          diags.add(Severity::Error, line_no, "bad vertices", "vertex " + std::to_string(i) + " has homogeneous weight 0");
          bad = line_no;
        } else {
          p /= w;
        }
      }
      for (int c = 0; c < 3 && bad == 0; ++c)
        if (!in_supported_range(p[c])) {
          diags.add(Severity::Error, line_no, "bad vertices",
                    "vertex " + std::to_string(i) + " has a coordinate " + kOutsideRange + " (" + printable_number(p[c]) + ")");
          bad = line_no;
        }
    }
    vertices.push_back(bad ? Vec3::Zero() : p);
    bad_vertex_line.push_back(bad);
  }
  return std::nullopt;
}

// The `nf` faces: one colour group per distinct colour (groups in order of first use); a bad face is
// listed and dropped (`dropped`), as are missing faces and trailing data.
void read_faces(OffScanner& sc, std::int64_t nf, std::int64_t nv, std::int64_t counts_line,
                const std::vector<Vec3>& vertices, const std::vector<std::int64_t>& bad_vertex_line,
                DiagnosticCollector& diags, std::vector<OffFace>& faces, std::vector<FaceColour>& groups, bool& dropped) {
  const std::vector<std::string_view>& tokens = sc.tokens;
  std::unordered_map<std::string, std::uint32_t> group_of_key;
  std::int64_t faces_read = 0;
  for (; faces_read < nf; ++faces_read) {
    if (!sc.next_tokens()) break;
    const std::int64_t line_no = sc.lines.line_number();
    std::int64_t n = 0;
    std::string problem;
    OffFace face{line_no, {}, 0};
    if (!parse_int(tokens[0], n) || n < 0) {
      // Appended, not "'" + string: GCC 12 warns wrongly (-Wrestrict, bug 105329) on that at -O2.
      problem.append("'").append(printable_token(tokens[0])).append("' is not a corner count");
    } else if (n < 3) {
      problem = "a face needs at least 3 vertices, found " + std::to_string(n);
    } else if (tokens.size() < static_cast<std::size_t>(n) + 1) {
      problem = "the face announces " + std::to_string(n) + " vertices but lists " + std::to_string(tokens.size() - 1);
    } else {
      for (std::int64_t k = 1; k <= n && problem.empty(); ++k) {
        std::int64_t index = 0;
        if (!parse_int(tokens[static_cast<std::size_t>(k)], index))
          problem = "'" + printable_token(tokens[static_cast<std::size_t>(k)]) + "' is not a vertex index";
        else if (index < 0 || index >= nv)
          problem = "vertex index " + std::to_string(index) + " is out of range (the file has " + std::to_string(nv) +
                    " vertices, numbered from 0)";
        else if (bad_vertex_line[static_cast<std::size_t>(index)] != 0)
          problem = "it uses vertex " + std::to_string(index) + ", which is bad (line " +
                    std::to_string(bad_vertex_line[static_cast<std::size_t>(index)]) + ")";
        else
          face.corners.push_back(static_cast<std::uint32_t>(index));
      }
    }
    FaceColour colour;
    if (problem.empty()) {
      const auto extra = std::span<const std::string_view>(tokens).subspan(static_cast<std::size_t>(n) + 1);
      parse_face_colour(extra, colour, problem);
    }
    if (!problem.empty()) {
      diags.add(Severity::Error, line_no, "faces dropped", "face " + std::to_string(faces_read) + " dropped: " + problem);
      dropped = true;
      continue;
    }
    if (colour.key.empty()) colour.key = "uncoloured";
    auto [it, inserted] = group_of_key.try_emplace(colour.key, static_cast<std::uint32_t>(groups.size()));
    if (inserted) groups.push_back(colour);
    face.group = it->second;
    std::vector<Vec3> points;
    for (std::uint32_t v : face.corners) points.push_back(vertices[v]);
    if (const std::string why = degenerate_face(points); !why.empty())
      diags.add(Severity::Warning, line_no, "degenerate faces kept", "face " + std::to_string(faces_read) + " " + why + "; kept");
    faces.push_back(std::move(face));
  }
  if (faces_read < nf) {
    diags.add(Severity::Error, sc.lines.line_number(), "truncated files",
              "truncated: the header (line " + std::to_string(counts_line) + ") announces " + std::to_string(nf) +
                  " faces but the file ends after " + std::to_string(faces_read));
    dropped = true;
  } else if (sc.next_tokens()) {
    diags.add(Severity::Error, sc.lines.line_number(), "trailing data",
              "data after the " + std::to_string(nf) + " faces the header (line " + std::to_string(counts_line) +
                  ") announces: its counts are probably wrong; the rest is ignored");
    dropped = true;
  }
}

// The validated vertices and faces through CGAL's OFF reader into one surface per colour group of
// `model`; false when CGAL cannot read them (listed).
bool build_surfaces(const std::vector<Vec3>& vertices, const std::vector<OffFace>& faces,
                    const std::vector<FaceColour>& groups, DiagnosticCollector& diags, Model& model) {
  // CGAL reads the normalised copy.
  std::string normalised = "OFF\n" + std::to_string(vertices.size()) + ' ' + std::to_string(faces.size()) + " 0\n";
  for (const Vec3& p : vertices) {
    for (int c = 0; c < 3; ++c) {
      append_double(normalised, p[c]);
      normalised += c < 2 ? ' ' : '\n';
    }
  }
  for (const OffFace& f : faces) {
    normalised += std::to_string(f.corners.size());
    for (std::uint32_t v : f.corners) normalised += ' ' + std::to_string(v);
    normalised += '\n';
  }
  std::vector<Kernel::Point_3> points;
  std::vector<std::vector<std::size_t>> polygons;
  std::istringstream in(std::move(normalised));
  const bool ok = CGAL::IO::read_OFF(in, points, polygons, CGAL::parameters::verbose(false));
  if (!ok || points.size() != vertices.size() || polygons.size() != faces.size()) {
    diags.add(Severity::Error, 0, "CGAL failures", "CGAL could not read the validated OFF data");
    return false;
  }

  std::vector<Surface>& surfaces = model.surfaces;
  surfaces.resize(groups.size());
  std::vector<std::unordered_map<std::size_t, std::uint32_t>> local_index(groups.size());
  std::vector<std::vector<std::uint64_t>> source_of_local(groups.size());
  std::vector<std::uint32_t> corners;
  std::size_t not_simple = 0;
  for (std::size_t fi = 0; fi < polygons.size(); ++fi) {
    const std::uint32_t s = faces[fi].group;
    TriangleMesh& mesh = surfaces[s].mesh;
    corners.clear();
    for (std::size_t v : polygons[fi]) {
      auto [it, inserted] = local_index[s].try_emplace(v, static_cast<std::uint32_t>(mesh.vertices.size()));
      if (inserted) {
        mesh.vertices.emplace_back(points[v].x(), points[v].y(), points[v].z());
        source_of_local[s].push_back(v);
      }
      corners.push_back(it->second);
    }
    if (!triangulate_polygon(mesh.vertices, corners, mesh.triangles)) ++not_simple;
  }
  if (not_simple > 0)
    diags.add(Severity::Warning, 0, "polygons not simple",
              std::to_string(not_simple) + " polygons are self-intersecting or without area; triangulated as well as possible");

  for (std::uint32_t s = 0; s < surfaces.size(); ++s) {
    renumber_in_source_order(surfaces[s].mesh, source_of_local[s]);
    surfaces[s].name = groups[s].key;
    surfaces[s].provenance.kind = SourceKind::OffColourGroup;
    surfaces[s].provenance.source_name = groups[s].key;
    surfaces[s].provenance.face_index = static_cast<std::int32_t>(s);
    surfaces[s].provenance.colour = groups[s].rgb;
  }
  return true;
}

}  // namespace

ImportResult read_off(const std::string& path, const ImportOptions&) {
  std::string text, error;
  if (!read_whole_file(path, text, error)) return failed_import(path, error);
  if (text.empty()) return failed_import(path, "empty file: no OFF header");
  OffScanner sc{path, LineReader(text), {}, {}};
  const std::vector<std::string_view>& tokens = sc.tokens;

  // Header keyword, then the counts (possibly on the same line).
  if (!sc.next_tokens()) return sc.fail_at(sc.lines.line_number(), "no OFF header: the file holds only comments or blanks");
  OffHeader header;
  bool n_dimension = false;
  if (!parse_off_keyword(tokens[0], header, n_dimension))
    return sc.fail_at(sc.lines.line_number(), "not an OFF file: the first word is not an OFF keyword ('" +
                                            printable_token(tokens[0]) + "')");
  if (tokens.size() > 1 && tokens[1] == "BINARY") return sc.fail_at(sc.lines.line_number(), "binary OFF is not supported");
  if (std::int64_t line = 0; find_binary_byte(text, line)) return sc.fail_at(line, "binary data: not a text OFF file");
  std::vector<std::string_view> counts(tokens.begin() + 1, tokens.end());
  if (n_dimension) {
    if (counts.empty() && sc.next_tokens()) counts = tokens;
    std::int64_t dim = 0;
    if (counts.empty() || !parse_int(counts[0], dim) || dim != 3)
      return sc.fail_at(sc.lines.line_number(), "only 3-dimensional nOFF files are supported");
    counts.erase(counts.begin());
  }
  if (counts.empty()) {
    if (!sc.next_tokens()) return sc.fail_at(sc.lines.line_number(), "truncated: the file ends before the vertex and face counts");
    counts = tokens;
  }
  const std::int64_t counts_line = sc.lines.line_number();
  std::int64_t nv = 0, nf = 0;
  if (counts.size() < 2 || !parse_int(counts[0], nv) || !parse_int(counts[1], nf) || nv < 0 || nf < 0)
    return sc.fail_at(counts_line, "malformed counts: expected 'vertices faces [edges]' as non-negative integers");

  ImportResult result;
  DiagnosticCollector diags(path);
  bool dropped = false;

  // Vertices. Nothing is reserved from the header: a wrong count must not allocate.
  std::vector<Vec3> vertices;
  std::vector<std::int64_t> bad_vertex_line;
  if (auto failed = read_vertices(sc, header, nv, counts_line, diags, vertices, bad_vertex_line)) return std::move(*failed);
  std::vector<OffFace> faces;
  std::vector<FaceColour> groups;
  read_faces(sc, nf, nv, counts_line, vertices, bad_vertex_line, diags, faces, groups, dropped);
  if (faces.empty()) {
    diags.add(Severity::Error, 0, "files without faces", "no usable faces: nothing to import");
    diags.flush_into(result.diagnostics);
    result.complete = false;
    return result;
  }

  if (!build_surfaces(vertices, faces, groups, diags, result.model)) {
    diags.flush_into(result.diagnostics);
    result.complete = false;
    return result;
  }
  finish_single_part_model(result.model, path);
  diags.flush_into(result.diagnostics);
  result.complete = !dropped && !has_error(result.diagnostics);
  return result;
}

}  // namespace cadclash::detail
