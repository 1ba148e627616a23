// cadclash/import.h — reading files into a surface-tagged Model, and writing one back out.
// The one public header of cadclash::import.
//
// Formats, chosen by file extension (case-insensitive):
//   .stp .step (AP203/AP214/AP242), .igs .iges, .brep   B-rep assemblies through OCCT XCAF; one surface per face
//   .obj                                                one surface per `g` group / `o` object (assimp)
//   .off                                                one surface per distinct face colour (CGAL)
//   .stl .ply .gltf .glb and other assimp formats       one surface per mesh; a .glb written by cadclash
//                                                       gives back its surfaces, names and ids
#pragma once

#include "cadclash/collide.h"
#include "cadclash/tessellate.h"

#include <span>
#include <string>
#include <vector>

namespace cadclash {

struct ImportOptions {
  TessellationOptions tessellation;  // for B-rep formats
  bool lazy = false;                 // B-rep: AABBs from the exact geometry now, triangles when first required
};

struct ImportResult {
  Model model;                           // everything that could be read, even when diagnostics hold errors
  std::vector<Diagnostic> diagnostics;   // every problem; each dropped element is named here
  bool complete = true;                  // false when any part of the input was dropped or failed to mesh
};

// Reads one file. Never throws for bad input: problems come back as diagnostics, and the good parts
// of a partly bad file are kept. A file that cannot be read at all gives an empty model and an error.
ImportResult import_file(const std::string& path, const ImportOptions& options = {});

// Reads several files into one scene. When more than one file is given, each file's instance paths
// are prefixed with "/<file name>" so they stay unique.
ImportResult import_files(std::span<const std::string> paths, const ImportOptions& options = {});

// Writes `model` to `path`: .obj (one `g` per surface) or .glb (glTF 2.0 binary, one primitive per
// surface, instances as nodes, provenance in `extras`). Surfaces without triangles are written
// empty-free: they are skipped and listed. Returns diagnostics; an error means nothing usable was written.
std::vector<Diagnostic> export_model(const Model& model, const std::string& path);

}  // namespace cadclash
