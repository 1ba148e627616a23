// STEP (AP203/AP214/AP242) through STEPCAFControl_Reader into an XCAF document.
#include "cad_xcaf.h"
#include "readers.h"

#include <IFSelect_ReturnStatus.hxx>
#include <Interface_Static.hxx>
#include <STEPCAFControl_Reader.hxx>
#include <STEPControl_Reader.hxx>
#include <Standard_Failure.hxx>
#include <StepData_StepModel.hxx>
#include <StepRepr_RepresentationItem.hxx>
#include <StepShape_Face.hxx>
#include <TCollection_HAsciiString.hxx>
#include <TDocStd_Document.hxx>
#include <XCAFApp_Application.hxx>
#include <XSControl_TransferReader.hxx>
#include <XSControl_WorkSession.hxx>

namespace cadclash::detail {
namespace {

const char* status_text(IFSelect_ReturnStatus status) {
  switch (status) {
    case IFSelect_RetVoid: return "the file holds no data";
    case IFSelect_RetDone: return "read";
    case IFSelect_RetError: return "the file could not be opened or is not STEP";
    case IFSelect_RetFail: return "the file could not be parsed";
    case IFSelect_RetStop: return "reading was stopped";
  }
  return "unknown status";
}

// Closes the XCAF document on every path out (the shapes we keep hold their own handles).
struct DocumentGuard {
  Handle(TDocStd_Document) doc;
  ~DocumentGuard() {
    try {
      if (!doc.IsNull() && doc->IsOpened()) XCAFApp_Application::GetApplication()->Close(doc);
    } catch (const Standard_Failure&) {
    }
  }
};

}  // namespace

ImportResult read_step(const std::string& path, const ImportOptions& options) {
  prepare_occt_exchange();
  ImportResult result;
  try {
    STEPCAFControl_Reader reader;  // its constructor registers the STEP controller and its parameters
    Interface_Static::SetCVal("xstep.cascade.unit", "MM");
    reader.SetColorMode(Standard_True);
    reader.SetNameMode(Standard_True);
    reader.SetLayerMode(Standard_False);
    reader.SetPropsMode(Standard_False);
    reader.SetGDTMode(Standard_False);
    reader.SetMatMode(Standard_False);
    reader.SetViewMode(Standard_False);

    const IFSelect_ReturnStatus status = reader.ReadFile(path.c_str());
    STEPControl_Reader& step = reader.ChangeReader();
    const Handle(StepData_StepModel) model = step.StepModel();
    const EntityLabelFn label = [&model](const Handle(Standard_Transient)& entity) -> std::int64_t {
      if (model.IsNull()) return -1;
      const Standard_Integer id = model->IdentLabel(entity);
      return id > 0 ? id : -1;
    };
    const Handle(XSControl_WorkSession) ws = step.WS();
    std::size_t load_fails = 0;
    if (!ws.IsNull() && !model.IsNull())
      load_fails = append_checks(ws->ModelCheckList(Standard_False), model, label, path, "STEP syntax", false,
                                 result.diagnostics);
    if (status != IFSelect_RetDone) {
      result.diagnostics.push_back({Severity::Error, path, 0, -1, std::string("cannot read STEP file: ") + status_text(status)});
      result.complete = false;
      return result;
    }
    if (load_fails > 0) result.complete = false;
    if (model.IsNull() || model->NbEntities() == 0) {
      result.diagnostics.push_back({Severity::Error, path, 0, -1, "STEP file has an empty DATA section"});
      result.complete = false;
      return result;
    }
    if (reader.NbRootsForTransfer() == 0) {
      result.diagnostics.push_back({Severity::Error, path, 0, -1,
                                    "STEP file holds no shape to transfer (no product with a shape representation "
                                    "that this reader's schema knows)"});
      result.complete = false;
      return result;
    }

    DocumentGuard guard;
    XCAFApp_Application::GetApplication()->NewDocument("MDTV-XCAF", guard.doc);
    const bool transferred = reader.Transfer(guard.doc) == Standard_True;
    const Handle(Transfer_TransientProcess) process =
        ws.IsNull() || ws->TransferReader().IsNull() ? Handle(Transfer_TransientProcess)() : ws->TransferReader()->TransientProcess();
    if (!process.IsNull() &&
        append_checks(process->CheckList(Standard_True), model, label, path, "STEP transfer", false, result.diagnostics) > 0)
      result.complete = false;
    if (!transferred) {
      result.diagnostics.push_back({Severity::Error, path, 0, -1, "STEP transfer failed; no shape could be made"});
      result.complete = false;
      return result;
    }

    const FaceEntityMap faces = map_face_entities(process, [&](const Handle(Standard_Transient)& entity, FaceEntity& out) {
      if (!entity->IsKind(STANDARD_TYPE(StepShape_Face))) return false;
      out.id = label(entity);
      const Handle(StepRepr_RepresentationItem) item = Handle(StepRepr_RepresentationItem)::DownCast(entity);
      if (!item.IsNull() && !item->Name().IsNull()) out.name = item->Name()->ToCString();
      return true;
    });
    add_xcaf_document(guard.doc, path, SourceKind::StepFace, faces, options, result);
    if (result.model.instances.empty()) {
      result.diagnostics.push_back({Severity::Error, path, 0, -1, "STEP file produced no shape"});
      result.complete = false;
    }
  } catch (const Standard_Failure& e) {
    result.diagnostics.push_back({Severity::Error, path, 0, -1, std::string("OCCT failed while reading STEP: ") + e.GetMessageString()});
    result.complete = false;
  }
  return result;
}

}  // namespace cadclash::detail
