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
#include <BRep_Builder.hxx>
#include <TopExp.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS_Compound.hxx>

#include <algorithm>
#include <cctype>
#include <fstream>
#include <optional>
#include <sstream>
#include <utility>

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

// The FILE_SCHEMA names of the header and the line they are on; empty when there is none.
std::pair<std::vector<std::string>, std::int64_t> header_schemas(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string header(64 * 1024, '\0');
  in.read(header.data(), static_cast<std::streamsize>(header.size()));
  header.resize(static_cast<std::size_t>(in.gcount()));
  const std::size_t at = header.find("FILE_SCHEMA");
  if (at == std::string::npos) return {{}, 0};
  const auto line = 1 + std::count(header.begin(), header.begin() + static_cast<std::ptrdiff_t>(at), '\n');
  const std::size_t end = header.find(';', at);
  std::vector<std::string> names;
  const std::string list = header.substr(at, end == std::string::npos ? std::string::npos : end - at);
  for (std::size_t q = list.find('\''); q != std::string::npos;) {
    const std::size_t close = list.find('\'', q + 1);
    if (close == std::string::npos) break;
    names.push_back(list.substr(q + 1, close - q - 1));
    q = list.find('\'', close + 1);
  }
  return {names, line};
}

bool known_schema(std::string name) {
  std::transform(name.begin(), name.end(), name.begin(), [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  for (const char* prefix : {"AUTOMOTIVE_DESIGN", "CONFIG_CONTROL_DESIGN", "CONFIGURATION_CONTROL_3D_DESIGN",
                             "AP203_CONFIGURATION_CONTROLLED", "AP214", "AP242_MANAGED_MODEL_BASED_3D_ENGINEERING",
                             "AP209_MULTIDISCIPLINARY", "STRUCTURAL_ANALYSIS_DESIGN"})
    if (name.rfind(prefix, 0) == 0) return true;
  return false;
}

// A truncated file cut back to its last complete entity and closed properly, with the line of the
// cut; nullopt when the file is not truncated (it ends with END-ISO-10303-21).
std::optional<std::pair<std::string, std::int64_t>> close_truncated(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream buffer;
  buffer << in.rdbuf();
  std::string text = buffer.str();
  if (text.find("END-ISO-10303-21") != std::string::npos) return std::nullopt;
  const std::size_t data = text.find("DATA;");
  if (data == std::string::npos) return std::nullopt;
  std::size_t cut = text.rfind(");", std::string::npos);
  while (cut != std::string::npos && cut > data) {
    const std::size_t after = cut + 2;
    if (after >= text.size() || text[after] == '\n' || text[after] == '\r') break;
    cut = cut == 0 ? std::string::npos : text.rfind(");", cut - 1);
  }
  if (cut == std::string::npos || cut < data) cut = data + 3;  // keep "DATA;" only
  text.resize(cut + 2);
  const auto line = 1 + std::count(text.begin(), text.end(), '\n');
  text += "\nENDSEC;\nEND-ISO-10303-21;\n";
  return std::make_pair(std::move(text), static_cast<std::int64_t>(line));
}

// When no product can be transferred (a cut-off file loses its product structure, which OCCT
// writes last), every face entity is transferred on its own into one part named after the file.
void recover_loose_faces(STEPControl_Reader& step, const Handle(StepData_StepModel)& model, const std::string& path,
                         const ImportOptions& options, const EntityLabelFn& label, ImportResult& result) {
  TopoDS_Compound faces;
  BRep_Builder builder;
  builder.MakeCompound(faces);
  std::size_t tried = 0, made = 0;
  for (Standard_Integer i = 1; i <= model->NbEntities(); ++i) {
    const Handle(Standard_Transient) entity = model->Value(i);
    if (entity.IsNull() || !entity->IsKind(STANDARD_TYPE(StepShape_Face))) continue;
    ++tried;
    try {
      step.ClearShapes();
      if (!step.TransferEntity(entity) || step.NbShapes() == 0) {
        result.diagnostics.push_back({Severity::Error, path, 0, label(entity), "face entity could not be made; dropped"});
        continue;
      }
      TopTools_IndexedMapOfShape map;
      TopExp::MapShapes(step.Shape(1), TopAbs_FACE, map);
      for (Standard_Integer f = 1; f <= map.Extent(); ++f) builder.Add(faces, map(f));
      ++made;
    } catch (const Standard_Failure&) {
      result.diagnostics.push_back({Severity::Error, path, 0, label(entity), "face entity could not be made; dropped"});
    }
  }
  if (made == 0) return;
  const Handle(XSControl_WorkSession) ws = step.WS();
  const FaceEntityMap tags = map_face_entities(ws->TransferReader()->TransientProcess(),
                                               [&](const Handle(Standard_Transient)& entity, FaceEntity& out) {
                                                 if (!entity->IsKind(STANDARD_TYPE(StepShape_Face))) return false;
                                                 out.id = label(entity);
                                                 return true;
                                               });
  BrepPartInput in;
  in.shape = &faces;
  in.name = cad_file_stem(path);
  in.source_file = path;
  in.kind = SourceKind::StepFace;
  TopTools_IndexedMapOfShape map;
  TopExp::MapShapes(faces, TopAbs_FACE, map);
  in.tags.resize(static_cast<std::size_t>(map.Extent()));
  for (Standard_Integer f = 1; f <= map.Extent(); ++f)
    if (auto it = tags.find(map(f).TShape().get()); it != tags.end()) in.tags[static_cast<std::size_t>(f - 1)].entity_id = it->second.id;
  const auto ids = add_brep_parts(result.model, std::span<const BrepPartInput>(&in, 1), options.tessellation, options.lazy,
                                  result.diagnostics, result.complete);
  result.model.instances.push_back(Instance{"/" + in.name, ids[0], Pose::Identity()});
  result.diagnostics.push_back({Severity::Error, path, 0, -1,
                                "no product structure could be read; " + std::to_string(made) + " of " +
                                    std::to_string(tried) + " face entities recovered as loose faces of one part"});
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

    const auto [schemas, schema_line] = header_schemas(path);
    for (const std::string& schema : schemas) {
      if (!known_schema(schema)) {
        result.diagnostics.push_back({Severity::Error, path, schema_line, -1,
                                      "FILE_SCHEMA '" + schema + "' is not a STEP AP203/AP214/AP242 schema; read as AP214 anyway"});
        result.complete = false;
      }
    }
    IFSelect_ReturnStatus status = reader.ReadFile(path.c_str());
    STEPControl_Reader& step = reader.ChangeReader();
    if (status != IFSelect_RetDone) {
      if (auto closed = close_truncated(path)) {
        result.diagnostics.push_back({Severity::Error, path, closed->second, -1,
                                      "STEP file is truncated (no END-ISO-10303-21); read up to its last complete entity, "
                                      "which ends on this line"});
        result.complete = false;
        std::istringstream stream(closed->first);
        status = step.ReadStream(path.c_str(), stream);
      }
    }
    const Handle(StepData_StepModel) model = step.StepModel();
    const EntityLabelFn label = [&model](const Handle(Standard_Transient)& entity) -> std::int64_t {
      if (model.IsNull()) return -1;
      const Standard_Integer id = model->IdentLabel(entity);
      return id > 0 ? id : -1;
    };
    const Handle(XSControl_WorkSession) ws = step.WS();
    std::size_t load_fails = 0;
    if (!ws.IsNull() && !model.IsNull() && model->NbEntities() > 0)
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
      recover_loose_faces(step, model, path, options, label, result);
      if (!result.model.instances.empty()) return result;
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
