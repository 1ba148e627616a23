// A STEP file's text cut into pieces that processes parse and transfer at once: each piece holds
// the insides of some B-rep items (solids, shells and everything below them) with a representation
// that gives them their units; what is left (products, assembly, representations, styles) is the
// main text, where each item and each face named from outside an item stands in as a small
// placeholder of the same type and name. The reader binds the placeholders to the pieces' shapes
// before its transfer, which then makes what it makes from the whole file. Internal to
// cadclash::import.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace cadclash::detail {

struct StepPiece {
  std::string text;                // a whole STEP file: the original header, the entities, the end
  std::vector<std::int64_t> reps;  // representations to transfer, in order (ids in `text`)
  std::vector<std::int64_t> bind;  // ids whose shapes the main reader needs (its placeholders), ascending
};

struct StepSplit {
  std::string main_text;
  std::vector<StepPiece> pieces;  // at least two
  std::size_t groups = 0;         // sets of items that share topology (each in one piece)
};

// The file cut for `workers` processes (items that reach a common entity other than a point,
// direction, vector or placement share a piece; pieces balanced by their bytes). nullopt, with
// `why_not`, when the text holds fewer than two such sets, or anything the cut does not handle:
// comments, a reference to an undefined id, a truncated file, mapped items, non-manifold or
// complex-typed shape representations, an item without a representation or in representations of
// different contexts, or a named piece of an item that is not a face, shell or solid.
std::optional<StepSplit> split_step_text(const std::string& text, std::size_t workers, std::string& why_not);

}  // namespace cadclash::detail
