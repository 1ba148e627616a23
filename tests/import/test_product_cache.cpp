// The import cache per product (ImportOptions::cache_dir on a STEP file cut into pieces): a file
// read again after a placement was edited, its ids renumbered, or one product's geometry changed
// takes every unchanged product's shapes and healed parts from the cache and gives what reading it
// afresh gives; damaged entries of products are never trusted.
#include "cadclash/import.h"
#include "../test_temp.h"
#include "import_cache.h"
#include "import_compare.h"

#include <gtest/gtest.h>

#include <algorithm>

#include <bit>
#include <filesystem>
#include <fstream>
#include <iterator>
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

// The truth tests' board written as a STEP assembly by OCCT's XCAF writer (7 products, 100 items).
std::string board(const std::string& name) {
  const std::string out = (fs::path(testing::scratch_dir()) / name).string();
  const std::string command = std::string("'") + CADCLASH_WRITE_BOARD_STEP + "' '" + CADCLASH_DATA_DIR + "/external' '" +
                              out + "' 1 >/dev/null";
  EXPECT_EQ(std::system(command.c_str()), 0) << command;
  return out;
}

// The statement "#id = ...;" of `text`, from '#' to ';'.
std::pair<std::size_t, std::size_t> statement(const std::string& text, const std::string& id) {
  std::string head = "\n";  // two steps: GCC 12 warns falsely (-Wrestrict) on "\n" + string
  head += id + " = ";
  const std::size_t at = text.find(head);
  EXPECT_NE(at, std::string::npos) << id;
  return {at + 1, text.find(';', at) + 1};
}

// The n-th reference "#k" inside statement `s` (0: the first after '=').
std::string reference(const std::string& text, std::pair<std::size_t, std::size_t> s, int n) {
  std::size_t at = text.find('=', s.first);
  for (int k = 0; k <= n; ++k) at = text.find('#', at + 1);
  std::size_t end = at + 1;
  while (std::isdigit(static_cast<unsigned char>(text[end]))) ++end;
  return text.substr(at, end - at);
}

// The point of the placement an occurrence is moved by, moved 0.5 mm along x: an edited placement.
std::string with_placement_moved(std::string text) {
  const std::size_t transformation = text.find("= ITEM_DEFINED_TRANSFORMATION(");
  EXPECT_NE(transformation, std::string::npos);
  const std::size_t start = text.rfind('\n', transformation) + 1;
  const auto s = std::make_pair(start, text.find(';', start) + 1);
  const std::string placement = reference(text, s, 1);
  const std::string point = reference(text, statement(text, placement), 0);
  const auto p = statement(text, point);
  const std::string old = text.substr(p.first, p.second - p.first);
  const std::size_t open = old.rfind('(') + 1;  // CARTESIAN_POINT(name,(x,y,z))
  const std::size_t comma = old.find(',', open);
  const double x = std::stod(old.substr(open, comma - open));
  const std::string moved = old.substr(0, open) + std::to_string(x + 0.5) + old.substr(comma);
  text.replace(p.first, p.second - p.first, moved);
  return text;
}

// Every id plus 100000 (outside strings): another export of the same products.
std::string renumbered(const std::string& text) {
  std::string out;
  bool quoted = false;
  const std::size_t data = text.find("DATA;");
  out.append(text, 0, data);
  for (std::size_t i = data; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '\'') quoted = !quoted;
    if (!quoted && c == '#' && std::isdigit(static_cast<unsigned char>(text[i + 1]))) {
      std::size_t end = i + 1;
      while (std::isdigit(static_cast<unsigned char>(text[end]))) ++end;
      out += '#';  // two steps: GCC 12 warns falsely (-Wrestrict) on '#' + string
      out += std::to_string(std::stoll(text.substr(i + 1, end - i - 1)) + 100000);
      i = end - 1;
      continue;
    }
    out += c;
  }
  return out;
}

