// The import cache: entry names from a SHA-256 of the file and the options, entries checked whole
// before use, written through a temporary file and a rename.
#include "import_cache.h"
#include "step_placements.h"

#include "cadclash/internal/byte_io.h"

#include <BRep_Tool.hxx>
#include <Standard_Version.hxx>
#include <TopLoc_Location.hxx>
#include <openssl/evp.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cstring>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <future>
#include <limits>
#include <sstream>
#include <system_error>
#include <thread>

#include <dlfcn.h>
#include <sys/stat.h>
#include <unistd.h>

namespace cadclash::detail {
namespace {

// Bumped whenever the entry layout or what it stores (save_import, save_brep_source) changes; part
// of every key, so entries of another version are never looked up.
constexpr std::uint64_t kCacheFormat = 6;
constexpr std::string_view kMagic = "CCIMPORT";
constexpr std::size_t kDigestBytes = 32;
using Digest = std::array<unsigned char, kDigestBytes>;

Digest sha256(std::string_view bytes) {
  Digest d{};
  unsigned int n = 0;
  EVP_Digest(bytes.data(), bytes.size(), d.data(), &n, EVP_sha256(), nullptr);
  return d;
}

std::string hex(const Digest& d) {
  static constexpr char digits[] = "0123456789abcdef";
  std::string out;
  for (const unsigned char c : d) {
    out += digits[c >> 4];
    out += digits[c & 15];
  }
  return out;
}

}  // namespace

std::optional<std::string> file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::nullopt;
  // Sized once and read in one call: a stream copy of a 40 MB file costs several times more.
  std::error_code ec;
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  if (ec || size > std::numeric_limits<std::size_t>::max() / 2) {
    std::ostringstream buffer;  // not a regular file: as the stream gives it
    buffer << in.rdbuf();
    if (in.bad()) return std::nullopt;
    return std::move(buffer).str();
  }
  std::string out(static_cast<std::size_t>(size), '\0');
  in.read(out.data(), static_cast<std::streamsize>(out.size()));
  out.resize(static_cast<std::size_t>(in.gcount()));
  if (in.bad()) return std::nullopt;
  char more = 0;
  if (in.get(more)) {  // grew since its size was taken: the rest as the stream gives it
    std::ostringstream rest;
    rest << more << in.rdbuf();
    out += std::move(rest).str();
  }
  return out;
}

