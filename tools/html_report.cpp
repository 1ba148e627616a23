// The HTML clash report: viewer/src/report.html filled with the report data and the viewer bundle.
#include "html_report.h"

#include "cli_common.h"
#include "html_path.h"

#include "cadclash/report.h"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iostream>
#include <string>
#include <string_view>
#include <vector>

namespace cadclash::cli {

#if CADCLASH_HTML_VIEWER
// Generated from viewer/ at build time (viewer/embed_assets.cmake).
extern const char* const kHtmlViewerTemplate;
extern const char* const kHtmlViewerScript;
#endif

namespace {

// Version of the data the page reads (viewer/src); bump with any incompatible change. Fields added
// to a record (the pairs' decided_by and distance_interval, the top-level "path" of --continuous)
// are compatible: the page and its data are always written together, and a reader of version 1
// ignores them.
constexpr int kHtmlDataVersion = 1;

constexpr std::string_view kTitleMarker = "<!--cadclash:title-->";
constexpr std::string_view kDataMarker = "<!--cadclash:data-->";
constexpr std::string_view kScriptMarker = "<!--cadclash:script-->";

std::string base64(const std::vector<unsigned char>& bytes) {
  static constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 3 <= bytes.size(); i += 3) {
    const std::uint32_t v = (std::uint32_t{bytes[i]} << 16) | (std::uint32_t{bytes[i + 1]} << 8) | bytes[i + 2];
    out += kAlphabet[v >> 18];
    out += kAlphabet[(v >> 12) & 63];
    out += kAlphabet[(v >> 6) & 63];
    out += kAlphabet[v & 63];
  }
  if (i < bytes.size()) {
    const bool two = i + 1 < bytes.size();
    const std::uint32_t v = (std::uint32_t{bytes[i]} << 16) | (two ? std::uint32_t{bytes[i + 1]} << 8 : 0u);
    out += kAlphabet[v >> 18];
    out += kAlphabet[(v >> 12) & 63];
    out += two ? kAlphabet[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

// Appends little-endian bytes whatever the host order, so the page's typed arrays read them alike.
void put_u32(std::vector<unsigned char>& out, std::uint32_t v) {
  for (int k = 0; k < 4; ++k) out.push_back(static_cast<unsigned char>(v >> (8 * k)));
}
void put_u16(std::vector<unsigned char>& out, std::uint32_t v) {
  out.push_back(static_cast<unsigned char>(v));
  out.push_back(static_cast<unsigned char>(v >> 8));
}
void put_f32(std::vector<unsigned char>& out, double v) {
  const float f = static_cast<float>(v);
  std::uint32_t bits;
  std::memcpy(&bits, &f, sizeof bits);
  put_u32(out, bits);
}

// One part's surfaces concatenated: positions and indices, and each surface's triangle range.
nlohmann::json part_json(const Model& m, PartId p, nlohmann::json& surfaces) {
  const Part& part = m.parts[p];
  std::size_t vertex_count = 0;
  for (SurfaceId s = part.first_surface; s < part.first_surface + part.surface_count; ++s)
    if (m.surfaces[s].has_triangles) vertex_count += m.surfaces[s].mesh.vertices.size();
  // Uint16 indices halve the biggest array whenever a part is small enough, which most parts are.
  const bool short_indices = vertex_count <= 0xFFFF;
  std::vector<unsigned char> positions, indices;
  positions.reserve(vertex_count * 12);
  std::uint32_t base = 0, triangles = 0;
  for (SurfaceId s = part.first_surface; s < part.first_surface + part.surface_count; ++s) {
    const Surface& surf = m.surfaces[s];
    nlohmann::json js = surface_json(surf);
    js["part"] = p;
    js["name"] = surf.name;
    js["first_triangle"] = triangles;
    std::uint32_t count = 0;
    if (surf.has_triangles) {
      for (const Vec3& v : surf.mesh.vertices)
        for (int k = 0; k < 3; ++k) put_f32(positions, v[k]);
      for (const std::array<std::uint32_t, 3>& t : surf.mesh.triangles)
        for (std::uint32_t i : t) short_indices ? put_u16(indices, base + i) : put_u32(indices, base + i);
      base += static_cast<std::uint32_t>(surf.mesh.vertices.size());
      count = static_cast<std::uint32_t>(surf.mesh.triangles.size());
    }
    js["triangle_count"] = count;
    triangles += count;
    surfaces.push_back(std::move(js));
  }
  return {{"name", part.name},
          {"first_surface", part.first_surface},
          {"surface_count", part.surface_count},
          {"vertex_count", base},
          {"triangle_count", triangles},
          {"index_bytes", short_indices ? 2 : 4},
          {"positions", base64(positions)},
          {"indices", base64(indices)}};
}

nlohmann::json signed_id(std::uint32_t id) {
  return id == kInvalidId ? nlohmann::json(-1) : nlohmann::json(id);
}

nlohmann::json data_json(const Model& m, std::span<const Pose> poses, const Report& r, const nlohmann::json& meta,
                         const HtmlPath* path) {
  nlohmann::json j{{"schema", "cadclash-html-report"}, {"version", kHtmlDataVersion}};
  for (const char* key : {"settings", "summary"}) j[key] = meta.value(key, nlohmann::json::object());
  j["files"] = meta.value("files", nlohmann::json::array());
  j["diagnostics"] = meta.value("diagnostics", nlohmann::json::array());
  // The clash review (cadclash/review.h), for the page's clash list: absent for a trajectory.
  if (meta.contains("clashes")) j["clashes"] = meta["clashes"];
  if (meta.contains("review")) j["review"] = meta["review"];
  // A partial report (bad input dropped, or a budget ran out) must say so on the page too.
  j["complete"] = meta.value("complete", true);
  j["stopped_by"] = meta.value("stopped_by", nlohmann::json(nullptr));
  nlohmann::json parts = nlohmann::json::array(), surfaces = nlohmann::json::array();
  for (PartId p = 0; p < m.parts.size(); ++p) parts.push_back(part_json(m, p, surfaces));
  nlohmann::json instances = nlohmann::json::array();
  for (InstanceId i = 0; i < m.instances.size(); ++i) {
    const Eigen::Matrix4d t = poses[i].matrix();
    std::vector<double> columns(t.data(), t.data() + 16);  // Eigen is column-major, like three.js
    instances.push_back({{"path", m.instances[i].path}, {"part", m.instances[i].part}, {"matrix", columns}});
  }
  // The JSON report's pair fields (cadclash/report.h), with ids in place of the sides.
  const QueryReport q = query_report(m, r);
  nlohmann::json pairs = nlohmann::json::array();
  for (std::size_t k = 0; k < r.pairs.size(); ++k) {
    const SurfacePairResult& p = r.pairs[k];
    nlohmann::json jp = pair_json(q.pairs[k], /*sides=*/false);
    jp["instance_a"] = p.instance_a;
    jp["instance_b"] = p.instance_b;
    jp["surface_a"] = signed_id(p.surface_a);
    jp["surface_b"] = signed_id(p.surface_b);
    // ε of each side and where it came from (the report's side fields, which the page does not carry).
    for (const auto& [key, side] : {std::pair{"a", &q.pairs[k].a}, std::pair{"b", &q.pairs[k].b}}) {
      if (side->whole_part) continue;
      jp[std::string("uncertainty_") + key] = side->uncertainty;
      if (side->uncertainty_source)
        jp[std::string("uncertainty_source_") + key] = uncertainty_source_name(*side->uncertainty_source);
    }
    pairs.push_back(std::move(jp));
  }
  j["parts"] = std::move(parts);
  j["surfaces"] = std::move(surfaces);
  j["instances"] = std::move(instances);
  j["pairs"] = std::move(pairs);
  // Only a path checked continuously has a timeline to play: without it the page has no slider.
  if (path != nullptr) j["path"] = path_json(*path);
  return j;
}

// JSON inside <script>: '<' only occurs in strings, where \u003c means the same and can never
// close the element or open a comment.
std::string script_safe_json(const nlohmann::json& j) {
  const std::string text = j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    if (c == '<') out += "\\u003c";
    else out += c;
  }
  return out;
}

std::string html_escape(std::string_view text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

}  // namespace

bool html_report_available() { return CADCLASH_HTML_VIEWER != 0; }

bool write_html_report(std::ostream& os, const Model& model, std::span<const Pose> poses, const Report& report,
                       const nlohmann::json& meta, const HtmlPath* path) {
#if CADCLASH_HTML_VIEWER
  const std::string_view page = kHtmlViewerTemplate;
  std::string title;
  for (const nlohmann::json& f : meta.value("files", nlohmann::json::array()))
    if (f.is_string()) title += (title.empty() ? "" : ", ") + f.get<std::string>();
  const nlohmann::json data = data_json(model, poses, report, meta, path);
  // The template holds each marker once, in this order (viewer/src/report.html).
  const std::size_t t = page.find(kTitleMarker), d = page.find(kDataMarker), s = page.find(kScriptMarker);
  os << page.substr(0, t) << html_escape(title);
  os << page.substr(t + kTitleMarker.size(), d - t - kTitleMarker.size()) << script_safe_json(data);
  os << page.substr(d + kDataMarker.size(), s - d - kDataMarker.size()) << kHtmlViewerScript;
  os << page.substr(s + kScriptMarker.size());
  os.flush();
  return static_cast<bool>(os);
#else
  (void)os, (void)model, (void)poses, (void)report, (void)meta, (void)path;
  return false;
#endif
}

bool save_html_report(const std::string& path, Model& model, const Scene& scene, const Report& report,
                      const nlohmann::json& meta, const HtmlPath* motion) {
  std::vector<SurfaceId> missing;
  for (SurfaceId s = 0; s < model.surfaces.size(); ++s)
    if (!model.surfaces[s].has_triangles) missing.push_back(s);
  if (!missing.empty()) print_diagnostics(require_triangles(model, missing, 0.0));
  std::vector<Pose> poses;
  poses.reserve(model.instances.size());
  for (InstanceId i = 0; i < model.instances.size(); ++i) poses.push_back(scene.pose(i));
  std::ofstream f(path, std::ios::binary);
  if (!f || !write_html_report(f, model, poses, report, meta, motion)) {
    std::cerr << path << ": error: cannot write the HTML report\n";
    return false;
  }
  return true;
}

}  // namespace cadclash::cli
