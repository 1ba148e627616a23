// STEP files and the supported range (model.h): a face that reaches past kMaxLength is dropped with
// an error naming its entity #id and the coordinate; an instance placed past it is dropped with an
// error naming its path and the offset; the rest of the file is kept.
#include "cadclash/collide.h"
#include "cadclash/import.h"
#include "../test_temp.h"

#include <BRepPrimAPI_MakeBox.hxx>
#include <STEPCAFControl_Writer.hxx>
#include <TDataStd_Name.hxx>
#include <TDocStd_Document.hxx>
#include <XCAFApp_Application.hxx>
#include <XCAFDoc_DocumentTool.hxx>
#include <XCAFDoc_ShapeTool.hxx>
#include <gp_Pnt.hxx>
#include <gp_Trsf.hxx>

#include <gtest/gtest.h>

#include <algorithm>
#include <string>

namespace cadclash {
namespace {

// assembly → plate (a 10 mm box at the origin), far (a 1 mm box at x = 1e200), and a second
// occurrence of the plate translated by 1e200 in z.
std::string write_far_assembly() {
  Handle(TDocStd_Document) doc;
  XCAFApp_Application::GetApplication()->NewDocument("MDTV-XCAF", doc);
  const Handle(XCAFDoc_ShapeTool) tool = XCAFDoc_DocumentTool::ShapeTool(doc->Main());
  auto name = [](const TDF_Label& l, const char* n) { TDataStd_Name::Set(l, TCollection_ExtendedString(n)); };
  const TDF_Label root = tool->NewShape();
  name(root, "assembly");
  const TDF_Label plate = tool->AddShape(BRepPrimAPI_MakeBox(10, 10, 1).Shape(), Standard_False);
  name(plate, "plate");
  const TDF_Label far = tool->AddShape(BRepPrimAPI_MakeBox(gp_Pnt(1e200, 0, 0), 1, 1, 1).Shape(), Standard_False);
  name(far, "far");
  name(tool->AddComponent(root, plate, TopLoc_Location()), "plate");
  name(tool->AddComponent(root, far, TopLoc_Location()), "far");
  gp_Trsf up;
  up.SetTranslation(gp_Vec(0, 0, 1e200));
  name(tool->AddComponent(root, plate, TopLoc_Location(up)), "lifted");
  tool->UpdateAssemblies();
  const std::string path = testing::scratch_dir() + "/far_assembly.step";
  STEPCAFControl_Writer writer;
  writer.SetNameMode(Standard_True);
  EXPECT_TRUE(writer.Transfer(doc, STEPControl_AsIs));
  EXPECT_EQ(writer.Write(path.c_str()), IFSelect_RetDone);
  XCAFApp_Application::GetApplication()->Close(doc);
  return path;
}

std::string messages(const ImportResult& r) {
  std::string out;
  for (const Diagnostic& d : r.diagnostics) out += format_diagnostic(d) + "\n";
  return out;
}

TEST(CadRange, FacesAndPlacementsPastTheRangeAreDroppedAndNamed) {
  const std::string file = write_far_assembly();
  ImportOptions o;
  o.lazy = false;
  ImportResult r = import_file(file, o);
  EXPECT_FALSE(r.complete);
  const auto range_errors = [&](auto pred) {
    return std::count_if(r.diagnostics.begin(), r.diagnostics.end(), [&](const Diagnostic& d) {
      return d.severity == Severity::Error && d.message.find("outside the supported range") != std::string::npos && pred(d);
    });
  };
  // The far box's six faces, each by its ADVANCED_FACE #id and the coordinate it reaches.
  EXPECT_EQ(range_errors([](const Diagnostic& d) { return d.step_id > 0 && d.message.find("1e+200") != std::string::npos; }), 6)
      << messages(r);
  EXPECT_EQ(range_errors([](const Diagnostic& d) { return d.message.find("instance /assembly/lifted") != std::string::npos; }), 1)
      << messages(r);
  // Kept: the plate's occurrence with its six faces meshed; the far part's faces have no triangles
  // and no box, so no query reaches them; nothing in the model lies past the range.
  std::vector<std::string> paths;
  for (const Instance& i : r.model.instances) paths.push_back(i.path);
  std::sort(paths.begin(), paths.end());
  EXPECT_EQ(paths, (std::vector<std::string>{"/assembly/far", "/assembly/plate"}));
  std::size_t meshed = 0;
  for (const Surface& s : r.model.surfaces) {
    if (!s.aabb.isEmpty()) EXPECT_LE(std::max(s.aabb.min().cwiseAbs().maxCoeff(), s.aabb.max().cwiseAbs().maxCoeff()), kMaxLength);
    meshed += !s.mesh.triangles.empty();
  }
  EXPECT_EQ(meshed, 6u);
  // The query over what was kept answers (the far part reaches nothing) rather than refusing.
  Scene scene(r.model);
  const Report report = scene.check();
  EXPECT_TRUE(report.complete) << report.stopped_by;
  EXPECT_TRUE(report.pairs.empty());
}

}  // namespace
}  // namespace cadclash
