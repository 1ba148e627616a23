// cadclash/import.h — reading files into a surface-tagged Model.
// The one public header of cadclash::import. Writing a Model out (OBJ, .glb) is cadclash::export's
// (cadclash/export.h); this reads what it writes back exactly.
//
// Formats, chosen by file extension (case-insensitive):
//   .stp .step (AP203/AP214/AP242), .igs .iges, .brep   B-rep assemblies through OCCT XCAF; one surface per face
//   .obj                                                one surface per `g` group / `o` object (assimp)
//   .off                                                one surface per distinct face colour (CGAL)
//   .stl .ply .gltf .glb and other assimp formats       one surface per mesh; a .glb written by cadclash
//                                                       gives back its surfaces, names and ids
//
// Mesh files give one part named after the file stem, placed once at identity as "/<stem>".
// - OBJ: the latest `g` or `o` name is the surface of a face ("default" before any); a name that
//   recurs is the same surface; `usemtl` does not split surfaces. face_index = order of first use.
//   Coordinates stay double precision. `l`/`p` elements and free-form geometry are listed and ignored.
// - OFF: surfaces are named "colour-RRGGBB" (or "colour-index-N", or "uncoloured"), in order of first
//   use; a colour with '.' or an exponent is 0..1, otherwise 0..255.
// - Polygons: a fan when strictly convex, else ear clipping in the polygon's plane; the winding is kept.
//   No triangle is dropped for being small.
// - Damage: a bad vertex (NaN, Inf, malformed) or a bad face (index out of range, < 3 corners) is
//   dropped with an error naming file and line; the rest is kept and complete = false. At most 20
//   messages per kind are listed, then a count of the rest.
//
// CAD files (STEP, IGES through XCAF; BREP) give one part per distinct leaf shape, shared by all its
// instances (tessellated once), and one instance per leaf occurrence:
// - Instance path: "/" + the names of each level from the root to the leaf, joined by "/". A level's
//   name is the occurrence's own name when the file gives one (STEP: the NEXT_ASSEMBLY_USAGE_OCCURRENCE
//   name), else its product's name; a root's is its product's name. '/' inside a name becomes '_', an
//   empty name "unnamed". Occurrence rule: among the children of one node (and among the roots), a
//   name that occurs more than once gets "::k" on every occurrence, k = 1, 2, ... in file order,
//   skipping any k whose result equals another sibling's name; a name that occurs once is left as is.
//   as1-tu-203.stp: "/as1/L-BRACKET-ASSEMBLY::2/NUT-BOLT-ASSEMBLY::1/BOLT" (the "::k" there is the
//   file's own). BREP: one part and one instance "/<file stem>".
//   Generic names are names no one chose: empty, the label entries OCCT's XCAF writer gives unnamed
//   occurrences ("=>[0:1:1:9]") and the shape types it gives unnamed products ("SOLID", "COMPOUND",
//   "COMPSOLID", "SHELL"). An only child whose level name is generic adds no level: a KiCad export's
//   "/board/D15/=>[0:1:1:9]" is "/board/D15". A leaf's part is named after its product, or when
//   that name is generic after the nearest enclosing product whose name is not (KiCad: the model,
//   "LED_D5.0mm_IRGrey", not "COMPOUND"), else the generic name; a part shared by several leaf
//   occurrences takes the name from the first in file order.
// - Pose: the composed placements of the levels, in millimetres (OCCT converts the file's length unit).
// - Surfaces: one per face, in TopExp::MapShapes order of the part's shape (face_index). step_id is
//   the face entity's label as written in the file (STEP #N of its ADVANCED_FACE; IGES directory entry
//   number), found through one shape→entity map per file; source_name is the entity's name; colour
//   is the face's XCAF colour, else its enclosing shell's/solid's/part's. Faces BRepCheck rejects are
//   fixed with ShapeFix_Face first (provenance.healed). Lazy: see ImportOptions::lazy.
// - Damage: OCCT's syntax and transfer check lists become diagnostics naming the file and the entity
//   (#N); entities that cannot be made are left out, every face that could be made is kept, and
//   complete = false. A STEP FILE_SCHEMA that is not AP203/AP214/AP242 is an error (read anyway). A
//   truncated STEP file is read up to its last complete entity. A face that fails to mesh keeps its
//   surface without triangles, with an error naming its #id and part.
#pragma once

