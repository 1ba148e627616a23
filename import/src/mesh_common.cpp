#include "mesh_common.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <cstdlib>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <system_error>

namespace cadclash::detail {

bool read_whole_file(const std::string& path, std::string& out, std::string& error) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    error = "no such file";
    return false;
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    error = "cannot open the file for reading";
    return false;
  }
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  in.seekg(0, std::ios::beg);
  if (size < 0) {
    error = "cannot determine the file size";
    return false;
  }
  out.resize(static_cast<std::size_t>(size));
  if (size > 0 && !in.read(out.data(), size)) {
    error = "read error";
    return false;
  }
  return true;
}

std::string file_stem(const std::string& path) { return std::filesystem::path(path).stem().string(); }

bool LineReader::next(std::string_view& line) {
  if (pos_ >= text_.size()) return false;
  const std::size_t end = text_.find_first_of("\r\n", pos_);
  ++line_;
  if (end == std::string_view::npos) {
    line = text_.substr(pos_);
    pos_ = text_.size();
    return true;
  }
  line = text_.substr(pos_, end - pos_);
  pos_ = end + 1;
  if (text_[end] == '\r' && pos_ < text_.size() && text_[pos_] == '\n') ++pos_;
  return true;
}

void split_tokens(std::string_view line, std::vector<std::string_view>& tokens) {
  tokens.clear();
  std::size_t i = 0;
  const auto is_space = [](char c) { return c == ' ' || c == '\t' || c == '\v' || c == '\f' || c == '\r'; };
  while (i < line.size()) {
    while (i < line.size() && is_space(line[i])) ++i;
    const std::size_t start = i;
    while (i < line.size() && !is_space(line[i])) ++i;
    if (i > start) tokens.push_back(line.substr(start, i - start));
  }
}

const std::string kOutsideRange = "outside the supported range (magnitude <= 2^128, about 3.4e38 mm)";

std::string printable_number(double x) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", x);
  return buf;
}

NumberStatus parse_double(std::string_view token, double& value) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  const char* first = token.data();
  const char* last = token.data() + token.size();
  const auto [ptr, ec] = std::from_chars(first, last, value);
  if (ec == std::errc::result_out_of_range) {
    // from_chars reports overflow and underflow alike; strtod tells them apart (underflow is finite).
    if (ptr != last) return NumberStatus::Invalid;
    value = std::strtod(std::string(token).c_str(), nullptr);
    return std::isfinite(value) ? NumberStatus::Ok : NumberStatus::NotFinite;
  }
  if (ec != std::errc{} || ptr != last || token.empty()) return NumberStatus::Invalid;
  return std::isfinite(value) ? NumberStatus::Ok : NumberStatus::NotFinite;
}

bool parse_int(std::string_view token, std::int64_t& value) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  const auto [ptr, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  return ec == std::errc{} && ptr == token.data() + token.size() && !token.empty();
}

std::string printable_token(std::string_view token) { return printable_text(token.substr(0, 32)); }

std::string printable_text(std::string_view text) {
  static const char* const hex = "0123456789ABCDEF";
  std::string out;
  for (const char c : text) {
    const auto byte = static_cast<unsigned char>(c);
    if (byte >= 0x20 && byte < 0x7F) {
      out += c;
    } else {
      out += "\\x";
      out += hex[byte >> 4];
      out += hex[byte & 0xF];
    }
  }
  return out;
}

bool find_binary_byte(std::string_view text, std::int64_t& line) {
  std::int64_t current = 1;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c == '\n') {
      ++current;
    } else if (c == '\r') {
      if (i + 1 < text.size() && text[i + 1] == '\n') ++i;
      ++current;
    } else if (c < 0x20 && c != '\t' && c != '\v' && c != '\f') {
      line = current;
      return true;
    } else if (c == 0x7f) {
      line = current;
      return true;
    }
  }
  return false;
}

void DiagnosticCollector::add(Severity severity, std::int64_t line, const std::string& category, std::string message) {
  Category& c = categories_[category];
  if (severity == Severity::Error) {
    ++errors_;
    c.severity = Severity::Error;
  }
  if (c.listed < cap_) {
    ++c.listed;
    listed_.push_back({severity, file_, line, -1, std::move(message)});
  } else {
    ++c.unlisted;
  }
}

void DiagnosticCollector::flush_into(std::vector<Diagnostic>& out) {
  out.insert(out.end(), std::make_move_iterator(listed_.begin()), std::make_move_iterator(listed_.end()));
  listed_.clear();
  for (auto& [category, c] : categories_) {
    if (c.unlisted == 0) continue;
    out.push_back({c.severity, file_, 0, -1,
                   "... and " + std::to_string(c.unlisted) + " more " + category + " not listed"});
    c.unlisted = 0;
  }
}

void renumber_in_source_order(TriangleMesh& mesh, std::vector<std::uint64_t>& source_of_local) {
  const std::size_t n = mesh.vertices.size();
  std::vector<std::uint32_t> order(n);
  for (std::uint32_t i = 0; i < n; ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return source_of_local[a] < source_of_local[b]; });
  std::vector<std::uint32_t> new_index(n);
  std::vector<Vec3> vertices(n);
  for (std::uint32_t k = 0; k < n; ++k) {
    new_index[order[k]] = k;
    vertices[k] = mesh.vertices[order[k]];
  }
  mesh.vertices = std::move(vertices);
  for (auto& t : mesh.triangles)
    for (std::uint32_t& v : t) v = new_index[v];
  source_of_local.clear();
}

void finish_single_part_model(Model& model, const std::string& path) {
  Part part;
  part.name = file_stem(path);
  part.source_file = path;
  part.first_surface = 0;
  part.surface_count = static_cast<std::uint32_t>(model.surfaces.size());
  for (Surface& s : model.surfaces) {
    s.part = 0;
    s.provenance.source_file = path;
    s.has_triangles = true;
    s.aabb = mesh_aabb(s.mesh);
  }
  model.parts.push_back(std::move(part));
  Instance instance;
  instance.path = "/" + model.parts.back().name;
  instance.part = 0;
  model.instances.push_back(std::move(instance));
}

std::string degenerate_face(std::span<const Vec3> c) {
  const std::size_t n = c.size();
  for (std::size_t k = 0; k < n; ++k)
    if (c[k] == c[(k + 1) % n])
      return "has a zero-length edge (corners " + std::to_string(k + 1) + " and " + std::to_string((k + 1) % n + 1) +
             " are the same point)";
  if (n < 3) return {};
  // Exact (CGAL's filtered predicate): a float cross product underflows to zero for faces of 1e-160
  // mm and less, which have area.
  using K = CGAL::Exact_predicates_inexact_constructions_kernel;
  const auto point = [](const Vec3& v) { return K::Point_3(v.x(), v.y(), v.z()); };
  const K::Point_3 p0 = point(c[0]), p1 = point(c[1]);  // distinct: no zero-length edge
  for (std::size_t k = 2; k < n; ++k)
    if (!CGAL::collinear(p0, p1, point(c[k]))) return {};
  return "has zero area (its corners are collinear)";
}

}  // namespace cadclash::detail
