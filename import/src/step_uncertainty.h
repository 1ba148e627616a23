// The length uncertainty a STEP file declares. Internal to cadclash::import.
#pragma once

#include "cadclash/collide.h"

#include <string>
#include <vector>

namespace cadclash::detail {

// The largest UNCERTAINTY_MEASURE_WITH_UNIT(LENGTH_MEASURE(x), #unit, ...) of the file's text, in
// millimetres (SI metre prefixes, inch, foot); 0 when none. An uncertainty whose value or unit cannot
// be read is a warning naming its #id, and is ignored.
double declared_length_uncertainty(const std::string& text, const std::string& path,
                                   std::vector<Diagnostic>& diagnostics);

}  // namespace cadclash::detail
