// step_rewrite IN.stp OUT.stp [INSTANCE_NAME DX DY DZ] — test support, not part of the product.
//
// Reads an assembly with OCCT's XDE reader and writes it again with STEPCAFControl_Writer: the same
// assembly (names, structure, geometry) under the entity #ids OCCT chooses, which differ from the
// original exporter's. With INSTANCE_NAME, the first assembly component of that name (depth first,
// in file order) is moved by (DX, DY, DZ) mm first. Exit 0 on success, 1 with a message otherwise.
#include <IFSelect_ReturnStatus.hxx>
#include <STEPCAFControl_Reader.hxx>
#include <STEPCAFControl_Writer.hxx>
#include <TDF_LabelSequence.hxx>
#include <TDataStd_Name.hxx>
#include <TDocStd_Document.hxx>
#include <TopoDS_Shape.hxx>
#include <XCAFApp_Application.hxx>
#include <XCAFDoc_DocumentTool.hxx>
#include <XCAFDoc_Location.hxx>
#include <XCAFDoc_ShapeTool.hxx>
#include <gp_Trsf.hxx>

#include <cstdlib>
#include <iostream>
#include <string>

namespace {

std::string name_of(const TDF_Label& l) {
  Handle(TDataStd_Name) n;
  if (!l.FindAttribute(TDataStd_Name::GetID(), n)) return {};
  return TCollection_AsciiString(n->Get()).ToCString();
}

// The first component named `name` under `label` (depth first); a null label when none.
TDF_Label find_component(const TDF_Label& label, const std::string& name) {
  if (!XCAFDoc_ShapeTool::IsAssembly(label)) return {};
  TDF_LabelSequence components;
  XCAFDoc_ShapeTool::GetComponents(label, components, Standard_False);
  for (Standard_Integer i = 1; i <= components.Length(); ++i) {
    TDF_Label ref;
    if (!XCAFDoc_ShapeTool::GetReferredShape(components(i), ref)) ref = components(i);
    if (name_of(components(i)) == name || (name_of(components(i)).empty() && name_of(ref) == name)) return components(i);
    const TDF_Label below = find_component(ref, name);
    if (!below.IsNull()) return below;
  }
  return {};
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3 && argc != 7) {
    std::cerr << "usage: step_rewrite IN.stp OUT.stp [INSTANCE_NAME DX DY DZ]\n";
    return 1;
  }
  Handle(XCAFApp_Application) app = XCAFApp_Application::GetApplication();
  Handle(TDocStd_Document) doc;
  app->NewDocument("MDTV-XCAF", doc);
  STEPCAFControl_Reader reader;
  reader.SetNameMode(true);
  reader.SetColorMode(true);
  if (reader.ReadFile(argv[1]) != IFSelect_RetDone || !reader.Transfer(doc)) {
    std::cerr << argv[1] << ": cannot read\n";
    return 1;
  }
  Handle(XCAFDoc_ShapeTool) shapes = XCAFDoc_DocumentTool::ShapeTool(doc->Main());
  if (argc == 7) {
    TDF_LabelSequence free;
    shapes->GetFreeShapes(free);
    TDF_Label component;
    for (Standard_Integer i = 1; i <= free.Length() && component.IsNull(); ++i) component = find_component(free(i), argv[3]);
    if (component.IsNull()) {
      std::cerr << argv[1] << ": no assembly component named " << argv[3] << "\n";
      return 1;
    }
    gp_Trsf move;
    move.SetTranslation(gp_Vec(std::atof(argv[4]), std::atof(argv[5]), std::atof(argv[6])));
    const TopLoc_Location location = TopLoc_Location(move) * XCAFDoc_ShapeTool::GetLocation(component);
    // The component's location attribute says where it is; UpdateAssemblies() rebuilds the
    // assemblies' compounds from it. (Moving a sub-assembly this way loses its instance name in
    // OCCT 7.6's writer; a part keeps it.)
    XCAFDoc_Location::Set(component, location);
    shapes->UpdateAssemblies();
  }
  STEPCAFControl_Writer writer;
  writer.SetNameMode(true);
  writer.SetColorMode(true);
  if (!writer.Transfer(doc, STEPControl_AsIs) || writer.Write(argv[2]) != IFSelect_RetDone) {
    std::cerr << argv[2] << ": cannot write\n";
    return 1;
  }
  return 0;
}