namespace {

// The build of cadclash reading the files: the file this code was loaded from (the program, or the
// Python module) by its canonical path, its size and modification time. Any rebuild changes it, so an entry written by
// another build, whose readers or tessellation may differ, is never looked up; stat is all it costs.
std::string build_identity() {
  static const std::string id = [] {
    Dl_info info{};
    std::string file = "/proc/self/exe";
    if (dladdr(reinterpret_cast<const void*>(&build_identity), &info) != 0 && info.dli_fname != nullptr &&
        info.dli_fname[0] == '/')
      file = info.dli_fname;
    // The same build by whatever name it was started (a relative path, /proc/self/exe, a link):
    // the key names the file itself, or every entry would miss when the command is typed differently.
    std::error_code ec;
    if (const std::filesystem::path real = std::filesystem::canonical(file, ec); !ec) file = real.string();
    struct stat st {};
    if (stat(file.c_str(), &st) != 0) return std::string("build unknown");
    return "build " + file + " " + std::to_string(st.st_size) + " " + std::to_string(st.st_mtim.tv_sec) + "." +
           std::to_string(st.st_mtim.tv_nsec);
  }();
  return id;
}

// Everything the stored result depends on, as text: the file's bytes (by hash) and path, each option
// that changes what is read or how it is tessellated, the versions of this cache and of OCCT, and the
// build reading them.
// Doubles in hexadecimal, so no two settings share a key. `parallel_files` and the threads BRepMesh
// uses do not change the result, so they are not in it.
std::string options_key(const std::string& path, const ImportOptions& o) {
  std::ostringstream k;
  k << std::hexfloat;
  k << "path " << path << "\ndeflection " << o.tessellation.linear_deflection << " relative "
    << o.tessellation.relative << " angular " << o.tessellation.angular_deflection << " verify "
    << o.tessellation.verify_deflection << " time limit " << o.tessellation.time_limit_seconds << "\nlazy " << o.lazy
    << " isolated " << o.isolate_cad_readers << " reader time limit " << o.reader_time_limit_seconds
    << " transfer healing " << o.transfer_healing << " model tolerance " << o.model_tolerance << " uncertainty " << static_cast<int>(o.uncertainty) << " "
    << o.uncertainty_value << '\n';
  return k.str();
}

std::string cache_key(const std::string& path, const std::string& bytes, const ImportOptions& o) {
  return "cadclash import cache " + std::to_string(kCacheFormat) + "\n" + build_identity() + "\nocct " + OCC_VERSION_COMPLETE +
         "\nfile sha256 " + hex(sha256(bytes)) + "\n" + options_key(path, o);
}

// A path's placements entry (step_placements.h): which entry holds the model of the file last
// read at `path`, what its text was without its placements' numbers, and how those numbers make
// its instances' poses. One per path and options: the file at a path is what users edit.
std::string placements_key(const std::string& path, const ImportOptions& o) {
  return "cadclash import cache " + std::to_string(kCacheFormat) + "\n" + build_identity() + "\nocct " + OCC_VERSION_COMPLETE +
         "\nplacements of the file at\n" + options_key(path, o);
}

std::string entry_name(const std::string& key) { return hex(sha256(key)) + ".entry"; }

// magic, format, key, payload size, SHA-256 of the payload, payload.
std::string entry_bytes(const std::string& key, const std::string& payload) {
  ByteWriter w;
  w.out += kMagic;
  w.u64(kCacheFormat);
  w.str(key);
  w.u64(payload.size());
  const Digest d = sha256(payload);
  w.out.append(reinterpret_cast<const char*>(d.data()), d.size());
  w.out += payload;
  return std::move(w.out);
}

// The payload of a whole entry for `key`; nullopt and `why` otherwise.
std::optional<std::string_view> entry_payload(std::string_view entry, const std::string& key, std::string& why) {
  if (entry.substr(0, kMagic.size()) != kMagic) {
    why = "not a cadclash cache entry";
    return std::nullopt;
  }
  ByteReader r{entry, kMagic.size()};
  if (r.u64() != kCacheFormat || !r.ok) {
    why = "written by another version of the cache";
    return std::nullopt;
  }
  if (r.str() != key || !r.ok) {
    why = "written for other input (its key differs)";
    return std::nullopt;
  }
  const std::uint64_t size = r.u64();
  if (!r.ok || entry.size() - r.at < kDigestBytes || entry.size() - r.at - kDigestBytes != size) {
    why = "its size is wrong (cut short or appended to)";
    return std::nullopt;
  }
  const std::string_view payload = entry.substr(r.at + kDigestBytes);
  const Digest stored = [&] {
    Digest d{};
    std::copy_n(entry.begin() + static_cast<std::ptrdiff_t>(r.at), kDigestBytes, d.begin());
    return d;
  }();
  if (sha256(payload) != stored) {
    why = "its checksum does not match its contents";
    return std::nullopt;
  }
  return payload;
}

// Writes the entry whole or not at all: a temporary file in the same directory, then a rename over
// the name (atomic on POSIX), so a concurrent run reads the old entry, the new one, or none.
bool write_entry(const std::filesystem::path& target, const std::string& bytes, std::string& why) {
  static std::atomic<unsigned> serial{0};
  const std::filesystem::path temporary =
      target.string() + ".tmp." + std::to_string(getpid()) + "." + std::to_string(serial++);
  {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    out.flush();
    if (!out) {
      why = "cannot write " + temporary.string();
      std::error_code ignored;
      std::filesystem::remove(temporary, ignored);
      return false;
    }
  }
  std::error_code ec;
  std::filesystem::rename(temporary, target, ec);
  if (ec) {
    why = "cannot rename " + temporary.string() + ": " + ec.message();
    std::filesystem::remove(temporary, ec);
    return false;
  }
  return true;
}

// An entry's use, for prune_cache: its modification time set to now (errors ignored).
void mark_used(const std::string& file) {
  std::error_code ignored;
  std::filesystem::last_write_time(file, std::filesystem::file_time_type::clock::now(), ignored);
}

double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

Diagnostic cache_warning(const std::string& path, std::string message) {
  return Diagnostic{Severity::Warning, path, 0, -1, std::move(message)};
}

// Whether a time limit cut the reading short: such a result depends on the machine's speed.
bool stopped_by_time_limit(const ImportResult& r, const ImportOptions& o) {
  if (!(o.reader_time_limit_seconds > 0.0) && !(o.tessellation.time_limit_seconds > 0.0)) return false;
  for (const Diagnostic& d : r.diagnostics)
    if (d.message.find("time limit") != std::string::npos) return true;
  return false;
}

}  // namespace