#include "cadclash/collide.h"
#include "cadclash/tessellate.h"

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace cadclash {

// Where a B-rep face's model uncertainty ε (Surface::uncertainty, uncertainty_source) is taken from.
// A B-rep face's ε is never below its OCCT tolerance: the certified decision also takes ε as how far
// the face's own vertices and edges may lie off its surface, which that tolerance bounds.
enum class UncertaintyChoice : std::uint8_t {
  Auto,           // the larger of the face's OCCT tolerance and its STEP file's declared length uncertainty
  OcctTolerance,  // the face's OCCT tolerance alone (the file's declared uncertainty ignored)
  Value,          // ImportOptions::uncertainty_value for every surface, meshes too (a B-rep face whose
                  // OCCT tolerance is larger keeps that)
};

struct ImportOptions {
  TessellationOptions tessellation;  // for B-rep formats
  bool lazy = false;                 // B-rep: AABBs from the exact geometry now, triangles when first required
  // STEP/IGES/BREP: run OCCT's reader and transfer in a forked child process, so that a file on which
  // OCCT crashes gives an error naming it instead of ending this process (a STEP file is then read
  // again without the faces that reach malformed entities, then as loose faces). STEP and IGES come
  // back as their parts and instances (each part's shape in OCCT's binary format), a .brep's shape
  // in that format too.
  // Turn it off only for trusted files, or in a host that must not fork (fork copies only the
  // calling thread; a thread of the host holding a lock OCCT needs would hang the child).
  bool isolate_cad_readers = true;
  // STEP/IGES: OCCT's shape healing of every transferred shape (ShapeFix_Shape, what STEPControl_Reader
  // and IGESControl_Reader run after translating: wires, edges' pcurves and tolerances, shells'
  // orientation). false skips it: the faces are the file's as translated, and the per-part check
  // (BRepCheck, ShapeFix_Face on each invalid face, a warning per face) still runs. A speed knob,
  // measured in docs/import.md ("Healing at transfer"): on the 40 MB KiCad board 19 % less time, 445
  // faces then healed one by one, the same clashes; on as1-tu-203.stp the same pairs.
  bool transfer_healing = true;
  // STEP with isolate_cad_readers: processes that transfer one file's shapes into B-rep at once, forked
  // from its isolated reader after parsing (they share the parsed file; shapes whose topology meets
  // go to one process). 0 = one per OpenMP thread (omp_get_max_threads) for files of 20,000 entities
  // or more, else 1; 1 = the reader alone. The result does not depend on it.
  int transfer_workers = 0;
  // STEP/IGES/BREP with isolate_cad_readers: seconds the isolated reader of one file may take over
  // all its attempts; 0 = no limit. Past it the child is killed and the file reported with an error
  // naming what it was reading (the entity #id when known); an earlier attempt's faces are kept.
  // Tessellation runs in this process afterwards and is not covered. Without isolation it cannot be
  // applied (a warning says so).
  double reader_time_limit_seconds = 0.0;
  // Meshes (OBJ/OFF/STL/...): how far their coordinates may be from the intended geometry, mm, set as
  // every mesh surface's Surface::uncertainty. 0 = derived by collide from the coordinates (2^-24 x the
  // part's largest coordinate: the single-precision bound, as STL, glTF and PLY store float32).
  double model_tolerance = 0.0;
  // B-rep faces' model uncertainty (docs/report-schema.md, "Classes"): see UncertaintyChoice. With
  // Value, uncertainty_value (mm, > 0) is every surface's uncertainty, meshes' too (model_tolerance
  // is then unused), at least each B-rep face's OCCT tolerance.
  UncertaintyChoice uncertainty = UncertaintyChoice::Auto;
  double uncertainty_value = 0.0;
  // A directory for a persistent cache of imported files (made when missing); empty = no cache. One
  // entry per file, keyed by a SHA-256 of the file's bytes, its path as given and every option above
  // that changes the result, the cache format and OCCT versions and the build of cadclash (the program
  // or module file's size and time: a rebuild starts afresh): a file read again with the
  // same bytes and options comes back from its entry, the same model (B-rep parts with their exact
  // faces and triangles, bit for bit) and diagnostics as when it was read. Every entry is checked
  // (format version, key, size, SHA-256 of its contents) before it is used; a damaged one is read
  // again from the file, rewritten, and named in a warning. Entries are written whole (temporary file,
  // then rename), so runs sharing the directory never see half an entry. A file whose reading ran into
  // a time limit is not stored. Entries are removed only under cache_max_bytes (below).
  // Besides the file's entry, a STEP file that can be cut (docs/import.md) keeps one entry per piece
  // (a product's shapes, keyed by the piece's text with its ids renumbered canonically) and every
  // CAD file one per checked and healed B-rep part (keyed by its transferred shape, names, tags and
  // the tessellation options, not by its file: another file holding the same product, or the file
  // renamed, finds it): a changed file reads and heals only the products that changed.
  std::string cache_dir;
  // With cache_dir: after a file is read (and after store_triangles_in_cache), the least recently
  // used entries are removed until the directory's entries take at most this many bytes (an entry
  // is used when it is written or read; its file's modification time says when); 0 = no limit.
  // Never part of a key: it changes what is kept, not what is read.
  std::uint64_t cache_max_bytes = 0;
  // import_files: how many files are read at once (each in its own thread, a CAD file's isolated reader
  // in its own process); 0 = one per OpenMP thread (omp_get_max_threads). The result does not depend on it.
  int parallel_files = 0;
  // Told how far the import is (collide.h, "Progress of long work"): ReadFile as each file starts
  // and ends (done = files finished), CheckPart as each B-rep part of a file is checked and healed,
  // and TessellatePart as each B-rep part of a file is meshed
  // (eager import of a file not in the cache; one run per file). Calls never overlap; with
  // parallel_files > 1 they come from the threads reading files, and one file's TessellatePart run
  // may be interleaved with another's. Isolated readers' child processes never call it. Empty =
  // nothing; tessellation.progress is ignored (this one gets every stage). Never part of the cache key.
  ProgressCallback progress;
};

// Where one file's import spent its time, seconds of wall clock on the thread that read it.
struct ImportTimings {
  double read = 0.0;        // parsing the file (CAD: OCCT's reader, in the isolated child); from the cache: loading the entry
  double transfer = 0.0;    // the rest: OCCT's transfer into shapes and bringing them back, the assembly walk, hashing
  double heal = 0.0;        // B-rep: checking and fixing faces, exact face boxes and facts
  double tessellate = 0.0;  // B-rep: BRepMesh and measuring the triangles (0 when lazy)
  double total = 0.0;       // the whole file, storing its cache entry included
};

// What the cache did for one file: not asked, gave it, did not hold it (now stored), held a
// damaged entry (read again and rewritten), or held the entry of an earlier version of the file
// at the same path that differs only in the numbers of its assembly placements (Placements: the
// model read from that entry, each instance's pose computed from the new numbers as the reader
// would; docs/import.md, "A cache per product").
enum class CacheUse : std::uint8_t { Off, Hit, Miss, Rebuilt, Placements };
// Returns "off", "hit", "miss", "rebuilt" or "placements".
const char* cache_use_name(CacheUse c);

// A STEP file read in pieces (FileImport::pieces > 0): what each stage of the cut read cost, so
// that its time on more cores can be modelled from measured costs (scripts/import_peer_bench.sh;
// docs/import.md, "One large STEP file on every core"). The workers' costs are CPU seconds, which
// do not grow when the processes share cores; the rest is wall clock of the reader's process.
struct PieceCosts {
  double split = 0.0;       // wall: cutting the text, the cache's lookups, until the workers start (serial)
  double main_parse = 0.0;  // CPU: the reader parsing the main text, while the workers run
  double workers = 0.0;     // wall: from the workers' start until the last one's shapes are back
  // Per piece, in file order: the bytes of its items, its weight (what the pieces are shared out by:
  // its bytes and its faces' wires, step_split_text.h) and its worker's CPU seconds for it (parsing,
  // transfer, encoding the shapes); 0 for a piece from the cache.
  std::vector<std::size_t> bytes, weights;
  std::vector<double> seconds;
};

namespace detail {
struct CacheRecord;  // what store_triangles_in_cache needs of a file read through the cache (import_cache.h)
struct Placements;   // how a STEP file's numbers place its instances (step_placements.h)
}

struct FileImport {
  std::string path;  // as given
  CacheUse cache = CacheUse::Off;
  ImportTimings timings;
  // STEP: processes that transferred the file's shapes (ImportOptions::transfer_workers); 1 = the
  // reader alone, and for other formats and cache hits.
  std::size_t transfer_workers = 1;
  // STEP: the pieces its products' shapes were cut into (0: the file was not cut; step_split_text),
  // of which this many came from the cache (ImportOptions::cache_dir), not from the file.
  std::size_t pieces = 0, pieces_cached = 0;
  // CAD parts that came checked and healed from the cache (with a cache only).
  std::size_t parts_cached = 0;
  // STEP read in pieces by this process's reader (not from a cache entry of the whole file, nor a
  // distributed check's description): the pieces' costs; empty otherwise.
  PieceCosts piece_costs;
  // B-rep parts checked and healed here (not from the cache), in the order they were added: each
  // one's wall seconds on the thread that checked it (ImportTimings::heal spreads them over threads).
  std::vector<double> part_heal_seconds;
  // A lazy import through a cache: the entries its B-rep parts came from or went to.
  std::shared_ptr<detail::CacheRecord> cache_record = nullptr;
  // STEP assemblies: how the file's numbers place its instances, for the cache's recomputed poses.
  std::shared_ptr<const detail::Placements> placements = nullptr;
};

struct ImportResult {
  Model model;                           // everything that could be read, even when diagnostics hold errors
  std::vector<Diagnostic> diagnostics;   // every problem; each dropped element is named here
  bool complete = true;                  // false when any part of the input was dropped or failed to mesh
  std::vector<FileImport> files;         // one per file, in the order given
  double seconds = 0.0;                  // wall clock of the whole import (files read in parallel)
};

// Reads one file. Never throws for bad input: problems come back as diagnostics, and the good parts
// of a partly bad file are kept. A file that cannot be read at all gives an empty model and an error.
ImportResult import_file(const std::string& path, const ImportOptions& options = {});

// Reads several files into one scene, options.parallel_files at a time. When more than one file is
// given, each file's instance paths are prefixed with "/<file name>" so they stay unique. The files
// are merged in the order given, so the result is the same however many are read at once.
ImportResult import_files(std::span<const std::string> paths, const ImportOptions& options = {});

// import_files in two steps, for processes that read some of the files each (distributed checks):
// import_each_file reads every file on its own (import_file, options.parallel_files at a time),
// results in the order given; merge_file_imports makes of one result per path (in that order) the
// scene import_files gives (seconds: the results' largest). Precondition: each.size() == paths.size().
std::vector<ImportResult> import_each_file(std::span<const std::string> paths, const ImportOptions& options = {});
ImportResult merge_file_imports(std::span<const std::string> paths, std::vector<ImportResult> each);

// A lazy import through a cache (ImportOptions::cache_dir, lazy), after a check meshed some of its
// B-rep faces: writes those faces' triangles into the cache entries the parts came from (the file's
// and each part's), so that a later run reads them instead of meshing again. The entries keep the
// import as it was (the surfaces without triangles, as a lazy import gives them): only the exact
// faces carry their triangulations, which BrepSource::triangulate reads when it is asked for them.
// Does nothing for files without such an entry (no cache, eager, a time limit) or parts whose faces
// gained no triangles. Returns how many entries it rewrote; a warning in `diagnostics` for each
// entry it could not write. Precondition: no other thread meshes the model's parts meanwhile.
std::size_t store_triangles_in_cache(const ImportResult& imported, std::vector<Diagnostic>& diagnostics);

// One file's ImportResult (import_file's) for a process that plans a check with it but reads the
// file only if it needs the exact faces: the bytes of an import cache entry with each B-rep part's
// exact faces left out (its default deflection kept), then the file's FileImport. Everything else
// comes back as read: diagnostics, complete, parts, surfaces (names, STEP #ids, boxes, facts, a mesh
// file's triangles), instances and poses. Precondition: the B-rep parts' sources are BrepSources.
std::string import_description(const ImportResult& one_file);
// The bytes back. Each B-rep part gets a stand-in SurfaceSource: default_deflection() as read,
// triangulate() fails (nothing else answers); replace it by reading the file. False and `why` when
// the bytes are not a whole description.
bool import_from_description(std::string_view bytes, ImportResult& out, std::string& why);

}  // namespace cadclash
