// IGES through IGESCAFControl_Reader into an XCAF document (or root by root after a crash).
#include "cad_xcaf.h"
#include "cad_transfer.h"
#include "readers.h"

#include <BRep_Builder.hxx>
#include <IFSelect_ReturnStatus.hxx>
#include <IGESCAFControl_Reader.hxx>
#include <IGESData_IGESEntity.hxx>
#include <IGESData_IGESModel.hxx>
#include <Interface_Static.hxx>
#include <Standard_Failure.hxx>
#include <TCollection_HAsciiString.hxx>
#include <TDocStd_Document.hxx>
#include <XCAFApp_Application.hxx>
#include <XSControl_TransferReader.hxx>
#include <TopoDS_Compound.hxx>
#include <XSControl_WorkSession.hxx>

#include <chrono>
#include <set>

namespace cadclash::detail {

namespace {

FaceEntityFn describe_iges_face(const EntityLabelFn& label) {
  return [label](const Handle(Standard_Transient)& entity, FaceEntity& out) {
    const Handle(IGESData_IGESEntity) iges = Handle(IGESData_IGESEntity)::DownCast(entity);
    if (iges.IsNull()) return false;
    out.id = label(entity);
    if (iges->HasName() && !iges->NameValue().IsNull()) out.name = iges->NameValue()->ToCString();
    return true;
  };
}

void transfer_roots_one_by_one(IGESCAFControl_Reader& reader, const EntityLabelFn& label, const std::string& path,
                               const std::set<std::int64_t>& skip, const Mark& mark, Transfer& result) {
  reader.ClearShapes();
  const Standard_Integer roots = reader.NbRootsForTransfer();
  std::size_t made = 0;
  for (Standard_Integer i = 1; i <= roots; ++i) {
    const std::int64_t id = label(reader.RootForTransfer(i));
    if (skip.count(id)) continue;  // read_iges names it
    mark_entity_begin(mark, id);
    try {
      const Standard_Integer before = reader.NbShapes();
      if (reader.TransferOneRoot(i) && reader.NbShapes() > before) ++made;
      else result.diagnostics.push_back({Severity::Error, path, 0, id, "root entity could not be transferred; dropped"});
    } catch (const Standard_Failure&) {
      result.diagnostics.push_back({Severity::Error, path, 0, id, "root entity could not be transferred; dropped"});
    }
    mark_entity_end(mark);
  }
  result.complete = false;
  if (made == 0) return;
  TopoDS_Compound faces;
  BRep_Builder builder;
  builder.MakeCompound(faces);
  for (Standard_Integer k = 1; k <= reader.NbShapes(); ++k) builder.Add(faces, reader.Shape(k));
  const Handle(XSControl_WorkSession) ws = reader.WS();
  result.set_loose(faces, map_face_entities(ws->TransferReader()->TransientProcess(), describe_iges_face(label)),
                   "the file could not be transferred whole; " + std::to_string(made) + " of " + std::to_string(roots) +
                       " root entities transferred on their own into loose faces of one part");
}

// Marks of the child (isolated_run.h): the file was parsed.
constexpr char kParsed = 'P';

// Reads and transfers the file, tessellating nothing: the whole document (colours, names, assembly
// structure), or, after OCCT crashed on that, each root entity on its own into loose faces of one
// part, without the roots in `skip` (directory entry numbers a child crashed on).
Transfer read_iges_transfer(const std::string& path, bool one_by_one, const std::set<std::int64_t>& skip, const Mark& mark) {
  Transfer result;
  result.kind = SourceKind::IgesFace;
  try {
    IGESCAFControl_Reader reader;  // registers the IGES controller and its parameters
    Interface_Static::SetCVal("xstep.cascade.unit", "MM");
    reader.SetColorMode(Standard_True);
    reader.SetNameMode(Standard_True);
    reader.SetLayerMode(Standard_False);
    const auto read_start = std::chrono::steady_clock::now();
    const IFSelect_ReturnStatus status = reader.ReadFile(path.c_str());
    result.read_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - read_start).count();
    const Handle(IGESData_IGESModel) model = Handle(IGESData_IGESModel)::DownCast(reader.Model());
    const EntityLabelFn label = [&model](const Handle(Standard_Transient)& entity) -> std::int64_t {
      const Handle(IGESData_IGESEntity) iges = Handle(IGESData_IGESEntity)::DownCast(entity);
      if (model.IsNull() || iges.IsNull()) return -1;
      const Standard_Integer de = model->DNum(iges);
      return de > 0 ? de : -1;
    };
    const Handle(XSControl_WorkSession) ws = reader.WS();
    if (!ws.IsNull() && !model.IsNull() && model->NbEntities() > 0 &&
        append_checks(ws->ModelCheckList(Standard_False), model, label, path, "IGES syntax", false, result.diagnostics) > 0)
      result.complete = false;
    if (status != IFSelect_RetDone || model.IsNull() || model->NbEntities() == 0) {
      result.diagnostics.push_back({Severity::Error, path, 0, -1,
                                    status == IFSelect_RetDone ? "IGES file holds no entities" : "cannot read IGES file"});
      result.complete = false;
      return result;
    }
    mark(kParsed);
    if (one_by_one) {
      transfer_roots_one_by_one(reader, label, path, skip, mark, result);
      return result;
    }
    if (const auto process = transfer_document(reader, ws, model, label, path, "IGES", result))
      result.faces = map_face_entities(*process, describe_iges_face(label));
  } catch (const Standard_Failure& e) {
    record_occt_failure(result, path, "IGES", e);
  }
  return result;
}

}  // namespace

