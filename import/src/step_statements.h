// The statements of a STEP file's DATA section, read in one pass: what the text cut
// (step_split_text.h) and the placements' hash (step_placements.h) both walk. Internal to
// cadclash::import.
#pragma once

#include <cctype>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace cadclash::detail {

// "#id = TYPE(...);" or "#id = (A(...) B(...));" in the text.
struct StatementSpan {
  std::int64_t id = 0;
  std::size_t begin = 0, end = 0;  // from '#' to just after ';'
  std::size_t body = 0;            // just after '='
  std::size_t after_type = 0;      // just after the type (at `body`'s first non-space for a complex entity)
  std::string_view type;           // the simple entity's type; empty for a complex entity
};

inline bool step_space(char c) { return std::isspace(static_cast<unsigned char>(c)) != 0; }

// Calls reference(id) for each "#id" a statement holds outside quoted strings, then
// statement(StatementSpan) (which returns false to stop the walk), for every statement in order.
// False, with `why`, when the text is not plain enough: not one DATA section, a comment or other
// text between or inside statements, a statement without '=' or that does not end, a file that does
// not end (END-ISO-10303-21); or when `statement` stopped it (`why` empty).
template <class OnStatement, class OnReference>
bool for_each_statement(std::string_view text, OnStatement&& statement, OnReference&& reference, std::string& why) {
  const std::size_t data = text.find("DATA;");
  if (data == std::string_view::npos || text.find("DATA;", data + 5) != std::string_view::npos) {
    why = "not one DATA section";
    return false;
  }
  const std::size_t n = text.size();
  std::size_t i = data + 5;
  for (;;) {
    while (i < n && step_space(text[i])) ++i;
    if (i >= n) {
      why = "the DATA section does not end";
      return false;
    }
    if (text.compare(i, 7, "ENDSEC;") == 0) break;
    if (text[i] != '#') {
      why = text.compare(i, 2, "/*") == 0 ? "a comment in the DATA section" : "unexpected text in the DATA section";
      return false;
    }
    StatementSpan s;
    s.begin = i++;
    while (i < n && std::isdigit(static_cast<unsigned char>(text[i])) && s.id < (std::int64_t{1} << 50)) s.id = s.id * 10 + (text[i++] - '0');
    while (i < n && step_space(text[i])) ++i;
    if (i >= n || text[i] != '=') {
      why = "a statement without '='";
      return false;
    }
    s.body = ++i;
    while (i < n && step_space(text[i])) ++i;
    const std::size_t type_at = i;
    if (i < n && text[i] != '(')
      while (i < n && (std::isalnum(static_cast<unsigned char>(text[i])) || text[i] == '_')) ++i;
    s.type = text.substr(type_at, i - type_at);
    s.after_type = i;
    bool quoted = false;
    for (; i < n; ++i) {
      const char c = text[i];
      if (quoted) {
        quoted = c != '\'';  // '' closes and reopens: the same
      } else if (c == '\'') {
        quoted = true;
      } else if (c == ';') {
        break;
      } else if (c == '#') {
        std::int64_t id = 0;
        std::size_t j = i + 1;
        while (j < n && std::isdigit(static_cast<unsigned char>(text[j])) && id < (std::int64_t{1} << 50)) id = id * 10 + (text[j++] - '0');
        if (j > i + 1) reference(id);
        i = j - 1;
      } else if (c == '/' && i + 1 < n && text[i + 1] == '*') {
        why = "a comment in the DATA section";
        return false;
      }
    }
    if (i >= n) {
      why = "a statement does not end";
      return false;
    }
    s.end = ++i;
    if (!statement(s)) {
      why.clear();
      return false;
    }
  }
  if (text.find("END-ISO-10303-21", i) == std::string_view::npos) {
    why = "the file does not end";
    return false;
  }
  return true;
}

}  // namespace cadclash::detail
