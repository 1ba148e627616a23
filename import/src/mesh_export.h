// The writers behind export_model(). Internal.
#pragma once

#include "cadclash/import.h"

#include <nlohmann/json.hpp>

namespace cadclash::detail {

// Writes one `g` per surface and instance in world coordinates; see import.h.
std::vector<Diagnostic> write_obj(const Model& model, const std::string& path);
// Writes glTF 2.0 binary; layout in mesh_glb.h.
std::vector<Diagnostic> write_glb(const Model& model, const std::string& path);

// A surface's name and provenance as JSON, shared by both writers and the .glb reader.
nlohmann::json surface_provenance_json(const Surface& surface);
// Reads back what surface_provenance_json wrote (the AABB is left empty if none was written).
// Throws nlohmann::json::exception on a bad value.
void surface_provenance_from_json(const nlohmann::json& j, Surface& surface);

}  // namespace cadclash::detail
