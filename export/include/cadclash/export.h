// cadclash/export.h — writing a surface-tagged Model out, for any viewer and for cadclash to read back.
// The one public header of cadclash::export.
//
// Depends on cadclash::collide (the Model) and, privately, cadclash::report (the provenance JSON
// both formats carry) and nlohmann_json; never on OpenCASCADE or assimp. cadclash::import reads
// both formats back (import.h); the .glb layout the two share is in cadclash/glb_layout.h.
#pragma once

#include "cadclash/model.h"

#include <string>
#include <vector>

namespace cadclash {

// Writes `model` to `path`: .obj (one `g` per surface) or .glb (glTF 2.0 binary, one primitive per
// surface, instances as nodes, provenance in `extras`). Surfaces without triangles are written
// empty-free: they are skipped and listed. Returns diagnostics; an error means nothing usable was written.
// - .obj: every instance's copy of every surface, placed in world coordinates, as
//   `g <instance path>/<surface name>` (whitespace and '#' become '_') preceded by a comment
//   `# cadclash-surface {json}` with the exact name, part, surface id and provenance. Coordinates are
//   written to read back bit-exact. Reading it back gives one surface per group, in the same order.
// - .glb: one mesh per part, one primitive per surface (part-local float32 POSITION with min/max,
//   uint32 indices), one node per instance (name = path, column-major matrix). Provenance is in
//   each primitive's extras.cadclash, with a float64 copy of the positions, so importing our .glb
//   gives back exactly the same parts, surfaces, names, ids, vertices, instances and poses.
std::vector<Diagnostic> export_model(const Model& model, const std::string& path);

}  // namespace cadclash
