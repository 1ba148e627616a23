// write_board_step — writes the truth tests' board scene (cadclash/testing/scenes.h) as a STEP
// assembly, the input of the import benchmark (scripts/import_bench.sh).
//   write_board_step DATA_EXTERNAL_DIR OUT.step [COPIES [SHIFT_X [unshared]]]
// One product per distinct part (the faces of its B-rep, as a compound), one occurrence per instance,
// placed by its pose; COPIES (default 1) boards side by side (grid_copies, 5 mm apart), the whole
// moved SHIFT_X mm along x (default 0; a second file far from the first has no pair with it). With
// "unshared", every instance gets a product of its own (a copy of its part's faces), as exporters
// that do not find repeated components write them.
#include "cadclash/geometry.h"
#include "cadclash/tessellate.h"
#include "cadclash/testing/scenes.h"

#include <BRepBuilderAPI_Copy.hxx>
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

#include <algorithm>
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
  if (argc < 3 || argc > 6) {
    std::cerr << "usage: write_board_step DATA_EXTERNAL_DIR OUT.step [COPIES [SHIFT_X [unshared]]]\n";
    return 2;
  }
  const int copies = argc >= 4 ? std::atoi(argv[3]) : 1;
  const double shift = argc >= 5 ? std::atof(argv[4]) : 0.0;
  const bool unshared = argc >= 6 && std::string(argv[5]) == "unshared";
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
  auto add_part = [&](std::size_t p, bool copy) {
    const auto* source = dynamic_cast<const cadclash::BrepSource*>(model.parts[p].source.get());
    if (!source) return TDF_Label();
    BRep_Builder b;
    TopoDS_Compound c;
    b.MakeCompound(c);
    for (std::uint32_t k = 0; k < source->face_count(); ++k) b.Add(c, source->face(k));
    const TDF_Label label = shapes->AddShape(copy ? BRepBuilderAPI_Copy(c).Shape() : TopoDS_Shape(c), Standard_False);
    TDataStd_Name::Set(label, model.parts[p].name.c_str());
    return label;
  };
  std::vector<TDF_Label> part_labels(model.parts.size());
  for (std::size_t p = 0; p < model.parts.size(); ++p) part_labels[p] = add_part(p, false);
  const TDF_Label board = shapes->NewShape();
  TDataStd_Name::Set(board, "board");
  for (std::size_t i = 0; i < model.instances.size(); ++i) {
    const cadclash::Instance& instance = model.instances[i];
    if (part_labels[instance.part].IsNull()) continue;
    // Every instance after the first of its part: a copy of its own when unshared.
    const bool own = unshared &&
                     std::any_of(model.instances.begin(), model.instances.begin() + static_cast<std::ptrdiff_t>(i),
                                 [&](const cadclash::Instance& e) { return e.part == instance.part; });
    const TDF_Label part = own ? add_part(instance.part, true) : part_labels[instance.part];
    const TDF_Label component = shapes->AddComponent(board, part, TopLoc_Location(trsf_of(instance.pose)));
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