std::string sha256_hex(std::string_view bytes) { return hex(sha256(bytes)); }

Sha256Stream::Sha256Stream() : context_(EVP_MD_CTX_new()) {
  if (context_ == nullptr || EVP_DigestInit_ex(static_cast<EVP_MD_CTX*>(context_), EVP_sha256(), nullptr) != 1)
    throw std::bad_alloc();
}
Sha256Stream::~Sha256Stream() { EVP_MD_CTX_free(static_cast<EVP_MD_CTX*>(context_)); }
void Sha256Stream::update(std::string_view bytes) { EVP_DigestUpdate(static_cast<EVP_MD_CTX*>(context_), bytes.data(), bytes.size()); }
std::string Sha256Stream::hex() {
  Digest d{};
  unsigned int n = 0;
  EVP_DigestFinal_ex(static_cast<EVP_MD_CTX*>(context_), d.data(), &n);
  return cadclash::detail::hex(d);
}

std::string cache_versions() {
  std::ostringstream k;
  k << "cadclash import cache " << kCacheFormat << "\n" << build_identity() << "\nocct " << OCC_VERSION_COMPLETE << '\n';
  return k.str();
}

CacheRead read_cache_entry(const std::string& dir, const std::string& key) {
  CacheRead out;
  const std::filesystem::path entry = std::filesystem::path(dir) / entry_name(key);
  out.file = entry.string();
  const std::optional<std::string> stored = file_bytes(out.file);
  if (!stored) return out;
  if (const auto payload = entry_payload(*stored, key, out.damaged)) {
    out.payload.emplace(*payload);
    mark_used(out.file);
  }
  return out;
}

void prune_cache(const std::string& dir, std::uint64_t max_bytes) {
  if (max_bytes == 0 || dir.empty()) return;
  struct Held {
    std::filesystem::file_time_type used;
    std::string name;
    std::uintmax_t size;
  };
  std::vector<Held> held;
  std::uintmax_t total = 0;
  std::error_code ec;
  for (std::filesystem::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::filesystem::path& p = it->path();
    if (p.extension() != ".entry") continue;
    std::error_code e;
    const std::uintmax_t size = std::filesystem::file_size(p, e);
    const auto used = std::filesystem::last_write_time(p, e);
    if (e) continue;
    held.push_back({used, p.string(), size});
    total += size;
  }
  std::sort(held.begin(), held.end(), [](const Held& a, const Held& b) { return a.used != b.used ? a.used < b.used : a.name < b.name; });
  for (const Held& h : held) {
    if (total <= max_bytes) break;
    std::error_code e;
    std::filesystem::remove(h.name, e);
    total -= h.size;
  }
}

bool write_cache_entry(const std::string& dir, const std::string& key, const std::string& payload, std::string& why) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) {
    why = "cannot make the directory: " + ec.message();
    return false;
  }
  return write_entry(std::filesystem::path(dir) / entry_name(key), entry_bytes(key, payload), why);
}

bool is_cache_note(const Diagnostic& d) { return d.message.rfind(kCacheNote, 0) == 0; }

