// B-rep parts kept between runs (ImportOptions::cache_dir): what add_brep_parts made of a part
// (healed faces, exact boxes, face facts, eager triangles, its diagnostics), stored under a digest
// of everything it was made from, so a part that did not change is not checked and healed again.
// Internal to cadclash::import.
#pragma once

#include "cadclash/import.h"
#include "cadclash/tessellate.h"
#include "import_cache.h"

#include <span>
#include <vector>

namespace cadclash::detail {

// add_brep_parts(model, parts, options.tessellation, options.lazy, ...) through the cache in
// options.cache_dir: the same parts, surfaces, diagnostics and completeness, in input order. A part
// comes from its entry when one is held for the same shape (its bytes in OCCT's binary format),
// name, file, kind, face tags and tessellation settings; the others are made and stored. Without a
// cache, with a tessellation time limit, or when two parts share an edge (one part's healing and
// meshing then reach the other's), it is add_brep_parts. A damaged entry is made again, rewritten,
// and named in a warning. `from_cache`, when given, gets how many parts came from entries; `record`,
// when given, gets the key of each part that has an entry (for the file's entry, which names it)
// and, when the import is lazy, each part's entry (store_triangles_in_cache).
std::vector<PartId> add_brep_parts_cached(Model& model, std::span<const BrepPartInput> parts, const ImportOptions& options,
                                          std::vector<Diagnostic>& diagnostics, bool& complete, BrepPartTimings* timings,
                                          std::size_t* from_cache = nullptr, CacheRecord* record = nullptr);

}  // namespace cadclash::detail
