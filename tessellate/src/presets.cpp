// Tessellation presets: the four named qualities and their parsing.
#include "cadclash/tessellate.h"

#include <cassert>

namespace cadclash {

TessellationOptions tessellation_preset(TessellationPreset preset) {
  TessellationOptions o;
  switch (preset) {
    case TessellationPreset::Coarse: o.linear_deflection = 1.0, o.angular_deflection = 0.8; break;
    case TessellationPreset::Normal: o.linear_deflection = 0.1, o.angular_deflection = 0.5; break;
    case TessellationPreset::Fine: o.linear_deflection = 0.01, o.angular_deflection = 0.25; break;
    case TessellationPreset::VeryFine: o.linear_deflection = 0.001, o.angular_deflection = 0.1; break;
  }
  return o;
}

TessellationOptions apply_preset(TessellationOptions base, TessellationPreset preset) {
  const TessellationOptions p = tessellation_preset(preset);
  base.linear_deflection = p.linear_deflection;
  base.angular_deflection = p.angular_deflection;
  base.relative = false;
  return base;
}

std::optional<TessellationPreset> parse_tessellation_preset(std::string_view name) {
  if (name == "coarse") return TessellationPreset::Coarse;
  if (name == "normal") return TessellationPreset::Normal;
  if (name == "fine") return TessellationPreset::Fine;
  if (name == "very-fine" || name == "very_fine" || name == "veryfine") return TessellationPreset::VeryFine;
  return std::nullopt;
}

const char* tessellation_preset_name(TessellationPreset preset) {
  switch (preset) {
    case TessellationPreset::Coarse: return "coarse";
    case TessellationPreset::Normal: return "normal";
    case TessellationPreset::Fine: return "fine";
    case TessellationPreset::VeryFine: return "very-fine";
  }
  assert(false && "unknown preset");
  return "normal";
}

}  // namespace cadclash
