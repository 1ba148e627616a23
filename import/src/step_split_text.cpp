// A STEP file's text cut into pieces by B-rep item (step_split_text.h).
#include "step_split_text.h"

#include "import_cache.h"
#include "step_statements.h"

#include <algorithm>
#include <atomic>
#include <cassert>
#include <cctype>
#include <charconv>
#include <cstring>
#include <exception>
#include <numeric>
#include <span>
#include <string_view>
#include <system_error>
#include <thread>
#include <unordered_map>
#include <unordered_set>
#include <utility>

namespace cadclash::detail {
namespace {

// One "#id = ... ;" of the DATA section.
struct Statement {
  std::int64_t id = 0;
  std::size_t begin = 0, end = 0;  // the statement, ';' included
  std::size_t body = 0;            // just after '='
  std::string_view type;           // the simple entity's type; empty for a complex entity "(A() B())"
  std::size_t first_ref = 0, refs = 0;  // into Scan::refs: the statements it references, in order
};

struct Scan {
  std::string_view header;  // up to and without "DATA;"
  std::vector<Statement> statements;
  std::vector<std::uint32_t> refs;  // statement indices
};

// Every statement of the DATA section with what it references; nullopt (and why) when the text is
// not plain enough to cut.
std::optional<Scan> scan(const std::string& text, std::string& why) {
  Scan out;
  out.header = std::string_view(text).substr(0, text.find("DATA;"));
  std::vector<std::int64_t> raw;  // referenced ids, resolved to statements below
  // At most one statement per ';' (strings may hold more): reserved at once, as growing tens of MB
  // of statements step by step copies them again and again.
  const auto semicolons = static_cast<std::size_t>(std::count(text.begin(), text.end(), ';'));
  out.statements.reserve(semicolons);
  raw.reserve(semicolons + semicolons / 2);
  std::size_t first_ref = 0;
  const bool scanned = for_each_statement(
      text,
      [&](const StatementSpan& span) {
        Statement s;
        s.id = span.id;
        s.begin = span.begin;
        s.end = span.end;
        s.body = span.body;
        s.type = span.type;
        s.first_ref = first_ref;
        s.refs = raw.size() - first_ref;
        first_ref = raw.size();
        out.statements.push_back(s);
        return true;
      },
      [&](std::int64_t id) { raw.push_back(id); }, why);
  if (!scanned) return std::nullopt;
  // Ids to statements: an array when the ids are about as many as the statements (exporters number
  // 1, 2, ...), a hash map when they are sparse.
  constexpr std::uint32_t kNone = 0xffffffffu;
  std::int64_t largest = 0;
  for (const Statement& s : out.statements) largest = std::max(largest, s.id);
  const bool dense = largest <= static_cast<std::int64_t>(8 * out.statements.size() + 1024);
  std::vector<std::uint32_t> array(dense ? static_cast<std::size_t>(largest) + 1 : 0, kNone);
  std::unordered_map<std::int64_t, std::uint32_t> map;
  if (!dense) map.reserve(out.statements.size());
  for (std::size_t k = 0; k < out.statements.size(); ++k) {
    const std::int64_t id = out.statements[k].id;
    const bool fresh = dense ? std::exchange(array[static_cast<std::size_t>(id)], static_cast<std::uint32_t>(k)) == kNone
                             : map.emplace(id, static_cast<std::uint32_t>(k)).second;
    if (!fresh) {
      why = "an id defined twice";
      return std::nullopt;
    }
  }
  out.refs.resize(raw.size());
  for (std::size_t r = 0; r < raw.size(); ++r) {
    std::uint32_t k = kNone;
    if (dense) {
      if (raw[r] >= 0 && raw[r] <= largest) k = array[static_cast<std::size_t>(raw[r])];
    } else if (const auto it = map.find(raw[r]); it != map.end()) {
      k = it->second;
    }
    if (k == kNone) {
      why = "a reference to an undefined id";
      return std::nullopt;
    }
    out.refs[r] = k;
  }
  return out;
}

// B-rep items: what a piece transfers.
bool is_item(std::string_view t) {
  return t == "MANIFOLD_SOLID_BREP" || t == "BREP_WITH_VOIDS" || t == "FACETED_BREP" || t == "SHELL_BASED_SURFACE_MODEL";
}

// Entities any number of items may share without sharing topology: OCCT makes new objects of them
// for every use.
bool is_leaf(std::string_view t) {
  return t == "CARTESIAN_POINT" || t == "DIRECTION" || t == "VECTOR" || t == "AXIS2_PLACEMENT_3D" ||
         t == "AXIS2_PLACEMENT_2D" || t == "AXIS1_PLACEMENT";
}

bool is_shape_representation(std::string_view t) {
  return t.size() >= 20 && t.substr(t.size() - 20) == "SHAPE_REPRESENTATION";
}

// The first parameter of a simple entity (its name, for representation items): the token after
// "TYPE(", a quoted string with its quotes, or '$' / '*'.
std::string_view first_parameter(const std::string& text, const Statement& s) {
  std::size_t i = text.find('(', s.body);
  if (i == std::string::npos || i >= s.end) return "''";
  ++i;
  while (i < s.end && step_space(text[i])) ++i;
  if (i < s.end && text[i] == '\'') {
    std::size_t j = i + 1;
    for (; j < s.end; ++j)
      if (text[j] == '\'') {
        if (j + 1 < s.end && text[j + 1] == '\'') ++j;
        else break;
      }
    return std::string_view(text).substr(i, j + 1 - i);
  }
  if (i < s.end && (text[i] == '$' || text[i] == '*')) return std::string_view(text).substr(i, 1);
  return "''";
}

// What a styled item's styles may reach for the item to go with its face into a piece: the
// presentation entities STEPConstruct_Styles::GetColors reads, nothing that names a representation
// (a style by context: a component's colour) or a shape.
bool is_style_entity(std::string_view t) {
  return t == "PRESENTATION_STYLE_ASSIGNMENT" || t == "SURFACE_STYLE_USAGE" || t == "SURFACE_SIDE_STYLE" ||
         t == "SURFACE_STYLE_FILL_AREA" || t == "FILL_AREA_STYLE" || t == "FILL_AREA_STYLE_COLOUR" || t == "COLOUR_RGB" ||
         t == "DRAUGHTING_PRE_DEFINED_COLOUR" || t == "SURFACE_STYLE_BOUNDARY" || t == "CURVE_STYLE" ||
         t == "DRAUGHTING_PRE_DEFINED_CURVE_FONT" || t == "SURFACE_STYLE_RENDERING" ||
         t == "SURFACE_STYLE_RENDERING_WITH_PROPERTIES" || t == "SURFACE_STYLE_TRANSPARENT";
}

// Representations that list styled items for OCCT's colour reading (STEPConstruct_Styles::LoadStyles).
bool is_style_container(std::string_view t) {
  return t == "MECHANICAL_DESIGN_GEOMETRIC_PRESENTATION_REPRESENTATION" || t == "DRAUGHTING_MODEL";
}

std::string ref_text(std::int64_t id) {
  std::string r = "#";  // two steps: GCC 12 warns falsely (-Wrestrict) on "#" + string
  r += std::to_string(id);
  return r;
}

// The statement without blanks outside quoted strings.
std::string compact(std::string_view statement) {
  std::string out;
  out.reserve(statement.size());
  bool quoted = false;
  for (const char c : statement) {
    if (c == '\'') quoted = !quoted;
    if (quoted || !step_space(c)) out += c;
  }
  return out;
}

struct UnionFind {
  std::vector<std::uint32_t> parent;
  explicit UnionFind(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0u); }
  std::uint32_t root(std::uint32_t a) {
    while (parent[a] != a) a = parent[a] = parent[parent[a]];
    return a;
  }
  void unite(std::uint32_t a, std::uint32_t b) {
    a = root(a), b = root(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
};

// The header's FILE_SCHEMA statement (which schema the entities are read in); "" when none.
std::string_view file_schema(std::string_view header) {
  const std::size_t at = header.find("FILE_SCHEMA");
  if (at == std::string_view::npos) return {};
  const std::size_t end = header.find(';', at);
  return header.substr(at, end == std::string_view::npos ? std::string_view::npos : end + 1 - at);
}

void append_number(std::string& out, std::int64_t v) {
  char digits[24];
  const auto end = std::to_chars(digits, digits + sizeof digits, v).ptr;
  out.append(digits, end);
}

// Statement k with its own id and the ones it references (`refs`, in the order for_each_statement
// found them) replaced by `number`'s of their statements, copied in runs between them. The next '#'
// and the next quote are found a run at a time (memchr); a quoted string is skipped whole.
void renumbered(const std::string& text, std::uint32_t k, const Statement& s, std::span<const std::uint32_t> refs,
                const std::vector<std::int64_t>& number, std::string& out) {
  auto id_end = [&](std::size_t hash) {  // just after the digits of the id at text[hash] == '#'
    std::int64_t id = 0;
    std::size_t j = hash + 1;
    while (j < s.end && step_digit(text[j]) && id < (std::int64_t{1} << 50)) id = id * 10 + (text[j++] - '0');
    return j;
  };
  auto next = [&](char c, std::size_t from) {  // the first c in [from, s.end), or s.end
    if (from >= s.end) return s.end;
    const void* at = std::memchr(text.data() + from, c, s.end - from);
    return at ? static_cast<std::size_t>(static_cast<const char*>(at) - text.data()) : s.end;
  };
  out += '#';
  append_number(out, number[k]);
  std::size_t from = id_end(s.begin), r = 0;
  std::size_t quote = next('\'', s.body), hash = next('#', s.body);
  while (hash < s.end) {
    if (quote < hash) {
      const std::size_t close = next('\'', quote + 1);  // the statement ends after its strings: found
      if (close >= s.end) break;
      quote = next('\'', close + 1);
      if (hash <= close) hash = next('#', close + 1);
      continue;
    }
    const std::size_t j = id_end(hash);
    if (j == hash + 1) {
      hash = next('#', j);
      continue;
    }
    assert(r < refs.size());
    out.append(text, from, hash - from);
    out += '#';
    append_number(out, number[refs[r++]]);
    from = j;
    hash = next('#', j);
  }
  assert(r == refs.size());
  out.append(text, from, s.end - from);
}

}  // namespace

std::optional<StepSplit> split_step_text(const std::string& text, bool canonical, std::string& why_not) {
  std::optional<Scan> scanned = scan(text, why_not);
  if (!scanned) return std::nullopt;
  const Scan& sc = *scanned;
  const std::vector<Statement>& st = sc.statements;
  const std::size_t n = st.size();
  std::vector<std::uint32_t> items;
  std::int64_t max_id = 0;
  bool products = false;
  // What items may share without being joined: leaves, and representation contexts (of the
  // parameter curves' 2D spaces, which some exporters write once for all).
  std::vector<char> joins_nothing(n, 0);
  for (std::size_t k = 0; k < n; ++k) {
    max_id = std::max(max_id, st[k].id);
    products = products || st[k].type == "PRODUCT_DEFINITION";
    joins_nothing[k] = is_leaf(st[k].type) ||
                       (st[k].type.empty() &&
                        std::string_view(text).substr(st[k].body, st[k].end - st[k].body).find("REPRESENTATION_CONTEXT") !=
                            std::string_view::npos);
    if (st[k].type == "MAPPED_ITEM" || st[k].type == "NON_MANIFOLD_SURFACE_SHAPE_REPRESENTATION") {
      why_not = std::string(st[k].type) + " in the file";
      return std::nullopt;
    }
    if (is_item(st[k].type)) items.push_back(static_cast<std::uint32_t>(k));
  }
  if (items.size() < 2 || !products) {
    why_not = products ? "fewer than two B-rep items" : "no product";
    return std::nullopt;
  }
  auto refs_of = [&](std::uint32_t k) {
    return std::span<const std::uint32_t>(sc.refs.data() + st[k].first_ref, st[k].refs);
  };

  // Groups: items joined where their insides meet beyond leaves; each non-leaf inside has one owner.
  constexpr std::uint32_t kNone = 0xffffffffu;
  std::vector<std::uint32_t> owner(n, kNone);  // item ordinal
  UnionFind sets(items.size());
  std::vector<std::size_t> bytes(items.size(), 0), weight(items.size(), 0);
  std::vector<std::uint32_t> stack;
  for (std::uint32_t h = 0; h < items.size(); ++h) {
    stack.assign(1, items[h]);
    while (!stack.empty()) {
      const std::uint32_t e = stack.back();
      stack.pop_back();
      if (joins_nothing[e] != 0) continue;
      if (owner[e] == h) continue;
      if (owner[e] != kNone) {
        sets.unite(owner[e], h);
        continue;
      }
      owner[e] = h;
      bytes[h] += st[e].end - st[e].begin;
      weight[h] += st[e].end - st[e].begin;
      // A face's bounds (all its references but the surface): OCCT's healing at transfer compares
      // every wire of a face with every other, about two thirds of a byte of text's cost a pair
      // (fitted to every piece's CPU seconds on the KiCad boards, whose plates have 215 to 1,408
      // holes a face; two and a half before the healing's context remembered unchanged wires).
      if (st[e].type == "ADVANCED_FACE" || st[e].type == "FACE_SURFACE") {
        const std::size_t wires = st[e].refs > 0 ? st[e].refs - 1 : 0;
        weight[h] += wires * wires * 2 / 3;
      }
      for (const std::uint32_t r : refs_of(e)) stack.push_back(r);
    }
  }
  std::vector<std::uint32_t> group_of(items.size());
  std::vector<std::size_t> group_bytes, group_weight;
  {
    std::vector<std::uint32_t> number(items.size(), kNone);
    for (std::uint32_t h = 0; h < items.size(); ++h) {
      const std::uint32_t r = sets.root(h);
      if (number[r] == kNone) {
        number[r] = static_cast<std::uint32_t>(group_bytes.size());
        group_bytes.push_back(0);
        group_weight.push_back(0);
      }
      group_of[h] = number[r];
      group_bytes[number[r]] += bytes[h];
      group_weight[number[r]] += weight[h];
    }
  }
  const std::size_t groups = group_bytes.size();
  if (groups < 2) {
    why_not = "one group of shapes";
    return std::nullopt;
  }
  // One piece per group, so that a group's piece (and its shapes) do not depend on the rest.
  const std::size_t used = groups;
  auto worker_of = [&](std::uint32_t e) { return group_of[owner[e]]; };

  // Each item's representation context: the last reference of every shape representation that lists
  // it; they must agree (the units the item is read in).
  std::vector<std::int64_t> context_of(items.size(), -1);
  std::vector<char> in_items(n, 0);
  std::vector<std::uint32_t> item_ordinal(n, kNone);
  for (std::uint32_t h = 0; h < items.size(); ++h) item_ordinal[items[h]] = h;
  for (std::uint32_t k = 0; k < n; ++k) {
    const auto refs = refs_of(k);
    bool lists_item = false;
    for (const std::uint32_t r : refs) lists_item = lists_item || item_ordinal[r] != kNone;
    if (!lists_item) continue;
    if (st[k].type.empty()) {
      why_not = "a complex entity names a B-rep item";
      return std::nullopt;
    }
    if (!is_shape_representation(st[k].type) || refs.empty()) continue;
    const std::int64_t context = st[refs.back()].id;
    for (std::size_t r = 0; r + 1 < refs.size(); ++r) {
      const std::uint32_t h = item_ordinal[refs[r]];
      if (h == kNone) continue;
      if (context_of[h] >= 0 && context_of[h] != context) {
        why_not = "a B-rep item in representations of different contexts";
        return std::nullopt;
      }
      context_of[h] = context;
    }
  }
  for (std::uint32_t h = 0; h < items.size(); ++h)
    if (context_of[h] < 0) {
      why_not = "a B-rep item outside any shape representation";
      return std::nullopt;
    }

  // Styled faces: a STYLED_ITEM that is the only outside name of a face inside an item, whose styles
  // reach presentation entities only and which nothing but style containers lists, goes into its
  // face's piece with its styles (a worker reads its colours with OCCT's own code, step_attempt.cpp):
  // the main text then holds neither the item nor a stand-in for the face. Style entities other
  // statements of the main text still name stay there too.
  std::vector<char> moved(n, 0), style(n, 0);  // moved styled items; their styles
  std::vector<std::uint32_t> outside_names(n, 0);
  std::vector<char> named_elsewhere(n, 0);  // by a statement other than a style container
  for (std::uint32_t k = 0; k < n; ++k) {
    const bool container = is_style_container(st[k].type);
    for (const std::uint32_t r : refs_of(k)) {
      if (owner[k] == kNone) ++outside_names[r];
      if (!container) named_elsewhere[r] = 1;
    }
  }
  std::vector<std::vector<std::uint32_t>> styles_of(used);  // per piece: its styled items and their styles
  {
    std::vector<std::uint32_t> chain;
    for (std::uint32_t k = 0; k < n; ++k) {
      const auto refs = refs_of(k);
      if (st[k].type != "STYLED_ITEM" || refs.size() < 2 || named_elsewhere[k] != 0) continue;
      const std::uint32_t face = refs.back();
      if ((st[face].type != "ADVANCED_FACE" && st[face].type != "FACE_SURFACE") || owner[face] == kNone ||
          outside_names[face] != 1)
        continue;
      chain.clear();
      bool plain = true;
      stack.assign(refs.begin(), refs.end() - 1);
      while (!stack.empty() && plain) {
        const std::uint32_t e = stack.back();
        stack.pop_back();
        if (std::find(chain.begin(), chain.end(), e) != chain.end()) continue;
        plain = is_style_entity(st[e].type);
        chain.push_back(e);
        for (const std::uint32_t r : refs_of(e)) stack.push_back(r);
      }
      if (!plain) continue;
      moved[k] = 1;
      std::vector<std::uint32_t>& into = styles_of[worker_of(face)];
      into.push_back(k);
      for (const std::uint32_t e : chain) {
        style[e] = 1;
        into.push_back(e);
      }
    }
  }
  // A container's list without the moved items must be one the main text can hold: its statement
  // rewritten exactly (name, items, context), and not emptied while something names it.
  std::vector<char> rewritten(n, 0);  // containers that lose items (dropped when they lose all)
  for (std::uint32_t k = 0; k < n; ++k) {
    if (!is_style_container(st[k].type)) continue;
    const auto refs = refs_of(k);
    std::size_t losing = 0;
    for (std::size_t r = 0; r + 1 < refs.size(); ++r) losing += moved[refs[r]];
    if (losing == 0) continue;
    std::string whole = ref_text(st[k].id) + "=" + std::string(st[k].type) + "(" + std::string(first_parameter(text, st[k])) + ",(";
    for (std::size_t r = 0; r + 1 < refs.size(); ++r) whole += (r ? "," : "") + ref_text(st[refs[r]].id);
    whole += ")," + ref_text(st[refs.back()].id) + ");";
    const bool exact = compact(std::string_view(text).substr(st[k].begin, st[k].end - st[k].begin)) == whole;
    if (exact && (losing + 1 < refs.size() || outside_names[k] == 0)) {
      rewritten[k] = 1;
      continue;
    }
    for (std::size_t r = 0; r + 1 < refs.size(); ++r) moved[refs[r]] = 0;  // stays in the main text
  }
  for (std::uint32_t w = 0; w < used; ++w)
    std::erase_if(styles_of[w], [&](std::uint32_t k) { return st[k].type == "STYLED_ITEM" && moved[k] == 0; });

  // Pieces: per worker, its items' whole insides (leaves included) and, per context, a shape
  // representation of its items with that context and what the context reaches.
  StepSplit out;
  out.pieces.resize(used);
  for (std::size_t g = 0; g < groups; ++g) {
    out.pieces[g].bytes = group_bytes[g];
    out.pieces[g].weight = group_weight[g];
  }
  std::vector<std::uint32_t> stamp(n, kNone);  // worker whose piece holds the statement
  std::vector<std::vector<std::uint32_t>> members(used);
  auto take = [&](std::uint32_t start, std::uint32_t w) {
    stack.assign(1, start);
    while (!stack.empty()) {
      const std::uint32_t e = stack.back();
      stack.pop_back();
      if (stamp[e] == w) continue;
      stamp[e] = w;
      in_items[e] = 1;
      members[w].push_back(e);
      for (const std::uint32_t r : refs_of(e)) stack.push_back(r);
    }
  };
  // A statement can be in several pieces (leaves, contexts): stamps are per piece, and each piece
  // takes its statements in one sweep before the next.
  std::vector<std::vector<std::uint32_t>> items_of(used);
  for (std::uint32_t h = 0; h < items.size(); ++h) items_of[worker_of(items[h])].push_back(h);
  std::unordered_map<std::int64_t, std::uint32_t> statement_of_id;
  for (std::uint32_t k = 0; k < n; ++k)
    if (st[k].type.empty() || st[k].type.find("CONTEXT") != std::string_view::npos) statement_of_id.emplace(st[k].id, k);
  std::vector<char> context_statement(n, 0);
  std::int64_t next_id = max_id + 1;
  std::vector<std::string> synthetic(used);
  struct Synthetic {
    std::int64_t id;
    std::uint32_t context_statement;
    std::vector<std::uint32_t> item_statements;
  };
  std::vector<std::vector<Synthetic>> synthetic_reps(used);
  for (std::uint32_t w = 0; w < used; ++w) {
    std::vector<std::pair<std::int64_t, std::vector<std::uint32_t>>> by_context;  // the items' statements
    for (const std::uint32_t h : items_of[w]) {
      take(items[h], w);
      auto it = std::find_if(by_context.begin(), by_context.end(), [&](const auto& c) { return c.first == context_of[h]; });
      if (it == by_context.end()) it = by_context.insert(by_context.end(), {context_of[h], {}});
      it->second.push_back(items[h]);
    }
    for (auto& [context, item_statements] : by_context) {
      const auto c = statement_of_id.find(context);
      if (c == statement_of_id.end()) {
        why_not = "a representation context that is not a context";
        return std::nullopt;
      }
      const std::size_t before = members[w].size();
      take(c->second, w);
      for (std::size_t m = before; m < members[w].size(); ++m) {
        context_statement[members[w][m]] = 1;
        in_items[members[w][m]] = 0;  // a context stays whole in the main text too
      }
      std::string rep = "#";
      rep += std::to_string(next_id) + "=SHAPE_REPRESENTATION('',(";
      for (std::size_t k = 0; k < item_statements.size(); ++k)
        rep += (k ? ",#" : "#") + std::to_string(st[item_statements[k]].id);
      rep += "),#" + std::to_string(context) + ");\n";
      synthetic[w] += rep;
      synthetic_reps[w].push_back({next_id, c->second, item_statements});
      out.pieces[w].reps.push_back(next_id++);
    }
    for (const std::uint32_t k : styles_of[w])
      if (stamp[k] != w) {
        stamp[k] = w;
        members[w].push_back(k);
      }
  }

  // The main text: every statement no piece took as an item's inside, the leaves they reach, and a
  // placeholder for each item or inside entity they name.
  std::vector<char> keep(n, 0), stand_in(n, 0);
  for (std::uint32_t k = 0; k < n; ++k)
    keep[k] = (in_items[k] == 0 || context_statement[k] != 0) && moved[k] == 0 && style[k] == 0 ? 1 : 0;
  for (std::uint32_t k = 0; k < n; ++k) {  // styles the main text still names (its own styled items')
    if (keep[k] == 0 || style[k] != 0) continue;
    for (const std::uint32_t r : refs_of(k)) {
      if (style[r] == 0 || keep[r] != 0) continue;
      stack.assign(1, r);
      while (!stack.empty()) {
        const std::uint32_t e = stack.back();
        stack.pop_back();
        if (keep[e] != 0) continue;
        keep[e] = 1;
        for (const std::uint32_t q : refs_of(e)) stack.push_back(q);
      }
    }
  }
  for (std::uint32_t k = 0; k < n; ++k) {
    if (keep[k] == 0 || is_leaf(st[k].type)) continue;
    for (const std::uint32_t r : refs_of(k)) {
      if (keep[r] != 0 || moved[r] != 0) continue;
      if (!is_leaf(st[r].type)) {
        stand_in[r] = 1;
        continue;
      }
      // A leaf an item shares with the main text: kept, with the leaves below it.
      stack.assign(1, r);
      while (!stack.empty()) {
        const std::uint32_t e = stack.back();
        stack.pop_back();
        if (keep[e] != 0) continue;
        if (!is_leaf(st[e].type)) {
          why_not = "a point or placement names a shape's inside";
          return std::nullopt;
        }
        keep[e] = 1;
        for (const std::uint32_t q : refs_of(e)) stack.push_back(q);
      }
    }
  }
  // Placeholders share one small valid face (never transferred: their ids are bound first).
  const std::int64_t point = next_id++, axes = next_id++, plane = next_id++, vertex = next_id++, loop = next_id++,
                     bound = next_id++, face = next_id++, closed = next_id++, open = next_id++, void_shell = next_id++;
  const auto ref = ref_text;
  std::string& main = out.main_text;
  main.reserve(text.size() / 4);
  main.append(sc.header);
  main += "DATA;\n";
  for (std::uint32_t k = 0; k < n; ++k) {
    const Statement& s = st[k];
    if (keep[k] != 0 && rewritten[k] != 0) {  // a style container without the moved items
      const auto refs = refs_of(k);
      std::string list;
      for (std::size_t r = 0; r + 1 < refs.size(); ++r)
        if (moved[refs[r]] == 0) list += (list.empty() ? "" : ",") + ref(st[refs[r]].id);
      if (!list.empty())
        main += ref(s.id) + "=" + std::string(s.type) + "(" + std::string(first_parameter(text, s)) + ",(" + list + ")," +
                ref(st[refs.back()].id) + ");\n";
      continue;
    }
    if (keep[k] != 0) {
      main.append(text, s.begin, s.end - s.begin);
      main += '\n';
      continue;
    }
    if (stand_in[k] == 0) continue;
    if (owner[k] == kNone) {
      why_not = "a context inside a shape is named from outside it";
      return std::nullopt;
    }
    const std::string name(first_parameter(text, s));
    const std::string head = ref(s.id) + "=" + std::string(s.type) + "(" + name + ",";
    if (s.type == "ADVANCED_FACE" || s.type == "FACE_SURFACE") main += head + "(" + ref(bound) + ")," + ref(plane) + ",.T.);\n";
    else if (s.type == "MANIFOLD_SOLID_BREP" || s.type == "FACETED_BREP") main += head + ref(closed) + ");\n";
    else if (s.type == "BREP_WITH_VOIDS") main += head + ref(closed) + ",(" + ref(void_shell) + "));\n";
    else if (s.type == "SHELL_BASED_SURFACE_MODEL") main += head + "(" + ref(open) + "));\n";
    else if (s.type == "CLOSED_SHELL" || s.type == "OPEN_SHELL") main += head + "(" + ref(face) + "));\n";
    else {
      why_not = "a " + (s.type.empty() ? std::string("complex entity") : std::string(s.type)) + " inside a shape is named from outside it";
      return std::nullopt;
    }
    out.pieces[worker_of(k)].bind.push_back(s.id);
  }
  main += ref(point) + "=CARTESIAN_POINT('',(0.,0.,0.));\n" + ref(axes) + "=AXIS2_PLACEMENT_3D(''," + ref(point) + ",$,$);\n" +
          ref(plane) + "=PLANE(''," + ref(axes) + ");\n" + ref(vertex) + "=VERTEX_POINT(''," + ref(point) + ");\n" + ref(loop) +
          "=VERTEX_LOOP(''," + ref(vertex) + ");\n" + ref(bound) + "=FACE_BOUND(''," + ref(loop) + ",.T.);\n" + ref(face) +
          "=ADVANCED_FACE('',(" + ref(bound) + ")," + ref(plane) + ",.T.);\n" + ref(closed) + "=CLOSED_SHELL('',(" + ref(face) +
          "));\n" + ref(open) + "=OPEN_SHELL('',(" + ref(face) + "));\n" + ref(void_shell) + "=ORIENTED_CLOSED_SHELL('',*," +
          ref(closed) + ",.F.);\n";
  main += "ENDSEC;\nEND-ISO-10303-21;\n";

  // The pieces' texts, each on its own: on two threads (the work is copying and renumbering tens of
  // MB), each taking the next piece; joined before this returns, so a caller that forks next has
  // one thread again.
  auto write_piece = [&](std::uint32_t w, std::vector<std::int64_t>& number) {
    StepPiece& piece = out.pieces[w];
    std::sort(members[w].begin(), members[w].end());  // in file order (here: on the writers' threads)
    piece.text.append(sc.header);
    piece.text += "DATA;\n";
    for (const std::uint32_t k : members[w]) {
      piece.text.append(text, st[k].begin, st[k].end - st[k].begin);
      piece.text += '\n';
    }
    piece.text += synthetic[w];
    piece.text += "ENDSEC;\nEND-ISO-10303-21;\n";
    std::sort(piece.bind.begin(), piece.bind.end());
    if (!canonical) return;
    // Ids renumbered in the order the piece defines them: the same product written elsewhere in a
    // file, or by another export that numbers the rest differently, reads the same. `number` is by
    // statement; every statement a member names is a member, so it holds this piece's numbers.
    for (const std::uint32_t k : members[w]) {
      piece.ids.push_back(st[k].id);
      number[k] = static_cast<std::int64_t>(piece.ids.size());
    }
    // Hashed a megabyte at a time: the canonical text is as long as the piece's, and only its digest is kept.
    constexpr std::size_t kChunk = std::size_t{1} << 20;
    Sha256Stream digest;
    std::string c;
    c.reserve(kChunk + (std::size_t{1} << 16));
    c.append(file_schema(sc.header));
    c += '\n';
    for (const std::uint32_t k : members[w]) {
      renumbered(text, k, st[k], refs_of(k), number, c);
      c += '\n';
      if (c.size() >= kChunk) {
        digest.update(c);
        c.clear();
      }
    }
    for (const Synthetic& r : synthetic_reps[w]) {  // appended piece by piece: GCC 12 warns falsely on "#" + string
      piece.ids.push_back(r.id);
      c += '#';
      c += std::to_string(piece.ids.size());
      c += "=SHAPE_REPRESENTATION('',(";
      for (std::size_t k = 0; k < r.item_statements.size(); ++k) {
        c += k ? ",#" : "#";
        c += std::to_string(number[r.item_statements[k]]);
      }
      c += "),#";
      c += std::to_string(number[r.context_statement]);
      c += ");\n";
    }
    digest.update(c);
    piece.canonical_sha256 = digest.hex();
  };
  std::atomic<std::uint32_t> next{0};
  auto write_pieces = [&] {
    std::vector<std::int64_t> number(canonical ? n : 0);
    for (std::uint32_t w; (w = next.fetch_add(1)) < used;) write_piece(w, number);
  };
  std::optional<std::thread> helper;
  std::exception_ptr failed;  // the helper's exception (bad_alloc), thrown here after the join
  if (used > 1 && text.size() >= (std::size_t{1} << 20)) {
    try {
      helper.emplace([&] {
        try {
          write_pieces();
        } catch (...) {
          failed = std::current_exception();
          next = static_cast<std::uint32_t>(used);  // this thread stops taking pieces too
        }
      });
    } catch (const std::system_error&) {  // no thread to spare: this one writes them all
    }
  }
  try {
    write_pieces();
  } catch (...) {
    if (helper) helper->join();
    throw;
  }
  if (helper) helper->join();
  if (failed) std::rethrow_exception(failed);
  return out;
}

std::vector<std::vector<std::size_t>> share_pieces(const std::vector<StepPiece>& pieces,
                                                    const std::vector<std::size_t>& which, std::size_t workers) {
  assert(workers >= 1);
  const std::size_t used = std::min(workers, which.size());
  std::vector<std::vector<std::size_t>> shares(used);
  if (used == 0) return shares;
  std::vector<std::size_t> order = which;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return pieces[a].weight > pieces[b].weight; });
  std::vector<std::size_t> load(used, 0);
  for (const std::size_t p : order) {
    const auto w = static_cast<std::size_t>(std::min_element(load.begin(), load.end()) - load.begin());
    load[w] += pieces[p].weight + 1;
    shares[w].push_back(p);
  }
  for (auto& share : shares) std::sort(share.begin(), share.end());
  return shares;
}

}  // namespace cadclash::detail