// One vertex of one product moved by 1e-9 mm (within its tolerance): that product's geometry changed.
std::string with_one_vertex_moved(std::string text) {
  const std::size_t vertex = text.find("= VERTEX_POINT(");
  EXPECT_NE(vertex, std::string::npos);
  const std::size_t start = text.rfind('\n', vertex) + 1;
  const std::string point = reference(text, std::make_pair(start, text.find(';', start) + 1), 0);
  const auto p = statement(text, point);
  const std::string old = text.substr(p.first, p.second - p.first);
  const std::size_t open = old.rfind('(') + 1;  // CARTESIAN_POINT(name,(x,y,z))
  const std::size_t comma = old.find(',', open);
  const double x = std::stod(old.substr(open, comma - open));
  char moved[64];
  std::snprintf(moved, sizeof moved, "%.17g", x + 1e-9);
  text.replace(p.first, p.second - p.first, old.substr(0, open) + moved + old.substr(comma));
  return text;
}

// What reading the file afresh gives, compared with a read through the cache: the same scene,
// diagnostics, completeness and answers of a certified check (which queries the exact faces).
// `like`: the options of the cached read (their cache left out); default: two workers, eager.
void expect_as_read_afresh(const std::string& path, const ImportResult& cached, const ImportOptions* like = nullptr) {
  ImportOptions plain;
  plain.transfer_workers = 2;
  if (like) {
    plain = *like;
    plain.cache_dir.clear();
  }
  const ImportResult fresh = import_file(path, plain);
  EXPECT_EQ(messages(cached), messages(fresh));
  EXPECT_EQ(cached.complete, fresh.complete);
  EXPECT_TRUE(same_bytes(everything(cached), everything(fresh)));
  EXPECT_EQ(check_text(cached), check_text(fresh));
}

// A test's board, its text, and import options with a cache of its own (empty) read on two workers.
struct CachedBoard {
  std::string path, original;
  ImportOptions options;
};
CachedBoard cached_board(const std::string& name, bool lazy) {
  CachedBoard b;
  b.path = board(name + ".step");
  b.original = read_bytes(b.path);
  b.options.lazy = lazy;
  b.options.transfer_workers = 2;
  b.options.cache_dir = (fs::path(testing::scratch_dir()) / (name + "-cache")).string();
  fs::remove_all(b.options.cache_dir);
  return b;
}

bool have_data() { return fs::exists(std::string(CADCLASH_DATA_DIR) + "/external/as1-tu-203.stp"); }

// The cache without its placements entry for the file at `path`: an edit of a placement is then
// read through the products' entries (step_placements.h serves it otherwise).
void forget_placements(const std::string& path, const ImportOptions& options) {
  fs::remove(fs::path(options.cache_dir) / detail::placements_entry_name(path, options));
}

// The costs a read in pieces reports (PieceCosts): one per piece, a worker's time for each piece it
// read and none for a piece from the cache; a heal time per part made afresh.
void expect_costs(const FileImport& f, std::size_t pieces_read, std::size_t parts_made) {
  ASSERT_EQ(f.piece_costs.bytes.size(), f.pieces);
  ASSERT_EQ(f.piece_costs.seconds.size(), f.pieces);
  ASSERT_EQ(f.piece_costs.weights.size(), f.pieces);
  for (std::size_t p = 0; p < f.pieces; ++p) EXPECT_GE(f.piece_costs.weights[p], f.piece_costs.bytes[p]);
  EXPECT_EQ(static_cast<std::size_t>(std::count_if(f.piece_costs.seconds.begin(), f.piece_costs.seconds.end(),
                                                   [](double s) { return s > 0.0; })),
            pieces_read);
  for (const std::size_t b : f.piece_costs.bytes) EXPECT_GT(b, 0u);
  EXPECT_GT(f.piece_costs.main_parse, 0.0);
  if (pieces_read > 0) {
    EXPECT_GT(f.piece_costs.workers, 0.0);
  }
  EXPECT_EQ(f.part_heal_seconds.size(), parts_made);
}

