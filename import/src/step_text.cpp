// Checks and corrections of a STEP file's text before OCCT parses it (step_text.h says why).
#include "step_text.h"

#include "mesh_common.h"
#include "step_statements.h"

#include <algorithm>
#include <cctype>
#include <string_view>
#include <unordered_map>
#include <unordered_set>

namespace cadclash::detail {
namespace {

// The FILE_SCHEMA names of the header and the line they are on; empty when there is none.
std::pair<std::vector<std::string>, std::int64_t> header_schemas(const std::string& text) {
  const std::string header = text.substr(0, 64 * 1024);
  const std::size_t at = header.find("FILE_SCHEMA");
  if (at == std::string::npos) return {{}, 0};
  const auto line = 1 + std::count(header.begin(), header.begin() + static_cast<std::ptrdiff_t>(at), '\n');
  const std::size_t end = header.find(';', at);
  std::vector<std::string> names;
  const std::string list = header.substr(at, end == std::string::npos ? std::string::npos : end - at);
  for (std::size_t q = list.find('\''); q != std::string::npos;) {
    const std::size_t close = list.find('\'', q + 1);
    if (close == std::string::npos) break;
    names.push_back(list.substr(q + 1, close - q - 1));
    q = list.find('\'', close + 1);
  }
  return {names, line};
}

bool known_schema(std::string name) {
  std::transform(name.begin(), name.end(), name.begin(), [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  for (const char* prefix : {"AUTOMOTIVE_DESIGN", "CONFIG_CONTROL_DESIGN", "CONFIGURATION_CONTROL_3D_DESIGN",
                             "AP203_CONFIGURATION_CONTROLLED", "AP214", "AP242_MANAGED_MODEL_BASED_3D_ENGINEERING",
                             "AP209_MULTIDISCIPLINARY", "STRUCTURAL_ANALYSIS_DESIGN"})
    if (name.rfind(prefix, 0) == 0) return true;
  return false;
}

// The entity id after the '#' at text[i], or -1 when no digit follows; advances i past the digits.
std::int64_t read_id(const std::string& text, std::size_t& i) {
  std::int64_t id = 0;
  std::size_t j = i + 1;
  while (j < text.size() && std::isdigit(static_cast<unsigned char>(text[j])) && id < (std::int64_t{1} << 50))
    id = id * 10 + (text[j++] - '0');
  const bool any = j > i + 1;
  i = j;
  return any ? id : -1;
}

// The ids the DATA section (from `data`) defines: "#N =" at the start of a statement, outside strings.
std::unordered_set<std::int64_t> defined_ids(const std::string& text, std::size_t data) {
  std::unordered_set<std::int64_t> defined;
  bool in_string = false, statement_start = true;
  for (std::size_t i = data + 5; i < text.size();) {
    const char c = text[i];
    if (in_string) {
      in_string = c != '\'';  // '' inside a string closes and reopens it: same result
      ++i;
    } else if (c == '\'') {
      in_string = true;
      statement_start = false;
      ++i;
    } else if (c == '#' && statement_start) {
      std::size_t j = i;
      const std::int64_t id = read_id(text, j);
      while (j < text.size() && std::isspace(static_cast<unsigned char>(text[j]))) ++j;
      if (id >= 0 && j < text.size() && text[j] == '=') defined.insert(id);
      statement_start = false;
      i = j;
    } else {
      if (c == ';') statement_start = true;
      else if (!std::isspace(static_cast<unsigned char>(c))) statement_start = false;
      ++i;
    }
  }
  return defined;
}

}  // namespace

std::vector<Diagnostic> unknown_schemas(const std::string& text, const std::string& path) {
  std::vector<Diagnostic> out;
  const auto [schemas, schema_line] = header_schemas(text);
  for (const std::string& schema : schemas)
    if (!known_schema(schema))
      out.push_back({Severity::Error, path, schema_line, -1,
                     "FILE_SCHEMA '" + printable_token(schema) +
                         "' is not a STEP AP203/AP214/AP242 schema; read as AP214 anyway"});
  return out;
}

std::optional<std::pair<std::string, std::int64_t>> close_truncated(const std::string& source) {
  if (source.find("END-ISO-10303-21") != std::string::npos) return std::nullopt;
  const std::size_t data = source.find("DATA;");
  if (data == std::string::npos) return std::nullopt;
  std::string text = source;
  std::size_t cut = text.rfind(");", std::string::npos);
  while (cut != std::string::npos && cut > data) {
    const std::size_t after = cut + 2;
    if (after >= text.size() || text[after] == '\n' || text[after] == '\r') break;
    cut = cut == 0 ? std::string::npos : text.rfind(");", cut - 1);
  }
  if (cut == std::string::npos || cut < data) cut = data + 3;  // keep "DATA;" only
  text.resize(cut + 2);
  const auto line = 1 + std::count(text.begin(), text.end(), '\n');
  text += "\nENDSEC;\nEND-ISO-10303-21;\n";
  return std::make_pair(std::move(text), static_cast<std::int64_t>(line));
}

std::optional<UnsetReferences> unset_undefined_references(const std::string& text, const std::string& path) {
  const std::size_t data = text.find("DATA;");
  if (data == std::string::npos) return std::nullopt;
  const std::unordered_set<std::int64_t> defined = defined_ids(text, data);
  // Copy the text, unsetting references to ids not defined.
  UnsetReferences out;
  out.text.reserve(text.size());
  out.text.append(text, 0, data + 5);
  std::int64_t line = 1 + std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(data + 5), '\n');
  std::int64_t current = -1;  // the entity being read
  std::size_t unset = 0;
  bool in_string = false, statement_start = true;
  for (std::size_t i = data + 5; i < text.size();) {
    const char c = text[i];
    if (c == '\n') ++line;
    if (in_string || c == '\'') {
      in_string = in_string ? c != '\'' : true;
      statement_start = false;
      out.text += c;
      ++i;
      continue;
    }
    if (c != '#') {
      if (c == ';') statement_start = true;
      else if (!std::isspace(static_cast<unsigned char>(c))) statement_start = false;
      out.text += c;
      ++i;
      continue;
    }
    const std::size_t begin = i;
    const std::int64_t id = read_id(text, i);
    if (statement_start || id < 0 || defined.count(id) > 0) {
      if (statement_start) current = id;
      out.text.append(text, begin, i - begin);
    } else {
      out.text += '$';
      if (++unset <= 20)
        out.diagnostics.push_back({Severity::Error, path, line, current,
                                   "reference to #" + std::to_string(id) +
                                       " is unresolved: the file defines no such entity; read as unset"});
    }
    statement_start = false;
  }
  if (unset == 0) return std::nullopt;
  if (unset > 20)
    out.diagnostics.push_back({Severity::Error, path, 0, -1,
                               std::to_string(unset - 20) + " more unresolved references, read as unset"});
  return out;
}

std::vector<Diagnostic> unit_context_problems(const std::string& text, const std::string& path) {
  // Every statement's id and body in order, and the contexts' ids; the bodies wanted are looked up
  // afterwards (the last statement of an id counts), with no map of every statement.
  std::vector<std::pair<std::int64_t, std::string_view>> statements;
  std::vector<std::int64_t> contexts;
  std::size_t i = text.find("DATA;");
  while (i != std::string::npos && i < text.size()) {
    i = text.find('#', i);
    if (i == std::string::npos) break;
    std::size_t j = i + 1;
    std::int64_t id = 0;
    while (j < text.size() && step_digit(text[j]) && id < (std::int64_t{1} << 50)) id = id * 10 + (text[j++] - '0');
    std::size_t k = j;
    while (k < text.size() && step_space(text[k])) ++k;
    if (j == i + 1 || k >= text.size() || text[k] != '=') {
      i = j;
      continue;
    }
    const std::size_t end = statement_end(text, k);  // ';' inside a string does not end the entity
    const std::string_view body(text.data() + k + 1, end - k - 1);
    statements.emplace_back(id, body);
    if (body.find("GEOMETRIC_REPRESENTATION_CONTEXT") != std::string_view::npos &&
        body.find("REPRESENTATION_CONTEXT(2)") == std::string_view::npos)  // 2D parameter spaces need no unit
      contexts.push_back(id);
    i = end;
  }
  std::unordered_map<std::int64_t, std::string_view> entities;  // the contexts and the units they name
  for (const std::int64_t id : contexts) entities.emplace(id, std::string_view());
  for (const auto& [id, body] : statements)
    if (const auto it = entities.find(id); it != entities.end()) it->second = body;
  std::unordered_map<std::int64_t, std::string_view> units;
  for (const std::int64_t id : contexts) {
    const std::string_view body = entities[id];
    const std::size_t at = body.find("GLOBAL_UNIT_ASSIGNED_CONTEXT");
    if (at == std::string_view::npos) continue;
    const std::size_t open = body.find('(', at), close = body.find(')', at);
    for (std::size_t h = body.find('#', open); h != std::string_view::npos && h < close; h = body.find('#', h + 1)) {
      std::int64_t ref = 0;
      for (std::size_t d = h + 1; d < body.size() && step_digit(body[d]) && ref < (std::int64_t{1} << 50); ++d)
        ref = ref * 10 + (body[d] - '0');
      units.emplace(ref, std::string_view());
    }
  }
  std::unordered_set<std::int64_t> defined;  // of the units: a reference to no statement is no unit
  for (const auto& [id, body] : statements)
    if (const auto it = units.find(id); it != units.end()) {
      it->second = body;
      defined.insert(id);
    }
  std::vector<Diagnostic> out;
  for (const std::int64_t id : contexts) {
    const std::string_view body = entities[id];
    const std::size_t at = body.find("GLOBAL_UNIT_ASSIGNED_CONTEXT");
    if (at == std::string_view::npos) {
      out.push_back({Severity::Error, path, 0, id,
                     "representation context without GLOBAL_UNIT_ASSIGNED_CONTEXT: its lengths have no unit, so "
                     "OCCT rejects it and every shape representation placed in it"});
      continue;
    }
    // The unit list: the #ids in the parentheses after the keyword.
    const std::size_t open = body.find('(', at), close = body.find(')', at);
    bool length = false;
    for (std::size_t h = body.find('#', open); h != std::string_view::npos && h < close; h = body.find('#', h + 1)) {
      std::int64_t ref = 0;
      for (std::size_t d = h + 1; d < body.size() && step_digit(body[d]) && ref < (std::int64_t{1} << 50); ++d)
        ref = ref * 10 + (body[d] - '0');
      length = length || (defined.count(ref) > 0 && units[ref].find("LENGTH_UNIT") != std::string_view::npos);
    }
    if (!length)
      out.push_back({Severity::Warning, path, 0, id,
                     "representation context whose GLOBAL_UNIT_ASSIGNED_CONTEXT names no LENGTH_UNIT: its lengths "
                     "have no stated unit; read as millimetres"});
  }
  return out;
}

}  // namespace cadclash::detail
