// write_board_step — writes the truth tests' board scene (cadclash/testing/scenes.h) as a STEP
// assembly, the input of the import benchmark (scripts/import_bench.sh).
//   write_board_step DATA_EXTERNAL_DIR OUT.step [COPIES [SHIFT_X]]
// One product per distinct part (the faces of its B-rep, as a compound), one occurrence per instance,
// placed by its pose; COPIES (default 1) boards side by side (grid_copies, 5 mm apart), the whole
// moved SHIFT_X mm along x (default 0; a second file far from the first has no pair with it).
#include "cadclash/geometry.h"
#include "cadclash/tessellate.h"
#include "cadclash/testing/scenes.h"

#include <BRep_Builder.hxx>
#include <Interface_Static.hxx>
#include <STEPCAFControl_Writer.hxx>
#include <TDataStd_Name.hxx>
#include <TDocStd_Document.hxx>
#include <TopLoc_Location.hxx>
#include <TopoDS_Compound.hxx>
#include <XCAFApp_Application.hxx>
#include <XCAFDoc_DocumentTool.hxx>
#include <XCAFDoc_ShapeTool.hxx>
#include <gp_Trsf.hxx>

#include <cstdlib>
#include <iostream>
#include <string>
#include <vector>

namespace {

gp_Trsf trsf_of(const cadclash::Pose& pose) {
  const auto& r = pose.linear();
  const auto& t = pose.translation();
  gp_Trsf trsf;
  trsf.SetValues(r(0, 0), r(0, 1), r(0, 2), t.x(), r(1, 0), r(1, 1), r(1, 2), t.y(), r(2, 0), r(2, 1), r(2, 2), t.z());
  return trsf;
}

// The last component of an instance path ("/copy1/board/nut::3" -> "nut::3").
std::string leaf_name(const std::string& path) { return path.substr(path.rfind('/') + 1); }

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3 || argc > 5) {
    std::cerr << "usage: write_board_step DATA_EXTERNAL_DIR OUT.step [COPIES [SHIFT_X]]\n";
    return 2;
  }
  const int copies = argc >= 4 ? std::atoi(argv[3]) : 1;
  const double shift = argc >= 5 ? std::atof(argv[4]) : 0.0;
  cadclash::truth::BuiltScene scene = cadclash::truth::board_scene(argv[1], 0.1);
  if (!scene.ok()) {
    for (const auto& d : scene.diagnostics) std::cerr << cadclash::format_diagnostic(d) << '\n';
    return 1;
  }
  cadclash::Model model = copies > 1 ? cadclash::truth::grid_copies(scene.model, copies, 5.0) : scene.model;
  cadclash::Pose moved = cadclash::Pose::Identity();
  moved.translation() = cadclash::Vec3(shift, 0.0, 0.0);
  cadclash::truth::move_scene(model, moved);

  Handle(TDocStd_Document) doc;
  XCAFApp_Application::GetApplication()->NewDocument("MDTV-XCAF", doc);
  const Handle(XCAFDoc_ShapeTool) shapes = XCAFDoc_DocumentTool::ShapeTool(doc->Main());
  std::vector<TDF_Label> part_labels(model.parts.size());
  for (std::size_t p = 0; p < model.parts.size(); ++p) {
    const auto* source = dynamic_cast<const cadclash::BrepSource*>(model.parts[p].source.get());
    if (!source) continue;
    BRep_Builder b;
    TopoDS_Compound c;
    b.MakeCompound(c);
    for (std::uint32_t k = 0; k < source->face_count(); ++k) b.Add(c, source->face(k));
    part_labels[p] = shapes->AddShape(c, Standard_False);
    TDataStd_Name::Set(part_labels[p], model.parts[p].name.c_str());
  }
  const TDF_Label board = shapes->NewShape();
  TDataStd_Name::Set(board, "board");
  for (const cadclash::Instance& instance : model.instances) {
    if (part_labels[instance.part].IsNull()) continue;
    const TDF_Label component = shapes->AddComponent(board, part_labels[instance.part], TopLoc_Location(trsf_of(instance.pose)));
    TDataStd_Name::Set(component, leaf_name(instance.path).c_str());
  }
  shapes->UpdateAssemblies();

  Interface_Static::SetCVal("write.step.schema", "AP214IS");
  STEPCAFControl_Writer writer;
  writer.SetNameMode(Standard_True);
  if (!writer.Transfer(doc, STEPControl_AsIs) || writer.Write(argv[2]) != IFSelect_RetDone) {
    std::cerr << argv[2] << ": error: could not write the STEP file\n";
    return 1;
  }
  std::cout << argv[2] << ": " << model.parts.size() << " parts, " << model.instances.size() << " instances\n";
  return 0;
}