std::size_t triangulated_faces(const Part& part) {
  const auto* brep = dynamic_cast<const BrepSource*>(part.source.get());
  if (brep == nullptr) return 0;
  std::size_t n = 0;
  for (std::uint32_t f = 0; f < brep->face_count(); ++f) {
    TopLoc_Location where;
    n += BRep_Tool::Triangulation(brep->face(f), where).IsNull() ? 0 : 1;
  }
  return n;
}

CacheRecord::Entry record_entry(std::string key, ImportResult stored) {
  stored.files.clear();  // no record inside a record
  CacheRecord::Entry e{std::move(key), std::move(stored), {}};
  for (const Part& part : e.stored.model.parts) e.triangulated.push_back(triangulated_faces(part));
  return e;
}

namespace {

// The placements entry's payload: the skeleton of the file's text, the key of the entry holding its
// model, and its Placements.
std::string placements_payload(const std::string& skeleton, const std::string& file_key, const Placements& p,
                               const std::vector<std::int64_t>& free) {
  ByteWriter w;
  w.str(skeleton);
  w.str(file_key);
  w.str(save_placements(p));
  w.u64(free.size());
  for (const std::int64_t id : free) w.i64(id);
  return std::move(w.out);
}

// After `result` was read from `bytes` and stored under `file_key`, the path's placements entry is
// written when its instances are placed by numbers this can recompute (step_placements.h) and
// recomputing them from this text gives every pose bit for bit. Nothing said when it is not stored:
// the next edit of the file is then read as any other file is.
// Whether the file's placements can be recorded at all: a walk that warned about or dropped a pose
// placed it otherwise than its numbers say.
bool placements_recordable(const ImportResult& result) {
  if (result.files.empty() || !result.files.front().placements) return false;
  const Placements& p = *result.files.front().placements;
  if (p.components.empty() || p.chains.size() != result.model.instances.size()) return false;
  for (const Diagnostic& d : result.diagnostics)
    if (d.message.find(" is placed ") != std::string::npos) return false;
  return true;
}

// The placements entry's payload for the file's `bytes`; nullopt when no number of the file can
// change without changing more than poses, or when the poses this makes of its numbers are not the
// reader's (`instances`) bit for bit.
std::optional<std::string> placements_record(const std::string& bytes, const std::string& file_key, const Placements& p,
                                             const std::vector<Instance>& instances) {
  const std::optional<FreePlacementText> scanned = free_placement_text(bytes, p.value_ids(), p.axis_ids());
  if (!scanned || scanned->free.empty()) return std::nullopt;
  const std::vector<std::int64_t>& free = scanned->free;
  const PlacementText* text = &scanned->text;
  // Bit for bit: a pose the reader makes with a -0 where this makes a +0 is not the same pose.
  const std::optional<std::vector<Pose>> poses = placement_poses(p, text->values);
  if (!poses) return std::nullopt;
  for (std::size_t k = 0; k < poses->size(); ++k)
    if (std::memcmp((*poses)[k].matrix().data(), instances[k].pose.matrix().data(), 16 * sizeof(double)) != 0)
      return std::nullopt;
  return placements_payload(text->skeleton, file_key, p, free);
}

// A file's entry: its model, with the parts it holds by reference (save_import) read from their own
// entries on every thread and given this file's face ids. False, with `why`, when it cannot be; `why`
// empty when a part's entry is missing (the cache let it go: no damage, the file is read again).
// `record`, when given, gets each part entry as it was read (store_triangles_in_cache).
bool load_file_entry(std::string_view payload, const ImportOptions& options, ImportResult& out, std::string& why,
                     CacheRecord* record) {
  std::vector<std::pair<PartId, std::string>> referenced;
  if (!load_import(payload, out, why, false, &referenced)) return false;
  const std::size_t n = referenced.size();
  std::vector<std::optional<ImportResult>> loaded(n);
  std::vector<std::string> whys(n);
#pragma omp parallel for schedule(dynamic, 1) if (n > 1)
  for (std::ptrdiff_t i = 0; i < static_cast<std::ptrdiff_t>(n); ++i) {
    const auto k = static_cast<std::size_t>(i);
    const auto& [id, key] = referenced[k];
    const Part& part = out.model.parts[id];
    const CacheRead read = read_cache_entry(options.cache_dir, key);
    if (!read.payload) {
      if (!read.damaged.empty()) whys[k] = read.file + " is damaged (" + read.damaged + ")";
      continue;
    }
    ImportResult one;
    std::string one_why;
    auto* source = load_import(*read.payload, one, one_why) && one.model.parts.size() == 1
                       ? dynamic_cast<BrepSource*>(one.model.parts[0].source.get())
                       : nullptr;
    if (source == nullptr || source->face_count() != part.surface_count) {
      whys[k] = read.file + " is damaged (" + (one_why.empty() ? "it holds no part '" + part.name + "'" : one_why) + ")";
      continue;
    }
    std::vector<std::int64_t> ids(part.surface_count);
    for (std::uint32_t f = 0; f < part.surface_count; ++f) ids[f] = out.model.surfaces[part.first_surface + f].provenance.step_id;
    relabel_brep_faces(*source, ids, part.source_file);
    loaded[k] = std::move(one);
  }
  for (std::size_t k = 0; k < n; ++k)
    if (!loaded[k]) {
      why = whys[k];
      return false;
    }
  for (std::size_t k = 0; k < n; ++k) {
    const auto& [id, key] = referenced[k];
    out.model.parts[id].source = loaded[k]->model.parts[0].source;
    if (record == nullptr) continue;
    record->part_keys.emplace(out.model.parts[id].source.get(), key);
    if (options.lazy) record->parts.push_back(record_entry(key, std::move(*loaded[k])));
  }
  return true;
}

// The file at `path`, when the cache holds an earlier version of it that differs only in its
// placements' numbers, is that version's model with each instance's pose computed from `bytes`:
// first the plan (the entry holding the model and the poses), then the model loaded. A damaged
// placements entry adds a warning to `notes` (the file is then read, and the entry rewritten).
struct PlacedPlan {
  std::string file_key;
  std::vector<Pose> poses;
};
std::optional<PlacedPlan> placed_plan(const std::string& path, const std::string& bytes, const ImportOptions& options,
                                      std::vector<Diagnostic>& notes) {
  const CacheRead index = read_cache_entry(options.cache_dir, placements_key(path, options));
  if (!index.damaged.empty())
    notes.push_back(cache_warning(path, std::string(kCacheNote) + index.file + " is damaged (" + index.damaged +
                                            "); the file was read and the entry rewritten"));
  if (!index.payload) return std::nullopt;
  ByteReader r{*index.payload};
  const std::string skeleton = r.str(), file_key = r.str(), recipe = r.str();
  std::vector<std::int64_t> free(r.count(8));
  for (std::int64_t& id : free) id = r.i64();
  Placements p;
  if (!r.ok || r.at != index.payload->size() || !load_placements(recipe, p)) return std::nullopt;
  const std::optional<PlacementText> text = placement_text(bytes, p.value_ids(), free);
  if (!text || text->skeleton != skeleton) return std::nullopt;
  std::optional<std::vector<Pose>> poses = placement_poses(p, text->values);
  if (!poses) return std::nullopt;  // read: the reader says what is wrong with the new poses
  return PlacedPlan{file_key, std::move(*poses)};
}

std::optional<ImportResult> placed_import(const std::string& path, const ImportOptions& options, const PlacedPlan& plan) {
  const CacheRead file = read_cache_entry(options.cache_dir, plan.file_key);
  ImportResult placed;
  std::string why;
  auto record = std::make_shared<CacheRecord>();
  record->dir = options.cache_dir;
  record->max_bytes = options.cache_max_bytes;
  if (!file.payload || !load_file_entry(*file.payload, options, placed, why, record.get()) ||
      placed.model.instances.size() != plan.poses.size())
    return std::nullopt;
  placed.files.assign(1, FileImport{});
  placed.files.back().path = path;
  placed.files.back().cache = CacheUse::Placements;
  if (options.lazy) {  // triangles a check makes go to the entries the parts came from
    record->file = record_entry(plan.file_key, placed);
    placed.files.back().cache_record = std::move(record);
  }
  for (std::size_t k = 0; k < plan.poses.size(); ++k) placed.model.instances[k].pose = plan.poses[k];
  return placed;
}

}  // namespace