// OCCT's translators may crash on a malformed file (read_step says more): the transfer runs in a
// child process, which sends the document back.
ImportResult read_iges(const std::string& path, const ImportOptions& options) {
  prepare_occt_exchange();
  const TransferHealing healing(options.transfer_healing);
  std::vector<Diagnostic> notes;
  std::set<std::int64_t> skip;  // root entities a child crashed on
  constexpr std::size_t kMaxSkips = 20;
  bool one_by_one = false;
  const ReaderClock clock(options.reader_time_limit_seconds);
  if (auto warning = unapplied_time_limit(path, options)) notes.push_back(*warning);
  for (;;) {
    IsolatedTransfer run = transfer_in_child(path, options.isolate_cad_readers, clock.left(), [&](const Mark& mark) {
      return read_iges_transfer(path, one_by_one, skip, mark);
    });
    if (run.warning) notes.push_back(*run.warning);
    if (!run.child.crashed) {
      ImportResult result = finish_transfer(std::move(run.transfer), path, options);
      for (const Diagnostic& d : notes) result.complete = result.complete && d.severity != Severity::Error;
      result.diagnostics.insert(result.diagnostics.begin(), notes.begin(), notes.end());
      return result;
    }
    const bool parsed = run.child.marks.find(kParsed) != std::string::npos;
    const std::int64_t root = entity_in_progress(run.child.marks);
    if (run.child.timed_out) {
      notes.push_back({Severity::Error, path, 0, root,
                       clock.stopped_message(!parsed ? "parsing the file" : "transferring its shapes", root)});
      break;
    }
    if (one_by_one && root >= 0 && skip.size() < kMaxSkips && skip.insert(root).second) {
      notes.push_back({Severity::Error, path, 0, root,
                       "OCCT crashed with " + run.child.how + " while transferring this root entity on its own (in an isolated reader); dropped"});
      continue;
    }
    const bool retry = parsed && !one_by_one;
    notes.push_back({Severity::Error, path, 0, -1,
                     "OCCT crashed with " + run.child.how + " while " + (!parsed ? "parsing the file" : "transferring its shapes") +
                         " (in an isolated reader); " + (retry ? "read again root entity by root entity" : "nothing more could be read")});
    if (!retry) break;
    one_by_one = true;
  }
  ImportResult result = failed_import(path, "no shape could be read from the IGES file");
  result.diagnostics.insert(result.diagnostics.begin(), notes.begin(), notes.end());
  return result;
}

}  // namespace cadclash::detail
