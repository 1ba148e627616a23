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
  std::size_t bytes = 0;           // of the statements inside its items
  // What it costs to read, in bytes' worth (for sharing pieces out): its bytes, and for each face
  // with n bounds 2 n^2 / 3 (OCCT's healing at transfer compares every wire with every other).
  std::size_t weight = 0;
  // With `canonical` asked: the SHA-256 (hex) of the piece's canonical text, its schema and
  // statements with ids renumbered 1, 2, ... in the order the piece defines them (the same for the
  // same product however the rest of the file is numbered; hashed as it is made, never held
  // whole), and ids[c - 1] the id in `text` of canonical id c.
  std::string canonical_sha256;
  std::vector<std::int64_t> ids;
};

struct StepSplit {
  std::string main_text;
  std::vector<StepPiece> pieces;  // one per group of items that share topology, at least two
};

// The file cut into one piece per group of items (items that reach a common entity other than a
// point, direction, vector or placement share a group). nullopt, with `why_not`, when the text
// holds fewer than two such groups, or anything the cut does not handle: comments, a reference to
// an undefined id, a truncated file, mapped items, non-manifold or complex-typed shape
// representations, an item without a representation or in representations of different contexts,
// or a named piece of an item that is not a face, shell or solid.
std::optional<StepSplit> split_step_text(const std::string& text, bool canonical, std::string& why_not);

// The pieces listed in `which` shared out over at most `workers` processes, balanced by their
// weights (largest first onto the least loaded; ties: lower index); each share in ascending piece order.
// Precondition: workers >= 1.
std::vector<std::vector<std::size_t>> share_pieces(const std::vector<StepPiece>& pieces,
                                                    const std::vector<std::size_t>& which, std::size_t workers);

}  // namespace cadclash::detail