std::string placements_entry_name(const std::string& path, const ImportOptions& options) {
  return entry_name(placements_key(path, options));
}

std::optional<std::string> cache_entry_name(const std::string& path, const ImportOptions& options) {
  const std::optional<std::string> bytes = file_bytes(path);
  if (!bytes) return std::nullopt;
  return entry_name(cache_key(path, *bytes, options));
}

ImportResult cached_import(const std::string& path, const ImportOptions& options,
                           const std::function<ImportResult(const std::string* bytes)>& read) {
  const std::optional<std::string> bytes = file_bytes(path);
  if (!bytes) return read(nullptr);  // the reader names the problem (no such file, a directory, ...)
  // Whether the file differs from an earlier one only in its placements' numbers is worked out
  // while its key is hashed and its entry looked for (a pass over the text each; here when no
  // thread can be started); asked only when the file has no entry of its own.
  const auto placed_start = std::chrono::steady_clock::now();
  std::vector<Diagnostic> placed_notes;
  std::future<std::optional<PlacedPlan>> plan =
      std::async(std::launch::async | std::launch::deferred, [&] { return placed_plan(path, *bytes, options, placed_notes); });
  const std::string key = cache_key(path, *bytes, options);
  const std::filesystem::path dir(options.cache_dir);
  const std::filesystem::path entry = dir / entry_name(key);

  std::optional<Diagnostic> damaged;
  if (const std::optional<std::string> stored = file_bytes(entry.string())) {
    const auto load_start = std::chrono::steady_clock::now();
    std::string why;
    ImportResult hit;
    auto record = std::make_shared<CacheRecord>();
    record->dir = options.cache_dir;
    record->max_bytes = options.cache_max_bytes;
    const auto payload = entry_payload(*stored, key, why);
    if (payload && load_file_entry(*payload, options, hit, why, record.get())) {
      hit.files.assign(1, FileImport{});
      hit.files.back().path = path;
      hit.files.back().cache = CacheUse::Hit;
      hit.files.back().timings.read = seconds_since(load_start);
      mark_used(entry.string());
      prune_cache(options.cache_dir, options.cache_max_bytes);
      if (options.lazy) {
        record->file = record_entry(key, hit);
        hit.files.back().cache_record = std::move(record);
      }
      return hit;
    }
    if (!why.empty())
      damaged = cache_warning(path, std::string(kCacheNote) + entry.string() + " is damaged (" + why +
                                        "); the file was read again and the entry rewritten");
  }

  const std::optional<PlacedPlan> placed_as = plan.get();
  if (damaged) placed_notes.clear();  // the file is read: its placements entry was not asked
  if (!damaged && placed_as) {
    if (std::optional<ImportResult> placed = placed_import(path, options, *placed_as)) {
      placed->files.back().timings.read = seconds_since(placed_start);
      prune_cache(options.cache_dir, options.cache_max_bytes);
      return std::move(*placed);
    }
  }

  ImportResult result = read(&*bytes);  // the bytes hashed are the bytes read
  result.diagnostics.insert(result.diagnostics.begin(), placed_notes.begin(), placed_notes.end());
  result.files.front().cache = damaged ? CacheUse::Rebuilt : CacheUse::Miss;
  if (stopped_by_time_limit(result, options)) return result;
  // Stored without this run's warning about the damaged entry: a later run read from it says what
  // reading the file said.
  // Notes of this run's cache use (a damaged entry of a product, read again) are not stored either.
  std::vector<Diagnostic> notes;
  std::erase_if(result.diagnostics, [&](const Diagnostic& d) {
    if (!is_cache_note(d)) return false;
    notes.push_back(d);
    return true;
  });
  // The placements' record (a pass over the text and its hash) is made while the model is written
  // out; it reads only the placements, the poses and the text, which nothing here changes.
  std::optional<std::string> placements;
  std::thread recorder;
  auto record_placements = [&] {
    try {
      placements = placements_record(*bytes, key, *result.files.front().placements, result.model.instances);
    } catch (...) {  // (bad_alloc) not recorded: the next edit of the file is read as any other
      placements.reset();
    }
  };
  if (placements_recordable(result)) {
    try {
      recorder = std::thread(record_placements);
    } catch (const std::system_error&) {  // no thread to spare: recorded here
      record_placements();
    }
  }
  const std::shared_ptr<CacheRecord>& made = result.files.front().cache_record;
  const std::optional<std::string> payload = save_import(result, true, made ? &made->part_keys : nullptr);
  if (recorder.joinable()) recorder.join();
  result.diagnostics.insert(result.diagnostics.begin(), notes.begin(), notes.end());
  if (damaged) result.diagnostics.insert(result.diagnostics.begin(), *damaged);
  if (!payload) return result;  // a part this cache cannot store: read every time
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  std::string why;
  if (ec) why = "cannot make the directory: " + ec.message();
  if (ec || !write_entry(entry, entry_bytes(key, *payload), why)) {
    result.diagnostics.push_back(cache_warning(path, "could not store the file in the cache " + dir.string() + " (" + why + ")"));
  } else if (options.lazy) {
    std::shared_ptr<CacheRecord>& record = result.files.front().cache_record;
    if (!record) record = std::make_shared<CacheRecord>();
    record->dir = options.cache_dir;
    record->max_bytes = options.cache_max_bytes;
    ImportResult stored;
    stored.model = result.model;
    stored.complete = result.complete;
    for (const Diagnostic& d : result.diagnostics)  // as the entry holds them: without this run's notes
      if (!is_cache_note(d)) stored.diagnostics.push_back(d);
    record->file = record_entry(key, std::move(stored));
  }
  if (!ec && why.empty() && placements) write_cache_entry(options.cache_dir, placements_key(path, options), *placements, why);
  prune_cache(options.cache_dir, options.cache_max_bytes);
  return result;
}

}  // namespace cadclash::detail