TEST(ProductCache, OnlyChangedProductsAreReadAgain) {
  if (!have_data()) GTEST_SKIP() << "run scripts/setup.sh";
  auto [path, original, options] = cached_board("product_cache_board", false);

  const ImportResult cold = import_file(path, options);
  ASSERT_EQ(cold.files.size(), 1u);
  EXPECT_EQ(cold.files[0].cache, CacheUse::Miss);
  const std::size_t pieces = cold.files[0].pieces, parts = cold.model.parts.size();
  ASSERT_GT(pieces, 10u);
  ASSERT_GT(parts, 5u);
  EXPECT_EQ(cold.files[0].pieces_cached, 0u);
  EXPECT_EQ(cold.files[0].parts_cached, 0u);
  expect_costs(cold.files[0], pieces, parts);
  expect_as_read_afresh(path, cold);

  struct Edit {
    const char* what;
    std::string text;
    std::size_t pieces_read, parts_made;  // read from the file, made afresh
    int workers;
  };
  const std::vector<Edit> edits{
      {"a placement moved", with_placement_moved(original), 0, 0, 2},
      {"a placement moved, one worker", with_placement_moved(with_placement_moved(original)), 0, 0, 1},
      {"every id renumbered", renumbered(original), 0, 0, 2},
      {"one product's vertex moved", with_one_vertex_moved(original), 1, 1, 2},
  };
  for (const Edit& e : edits) {
    SCOPED_TRACE(e.what);
    write_bytes(path, e.text);
    options.transfer_workers = e.workers;
    forget_placements(path, options);
    const ImportResult warm = import_file(path, options);
    ASSERT_EQ(warm.files.size(), 1u);
    EXPECT_EQ(warm.files[0].cache, CacheUse::Miss);  // the file changed: no whole entry
    EXPECT_EQ(warm.files[0].pieces, pieces);
    EXPECT_EQ(warm.files[0].pieces_cached, pieces - e.pieces_read);
    EXPECT_EQ(warm.files[0].parts_cached, parts - e.parts_made);
    EXPECT_EQ(warm.files[0].transfer_workers, std::max<std::size_t>(1, std::min<std::size_t>(e.pieces_read, e.workers)));
    expect_costs(warm.files[0], e.pieces_read, e.parts_made);
    expect_as_read_afresh(path, warm);
  }
}

// A part's entry is not the file's: the same bytes at another path (a renamed or copied board, or
// another board holding the same component models) take every product and part from the first
// file's entries, named after the file read (its surfaces, parts and diagnostics), as reading it
// afresh gives.
TEST(ProductCache, AnotherFileHoldingTheSameProductsFindsTheirEntries) {
  if (!have_data()) GTEST_SKIP() << "run scripts/setup.sh";
  for (const bool lazy : {false, true}) {
    SCOPED_TRACE(lazy ? "lazy" : "eager");
    auto [path, original, options] = cached_board(lazy ? "same_products_lazy" : "same_products_eager", lazy);
    const ImportResult first = import_file(path, options);
    ASSERT_EQ(first.files.size(), 1u);
    const std::string copy = path + "-copy.step";
    write_bytes(copy, original);
    const ImportResult again = import_file(copy, options);
    ASSERT_EQ(again.files.size(), 1u);
    EXPECT_EQ(again.files[0].cache, CacheUse::Miss);  // the file's own entry is its path's
    EXPECT_EQ(again.files[0].pieces_cached, first.files[0].pieces);
    EXPECT_EQ(again.files[0].parts_cached, first.model.parts.size());
    for (const Part& part : again.model.parts) EXPECT_EQ(part.source_file, copy);
    for (const Surface& s : again.model.surfaces) EXPECT_EQ(s.provenance.source_file, copy);
    expect_as_read_afresh(copy, again, &options);
  }
}

