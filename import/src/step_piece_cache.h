// Products' shapes kept between runs (ImportOptions::cache_dir): the shapes a worker made of one
// piece of a cut STEP file (step_split_text.h), stored under the piece's canonical text, so a file
// read again after some of its products or placements changed parses and transfers only the
// pieces that changed. Internal to cadclash::import.
#pragma once

#include "step_split_text.h"

#include "cadclash/model.h"

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace cadclash::detail {

// The piece's shapes (ShapeBindings' bytes, step_parallel_transfer.h) from the cache in `dir`, with
// this file's ids; nullopt when the cache does not hold them. A damaged entry adds a warning naming
// `path` to `notes` and counts as not held. Precondition: the piece was split with `canonical`.
std::optional<std::string> load_cached_piece(const std::string& dir, const StepPiece& piece, const std::string& path,
                                             std::vector<Diagnostic>& notes);

// Stores a worker's bytes for the piece (its ids made canonical); false, and a warning in `notes`,
// when they cannot be stored. Precondition: the piece was split with `canonical`.
bool store_cached_piece(const std::string& dir, const StepPiece& piece, std::string_view bytes, const std::string& path,
                        std::vector<Diagnostic>& notes);

}  // namespace cadclash::detail
