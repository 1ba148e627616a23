// The context OCCT's healing at transfer works in (import/src/transfer_fix_context.h) gives the
// shapes OCCT's own context gives: healed faces with many holes, drilled plates written to STEP and
// read back, and the sample files, compared as BREP text byte for byte.
#include "cad_xcaf.h"
#include "transfer_fix_context.h"

#include <BRepBuilderAPI_MakeEdge.hxx>
#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepBuilderAPI_MakePolygon.hxx>
#include <BRepBuilderAPI_MakeWire.hxx>
#include <BRepPrimAPI_MakePrism.hxx>
#include <BRepTools.hxx>
#include <BRep_Builder.hxx>
#include <IGESControl_Reader.hxx>
#include <STEPControl_Reader.hxx>
#include <STEPControl_Writer.hxx>
#include <ShapeAlgo.hxx>
#include <ShapeAlgo_AlgoContainer.hxx>
#include <ShapeExtend.hxx>
#include <ShapeFix_Shape.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Iterator.hxx>
#include <TopoDS_Vertex.hxx>
#include <TopoDS_Wire.hxx>
#include <gp_Circ.hxx>
#include <gp_Pln.hxx>
#include <gp_Trsf.hxx>

#include <gtest/gtest.h>

#include <filesystem>
#include <unistd.h>
#include <sstream>
#include <string>
#include <vector>

