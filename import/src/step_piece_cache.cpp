// The cache of STEP pieces' shapes (step_piece_cache.h): entries of the import cache's directory,
// keyed by the SHA-256 of a piece's canonical text; ids stored canonical, mapped to each file's.
#include "step_piece_cache.h"

#include "cad_xcaf.h"
#include "import_cache.h"
#include "step_parallel_transfer.h"

#include <unordered_map>

namespace cadclash::detail {
namespace {

std::string piece_key(const StepPiece& piece) {
  // The piece's shapes are transferred with this thread's healing setting (cad_xcaf.h).
  return cache_versions() + "step piece sha256 " + piece.canonical_sha256 +
         (transfer_healing_on() ? "\n" : "\nno transfer healing\n");
}

Diagnostic note(const std::string& path, std::string message) {
  return Diagnostic{Severity::Warning, path, 0, -1, std::string(kCacheNote) + std::move(message)};
}

}  // namespace

std::optional<std::string> load_cached_piece(const std::string& dir, const StepPiece& piece, const std::string& path,
                                             std::vector<Diagnostic>& notes) {
  const CacheRead read = read_cache_entry(dir, piece_key(piece));
  std::string why = read.damaged;
  if (read.payload) {
    const std::size_t n = piece.ids.size();
    std::optional<std::string> bytes = renumber_bindings(*read.payload, [&](std::int64_t c) -> std::optional<std::int64_t> {
      if (c < 1 || static_cast<std::size_t>(c) > n) return std::nullopt;
      return piece.ids[static_cast<std::size_t>(c - 1)];
    });
    if (bytes) return bytes;
    why = "its shapes name entities the piece does not hold";
  }
  if (!why.empty())
    notes.push_back(note(path, read.file + " is damaged (" + why +
                                   "); that product's shapes were read from the file again and the entry rewritten"));
  return std::nullopt;
}

bool store_cached_piece(const std::string& dir, const StepPiece& piece, std::string_view bytes, const std::string& path,
                        std::vector<Diagnostic>& notes) {
  std::unordered_map<std::int64_t, std::int64_t> canonical;
  canonical.reserve(piece.ids.size());
  for (std::size_t c = 0; c < piece.ids.size(); ++c) canonical.emplace(piece.ids[c], static_cast<std::int64_t>(c + 1));
  const std::optional<std::string> stored = renumber_bindings(bytes, [&](std::int64_t id) -> std::optional<std::int64_t> {
    const auto it = canonical.find(id);
    if (it == canonical.end()) return std::nullopt;
    return it->second;
  });
  std::string why = "a worker's shapes name entities the piece does not hold";
  if (stored && write_cache_entry(dir, piece_key(piece), *stored, why)) return true;
  notes.push_back(note(path, "for a product's shapes could not be written in " + dir + " (" + why + ")"));
  return false;
}

}  // namespace cadclash::detail
