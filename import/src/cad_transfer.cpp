// Transfer ↔ bytes, and Transfer → model.
#include "cad_transfer.h"

#include "cadclash/internal/byte_io.h"

#include <BRep_Builder.hxx>
#include <BRep_CurveRepresentation.hxx>
#include <BRep_ListIteratorOfListOfCurveRepresentation.hxx>
#include <BRep_TEdge.hxx>
#include <BRep_TFace.hxx>
#include <BinTools.hxx>
#include <BinXCAFDrivers.hxx>
#include <PCDM_ReaderStatus.hxx>
#include <PCDM_StoreStatus.hxx>
#include <Standard_Failure.hxx>
#include <TDF_LabelSequence.hxx>
#include <TopExp.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS_Compound.hxx>
#include <TopoDS_Iterator.hxx>
#include <XCAFApp_Application.hxx>
#include <XCAFDoc_DocumentTool.hxx>
#include <XCAFDoc_ShapeTool.hxx>

#include <omp.h>

#include <algorithm>
#include <cassert>
#include <atomic>
#include <mutex>
#include <sstream>
#include <system_error>
#include <thread>
#include <unordered_map>

namespace cadclash::detail {
namespace {

// The application's document drivers keep state per call: files read in parallel (import_files)
// open, store and close their documents one at a time.
std::mutex& application_mutex() {
  static std::mutex m;
  return m;
}

Handle(XCAFApp_Application) application() {
  static std::once_flag once;
  std::call_once(once, [] { BinXCAFDrivers::DefineFormat(XCAFApp_Application::GetApplication()); });
  return XCAFApp_Application::GetApplication();
}

// Whether two of the parts reach one sub-shape, surface or curve: written apart, each would get a
// copy of its own, which the healing of one part could then change without the other.
bool parts_share(const std::vector<WalkedPart>& parts) {
  std::unordered_map<const void*, std::size_t> owner;
  auto claim = [&](const void* held, std::size_t p) {  // false when another part holds it too
    const auto [it, inserted] = owner.try_emplace(held, p);
    return inserted || it->second == p;
  };
  std::vector<TopoDS_Shape> todo;
  for (std::size_t p = 0; p < parts.size(); ++p) {
    if (parts[p].dropped) continue;
    todo.assign(1, parts[p].shape);
    while (!todo.empty()) {
      const TopoDS_Shape shape = std::move(todo.back());
      todo.pop_back();
      const auto [it, inserted] = owner.try_emplace(shape.TShape().get(), p);
      if (!inserted) {
        if (it->second != p) return true;
        continue;  // this part's, met again
      }
      if (const auto* face = dynamic_cast<const BRep_TFace*>(shape.TShape().get()); face != nullptr) {
        if (!face->Surface().IsNull() && !claim(face->Surface().get(), p)) return true;
      } else if (const auto* edge = dynamic_cast<const BRep_TEdge*>(shape.TShape().get()); edge != nullptr) {
        for (BRep_ListIteratorOfListOfCurveRepresentation c(edge->Curves()); c.More(); c.Next()) {
          const Handle(BRep_CurveRepresentation)& r = c.Value();
          if (r->IsCurve3D() && !r->Curve3D().IsNull() && !claim(r->Curve3D().get(), p)) return true;
          if (r->IsCurveOnSurface() && !r->PCurve().IsNull() && !claim(r->PCurve().get(), p)) return true;
          if (r->IsCurveOnClosedSurface() && !r->PCurve2().IsNull() && !claim(r->PCurve2().get(), p)) return true;
        }
      }
      for (TopoDS_Iterator sub(shape, Standard_False, Standard_False); sub.More(); sub.Next()) todo.push_back(sub.Value());
    }
  }
  return false;
}

// A shape as BinTools writes it without triangles (as a part's cache key does); nullopt when it cannot.
std::optional<std::string> shape_bytes(const TopoDS_Shape& shape) {
  std::ostringstream out;
  try {
    BinTools::Write(shape, out, Standard_False, Standard_False, BinTools_FormatVersion_CURRENT);
  } catch (const Standard_Failure&) {
    return std::nullopt;
  }
  return std::move(out).str();
}

// Each part's shape_bytes, written on up to `threads` threads (they share nothing: parts_share);
// empty when one cannot be written.
std::vector<std::string> parts_apart(const std::vector<WalkedPart>& parts, std::size_t threads) {
  std::vector<std::size_t> kept;
  for (std::size_t p = 0; p < parts.size(); ++p)
    if (!parts[p].dropped) kept.push_back(p);
  std::vector<std::optional<std::string>> each(kept.size());
  std::atomic<std::size_t> next{0};
  // (No OpenMP: this runs in a forked child, whose OpenMP runtime is the parent's copy.)
  auto write = [&] {
    for (std::size_t k; (k = next.fetch_add(1)) < kept.size();) each[k] = shape_bytes(parts[kept[k]].shape);
  };
  std::vector<std::jthread> helpers;
  try {
    for (std::size_t t = 1; t < std::min(threads, kept.size()); ++t) helpers.emplace_back(write);
  } catch (const std::system_error&) {  // fewer threads: the others write the rest
  }
  write();
  helpers.clear();  // joined
  std::vector<std::string> out;
  out.reserve(kept.size());
  for (std::optional<std::string>& bytes : each) {
    if (!bytes) return {};
    out.push_back(std::move(*bytes));
  }
  return out;
}

void write_walked(ByteWriter& w, const WalkedDocument& d, std::size_t threads) {
  write_diagnostics(w, d.diagnostics);
  w.u64(d.complete ? 1 : 0);
  w.u64(d.parts.size());
  for (const WalkedPart& part : d.parts) {
    w.str(part.name);
    w.u64(part.dropped ? 1 : 0);
    w.u64(part.tags.size());
    for (const BrepFaceTag& tag : part.tags) {
      w.i64(tag.entity_id);
      w.str(tag.name);
      w.u64(tag.colour ? 1 : 0);
      if (tag.colour)
        for (const float v : *tag.colour) w.f64(v);
    }
  }
  // Each part on its own when none shares anything with another: the reader then makes only the
  // shapes of parts its cache does not hold, and keys them by these bytes.
  std::vector<std::string> apart;
  if (!parts_share(d.parts)) apart = parts_apart(d.parts, threads);
  const bool is_apart = !apart.empty() || std::all_of(d.parts.begin(), d.parts.end(), [](const WalkedPart& p) { return p.dropped; });
  w.u64(is_apart ? 1 : 0);
  if (is_apart) {
    for (const std::string& bytes : apart) w.str(bytes);
  } else {
    TopoDS_Compound together;
    BRep_Builder builder;
    builder.MakeCompound(together);
    for (const WalkedPart& part : d.parts)
      if (!part.dropped) builder.Add(together, part.shape);
    std::ostringstream out;
    BinTools::Write(together, out, Standard_False, Standard_False, BinTools_FormatVersion_CURRENT);  // throws: no payload
    w.str(std::move(out).str());
  }
  assert(d.chains.size() == d.instances.size());
  w.u64(d.instances.size());
  for (std::size_t k = 0; k < d.instances.size(); ++k) {
    const Instance& instance = d.instances[k];
    w.str(instance.path);
    w.u64(instance.part);
    const double* m = instance.pose.matrix().data();
    for (int i = 0; i < 16; ++i) w.f64(m[i]);
    w.u64(d.chains[k].size());
    for (const std::string& entry : d.chains[k]) w.str(entry);
  }
}

bool read_walked(ByteReader& r, WalkedDocument& d, std::string& why) {
  d.diagnostics = read_diagnostics(r);
  d.complete = r.u64() == 1;
  d.parts.resize(r.ok ? r.count(24) : 0);
  for (WalkedPart& part : d.parts) {
    part.name = r.str();
    part.dropped = r.u64() == 1;
    part.tags.resize(r.ok ? r.count(24) : 0);
    for (BrepFaceTag& tag : part.tags) {
      tag.entity_id = r.i64();
      tag.name = r.str();
      if (r.u64() == 1) {
        std::array<float, 3> rgb{};
        for (float& v : rgb) v = static_cast<float>(r.f64());
        tag.colour = rgb;
      }
    }
  }
  const bool apart = r.u64() == 1;
  if (apart) {
    for (WalkedPart& part : d.parts)
      if (!part.dropped) part.packed = r.str();
  } else {
    std::istringstream stored(r.str());
    if (!r.ok) {
      why = "the reader's output is cut short";
      return false;
    }
    TopoDS_Shape together;
    BinTools::Read(together, stored);
    TopoDS_Iterator it(together);
    for (WalkedPart& part : d.parts) {
      if (part.dropped) continue;
      if (!it.More()) {
        why = "the reader's output is not whole";
        return false;
      }
      part.shape = it.Value();
      it.Next();
    }
  }
  d.instances.resize(r.ok ? r.count(8 + 8 + 128 + 8) : 0);
  d.chains.resize(d.instances.size());
  for (std::size_t k = 0; k < d.instances.size(); ++k) {
    Instance& instance = d.instances[k];
    instance.path = r.str();
    instance.part = static_cast<PartId>(r.u64());
    double* m = instance.pose.matrix().data();
    for (int i = 0; i < 16; ++i) m[i] = r.f64();
    d.chains[k].resize(r.ok ? r.count(8) : 0);
    for (std::string& entry : d.chains[k]) entry = r.str();
    if (r.ok && instance.part >= d.parts.size()) {
      why = "the reader's output is not whole";
      return false;
    }
  }
  if (!r.ok) why = "the reader's output is cut short";
  return r.ok;
}

// Each face's ε from its OCCT tolerance (what tessellate put there) and the file's declared length
// uncertainty (0: none), as `choice` says; Value is applied to every surface after reading
// (import_file.cpp).
void apply_declared_uncertainty(Model& m, double declared, UncertaintyChoice choice) {
  if (!(declared > 0.0) || choice == UncertaintyChoice::OcctTolerance || choice == UncertaintyChoice::Value) return;
  for (Surface& s : m.surfaces) {
    if (declared > s.uncertainty) {
      s.uncertainty = declared;
      s.uncertainty_source = UncertaintySource::Declared;
    }
  }
}

}  // namespace

Transfer::~Transfer() { discard_shapes(); }

void Transfer::discard_shapes() {
  try {
    const std::lock_guard<std::mutex> lock(application_mutex());
    if (!doc.IsNull() && doc->IsOpened()) XCAFApp_Application::GetApplication()->Close(doc);
  } catch (const Standard_Failure&) {
  }
  doc.Nullify();
  faces.clear();
  side_colours.clear();
  walked.reset();
  loose.Nullify();
  loose_ids.clear();
}

void Transfer::set_loose(const TopoDS_Shape& compound, const FaceEntityMap& entities, std::string note) {
  TopTools_IndexedMapOfShape map;
  TopExp::MapShapes(compound, TopAbs_FACE, map);
  loose = compound;
  loose_ids.assign(static_cast<std::size_t>(map.Extent()), -1);
  for (Standard_Integer f = 1; f <= map.Extent(); ++f)
    if (const auto it = entities.find(map(f).TShape().get()); it != entities.end())
      loose_ids[static_cast<std::size_t>(f - 1)] = it->second.id;
  loose_note = std::move(note);
  complete = false;
}

void record_occt_failure(Transfer& t, const std::string& path, const std::string& format, const Standard_Failure& e) {
  t.diagnostics.push_back({Severity::Error, path, 0, -1, "OCCT failed while reading " + format + ": " + e.GetMessageString()});
  t.complete = false;
  t.discard_shapes();
}

Handle(TDocStd_Document) new_xcaf_document() {
  Handle(TDocStd_Document) doc;
  const std::lock_guard<std::mutex> lock(application_mutex());
  application()->NewDocument("BinXCAF", doc);
  return doc;
}

std::string pack_transfer(const Transfer& t, std::size_t threads) {
  ByteWriter w;
  write_diagnostics(w, t.diagnostics);
  w.u64(t.complete ? 1 : 0);
  w.u64(static_cast<std::uint64_t>(t.kind));
  w.f64(t.declared_uncertainty);
  w.f64(t.read_seconds);
  w.u64(t.parallel_workers);
  w.f64(t.parallel_seconds);
  w.u64(t.split_failed ? 1 : 0);
  w.u64(t.pieces);
  w.u64(t.pieces_cached);
  w.f64(t.piece_costs.split);
  w.f64(t.piece_costs.main_parse);
  w.f64(t.piece_costs.workers);
  w.u64(t.piece_costs.bytes.size());
  for (std::size_t p = 0; p < t.piece_costs.bytes.size(); ++p) {
    w.u64(t.piece_costs.bytes[p]);
    w.u64(t.piece_costs.weights[p]);
    w.f64(t.piece_costs.seconds[p]);
  }
  write_component_placements(w, t.placements);
  if (t.walked) {
    w.u64(1);
    write_walked(w, *t.walked, threads);
  } else if (!t.loose.IsNull()) {
    w.u64(2);
    w.u64(t.loose_ids.size());
    for (const std::int64_t id : t.loose_ids) w.i64(id);
    w.str(t.loose_note);
    std::ostringstream stored;
    BinTools::Write(t.loose, stored, Standard_False, Standard_False, BinTools_FormatVersion_CURRENT);
    w.str(stored.str());
  } else {
    w.u64(0);
  }
  return std::move(w.out);
}

bool unpack_transfer(const std::string& bytes, Transfer& t, std::string& why) {
  ByteReader r{bytes};
  {
    std::vector<Diagnostic> read = read_diagnostics(r);
    t.diagnostics.insert(t.diagnostics.end(), std::make_move_iterator(read.begin()), std::make_move_iterator(read.end()));
  }
  t.complete = r.u64() == 1;
  t.kind = static_cast<SourceKind>(r.u64());
  t.declared_uncertainty = r.f64();
  t.read_seconds = r.f64();
  t.parallel_workers = r.u64();
  t.parallel_seconds = r.f64();
  t.split_failed = r.u64() == 1;
  t.pieces = r.u64();
  t.pieces_cached = r.u64();
  t.piece_costs.split = r.f64();
  t.piece_costs.main_parse = r.f64();
  t.piece_costs.workers = r.f64();
  t.piece_costs.bytes.resize(r.ok ? r.count(24) : 0);
  t.piece_costs.weights.resize(t.piece_costs.bytes.size());
  t.piece_costs.seconds.resize(t.piece_costs.bytes.size());
  for (std::size_t p = 0; p < t.piece_costs.bytes.size(); ++p) {
    t.piece_costs.bytes[p] = r.u64();
    t.piece_costs.weights[p] = r.u64();
    t.piece_costs.seconds[p] = r.f64();
  }
  t.unpacked = true;
  if (!read_component_placements(r, t.placements)) {
    why = "the placements are not whole";
    return false;
  }
  const std::uint64_t what = r.u64();
  try {
    if (r.ok && what == 1) {
      if (!read_walked(r, t.walked.emplace(), why)) return false;
    } else if (r.ok && what == 2) {
      t.loose_ids.resize(r.u64());
      for (std::int64_t& id : t.loose_ids) id = r.i64();
      t.loose_note = r.str();
      std::istringstream stored(r.str());
      if (r.ok) BinTools::Read(t.loose, stored);
    }
  } catch (const Standard_Failure& e) {
    why = std::string("OCCT could not load what the reader stored: ") + e.GetMessageString();
    return false;
  }
  if (!r.ok) why = "the reader's output is cut short";
  return r.ok;
}

void walk_transfer(Transfer& t, const std::string& path, bool as_stored) {
  if (t.doc.IsNull() || t.walked) return;
  try {
    t.walked = walk_xcaf_document(t.doc, path, t.kind, t.faces, t.side_colours, as_stored);
  } catch (const Standard_Failure& e) {
    record_occt_failure(t, path, t.kind == SourceKind::IgesFace ? "IGES" : "STEP", e);
  }
}

IsolatedTransfer transfer_in_child(const std::string& path, bool isolate, double time_limit_seconds,
                                   const std::function<Transfer(const Mark&)>& transfer) {
  IsolatedTransfer out;
  const auto threads = static_cast<std::size_t>(std::max(1, omp_get_max_threads()));  // the parts' writers (asked here, before the fork)
  // OCCT's file translators keep global state (their static parameters, the schema's protocol): in
  // this process, files read in parallel take turns.
  static std::mutex unprotected;
  if (!isolate) {
    {
      const std::lock_guard<std::mutex> lock(unprotected);
      out.transfer = transfer([&out](char c) { out.child.marks += c; });
    }
    walk_transfer(out.transfer, path, false);
    out.child.isolated = false;
    return out;
  }
  // The child's Transfer (its document and shapes) is not taken apart after it is packed: the child
  // ends with _exit, which frees it all at once (a 40 MB board's document took 0.04 s to destroy).
  out.child = run_in_child(
      [&](const Mark& mark) {
        auto* made = new Transfer(transfer(mark));
        walk_transfer(*made, path, true);
        return pack_transfer(*made, threads);
      },
      time_limit_seconds);
  std::string why;
  if (out.child.isolated && (out.child.crashed || unpack_transfer(out.child.payload, out.transfer, why))) return out;
  out.warning = Diagnostic{Severity::Warning, path, 0, -1,
                           (out.child.isolated ? "the isolated reader's result could not be read back (" + why + ")"
                                               : "could not start an isolated reader (" + out.child.how + ")") +
                               "; read in this process, unprotected from OCCT crashes"};
  out.child = ChildRun{};
  out.child.isolated = false;
  {
    const std::lock_guard<std::mutex> lock(unprotected);
    out.transfer = transfer([&out](char c) { out.child.marks += c; });
  }
  walk_transfer(out.transfer, path, false);
  return out;
}

ImportResult finish_transfer(Transfer&& t, const std::string& path, const ImportOptions& options) {
  walk_transfer(t, path, false);  // (transfer_in_child walks what it makes)
  ImportResult result;
  result.diagnostics = std::move(t.diagnostics);
  result.complete = t.complete;
  result.files.emplace_back().path = path;
  result.files.back().transfer_workers = t.parallel_workers;
  result.files.back().pieces = t.pieces;
  result.files.back().pieces_cached = t.pieces_cached;
  result.files.back().piece_costs = std::move(t.piece_costs);
  ImportTimings& timings = result.files.back().timings;
  timings.read = t.read_seconds;
  BrepPartTimings part_timings;
  const char* format = t.kind == SourceKind::IgesFace ? "IGES" : "STEP";
  if (t.walked) {
    std::vector<std::vector<std::string>> chains;
    add_walked_document(std::move(*t.walked), path, t.kind, options, result, &part_timings, &chains);
    if (t.placements)
      if (std::optional<Placements> p = file_placements(*t.placements, chains)) {
        p->stored = t.unpacked;
        result.files.back().placements = std::make_shared<const Placements>(std::move(*p));
      }
    if (result.model.instances.empty()) {
      result.diagnostics.push_back({Severity::Error, path, 0, -1, std::string(format) + " file produced no shape"});
      result.complete = false;
    }
  } else if (!t.loose.IsNull()) {
    BrepPartInput in;
    in.shape = &t.loose;
    in.name = cad_file_stem(path);
    in.source_file = path;
    in.kind = t.kind;
    in.tags.resize(t.loose_ids.size());
    for (std::size_t f = 0; f < t.loose_ids.size(); ++f) in.tags[f].entity_id = t.loose_ids[f];
    const auto ids = add_brep_parts(result.model, std::span<const BrepPartInput>(&in, 1), options.tessellation,
                                    options.lazy, result.diagnostics, result.complete, &part_timings);
    result.model.instances.push_back(Instance{"/" + in.name, ids[0], Pose::Identity()});
    if (!t.loose_note.empty()) {
      result.diagnostics.push_back({Severity::Error, path, 0, -1, t.loose_note});
      result.complete = false;
    }
  }
  apply_declared_uncertainty(result.model, t.declared_uncertainty, options.uncertainty);
  timings.heal = part_timings.heal;
  result.files.back().part_heal_seconds = std::move(part_timings.part_heal);
  timings.tessellate = part_timings.tessellate;
  return result;
}

}  // namespace cadclash::detail