// ImportOptions::transfer_healing changes the shapes: the file's entry and every product's are kept
// apart per setting, and each read is what reading the file afresh with its setting gives.
TEST(ProductCache, TransferHealingIsPartOfTheFilesAndTheProductsKeys) {
  if (!have_data()) GTEST_SKIP() << "run scripts/setup.sh";
  auto [path, original, options] = cached_board("transfer_healing", false);
  const ImportResult healed = import_file(path, options);
  ASSERT_EQ(healed.files.size(), 1u);
  const std::size_t pieces = healed.files[0].pieces;
  ASSERT_GT(pieces, 10u);

  options.transfer_healing = false;
  const ImportResult as_translated = import_file(path, options);
  ASSERT_EQ(as_translated.files.size(), 1u);
  EXPECT_EQ(as_translated.files[0].cache, CacheUse::Miss);
  EXPECT_EQ(as_translated.files[0].pieces, pieces);
  EXPECT_EQ(as_translated.files[0].pieces_cached, 0u);
  EXPECT_NE(messages(as_translated), messages(healed));  // faces BRepCheck rejects, healed one by one
  expect_as_read_afresh(path, as_translated, &options);

  for (const bool healing : {false, true}) {
    SCOPED_TRACE(healing ? "healing again" : "no healing again");
    options.transfer_healing = healing;
    const ImportResult again = import_file(path, options);
    ASSERT_EQ(again.files.size(), 1u);
    EXPECT_EQ(again.files[0].cache, CacheUse::Hit);
    EXPECT_EQ(messages(again), messages(healing ? healed : as_translated));
  }
}

// Every product entry damaged (a byte flipped, cut short, emptied): each is found before it is
// used, named in a warning, made again from the file and rewritten; the next read trusts them again.
TEST(ProductCache, DamagedProductEntriesAreRebuilt) {
  if (!have_data()) GTEST_SKIP() << "run scripts/setup.sh";
  const auto [path, original, options] = cached_board("product_cache_damaged", false);
  const ImportResult cold = import_file(path, options);
  std::size_t entries = cold.files[0].pieces + cold.model.parts.size();
  std::vector<std::string> files;
  for (const auto& f : fs::directory_iterator(options.cache_dir)) files.push_back(f.path().string());
  ASSERT_EQ(files.size(), entries + 2);  // and the whole file's and its placements'
  ++entries;                             // each damaged entry is named
  std::size_t k = 0;
  for (const std::string& f : files) {
    std::string bytes = read_bytes(f);
    switch (k++ % 3) {
      case 0: bytes[bytes.size() / 2] ^= 0x20; break;
      case 1: bytes.resize(bytes.size() - 3); break;
      default: bytes.clear();
    }
    write_bytes(f, bytes);
  }
  write_bytes(path, with_placement_moved(original));
  const ImportResult rebuilt = import_file(path, options);
  EXPECT_EQ(rebuilt.files[0].pieces_cached, 0u);
  EXPECT_EQ(rebuilt.files[0].parts_cached, 0u);
  std::size_t warnings = 0;
  ImportResult without = rebuilt;
  std::erase_if(without.diagnostics, [&](const Diagnostic& d) {
    const bool damaged = d.severity == Severity::Warning && d.message.find("is damaged") != std::string::npos;
    warnings += damaged ? 1 : 0;
    return damaged;
  });
  EXPECT_EQ(warnings, entries);
  expect_as_read_afresh(path, without);

  write_bytes(path, with_placement_moved(with_placement_moved(original)));
  forget_placements(path, options);
  const ImportResult again = import_file(path, options);
  EXPECT_EQ(again.files[0].pieces_cached, again.files[0].pieces);
  EXPECT_EQ(again.files[0].parts_cached, again.model.parts.size());
  expect_as_read_afresh(path, again);
}