namespace cadclash::detail {
namespace {

namespace fs = std::filesystem;

std::string brep_text(const TopoDS_Shape& shape) {
  std::ostringstream out;
  BRepTools::Write(shape, out);
  return out.str();
}

// A square hole's wire, its four edges added in the order given (0 1 2 3 is the loop's own).
TopoDS_Wire square_hole(double x, double y, double side, const std::vector<int>& order) {
  const gp_Pnt corners[4] = {{x, y, 0}, {x, y + side, 0}, {x + side, y + side, 0}, {x + side, y, 0}};  // clockwise
  BRepBuilderAPI_MakePolygon polygon(corners[0], corners[1], corners[2], corners[3], Standard_True);
  std::vector<TopoDS_Edge> edges;
  for (TopExp_Explorer it(polygon.Wire(), TopAbs_EDGE); it.More(); it.Next()) edges.push_back(TopoDS::Edge(it.Current()));
  BRep_Builder builder;
  TopoDS_Wire wire;
  builder.MakeWire(wire);
  for (int i : order) builder.Add(wire, edges[static_cast<std::size_t>(i)]);
  return wire;
}

// A 100 x 100 plane face with a grid of square holes; every third hole's wire has its edges out of
// order, which ShapeFix_Wire's reordering rebuilds (a replacement recorded in the context while the
// other holes' wires are remembered).
TopoDS_Face plate_with_holes(int per_side) {
  BRepBuilderAPI_MakeFace face(gp_Pln(gp::XOY()), 0.0, 100.0, 0.0, 100.0);
  const double pitch = 100.0 / per_side;
  int k = 0;
  for (int i = 0; i < per_side; ++i)
    for (int j = 0; j < per_side; ++j, ++k) {
      const std::vector<int> order = k % 3 == 1 ? std::vector<int>{0, 2, 1, 3} : std::vector<int>{0, 1, 2, 3};
      face.Add(square_hole(i * pitch + 0.25 * pitch, j * pitch + 0.25 * pitch, 0.5 * pitch, order));
    }
  return face.Face();
}

// The face healed as OCCT's transfer heals a shape, in the given context.
TopoDS_Shape healed(const TopoDS_Shape& shape, const Handle(ShapeBuild_ReShape) & context) {
  Handle(ShapeFix_Shape) fix = new ShapeFix_Shape;
  fix->SetContext(context);
  fix->Init(shape);
  fix->SetPrecision(1e-7);
  fix->SetMaxTolerance(1.0);
  fix->Perform();
  return fix->Shape();
}

Handle(ShapeBuild_ReShape) occt_context() {
  Handle(ShapeBuild_ReShape) context = new ShapeBuild_ReShape;
  context->ModeConsiderLocation() = Standard_True;  // as ShapeFix_Shape::Init makes its own
  return context;
}

TEST(TransferFixContext, AFaceWithManyHolesSomeRebuiltHealsAsInOcctsOwnContext) {
  for (int per_side : {4, 6, 9}) {  // 16, 36 and 81 holes
    SCOPED_TRACE(per_side);
    const TopoDS_Face face = plate_with_holes(per_side);
    const TopoDS_Shape expected = healed(face, occt_context());
    Handle(ShapeBuild_ReShape) context = make_transfer_fix_context();
    const TopoDS_Shape got = healed(face, context);
    ASSERT_NE(brep_text(expected), brep_text(face)) << "the healing should rebuild the out-of-order holes";
    EXPECT_EQ(brep_text(got), brep_text(expected));
    const auto& remembering = dynamic_cast<const WireRememberingReShape&>(*context);
    EXPECT_GT(remembering.answered_from_memory(), remembering.walked()) << "the unchanged holes are not walked again";
  }
}

// Apply() of the whole face in both contexts, compared as BREP text (the answers are different
// objects wherever something was rebuilt).
void expect_same_apply(const Handle(ShapeBuild_ReShape) & ours, const Handle(ShapeBuild_ReShape) & occt,
                       const TopoDS_Shape& face, const std::string& after) {
  const TopoDS_Shape expected = occt->Apply(face);
  const TopoDS_Shape got = ours->Apply(face);
  ASSERT_EQ(expected.IsNull(), got.IsNull()) << after;
  EXPECT_EQ(brep_text(got), brep_text(expected)) << after;
  EXPECT_EQ(got.IsSame(face), expected.IsSame(face)) << after;
  EXPECT_EQ(ours->Status(ShapeExtend_DONE1), occt->Status(ShapeExtend_DONE1)) << after;
  EXPECT_EQ(ours->Status(ShapeExtend_DONE3), occt->Status(ShapeExtend_DONE3)) << after;
}

// Between the questions, what ShapeFix does to a context and to shapes: records a rebuilt edge, a
// merged vertex, a rebuilt wire, a removed edge; edits an edge of a remembered wire in place;
// clears; switches ModeConsiderLocation. Each answer is OCCT's own context's.
TEST(TransferFixContext, AppliesAFaceAsOcctsOwnContextWhateverIsRecordedOrEditedBetween) {
  const TopoDS_Face face = plate_with_holes(5);  // 25 holes
  std::vector<TopoDS_Wire> wires;
  for (TopoDS_Iterator it(face); it.More(); it.Next()) wires.push_back(TopoDS::Wire(it.Value()));
  ASSERT_EQ(wires.size(), 26u);
  auto edge_of = [&](std::size_t wire, int k) {
    TopExp_Explorer it(wires[wire], TopAbs_EDGE);
    for (int i = 0; i < k; ++i) it.Next();
    return TopoDS::Edge(it.Current());
  };
  // A second face on the same wires: asked after the first face's answer is recorded, its wires
  // are asked again.
  TopoDS_Shape twin = face.EmptyCopied();
  BRep_Builder builder;
  for (const TopoDS_Wire& wire : wires) builder.Add(twin, wire);
  Handle(ShapeBuild_ReShape) ours = make_transfer_fix_context();
  Handle(ShapeBuild_ReShape) occt = occt_context();
  auto both = [&](auto&& record) {
    record(ours);
    record(occt);
  };
  auto expect_same = [&](const std::string& after) {
    expect_same_apply(ours, occt, face, after);
    expect_same_apply(ours, occt, twin, after + ", the twin face");
  };
  expect_same("nothing recorded");
  expect_same("asked again");

  const TopoDS_Shape edge_copy = edge_of(3, 1).EmptyCopied();
  both([&](const Handle(ShapeBuild_ReShape)& c) { c->Replace(edge_of(3, 1), edge_copy); });
  expect_same("an edge of hole 3 rebuilt");

  TopoDS_Vertex merged;
  builder.MakeVertex(merged, gp_Pnt(50, 50, 0), 1e-3);
  TopoDS_Vertex corner;
  for (TopExp_Explorer it(wires[7], TopAbs_VERTEX); it.More(); it.Next()) corner = TopoDS::Vertex(it.Current());
  both([&](const Handle(ShapeBuild_ReShape)& c) { c->Replace(corner, merged); });
  expect_same("a vertex of hole 7 merged");

  const TopoDS_Wire rebuilt = square_hole(1, 1, 2, {0, 1, 2, 3});
  both([&](const Handle(ShapeBuild_ReShape)& c) { c->Replace(wires[11], rebuilt); });
  expect_same("hole 11 rebuilt");

  both([&](const Handle(ShapeBuild_ReShape)& c) { c->Remove(edge_of(15, 2)); });
  expect_same("an edge of hole 15 removed");

  // Hole 19's last edge swapped in place for the edge rebuilt above (recorded, so Apply changes it).
  const TopoDS_Edge last = edge_of(19, 3);
  const TopoDS_Edge recorded = edge_of(3, 1);
  TopoDS_Wire in_place = wires[19];
  in_place.Free(Standard_True);
  builder.Remove(in_place, last);
  builder.Add(in_place, recorded);
  expect_same("hole 19 edited in place");

  both([&](const Handle(ShapeBuild_ReShape)& c) { c->Clear(); });
  expect_same("cleared");
  both([&](const Handle(ShapeBuild_ReShape)& c) { c->Replace(edge_of(23, 0), edge_of(23, 0).EmptyCopied()); });
  expect_same("an edge of hole 23 rebuilt after the clear");

  // Without ModeConsiderLocation a record is for the shape where it is placed: an edge recorded
  // where the face is not placed is not the moved face's; with it, it is.
  Handle(ShapeBuild_ReShape) ours_placed = make_transfer_fix_context();
  Handle(ShapeBuild_ReShape) occt_placed = occt_context();
  for (const auto& c : {ours_placed, occt_placed}) {
    c->ModeConsiderLocation() = Standard_False;
    c->Replace(edge_of(5, 0), edge_of(5, 0).EmptyCopied());
  }
  gp_Trsf shift;
  shift.SetTranslation(gp_Vec(0, 0, 10));
  const TopoDS_Shape moved = face.Moved(TopLoc_Location(shift));
  expect_same_apply(ours_placed, occt_placed, moved, "the moved face, locations not considered");
  expect_same_apply(ours_placed, occt_placed, moved, "asked again");
  for (const auto& c : {ours_placed, occt_placed}) c->ModeConsiderLocation() = Standard_True;
  expect_same_apply(ours_placed, occt_placed, moved, "the moved face, locations considered");
  const auto& remembering = dynamic_cast<const WireRememberingReShape&>(*ours);
  EXPECT_GT(remembering.answered_from_memory(), 0u);
}

TEST(TransferFixContext, OcctsTransferHealingWorksInIt) {
  prepare_occt_exchange();
  const Handle(ShapeFix_Shape) fix = ShapeAlgo::AlgoContainer()->ToolContainer()->FixShape();
  ASSERT_FALSE(fix.IsNull());
  EXPECT_NE(dynamic_cast<const WireRememberingReShape*>(fix->Context().get()), nullptr);
}

// The file's shapes as a STEP or IGES reader transfers them, healed with the tools given.
std::string transferred(const fs::path& path, const Handle(ShapeAlgo_ToolContainer) & tools) {
  const Handle(ShapeAlgo_ToolContainer) before = ShapeAlgo::AlgoContainer()->ToolContainer();
  ShapeAlgo::AlgoContainer()->SetToolContainer(tools);
  std::string text;
  const std::string ext = path.extension().string();
  if (ext == ".iges" || ext == ".igs") {
    IGESControl_Reader reader;
    if (reader.ReadFile(path.string().c_str()) == IFSelect_RetDone) {
      reader.TransferRoots();
      text = brep_text(reader.OneShape());
    }
  } else {
    STEPControl_Reader reader;
    if (reader.ReadFile(path.string().c_str()) == IFSelect_RetDone) {
      reader.TransferRoots();
      text = brep_text(reader.OneShape());
    }
  }
  ShapeAlgo::AlgoContainer()->SetToolContainer(before);
  return text;
}

// A board-like plate (a prism of a face drilled with round holes) written to STEP.
fs::path drilled_plate_step(int holes_per_side) {
  BRepBuilderAPI_MakeFace face(gp_Pln(gp::XOY()), 0.0, 80.0, 0.0, 60.0);
  for (int i = 0; i < holes_per_side; ++i)
    for (int j = 0; j < holes_per_side; ++j) {
      const gp_Circ circle(gp_Ax2(gp_Pnt(4.0 + i * 72.0 / holes_per_side, 4.0 + j * 52.0 / holes_per_side, 0), -gp::DZ()),
                           0.4 + 0.1 * ((i + j) % 3));
      face.Add(BRepBuilderAPI_MakeWire(BRepBuilderAPI_MakeEdge(circle).Edge()).Wire());
    }
  const TopoDS_Shape plate = BRepPrimAPI_MakePrism(face.Face(), gp_Vec(0, 0, 1.6)).Shape();
  const fs::path path = fs::temp_directory_path() / ("cadclash-drilled-plate-" + std::to_string(::getpid()) + ".step");
  STEPControl_Writer writer;
  writer.Transfer(plate, STEPControl_AsIs);
  writer.Write(path.string().c_str());
  return path;
}

TEST(TransferFixContext, ADrilledPlateReadFromStepIsTheShapeOcctsOwnContextGives) {
  prepare_occt_exchange();
  const Handle(ShapeAlgo_ToolContainer) occt_tools = new ShapeAlgo_ToolContainer;
  const fs::path path = drilled_plate_step(12);  // two faces of 145 wires
  const std::string expected = transferred(path, occt_tools);
  const std::string got = transferred(path, transfer_fix_tools());
  fs::remove(path);
  ASSERT_FALSE(expected.empty());
  EXPECT_EQ(got, expected);
}

TEST(TransferFixContext, TheSampleFilesAreTheShapesOcctsOwnContextGives) {
  prepare_occt_exchange();
  const fs::path external = fs::path(CADCLASH_DATA_DIR) / "external";
  if (!fs::exists(external / "as1-tu-203.stp")) GTEST_SKIP() << "data/external missing: run scripts/setup.sh";
  const Handle(ShapeAlgo_ToolContainer) occt_tools = new ShapeAlgo_ToolContainer;
  int files = 0;
  for (const char* name : {"as1-tu-203.stp", "linkrods.step", "screw.step", "t20_data.step", "frame.step",
                           "component8.step", "step_boundary_colors.stp", "bearing.iges", "hammer.iges"}) {
    const fs::path path = external / name;
    if (!fs::exists(path)) continue;
    SCOPED_TRACE(name);
    const std::string expected = transferred(path, occt_tools);
    EXPECT_FALSE(expected.empty());
    EXPECT_EQ(transferred(path, transfer_fix_tools()), expected);
    ++files;
  }
  EXPECT_GE(files, 5);
}

}  // namespace
}  // namespace cadclash::detail
