// STEP files and the supported range (model.h): a face that reaches past kMaxLength is dropped with
// an error naming its entity #id and the coordinate; an instance placed past it is dropped with an
// error naming its path and the offset; the rest of the file is kept.
#include "cadclash/collide.h"
#include "cadclash/import.h"
#include "xcaf_test_doc.h"

#include <BRepPrimAPI_MakeBox.hxx>
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
  testing::XcafTestDoc doc;
  const Handle(XCAFDoc_ShapeTool)& tool = doc.tool();
  const auto name = testing::XcafTestDoc::name;
  const TDF_Label root = name(tool->NewShape(), "assembly");
  const TDF_Label plate = name(tool->AddShape(BRepPrimAPI_MakeBox(10, 10, 1).Shape(), Standard_False), "plate");
  const TDF_Label far =
      name(tool->AddShape(BRepPrimAPI_MakeBox(gp_Pnt(1e200, 0, 0), 1, 1, 1).Shape(), Standard_False), "far");
  name(tool->AddComponent(root, plate, TopLoc_Location()), "plate");
  name(tool->AddComponent(root, far, TopLoc_Location()), "far");
  gp_Trsf up;
  up.SetTranslation(gp_Vec(0, 0, 1e200));
  name(tool->AddComponent(root, plate, TopLoc_Location(up)), "lifted");
  return doc.write_step("far_assembly.step");
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
  // The dropped faces are not checked or healed first: no BRepCheck warning names them.
  EXPECT_EQ(std::count_if(r.diagnostics.begin(), r.diagnostics.end(),
                          [](const Diagnostic& d) { return d.message.find("part 'far'") != std::string::npos &&
                                                           d.message.find("outside the supported range") == std::string::npos; }),
            0)
      << messages(r);
  // Kept: the plate's occurrence with its six faces meshed; the far part's faces have no triangles
  // and no box, so no query reaches them; nothing in the model lies past the range.
  std::vector<std::string> paths;
  for (const Instance& i : r.model.instances) paths.push_back(i.path);
  std::sort(paths.begin(), paths.end());
  EXPECT_EQ(paths, (std::vector<std::string>{"/assembly/far", "/assembly/plate"}));
  std::size_t meshed = 0;
  for (const Surface& s : r.model.surfaces) {
    if (!s.aabb.isEmpty()) {
      EXPECT_LE(std::max(s.aabb.min().cwiseAbs().maxCoeff(), s.aabb.max().cwiseAbs().maxCoeff()), kMaxLength);
    }
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
