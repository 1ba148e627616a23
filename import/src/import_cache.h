// The persistent cache of imported files (ImportOptions::cache_dir). Internal to cadclash::import.
#pragma once

#include "cadclash/import.h"

#include <functional>
#include <optional>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

namespace cadclash::detail {

// Reads `path` through the cache in options.cache_dir: a whole entry for the file's bytes and the
// options gives back what was stored (files[0].cache = Hit); otherwise `read(bytes)` runs and its
// result is stored (Miss, or Rebuilt with a warning first in the diagnostics when the entry was
// damaged). `read` gets the file's bytes this hashed (null when it could not read them: the reader
// then names the problem) and returns one file's result with files[0] set. A cache that cannot be
// read or written never stops the import: a warning says so and the file is read.
ImportResult cached_import(const std::string& path, const ImportOptions& options,
                           const std::function<ImportResult(const std::string* bytes)>& read);

// The bytes of the file at `path`; nullopt when it cannot be opened or read.
std::optional<std::string> file_bytes(const std::string& path);

// The file name of the entry for `path` read with `options` ("<64 hex digits>.entry"); nullopt when
// the file cannot be read. For the tests, which damage entries on purpose.
std::optional<std::string> cache_entry_name(const std::string& path, const ImportOptions& options);
// The file name of the placements entry of the file at `path` read with `options` (step_placements.h:
// the entry that lets an edit of its placements' numbers reuse the model read before).
std::string placements_entry_name(const std::string& path, const ImportOptions& options);

// One file's result as an entry's contents, and back. std::nullopt when the model holds a part whose
// source cannot be stored (neither none nor a BrepSource). load_import returns false and `why` when
// the contents are not whole. Without `exact_faces` a B-rep part is stored as its default deflection
// only (import_description), which load_import accepts only with `stand_ins`: the part then gets a
// source that knows that deflection and meshes nothing.
//
// A file's entry holds the B-rep parts that have entries of their own (brep_part_cache.h) by those
// entries' keys: save_import writes a part whose source `in_entries` names so, and load_import gives
// such a part no source and lists it in `referenced` (without `referenced`, it fails on one).
using PartEntries = std::unordered_map<const void*, std::string>;  // a part's source -> its entry's key
std::optional<std::string> save_import(const ImportResult& r, bool exact_faces = true, const PartEntries* in_entries = nullptr);
bool load_import(std::string_view bytes, ImportResult& r, std::string& why, bool stand_ins = false,
                 std::vector<std::pair<PartId, std::string>>* referenced = nullptr);

// The building blocks, for caches of pieces of files (step_piece_cache.h).
//
// The lines every key starts with: the cache format, the build of cadclash and OCCT's version.
std::string cache_versions();
std::string sha256_hex(std::string_view bytes);
// sha256_hex of bytes given a part at a time (one object per thread).
class Sha256Stream {
 public:
  Sha256Stream();
  ~Sha256Stream();
  Sha256Stream(const Sha256Stream&) = delete;
  Sha256Stream& operator=(const Sha256Stream&) = delete;
  void update(std::string_view bytes);
  std::string hex();  // of everything given; once

 private:
  void* context_;  // OpenSSL's EVP_MD_CTX
};
// An entry of `dir` for `key` (the entry file is named by the key's SHA-256 and holds the key
// whole): its payload when the entry is whole and for this key; `damaged` says why not when the
// file exists but is not (otherwise the entry is missing).
struct CacheRead {
  std::optional<std::string> payload;
  std::string damaged;
  std::string file;
};
CacheRead read_cache_entry(const std::string& dir, const std::string& key);
// Writes the entry whole or not at all (making `dir` when missing); false and `why` when it cannot.
bool write_cache_entry(const std::string& dir, const std::string& key, const std::string& payload, std::string& why);
// Warnings about the cache itself start with this; they are said by the run that met the problem
// and never stored in an entry.
inline constexpr std::string_view kCacheNote = "the cache entry ";
bool is_cache_note(const Diagnostic& d);

// A lazy import through the cache, for store_triangles_in_cache: the entries its parts came from
// or went to, each with what it holds (the parts' sources shared with the model read, so that the
// triangles a check gives them are seen) and how many faces of each part held triangles when it
// was last written.
struct CacheRecord {
  struct Entry {
    std::string key;
    ImportResult stored;
    std::vector<std::size_t> triangulated;
  };
  std::string dir;
  std::uint64_t max_bytes = 0;  // ImportOptions::cache_max_bytes
  std::optional<Entry> file;  // the whole file's entry
  std::vector<Entry> parts;   // each B-rep part's entry (brep_part_cache.h)
  PartEntries part_keys;      // the parts (lazy or not) that have entries of their own, by source
};
// Removes the least recently used entries of `dir` (oldest modification time first, then by name)
// until its entries take at most `max_bytes`; nothing when max_bytes is 0. Errors are ignored: an
// entry another run removes first, or one it is reading, costs nothing (POSIX keeps an open file).
void prune_cache(const std::string& dir, std::uint64_t max_bytes);

// Faces of the part's B-rep source that hold a triangulation; 0 for other parts.
std::size_t triangulated_faces(const Part& part);
// An entry of a record for `stored` (its parts' current triangulations counted).
CacheRecord::Entry record_entry(std::string key, ImportResult stored);

}  // namespace cadclash::detail
