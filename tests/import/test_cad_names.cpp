// Names a CAD user knows on exports whose writer named nothing (import.h, "Generic names"): a KiCad
// board written through OCCT's XCAF writer names each placed model's only occurrence after its label
// entry ("=>[0:1:1:9]") and its leaf product after the shape type ("SOLID"). The check reads
// "/board/D15 (LED_D5.0mm)", not "/board/D15/=>[0:1:1:9] (SOLID)".
#include "cadclash/import.h"
#include "xcaf_test_doc.h"

#include <BRepPrimAPI_MakeBox.hxx>
#include <gp_Trsf.hxx>

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace cadclash {
namespace {

// board → D15 → model "LED_D5.0mm" → one unnamed occurrence of an unnamed box; board → R1 →
// model "R_0603" → two unnamed occurrences of two boxes (two children: their levels stay).
std::string write_kicad_like_board() {
  testing::XcafTestDoc doc;
  const Handle(XCAFDoc_ShapeTool)& tool = doc.tool();
  const auto name = testing::XcafTestDoc::name;
  auto at = [](double x) {
    gp_Trsf t;
    t.SetTranslation(gp_Vec(x, 0, 0));
    return TopLoc_Location(t);
  };
  const TDF_Label board = name(tool->NewShape(), "board");
  const TDF_Label led = name(tool->NewShape(), "LED_D5.0mm");
  tool->AddComponent(led, tool->AddShape(BRepPrimAPI_MakeBox(5, 5, 8).Shape(), Standard_False), TopLoc_Location());
  const TDF_Label resistor = name(tool->NewShape(), "R_0603");
  tool->AddComponent(resistor, tool->AddShape(BRepPrimAPI_MakeBox(1.6, 0.8, 0.5).Shape(), Standard_False), TopLoc_Location());
  tool->AddComponent(resistor, tool->AddShape(BRepPrimAPI_MakeBox(0.3, 0.8, 0.5).Shape(), Standard_False), at(2));
  name(tool->AddComponent(board, led, at(0)), "D15");
  name(tool->AddComponent(board, resistor, at(20)), "R1");
  return doc.write_step("kicad_like_board.step");
}

TEST(CadNames, GenericOnlyChildrenAddNoLevelAndPartsTakeTheModelsName) {
  const std::string file = write_kicad_like_board();
  std::ifstream in(file);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  // The writer did name them as KiCad's export does.
  ASSERT_NE(text.find("=>["), std::string::npos);
  ASSERT_NE(text.find("PRODUCT('SOLID'"), std::string::npos);
  const ImportResult r = import_file(file);
  ASSERT_TRUE(r.complete);
  std::vector<std::string> seen;
  for (const Instance& i : r.model.instances) seen.push_back(i.path + " (" + r.model.parts[i.part].name + ")");
  std::sort(seen.begin(), seen.end());
  ASSERT_EQ(seen.size(), 3u);
  EXPECT_EQ(seen[0], "/board/D15 (LED_D5.0mm)");
  // Two children of one model: each keeps its level (the writer's entries), named after the model.
  EXPECT_EQ(seen[1].rfind("/board/R1/=>[", 0), 0u) << seen[1];
  EXPECT_NE(seen[1].find(" (R_0603)"), std::string::npos) << seen[1];
  EXPECT_EQ(seen[2].rfind("/board/R1/=>[", 0), 0u) << seen[2];
  EXPECT_NE(seen[2].find(" (R_0603)"), std::string::npos) << seen[2];
}

}  // namespace
}  // namespace cadclash
