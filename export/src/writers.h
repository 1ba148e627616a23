// The writers behind export_model(). Internal to cadclash::export.
#pragma once

#include "cadclash/export.h"

namespace cadclash::detail {

// Writes one `g` per surface and instance in world coordinates; see export.h.
std::vector<Diagnostic> write_obj(const Model& model, const std::string& path);
// Writes glTF 2.0 binary; layout in cadclash/glb_layout.h.
std::vector<Diagnostic> write_glb(const Model& model, const std::string& path);

}  // namespace cadclash::detail