// The whole file's entry names its parts' entries instead of holding their faces again: without
// them it is no hit, and the file is read as if the cache had never held it (no warning: a cache
// that lets entries go is not damaged); with a part's entry damaged, it is rebuilt and says so.
TEST(ProductCache, TheFilesEntryNamesItsPartsEntries) {
  if (!have_data()) GTEST_SKIP() << "run scripts/setup.sh";
  for (const bool lazy : {false, true}) {
    SCOPED_TRACE(lazy ? "lazy" : "eager");
    const auto [path, original, options] = cached_board(lazy ? "file_entry_lazy" : "file_entry_eager", lazy);
    (void)import_file(path, options);
    const fs::path whole = fs::path(options.cache_dir) / detail::cache_entry_name(path, options).value();
    ASSERT_TRUE(fs::exists(whole));
    const std::string whole_bytes = read_bytes(whole.string());
    const ImportResult hit = import_file(path, options);
    ASSERT_EQ(hit.files[0].cache, CacheUse::Hit);
    expect_as_read_afresh(path, hit, &options);

    for (const auto& f : fs::directory_iterator(options.cache_dir))
      if (f.path() != whole) fs::remove(f.path());
    const ImportResult alone = import_file(path, options);
    EXPECT_EQ(alone.files[0].cache, CacheUse::Miss);
    EXPECT_EQ(alone.files[0].parts_cached, 0u);
    expect_as_read_afresh(path, alone, &options);

    std::size_t damaged = 0;
    for (const auto& f : fs::directory_iterator(options.cache_dir)) {
      if (f.path() == whole || f.path().filename() == detail::placements_entry_name(path, options)) continue;
      std::string bytes = read_bytes(f.path().string());
      bytes[bytes.size() / 2] ^= 0x20;
      write_bytes(f.path().string(), bytes);
      ++damaged;
    }
    ASSERT_GT(damaged, 0u);
    const ImportResult rebuilt = import_file(path, options);
    EXPECT_EQ(rebuilt.files[0].cache, CacheUse::Rebuilt);
    ASSERT_FALSE(rebuilt.diagnostics.empty());
    EXPECT_NE(rebuilt.diagnostics[0].message.find("is damaged"), std::string::npos) << rebuilt.diagnostics[0].message;
    ImportResult without = rebuilt;
    std::erase_if(without.diagnostics, [](const Diagnostic& d) { return d.message.find("is damaged") != std::string::npos; });
    expect_as_read_afresh(path, without, &options);
    EXPECT_EQ(read_bytes(whole.string()), whole_bytes);  // rewritten as it was
  }
}

// A lazy import through the cache, checked: the faces the check meshed are written back into the
// entries (store_triangles_in_cache), so the next run reads them instead of meshing (nothing is
// left to store after its check), with the same report; and a run whose check reaches other faces
// (a placement moved) still gives what reading afresh gives.
TEST(ProductCache, TrianglesAChecksMadeAreKeptForTheNextRun) {
  if (!have_data()) GTEST_SKIP() << "run scripts/setup.sh";
  const auto [path, original, options] = cached_board("product_cache_triangles", true);
  ImportOptions plain = options;
  plain.cache_dir.clear();

  const ImportResult cold = import_file(path, options);
  const std::string report = check_text(cold);  // meshes the faces the check reaches, in the shared sources
  std::vector<Diagnostic> notes;
  // Every part's entry; the file's entry names them and holds no triangles of its own.
  EXPECT_EQ(store_triangles_in_cache(cold, notes), cold.model.parts.size());
  EXPECT_TRUE(notes.empty());
  EXPECT_EQ(store_triangles_in_cache(cold, notes), 0u);  // nothing gained since

  const ImportResult warm = import_file(path, options);
  ASSERT_EQ(warm.files[0].cache, CacheUse::Hit);
  EXPECT_EQ(check_text(warm), report);
  EXPECT_EQ(store_triangles_in_cache(warm, notes), 0u);  // the check meshed nothing new
  EXPECT_TRUE(same_bytes(everything(warm), everything(import_file(path, plain))));

  write_bytes(path, with_placement_moved(original));
  const ImportResult moved = import_file(path, options);
  EXPECT_EQ(moved.files[0].cache, CacheUse::Placements);  // the model of the file's entry, its poses recomputed
  const ImportResult fresh = import_file(path, plain);
  EXPECT_EQ(messages(moved), messages(fresh));
  EXPECT_TRUE(same_bytes(everything(moved), everything(fresh)));
  EXPECT_EQ(check_text(moved), check_text(fresh));
}

// A copy of `text` with `from` replaced by `to` (once; it must be there).
std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

