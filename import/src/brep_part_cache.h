// B-rep parts kept between runs (ImportOptions::cache_dir): what add_brep_parts made of a part
// (healed faces, exact boxes, face facts, eager triangles, its diagnostics), stored under a digest
// of everything it was made from, so a part that did not change is not checked and healed again.
// Internal to cadclash::import.
#pragma once

#include "cadclash/import.h"
#include "cadclash/tessellate.h"
#include "import_cache.h"

#include <TopoDS_Shape.hxx>

#include <span>
#include <string>
#include <vector>

namespace cadclash::detail {

// Parts a reader's child sent each on its own (cad_transfer.cpp): per part the bytes BinTools wrote
// for its shape (without triangles), which are what its key hashes, and the shape they make, made
// only when the cache does not hold the part (so that parts[k].shape, which points to shapes[k],
// is null until then). Parts sent apart share no sub-shape, surface or curve.
struct PackedShapes {
  std::span<const std::string> bytes;
  std::span<TopoDS_Shape> shapes;
};

// add_brep_parts(model, parts, options.tessellation, options.lazy, ...) through the cache in
// options.cache_dir: the same parts, surfaces, diagnostics and completeness, in input order. A part
// comes from its entry when one is held for the same shape (its bytes in OCCT's binary format),
// name, file, kind, face tags and tessellation settings; the others are made and stored. Without a
// cache, with a tessellation time limit, or when two parts share an edge (one part's healing and
// meshing then reach the other's), it is add_brep_parts. A damaged entry is made again, rewritten,
// and named in a warning. `from_cache`, when given, gets how many parts came from entries; `record`,
// when given, gets the key of each part that has an entry (for the file's entry, which names it)
// and, when the import is lazy, each part's entry (store_triangles_in_cache). With `packed`, the
// parts' shapes are made from their bytes where they are needed (a shape OCCT cannot make from them
// is an error, and its part has no faces).
// Precondition: packed->bytes and packed->shapes, when given, have one element per part.
std::vector<PartId> add_brep_parts_cached(Model& model, std::span<const BrepPartInput> parts, const ImportOptions& options,
                                          std::vector<Diagnostic>& diagnostics, bool& complete, BrepPartTimings* timings,
                                          std::size_t* from_cache = nullptr, CacheRecord* record = nullptr,
                                          const PackedShapes* packed = nullptr);

}  // namespace cadclash::detail
