// The import cache (ImportOptions::cache_dir): a file read from its entry is the file as read, down to
// the B-rep faces a certified check queries; damaged or stale entries are never trusted.
#include "cadclash/import.h"
#include "cadclash/report.h"
#include "../test_temp.h"
#include "import_cache.h"
#include "import_compare.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace cadclash {
namespace {

namespace fs = std::filesystem;
using testing_import::check_text;
using testing_import::everything;
using testing_import::messages;
using testing_import::read_bytes;
using testing_import::write_bytes;
using testing_import::same_bytes;

const std::string kExternal = std::string(CADCLASH_DATA_DIR) + "/external/";

// A cache directory of its own for each test.
std::string fresh_cache(const std::string& name) {
  const fs::path dir = fs::path(testing::scratch_dir()) / ("cache-" + name);
  fs::remove_all(dir);
  return dir.string();
}

class CacheRoundTrip : public ::testing::TestWithParam<bool> {};  // lazy or eager

TEST_P(CacheRoundTrip, WarmRunIsTheColdRun) {
  const std::string path = kExternal + "as1-tu-203.stp";
  if (!fs::exists(path)) GTEST_SKIP() << path << " missing: run scripts/setup.sh";
  ImportOptions options;
  options.lazy = GetParam();
  const ImportResult reference = import_file(path, options);  // no cache
  options.cache_dir = fresh_cache(GetParam() ? "lazy" : "eager");
  const ImportResult cold = import_file(path, options);
  const ImportResult warm = import_file(path, options);
  ASSERT_EQ(cold.files.size(), 1u);
  ASSERT_EQ(warm.files.size(), 1u);
  EXPECT_EQ(reference.files[0].cache, CacheUse::Off);
  EXPECT_EQ(cold.files[0].cache, CacheUse::Miss);
  EXPECT_EQ(warm.files[0].cache, CacheUse::Hit);
  EXPECT_EQ(warm.files[0].timings.tessellate, 0.0);
  EXPECT_EQ(messages(warm), messages(reference));
  EXPECT_TRUE(same_bytes(everything(cold), everything(reference)));
  EXPECT_TRUE(same_bytes(everything(warm), everything(reference)));
  // The certified decisions query the exact faces (witness points, exact distances): the same answers.
  const std::string report = check_text(reference);
  EXPECT_EQ(check_text(cold), report);
  EXPECT_EQ(check_text(warm), report);
  EXPECT_NE(report.find("\"pairs\""), std::string::npos);
}

INSTANTIATE_TEST_SUITE_P(LazyAndEager, CacheRoundTrip, ::testing::Bool());

// A mesh file (no exact geometry) and a CAD file with damage (its diagnostics come back from the entry).
TEST(ImportCache, MeshesAndDiagnosticsComeBack) {
  const std::string cache = fresh_cache("mixed");
  for (const std::string& path : {std::string(CADCLASH_DATA_DIR) + "/collide/box_a.obj",
                                 std::string(CADCLASH_DATA_DIR) + "/cad/truncated.step"}) {
    SCOPED_TRACE(path);
    ImportOptions options;
    const ImportResult reference = import_file(path, options);
    options.cache_dir = cache;
    const ImportResult cold = import_file(path, options);
    const ImportResult warm = import_file(path, options);
    EXPECT_EQ(warm.files[0].cache, CacheUse::Hit);
    EXPECT_EQ(messages(warm), messages(reference));
    EXPECT_EQ(warm.complete, reference.complete);
    EXPECT_TRUE(same_bytes(everything(warm), everything(reference)));
  }
}

// Every way an entry can be damaged is found before its contents are used: the file is read again,
// a warning names the entry, the result is the file as read, and the rewritten entry is whole.
TEST(ImportCache, DamagedEntriesAreRebuilt) {
  const std::string path = kExternal + "screw.step";
  if (!fs::exists(path)) GTEST_SKIP() << path << " missing: run scripts/setup.sh";
  ImportOptions options;
  options.cache_dir = fresh_cache("damaged");
  const ImportResult cold = import_file(path, options);
  ASSERT_EQ(cold.files[0].cache, CacheUse::Miss);
  const std::optional<std::string> name = detail::cache_entry_name(path, options);
  ASSERT_TRUE(name);
  const std::string entry = (fs::path(options.cache_dir) / *name).string();
  const std::string good = read_bytes(entry);
  ASSERT_GT(good.size(), 1000u);

  struct Damage {
    const char* what;
    std::string bytes;
  };
  std::string flipped_payload = good, flipped_key = good, flipped_face = good;
  flipped_payload[good.size() - 7] ^= 0x10;
  flipped_key[20] ^= 0x01;
  flipped_face[good.size() / 2] ^= 0x40;
  const std::vector<Damage> damages{
      {"truncated", good.substr(0, good.size() / 3)},
      {"one byte short", good.substr(0, good.size() - 1)},
      {"a byte appended", good + "x"},
      {"a payload bit flipped", flipped_payload},
      {"a bit flipped in the middle", flipped_face},
      {"a key bit flipped", flipped_key},
      {"empty", ""},
      {"another file", "CCIMPORT but not really"},
  };
  for (const Damage& d : damages) {
    SCOPED_TRACE(d.what);
    write_bytes(entry, d.bytes);
    const ImportResult rebuilt = import_file(path, options);
    EXPECT_EQ(rebuilt.files[0].cache, CacheUse::Rebuilt);
    ASSERT_FALSE(rebuilt.diagnostics.empty());
    EXPECT_EQ(rebuilt.diagnostics[0].severity, Severity::Warning);
    EXPECT_NE(rebuilt.diagnostics[0].message.find("is damaged"), std::string::npos) << rebuilt.diagnostics[0].message;
    EXPECT_NE(rebuilt.diagnostics[0].message.find(*name), std::string::npos);
    ImportResult without_warning = rebuilt;
    without_warning.diagnostics.erase(without_warning.diagnostics.begin());
    EXPECT_EQ(messages(without_warning), messages(cold));
    EXPECT_TRUE(same_bytes(everything(without_warning), everything(cold)));
    EXPECT_EQ(read_bytes(entry), good);  // rewritten whole
    const ImportResult again = import_file(path, options);
    EXPECT_EQ(again.files[0].cache, CacheUse::Hit);
    EXPECT_EQ(messages(again), messages(cold));
  }
}

// The key covers the file's bytes and every setting that changes the result; a changed file is read
// again, the others come from the cache.
TEST(ImportCache, OnlyChangedFilesAreReadAgain) {
  const std::string as1 = kExternal + "as1-tu-203.stp", screw = kExternal + "screw.step";
  if (!fs::exists(as1) || !fs::exists(screw)) GTEST_SKIP() << "data/external missing: run scripts/setup.sh";
  const std::string copy = (fs::path(testing::scratch_dir()) / "screw-copy.step").string();
  write_bytes(copy, read_bytes(screw));
  ImportOptions options;
  options.cache_dir = fresh_cache("changed");
  const std::vector<std::string> files{as1, copy};
  const ImportResult cold = import_files(files, options);
  ASSERT_EQ(cold.files.size(), 2u);
  EXPECT_EQ(cold.files[0].cache, CacheUse::Miss);
  EXPECT_EQ(cold.files[1].cache, CacheUse::Miss);

  // The same bytes with a comment added: another file to the cache.
  write_bytes(copy, read_bytes(screw) + "/* edited */\n");
  const ImportResult edited = import_files(files, options);
  EXPECT_EQ(edited.files[0].cache, CacheUse::Hit);
  EXPECT_EQ(edited.files[1].cache, CacheUse::Miss);
  EXPECT_TRUE(same_bytes(everything(edited), everything(cold)));  // the comment changes nothing read

  ImportOptions finer = options;
  finer.tessellation.linear_deflection = 0.05;
  EXPECT_EQ(import_file(as1, finer).files[0].cache, CacheUse::Miss);
  ImportOptions lazy = options;
  lazy.lazy = true;
  EXPECT_EQ(import_file(as1, lazy).files[0].cache, CacheUse::Miss);
  ImportOptions parallel = options;
  parallel.parallel_files = 1;  // does not change the result: the same entry
  EXPECT_EQ(import_file(as1, parallel).files[0].cache, CacheUse::Hit);
}

// A cache kept under its cap (ImportOptions::cache_max_bytes): the least recently used entries go
// first. An old file's entries are removed, the ones just read stay; the old file read again is
// read from the file, as without a cache.
TEST(ImportCache, KeptUnderItsCapLeastRecentlyUsedFirst) {
  const std::string old_file = kExternal + "screw.step", recent = std::string(CADCLASH_DATA_DIR) + "/cad/valid_two_solids.step";
  if (!fs::exists(old_file)) GTEST_SKIP() << old_file << " missing: run scripts/setup.sh";
  ImportOptions options;
  options.cache_dir = fresh_cache("capped");
  auto entries = [&] {
    std::map<std::string, std::uintmax_t> out;
    for (const auto& e : fs::directory_iterator(options.cache_dir)) out[e.path().filename().string()] = fs::file_size(e.path());
    return out;
  };
  auto bytes = [](const std::map<std::string, std::uintmax_t>& m) {
    std::uintmax_t n = 0;
    for (const auto& [name, size] : m) n += size;
    return n;
  };
  import_file(old_file, options);
  const auto old_entries = entries();
  import_file(recent, options);
  const auto all = entries();
  std::map<std::string, std::uintmax_t> recent_entries;
  for (const auto& [name, size] : all)
    if (!old_entries.count(name)) recent_entries[name] = size;
  ASSERT_FALSE(recent_entries.empty());
  ASSERT_GT(old_entries.size(), 1u);  // the file's and its parts'

  options.cache_max_bytes = bytes(recent_entries);
  const ImportResult hit = import_file(recent, options);  // a hit, which uses the recent file's entry
  EXPECT_EQ(hit.files[0].cache, CacheUse::Hit);
  const auto kept = entries();
  EXPECT_LE(bytes(kept), options.cache_max_bytes);
  for (const auto& [name, size] : old_entries) EXPECT_EQ(kept.count(name), 0u) << name;
  EXPECT_EQ(kept.count(*detail::cache_entry_name(recent, options)), 1u);

  options.cache_max_bytes = 0;
  const ImportResult again = import_file(old_file, options);
  EXPECT_EQ(again.files[0].cache, CacheUse::Miss);
  ImportOptions plain;
  EXPECT_EQ(messages(again), messages(import_file(old_file, plain)));
  EXPECT_TRUE(same_bytes(everything(again), everything(import_file(old_file, plain))));
}

// Parts of one file healed and meshed on several threads (TessellationOptions::parallel, the default),
// BRepMesh spreading each part's faces over threads too: the same model and check as one thread.
TEST(ImportParallel, PartsMeshedInParallelAsOneAfterAnother) {
  for (const char* name : {"as1-tu-203.stp", "linkrods.step"}) {
    const std::string path = kExternal + name;
    if (!fs::exists(path)) GTEST_SKIP() << path << " missing: run scripts/setup.sh";
    SCOPED_TRACE(name);
    ImportOptions serial;
    serial.tessellation.parallel = false;
    const ImportResult one = import_file(path, serial);
    const ImportResult many = import_file(path, ImportOptions{});
    EXPECT_GT(one.model.parts.size(), 0u);
    EXPECT_EQ(messages(many), messages(one));
    EXPECT_TRUE(same_bytes(everything(many), everything(one)));
    EXPECT_EQ(check_text(many), check_text(one));
  }
}

// A cache directory that cannot be made costs a warning, not the import.
TEST(ImportCache, UnwritableCacheIsAWarning) {
  const std::string path = std::string(CADCLASH_DATA_DIR) + "/collide/box_a.obj";
  const std::string blocker = testing::write_scratch_file("not-a-directory", "x");
  ImportOptions options;
  options.cache_dir = blocker + "/cache";
  const ImportResult r = import_file(path, options);
  EXPECT_FALSE(r.model.surfaces.empty());
  ASSERT_FALSE(r.diagnostics.empty());
  EXPECT_EQ(r.diagnostics.back().severity, Severity::Warning);
  EXPECT_NE(r.diagnostics.back().message.find("could not store the file in the cache"), std::string::npos);

  // A STEP file cut into pieces, with parts: one warning for the pieces, one for the parts, one for
  // the file (not one per piece or part), and the file as read without a cache.
  const std::string step = std::string(CADCLASH_DATA_DIR) + "/cad/valid_two_solids.step";
  options.transfer_workers = 2;
  const ImportResult cut = import_file(step, options);
  ImportOptions plain = options;
  plain.cache_dir.clear();
  const ImportResult fresh = import_file(step, plain);
  ASSERT_GT(cut.files[0].pieces, 1u);
  std::vector<std::string> warnings = messages(cut);
  std::erase_if(warnings, [](const std::string& m) { return m.find("could not") == std::string::npos; });
  EXPECT_EQ(warnings.size(), 3u) << ::testing::PrintToString(warnings);
  ImportResult without = cut;
  std::erase_if(without.diagnostics, [](const Diagnostic& d) { return d.message.find("could not") != std::string::npos; });
  EXPECT_TRUE(same_bytes(everything(without), everything(fresh)));
}

}  // namespace
}  // namespace cadclash