// A file edited only in the numbers of its placements is the model of the version the cache read
// before with the poses its new numbers give (CacheUse::Placements): the same as reading it afresh,
// down to the bits of every pose and the answers of a certified check. Any other edit is read.
TEST(PlacementCache, EditedPlacementsAreRecomputed) {
  if (!have_data()) GTEST_SKIP() << "run scripts/setup.sh";
  for (const bool lazy : {false, true}) {
    SCOPED_TRACE(lazy ? "lazy" : "eager");
    auto [path, original, options] = cached_board(lazy ? "placements_lazy" : "placements_eager", lazy);
    const ImportResult cold = import_file(path, options);
    ASSERT_EQ(cold.files[0].cache, CacheUse::Miss);
    EXPECT_TRUE(fs::exists(fs::path(options.cache_dir) / detail::placements_entry_name(path, options)));

    struct Edit {
      const char* what;
      std::string text;
      CacheUse use;
    };
    const std::vector<Edit> edits{
        {"a placement moved", with_placement_moved(original), CacheUse::Placements},
        {"moved again", with_placement_moved(with_placement_moved(original)), CacheUse::Placements},
        {"the placement and a product's vertex moved", with_one_vertex_moved(with_placement_moved(original)), CacheUse::Miss},
        {"every id renumbered", renumbered(original), CacheUse::Miss},
        {"the placement moved in the renumbered file", with_placement_moved(renumbered(original)), CacheUse::Placements},
    };
    for (const Edit& e : edits) {
      SCOPED_TRACE(e.what);
      write_bytes(path, e.text);
      const ImportResult warm = import_file(path, options);
      ASSERT_EQ(warm.files.size(), 1u);
      EXPECT_EQ(warm.files[0].cache, e.use);
      expect_as_read_afresh(path, warm, &options);
    }
  }
}

// On as1, some axis placements of occurrences are also the origins of mapped items: their numbers
// place geometry too, so a file with one of them edited is read; an occurrence's own axis is not.
// A pose moved outside the supported range is read too (the reader reports it).
TEST(PlacementCache, NumbersThatPlaceMoreThanOccurrencesAreRead) {
  const std::string as1 = std::string(CADCLASH_DATA_DIR) + "/external/as1-tu-203.stp";
  if (!fs::exists(as1)) GTEST_SKIP() << "run scripts/setup.sh";
  const std::string path = (fs::path(testing::scratch_dir()) / "placements_as1.stp").string();
  const std::string original = read_bytes(as1);
  ImportOptions options;
  options.cache_dir = (fs::path(testing::scratch_dir()) / "placements_as1-cache").string();
  fs::remove_all(options.cache_dir);
  write_bytes(path, original);
  ASSERT_EQ(import_file(path, options).files[0].cache, CacheUse::Miss);
  const std::string own = "#338=CARTESIAN_POINT('#338',(-10.,-7.5,185.));";      // an axis of an occurrence only
  const std::string shared = "#298=CARTESIAN_POINT('#298',(0.0,0.0,0.0));";      // also a mapped item's origin
  struct Edit {
    const char* what;
    std::string text;
    CacheUse use;
  };
  const std::vector<Edit> edits{
      {"an occurrence's axis moved", replaced(original, own, "#338=CARTESIAN_POINT('#338',(-10.,-7.5,185.5));"), CacheUse::Placements},
      {"an occurrence's axis turned", replaced(original, "#340=DIRECTION('#340',(0.0,0.0,1.0));", "#340=DIRECTION('#340',(0.0,0.6,0.8));"),
       CacheUse::Placements},
      {"a mapped item's origin moved", replaced(original, shared, "#298=CARTESIAN_POINT('#298',(0.0,0.0,0.25));"), CacheUse::Miss},
      {"an occurrence placed out of range", replaced(original, own, "#338=CARTESIAN_POINT('#338',(-10.,-7.5,1.E39));"), CacheUse::Miss},
  };
  for (const Edit& e : edits) {
    SCOPED_TRACE(e.what);
    write_bytes(path, e.text);
    const ImportResult warm = import_file(path, options);
    EXPECT_EQ(warm.files[0].cache, e.use);
    expect_as_read_afresh(path, warm, &options);
  }
}

}  // namespace
}  // namespace cadclash
