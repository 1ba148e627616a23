// IGES through IGESCAFControl_Reader into an XCAF document.
#include "cad_xcaf.h"
#include "cad_transfer.h"
#include "readers.h"

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
#include <XSControl_WorkSession.hxx>

namespace cadclash::detail {

namespace {

// Reads and transfers the file, tessellating nothing.
Transfer read_iges_transfer(const std::string& path) {
  Transfer result;
  result.kind = SourceKind::IgesFace;
  try {
    IGESCAFControl_Reader reader;  // registers the IGES controller and its parameters
    Interface_Static::SetCVal("xstep.cascade.unit", "MM");
    reader.SetColorMode(Standard_True);
    reader.SetNameMode(Standard_True);
    reader.SetLayerMode(Standard_False);
    const IFSelect_ReturnStatus status = reader.ReadFile(path.c_str());
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
    result.doc = new_xcaf_document();
    const bool transferred = reader.Transfer(result.doc) == Standard_True;
    const Handle(Transfer_TransientProcess) process =
        ws.IsNull() || ws->TransferReader().IsNull() ? Handle(Transfer_TransientProcess)() : ws->TransferReader()->TransientProcess();
    if (!process.IsNull() &&
        append_checks(process->CheckList(Standard_True), model, label, path, "IGES transfer", false, result.diagnostics) > 0)
      result.complete = false;
    if (!transferred) {
      result.diagnostics.push_back({Severity::Error, path, 0, -1, "IGES transfer failed; no shape could be made"});
      result.complete = false;
      result.discard_shapes();
    } else {
      result.faces = map_face_entities(process, [&](const Handle(Standard_Transient)& entity, FaceEntity& out) {
        const Handle(IGESData_IGESEntity) iges = Handle(IGESData_IGESEntity)::DownCast(entity);
        if (iges.IsNull()) return false;
        out.id = label(entity);
        if (iges->HasName() && !iges->NameValue().IsNull()) out.name = iges->NameValue()->ToCString();
        return true;
      });
    }
  } catch (const Standard_Failure& e) {
    result.diagnostics.push_back({Severity::Error, path, 0, -1, std::string("OCCT failed while reading IGES: ") + e.GetMessageString()});
    result.complete = false;
    result.discard_shapes();  // a transfer cut short keeps nothing
  }
  return result;
}

}  // namespace

// OCCT's translators may crash on a malformed file (read_step says more): the transfer runs in a
// child process, which sends the document back.
ImportResult read_iges(const std::string& path, const ImportOptions& options) {
  prepare_occt_exchange();
  IsolatedTransfer run = transfer_in_child(path, options.isolate_cad_readers, [&](const Mark&) { return read_iges_transfer(path); });
  if (run.child.crashed)
    return failed_import(path, "OCCT crashed with " + run.child.how + " while reading the IGES file (in an isolated reader); nothing could be read");
  ImportResult result = finish_transfer(std::move(run.transfer), path, options);
  if (run.warning) result.diagnostics.insert(result.diagnostics.begin(), *run.warning);
  return result;
}

}  // namespace cadclash::detail
