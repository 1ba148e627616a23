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

// The index of the first ';' at or after i outside quoted strings ('' inside a string closes and
// reopens it: the same); text.size() when there is none.
inline std::size_t statement_end(std::string_view text, std::size_t i) {
  const std::size_t n = text.size();
  const char* data = text.data();
  for (; i < n; ++i) {
    const char c = data[i];
    if (c == ';') return i;
    if (c == '\'') {
      const std::size_t close = text.find('\'', i + 1);
      if (close == std::string_view::npos) return n;
      i = close;
    }
  }
  return n;
}

// "#id = TYPE(...);" or "#id = (A(...) B(...));" in the text.
struct StatementSpan {
  std::int64_t id = 0;
  std::size_t begin = 0, end = 0;  // from '#' to just after ';'
  std::size_t body = 0;            // just after '='
  std::size_t after_type = 0;      // just after the type (at `body`'s first non-space for a complex entity)
  std::string_view type;           // the simple entity's type; empty for a complex entity
};

// The C locale's character classes, inline: the scans below look at every byte of files of
// hundreds of MB, where a call to std::isspace per byte is most of their time.
inline bool step_space(char c) { return c == ' ' || (c >= '\t' && c <= '\r'); }
inline bool step_digit(char c) { return c >= '0' && c <= '9'; }
inline bool step_word(char c) { return step_digit(c) || (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || c == '_'; }

// Whether a byte may end a run of plain statement text: a quote, ';', '#' or '/'.
inline bool step_stop(char c) { return c == '\'' || c == ';' || c == '#' || c == '/'; }

// The first index >= i (and < n) of a byte step_stop is true of; n when none.
inline std::size_t next_stop(std::string_view text, std::size_t i) {
  static constexpr auto table = [] {
    struct Table {
      bool stop[256] = {};
    } t;
    for (const char c : {'\'', ';', '#', '/'}) t.stop[static_cast<unsigned char>(c)] = true;
    return t;
  }();
  const std::size_t n = text.size();
  const char* data = text.data();
  while (i < n && !table.stop[static_cast<unsigned char>(data[i])]) ++i;
  return i;
}

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
    while (i < n && step_digit(text[i]) && s.id < (std::int64_t{1} << 50)) s.id = s.id * 10 + (text[i++] - '0');
    while (i < n && step_space(text[i])) ++i;
    if (i >= n || text[i] != '=') {
      why = "a statement without '='";
      return false;
    }
    s.body = ++i;
    while (i < n && step_space(text[i])) ++i;
    const std::size_t type_at = i;
    if (i < n && text[i] != '(')
      while (i < n && step_word(text[i])) ++i;
    s.type = text.substr(type_at, i - type_at);
    s.after_type = i;
    for (; (i = next_stop(text, i)) < n; ++i) {
      const char c = text[i];
      if (c == '\'') {  // a string: to its closing quote ('' closes and reopens: the same)
        const std::size_t close = text.find('\'', i + 1);
        i = close == std::string_view::npos ? n - 1 : close;
      } else if (c == ';') {
        break;
      } else if (c == '#') {
        std::int64_t id = 0;
        std::size_t j = i + 1;
        while (j < n && step_digit(text[j]) && id < (std::int64_t{1} << 50)) id = id * 10 + (text[j++] - '0');
        if (j > i + 1) reference(id);
        i = j - 1;
      } else if (i + 1 < n && text[i + 1] == '*') {  // '/'
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
