// Transfer ↔ bytes, and Transfer → model.
#include "cad_transfer.h"

#include "cadclash/internal/byte_io.h"

#include <BinTools.hxx>
#include <BinXCAFDrivers.hxx>
#include <PCDM_ReaderStatus.hxx>
#include <PCDM_StoreStatus.hxx>
#include <Standard_Failure.hxx>
#include <TDF_LabelSequence.hxx>
#include <TopExp.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <XCAFApp_Application.hxx>
#include <XCAFDoc_DocumentTool.hxx>
#include <XCAFDoc_ShapeTool.hxx>

#include <algorithm>
#include <mutex>
#include <sstream>

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

// Every face of the document's shapes, in one order that a stored and reloaded document repeats:
// shape labels in tag order, faces in TopExp::MapShapes order.
TopTools_IndexedMapOfShape document_faces(const Handle(TDocStd_Document)& doc) {
  TopTools_IndexedMapOfShape faces;
  TDF_LabelSequence labels;
  XCAFDoc_DocumentTool::ShapeTool(doc->Main())->GetShapes(labels);
  for (Standard_Integer i = 1; i <= labels.Length(); ++i)
    TopExp::MapShapes(XCAFDoc_ShapeTool::GetShape(labels(i)), TopAbs_FACE, faces);
  return faces;
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

std::string pack_transfer(const Transfer& t) {
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
  if (!t.doc.IsNull()) {
    w.u64(1);
    const TopTools_IndexedMapOfShape faces = document_faces(t.doc);
    std::vector<std::pair<Standard_Integer, const FaceEntity*>> tagged;
    for (Standard_Integer f = 1; f <= faces.Extent(); ++f)
      if (const auto it = t.faces.find(faces(f).TShape().get()); it != t.faces.end()) tagged.emplace_back(f, &it->second);
    w.u64(tagged.size());
    for (const auto& [f, entity] : tagged) {
      w.i64(f);
      w.i64(entity->id);
      w.str(entity->name);
    }
    std::unordered_map<const void*, Standard_Integer> index_of;  // by TShape, as the tags
    if (!t.side_colours.empty())
      for (Standard_Integer f = 1; f <= faces.Extent(); ++f) index_of.try_emplace(faces(f).TShape().get(), f);
    std::vector<std::pair<Standard_Integer, const SideColour*>> sides;
    for (const SideColour& c : t.side_colours)
      if (const auto it = index_of.find(c.face.TShape().get()); it != index_of.end()) sides.emplace_back(it->second, &c);
    w.u64(sides.size());
    for (const auto& [f, c] : sides) {
      w.i64(f);
      w.str(c->part);
      for (const float v : c->rgb) w.f64(v);
    }
    std::ostringstream stored;
    const std::lock_guard<std::mutex> lock(application_mutex());
    if (application()->SaveAs(t.doc, stored) != PCDM_SS_OK) return {};
    w.str(stored.str());
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
      std::vector<std::pair<std::int64_t, FaceEntity>> tagged(r.count(24));
      for (auto& [f, entity] : tagged) {
        f = r.i64();
        entity.id = r.i64();
        entity.name = r.str();
      }
      std::vector<std::pair<std::int64_t, SideColour>> sides(r.count(40));
      for (auto& [f, c] : sides) {
        f = r.i64();
        c.part = r.str();
        for (float& v : c.rgb) v = static_cast<float>(r.f64());
      }
      std::istringstream stored(r.str());
      if (!r.ok) {
        why = "the reader's output is cut short";
        return false;
      }
      const std::lock_guard<std::mutex> lock(application_mutex());
      if (application()->Open(stored, t.doc) != PCDM_RS_OK || t.doc.IsNull()) {
        why = "OCCT could not load the document the reader stored";
        return false;
      }
      const TopTools_IndexedMapOfShape faces = document_faces(t.doc);
      for (const auto& [f, entity] : tagged)
        if (f >= 1 && f <= faces.Extent()) t.faces.emplace(faces(static_cast<Standard_Integer>(f)).TShape().get(), entity);
      for (auto& [f, c] : sides) {
        if (f < 1 || f > faces.Extent()) {
          why = "the reader's output is not whole";
          return false;
        }
        c.face = faces(static_cast<Standard_Integer>(f));
        t.side_colours.push_back(std::move(c));
      }
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

IsolatedTransfer transfer_in_child(const std::string& path, bool isolate, double time_limit_seconds,
                                   const std::function<Transfer(const Mark&)>& transfer) {
  IsolatedTransfer out;
  // OCCT's file translators keep global state (their static parameters, the schema's protocol): in
  // this process, files read in parallel take turns.
  static std::mutex unprotected;
  if (!isolate) {
    const std::lock_guard<std::mutex> lock(unprotected);
    out.transfer = transfer([&out](char c) { out.child.marks += c; });
    out.child.isolated = false;
    return out;
  }
  // The child's Transfer (its document and shapes) is not taken apart after it is packed: the child
  // ends with _exit, which frees it all at once (a 40 MB board's document took 0.04 s to destroy).
  out.child = run_in_child([&](const Mark& mark) { return pack_transfer(*new Transfer(transfer(mark))); }, time_limit_seconds);
  std::string why;
  if (out.child.isolated && (out.child.crashed || unpack_transfer(out.child.payload, out.transfer, why))) return out;
  out.warning = Diagnostic{Severity::Warning, path, 0, -1,
                           (out.child.isolated ? "the isolated reader's result could not be read back (" + why + ")"
                                               : "could not start an isolated reader (" + out.child.how + ")") +
                               "; read in this process, unprotected from OCCT crashes"};
  out.child = ChildRun{};
  out.child.isolated = false;
  const std::lock_guard<std::mutex> lock(unprotected);
  out.transfer = transfer([&out](char c) { out.child.marks += c; });
  return out;
}

ImportResult finish_transfer(Transfer&& t, const std::string& path, const ImportOptions& options) {
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
  if (!t.doc.IsNull()) {
    std::vector<std::vector<std::string>> chains;
    add_xcaf_document(t.doc, path, t.kind, t.faces, options, result, &part_timings, &chains, t.side_colours);
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
