// The cache of B-rep parts (brep_part_cache.h): entries of the import cache's directory whose
// contents are a one-part ImportResult (save_import), keyed by the part's input and settings.
#include "brep_part_cache.h"

#include "import_cache.h"

#include <BRep_Builder.hxx>
#include <BinTools.hxx>
#include <Standard_Failure.hxx>
#include <TopoDS_Compound.hxx>

#include <cassert>
#include <chrono>
#include <numeric>
#include <optional>
#include <sstream>
#include <string_view>
#include <unordered_map>

namespace cadclash::detail {
namespace {

// Everything add_brep_parts' result for one part depends on, as text (doubles in hexadecimal);
// nullopt when OCCT cannot write the shape. Not the file it came from, which only names it
// (load_part names the file reading it): a product in several files, or a file renamed, is one entry.
// `written`, when given, is the shape as BinTools wrote it (PackedShapes), which is not written again.
std::optional<std::string> part_key(const BrepPartInput& in, const ImportOptions& options, const std::string* written) {
  std::string digest;
  if (written != nullptr) {
    digest = sha256_hex(*written);
  } else {
    std::ostringstream shape;
    try {
      BinTools::Write(*in.shape, shape, Standard_False, Standard_False, BinTools_FormatVersion_CURRENT);
    } catch (const Standard_Failure&) {
      return std::nullopt;
    }
    digest = sha256_hex(shape.str());
  }
  const TessellationOptions& t = options.tessellation;
  std::ostringstream k;
  k << std::hexfloat;
  k << cache_versions() << "brep part\nshape sha256 " << digest << "\nkind "
    << static_cast<int>(in.kind) << "\nname " << in.name.size() << ' ' << in.name << "\ndeflection " << t.linear_deflection << " relative " << t.relative << " angular "
    << t.angular_deflection << " verify " << t.verify_deflection << "\nlazy " << options.lazy << "\ntags "
    << in.tags.size() << '\n';
  // Entity ids by their pattern (canonical: 1, 2, ... in order of first use), so another export
  // of the same product, numbered differently, finds the entry; load_part gives back this file's.
  std::unordered_map<std::int64_t, std::size_t> canonical;
  for (const BrepFaceTag& tag : in.tags) {
    const std::int64_t id =
        tag.entity_id < 0 ? -1 : static_cast<std::int64_t>(canonical.emplace(tag.entity_id, canonical.size() + 1).first->second);
    k << id << ' ' << tag.name.size() << ' ' << tag.name;
    if (tag.colour) k << ' ' << (*tag.colour)[0] << ' ' << (*tag.colour)[1] << ' ' << (*tag.colour)[2];
    k << '\n';
  }
  return k.str();
}

// One part as add_brep_parts gave it: the part, its surfaces, its diagnostics and whether it is whole.
struct OnePart {
  Part part;
  std::vector<Surface> surfaces;
  std::vector<Diagnostic> diagnostics;
  bool complete = true;
};

// The part as an entry holds it: a one-part import (its source shared).
ImportResult one_part(const OnePart& p) {
  ImportResult r;
  r.diagnostics = p.diagnostics;
  r.complete = p.complete;
  r.model.parts.push_back(p.part);
  r.model.parts.back().first_surface = 0;
  r.model.surfaces = p.surfaces;
  for (Surface& s : r.model.surfaces) s.part = 0;
  return r;
}

// The part stored for `in` (another export's entity ids replaced by `in`'s).
bool load_part(std::string_view bytes, const BrepPartInput& in, OnePart& out, std::string& why) {
  ImportResult r;
  if (!load_import(bytes, r, why)) return false;
  auto* source = r.model.parts.size() == 1 ? dynamic_cast<BrepSource*>(r.model.parts[0].source.get()) : nullptr;
  if (source == nullptr || !r.model.instances.empty() || r.model.parts[0].surface_count != r.model.surfaces.size() ||
      source->face_count() != r.model.surfaces.size()) {
    why = "it holds no single B-rep part";
    return false;
  }
  std::unordered_map<std::int64_t, std::int64_t> id_of;  // stored id -> this file's
  std::vector<std::int64_t> ids(r.model.surfaces.size(), -1);
  for (std::size_t f = 0; f < ids.size(); ++f) {
    Provenance& p = r.model.surfaces[f].provenance;
    const std::int64_t now = f < in.tags.size() ? in.tags[f].entity_id : -1;
    if ((p.step_id < 0) != (now < 0) || id_of.emplace(p.step_id, now).first->second != now) {
      why = "its faces' entities do not match the part's";
      return false;
    }
    p.step_id = ids[f] = now;
  }
  // Stored under the file that made it (the same product in another file, or this file renamed, finds
  // it): named after this one.
  relabel_brep_faces(*source, ids, in.source_file);
  const std::string stored_file = r.model.parts[0].source_file;
  r.model.parts[0].source_file = in.source_file;
  for (Surface& s : r.model.surfaces) s.provenance.source_file = in.source_file;
  for (Diagnostic& d : r.diagnostics) {
    if (d.file == stored_file) d.file = in.source_file;
    if (d.step_id >= 0) {
      const auto it = id_of.find(d.step_id);
      if (it == id_of.end()) {
        why = "a diagnostic names an entity that is not one of the part's faces";
        return false;
      }
      d.step_id = it->second;
    }
  }
  out.part = std::move(r.model.parts[0]);
  out.surfaces = std::move(r.model.surfaces);
  out.diagnostics = std::move(r.diagnostics);
  out.complete = r.complete;
  return true;
}

// How BinTools' format opens (after a line feed), whatever its version.
constexpr std::string_view kBinToolsHeader = "Open CASCADE Topology V";

// The shapes of the parts listed in `which` made from their packed bytes, on every thread; a shape
// OCCT cannot make is an error in `notes` (in part order), an empty compound, and `complete` false.
void unpack_shapes(const PackedShapes& packed, std::span<const BrepPartInput> parts, const std::vector<std::size_t>& which,
                   std::vector<Diagnostic>& notes, bool& complete) {
  std::vector<std::string> failed(which.size());
#pragma omp parallel for schedule(dynamic, 1) if (which.size() > 1)
  for (std::ptrdiff_t i = 0; i < static_cast<std::ptrdiff_t>(which.size()); ++i) {
    const std::size_t k = which[static_cast<std::size_t>(i)];
    // (OCCT prints, to standard output, when the bytes do not open with its format's version line.)
    if (packed.bytes[k].find(kBinToolsHeader) > 1) {
      failed[static_cast<std::size_t>(i)] = "not OCCT's binary shape format";
      continue;
    }
    try {
      std::istringstream stream(packed.bytes[k]);
      BinTools::Read(packed.shapes[k], stream);
      if (!stream || packed.shapes[k].IsNull()) failed[static_cast<std::size_t>(i)] = "the shape is cut short";
    } catch (const Standard_Failure& e) {
      failed[static_cast<std::size_t>(i)] = e.GetMessageString();
    }
  }
  for (std::size_t i = 0; i < which.size(); ++i) {
    if (failed[i].empty()) continue;
    const std::size_t k = which[i];
    TopoDS_Compound empty;
    BRep_Builder().MakeCompound(empty);
    packed.shapes[k] = empty;
    complete = false;
    notes.push_back({Severity::Error, parts[k].source_file, 0, -1,
                     "part '" + parts[k].name + "' could not be made again from what the isolated reader sent (" + failed[i] +
                         "); it is left without faces"});
  }
}

}  // namespace

std::vector<PartId> add_brep_parts_cached(Model& model, std::span<const BrepPartInput> parts, const ImportOptions& options,
                                          std::vector<Diagnostic>& diagnostics, bool& complete, BrepPartTimings* timings,
                                          std::size_t* from_cache, CacheRecord* record, const PackedShapes* packed) {
  assert(packed == nullptr || (packed->bytes.size() == parts.size() && packed->shapes.size() == parts.size()));
  if (from_cache) *from_cache = 0;
  // Parts sent apart share no edge (PackedShapes): their shapes are not made to be asked.
  if (options.cache_dir.empty() || options.tessellation.time_limit_seconds > 0.0 || parts.empty() ||
      (packed == nullptr && brep_inputs_share_edges(parts))) {
    if (packed != nullptr) {
      std::vector<std::size_t> all(parts.size());
      std::iota(all.begin(), all.end(), std::size_t{0});
      unpack_shapes(*packed, parts, all, diagnostics, complete);
    }
    return add_brep_parts(model, parts, options.tessellation, options.lazy, diagnostics, complete, timings);
  }

  const std::size_t n = parts.size();
  std::vector<std::optional<std::string>> keys(n);
  std::vector<OnePart> made(n);
  std::vector<char> held(n, 0);
  std::vector<Diagnostic> notes;
  std::vector<std::size_t> missing;
  std::vector<BrepPartInput> to_make;
  const auto load_start = std::chrono::steady_clock::now();
  // Each part keyed (its shape written out and hashed) and looked up on its own, on every thread;
  // what was found is gathered in part order.
  std::vector<std::optional<Diagnostic>> damaged(n);
#pragma omp parallel for schedule(dynamic, 1)
  for (std::ptrdiff_t i = 0; i < static_cast<std::ptrdiff_t>(n); ++i) {
    const auto k = static_cast<std::size_t>(i);
    keys[k] = part_key(parts[k], options, packed != nullptr ? &packed->bytes[k] : nullptr);
    if (!keys[k]) continue;
    const CacheRead read = read_cache_entry(options.cache_dir, *keys[k]);
    std::string why = read.damaged;
    if (read.payload && load_part(*read.payload, parts[k], made[k], why)) {
      held[k] = 1;
      continue;
    }
    made[k] = OnePart{};
    if (!why.empty())
      damaged[k] = Diagnostic{Severity::Warning, parts[k].source_file, 0, -1,
                              std::string(kCacheNote) + read.file + " is damaged (" + why + "); part '" + parts[k].name +
                                  "' was checked and healed again and the entry rewritten"};
  }
  for (std::size_t k = 0; k < n; ++k) {
    if (damaged[k]) notes.push_back(std::move(*damaged[k]));
    if (held[k] != 0) continue;
    missing.push_back(k);
    to_make.push_back(parts[k]);
  }
  // Finding and loading the held parts stands in for checking and healing them.
  if (timings) timings->heal += std::chrono::duration<double>(std::chrono::steady_clock::now() - load_start).count();
  // The others' shapes, when they came packed: made now (reading them, not healing).
  if (packed != nullptr && !missing.empty()) unpack_shapes(*packed, parts, missing, notes, complete);

  std::vector<char> written(n, 0);  // made parts whose entry was written
  if (!to_make.empty()) {
    Model fresh;
    std::vector<Diagnostic> said;
    std::vector<std::size_t> counts;
    bool fresh_complete = true;
    const std::vector<PartId> ids = add_brep_parts(fresh, to_make, options.tessellation, options.lazy, said,
                                                   fresh_complete, timings, &counts);
    std::size_t next = 0;
    bool unwritable = false;
    for (std::size_t m = 0; m < missing.size(); ++m) {
      OnePart& p = made[missing[m]];
      p.part = fresh.parts[ids[m]];
      const auto first = fresh.surfaces.begin() + p.part.first_surface;
      p.surfaces.assign(first, first + p.part.surface_count);
      p.diagnostics.assign(said.begin() + static_cast<std::ptrdiff_t>(next),
                           said.begin() + static_cast<std::ptrdiff_t>(next + counts[m]));
      next += counts[m];
      for (const Diagnostic& d : p.diagnostics) p.complete = p.complete && d.severity != Severity::Error;
      if (!keys[missing[m]] || unwritable) continue;
      std::string why;
      const std::string bytes = save_import(one_part(p)).value_or(std::string());
      unwritable = bytes.empty() || !write_cache_entry(options.cache_dir, *keys[missing[m]], bytes, why);
      written[missing[m]] = unwritable ? 0 : 1;
      if (unwritable)  // one warning, not one per part
        notes.push_back({Severity::Warning, parts[missing[m]].source_file, 0, -1,
                         std::string(kCacheNote) + "for part '" + parts[missing[m]].name + "' could not be written in " +
                             options.cache_dir + " (" + (bytes.empty() ? "it cannot be stored" : why) + ")"});
    }
  }

  diagnostics.insert(diagnostics.end(), notes.begin(), notes.end());
  std::vector<PartId> out;
  out.reserve(n);
  for (std::size_t k = 0; k < n; ++k) {
    OnePart& p = made[k];
    if (record != nullptr && options.lazy && keys[k]) record->parts.push_back(record_entry(*keys[k], one_part(p)));
    const auto id = static_cast<PartId>(model.parts.size());
    p.part.first_surface = static_cast<SurfaceId>(model.surfaces.size());
    for (Surface& s : p.surfaces) {
      s.part = id;
      model.surfaces.push_back(std::move(s));
    }
    model.parts.push_back(std::move(p.part));
    if (record != nullptr && keys[k] && (held[k] != 0 || written[k] != 0) && model.parts.back().source)
      record->part_keys.emplace(model.parts.back().source.get(), *keys[k]);
    diagnostics.insert(diagnostics.end(), p.diagnostics.begin(), p.diagnostics.end());
    complete = complete && p.complete;
    out.push_back(id);
    if (from_cache && held[k]) ++*from_cache;
  }
  return out;
}

}  // namespace cadclash::detail
