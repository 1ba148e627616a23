// The length uncertainty a STEP file declares (UNCERTAINTY_MEASURE_WITH_UNIT with a LENGTH_MEASURE),
// in millimetres. OCCT's reader does not carry it into the shapes' tolerances, so it is read from the
// text and made the floor of every face's model uncertainty (collide.h, Surface::uncertainty).
#include "step_uncertainty.h"
#include "step_statements.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <string_view>
#include <unordered_map>
#include <unordered_set>
#include <vector>

namespace cadclash::detail {
namespace {

// The text after '=' up to ';' of each entity in `ids`, found in one pass over the statements (a
// search per entity from the top of a 40 MB file took seconds).
std::unordered_map<std::int64_t, std::string_view> entity_texts(const std::string& text,
                                                                 const std::unordered_set<std::int64_t>& ids) {
  std::unordered_map<std::int64_t, std::string_view> out;
  const std::size_t n = text.size();
  for (std::size_t i = 0; i < n && out.size() < ids.size(); i = statement_end(text, i) + 1) {
    while (i < n && step_space(text[i])) ++i;  // a statement starts here
    if (i >= n || text[i] != '#') continue;
    std::int64_t id = 0;
    std::size_t k = i + 1;
    while (k < n && step_digit(text[k]) && id < (std::int64_t{1} << 50)) id = id * 10 + (text[k++] - '0');
    while (k < n && step_space(text[k])) ++k;
    i = k;
    if (k >= n || text[k] != '=' || !ids.count(id)) continue;
    const std::size_t end = text.find(';', k);
    out.emplace(id, std::string_view(text).substr(k + 1, end == std::string::npos ? std::string::npos : end - k - 1));
  }
  return out;
}

double millimetres_per(std::string_view unit) {
  if (unit.find("SI_UNIT") != std::string_view::npos && unit.find(".METRE.") != std::string_view::npos) {
    struct Prefix {
      const char* name;
      double mm;
    };
    for (const Prefix& p : {Prefix{".MILLI.", 1.0}, Prefix{".CENTI.", 10.0}, Prefix{".DECI.", 100.0},
                            Prefix{".KILO.", 1e6}, Prefix{".MICRO.", 1e-3}, Prefix{".NANO.", 1e-6}})
      if (unit.find(p.name) != std::string_view::npos) return p.mm;
    return 1000.0;  // SI_UNIT($,.METRE.)
  }
  if (unit.find("CONVERSION_BASED_UNIT") != std::string_view::npos) {
    if (unit.find("'INCH'") != std::string_view::npos) return 25.4;
    if (unit.find("'FOOT'") != std::string_view::npos) return 304.8;
  }
  return 0.0;
}

}  // namespace

double declared_length_uncertainty(const std::string& text, const std::string& path,
                                   std::vector<Diagnostic>& diagnostics) {
  constexpr std::string_view kEntity = "UNCERTAINTY_MEASURE_WITH_UNIT";
  constexpr std::string_view kLength = "LENGTH_MEASURE(";
  struct Declared {
    std::int64_t self = -1;  // the entity's own #id, for messages
    double value = 0.0;
    std::int64_t unit = -1;  // the #id of its unit
  };
  std::vector<Declared> declared;
  std::unordered_set<std::int64_t> units;
  for (std::size_t at = text.find(kEntity); at != std::string::npos; at = text.find(kEntity, at + 1)) {
    // The entity's own #id: the last '#' before '=' that precedes this keyword.
    const std::size_t eq = text.rfind('=', at), hash = eq == std::string::npos ? eq : text.rfind('#', eq);
    const std::int64_t self = hash == std::string::npos ? -1 : std::strtoll(text.c_str() + hash + 1, nullptr, 10);
    const std::size_t stop = text.find(';', at);
    const std::size_t m = std::string_view(text).substr(at, stop == std::string::npos ? std::string::npos : stop - at).find(kLength);
    if (m == std::string_view::npos) continue;  // not a length uncertainty
    char* end = nullptr;
    const double value = std::strtod(text.c_str() + at + m + kLength.size(), &end);
    const std::size_t ref = text.find('#', static_cast<std::size_t>(end - text.c_str()));
    const std::int64_t unit = ref != std::string::npos && ref < stop ? std::strtoll(text.c_str() + ref + 1, nullptr, 10) : -1;
    declared.push_back({self, value, unit});
    if (unit >= 0) units.insert(unit);
  }
  const std::unordered_map<std::int64_t, std::string_view> unit_texts = entity_texts(text, units);
  double worst = 0.0;
  for (const Declared& d : declared) {
    const auto unit = unit_texts.find(d.unit);
    const double mm = unit == unit_texts.end() ? 0.0 : millimetres_per(unit->second);
    if (!(d.value >= 0.0) || !std::isfinite(d.value) || mm == 0.0) {
      diagnostics.push_back({Severity::Warning, path, 0, d.self,
                             "length uncertainty with a value or unit that could not be read; ignored"});
      continue;
    }
    worst = std::max(worst, d.value * mm);
  }
  return worst;
}

}  // namespace cadclash::detail