namespace cadclash {

std::size_t store_triangles_in_cache(const ImportResult& imported, std::vector<Diagnostic>& diagnostics) {
  std::size_t written = 0;
  for (const FileImport& f : imported.files) {
    if (!f.cache_record) continue;
    detail::CacheRecord& record = *f.cache_record;
    bool unwritable = false;  // one warning per file, not one per entry
    // The file's entry holds the parts with entries of their own by reference: their triangles go
    // to those entries, not to it.
    auto store = [&](detail::CacheRecord::Entry& e, const detail::PartEntries* referenced) {
      if (unwritable) return;
      bool gained = false;
      std::vector<std::size_t> now;
      for (const Part& part : e.stored.model.parts)
        now.push_back(referenced && referenced->count(part.source.get()) ? 0 : detail::triangulated_faces(part));
      for (std::size_t p = 0; p < now.size(); ++p) gained = gained || now[p] > e.triangulated[p];
      if (!gained) return;
      std::string why = "a part cannot be stored";
      const std::optional<std::string> payload = detail::save_import(e.stored, true, referenced);
      if (payload && detail::write_cache_entry(record.dir, e.key, *payload, why)) {
        e.triangulated = std::move(now);
        ++written;
        return;
      }
      unwritable = true;
      diagnostics.push_back({Severity::Warning, f.path, 0, -1,
                             std::string(detail::kCacheNote) + "for the triangles of '" + f.path +
                                 "' could not be written in " + record.dir + " (" + why + ")"});
    };
    if (record.file) store(*record.file, &record.part_keys);
    for (detail::CacheRecord::Entry& e : record.parts) store(e, nullptr);
    detail::prune_cache(record.dir, record.max_bytes);
  }
  return written;
}

}  // namespace cadclash
