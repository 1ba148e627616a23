// The length uncertainty a STEP file declares (UNCERTAINTY_MEASURE_WITH_UNIT with a LENGTH_MEASURE),
// in millimetres. OCCT's reader does not carry it into the shapes' tolerances, so it is read from the
// text and made the floor of every face's model uncertainty (collide.h, Surface::uncertainty).
#include "step_uncertainty.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <string_view>

namespace cadclash::detail {
namespace {

// The text of entity #id up to its ';' (empty when it is not found).
std::string_view entity_text(const std::string& text, std::int64_t id) {
  const std::string key = "#" + std::to_string(id);
  for (std::size_t at = text.find(key); at != std::string::npos; at = text.find(key, at + 1)) {
    std::size_t k = at + key.size();
    if (k < text.size() && std::isdigit(static_cast<unsigned char>(text[k]))) continue;  // #12 is not #123
    while (k < text.size() && std::isspace(static_cast<unsigned char>(text[k]))) ++k;
    if (k >= text.size() || text[k] != '=') continue;
    const std::size_t end = text.find(';', k);
    return std::string_view(text).substr(k + 1, end == std::string::npos ? std::string::npos : end - k - 1);
  }
  return {};
}

// Millimetres per unit of a LENGTH_UNIT entity; 0 when it is not understood.
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
  double worst = 0.0;
  for (std::size_t at = text.find(kEntity); at != std::string::npos; at = text.find(kEntity, at + 1)) {
    // The entity's own #id, for messages: the last '#' before '=' that precedes this keyword.
    const std::size_t eq = text.rfind('=', at), hash = eq == std::string::npos ? eq : text.rfind('#', eq);
    const std::int64_t self = hash == std::string::npos ? -1 : std::strtoll(text.c_str() + hash + 1, nullptr, 10);
    const std::size_t m = text.find(kLength, at);
    const std::size_t stop = text.find(';', at);
    if (m == std::string::npos || m > stop) continue;  // not a length uncertainty
    char* end = nullptr;
    const double value = std::strtod(text.c_str() + m + kLength.size(), &end);
    const std::size_t ref = text.find('#', static_cast<std::size_t>(end - text.c_str()));
    double mm = 0.0;
    if (ref != std::string::npos && ref < stop)
      mm = millimetres_per(entity_text(text, std::strtoll(text.c_str() + ref + 1, nullptr, 10)));
    if (!(value >= 0.0) || !std::isfinite(value) || mm == 0.0) {
      diagnostics.push_back({Severity::Warning, path, 0, self,
                             "length uncertainty with a value or unit that could not be read; ignored"});
      continue;
    }
    worst = std::max(worst, value * mm);
  }
  return worst;
}

}  // namespace cadclash::detail
