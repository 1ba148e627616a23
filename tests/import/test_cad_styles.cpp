// What a STEP file read in pieces (step_split_text.h) carries besides its shapes, as the reader alone
// makes it from the whole file. Face colours: a face's only styled item goes into the face's piece,
// its worker reads the colours with OCCT's own code and the main reader sets them where
// STEPCAFControl_Reader::ReadColors would (with the styles moved, and with each case that keeps a
// style in the main text). Edge regularity: encoded by the workers on their items, not again by the
// main reader.
#include "cadclash/import.h"
#include "import_cache.h"
#include "import_compare.h"
#include "step_split_text.h"
#include "xcaf_test_doc.h"

#include <BRepBuilderAPI_MakeEdge.hxx>
#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepBuilderAPI_MakePolygon.hxx>
#include <BRepBuilderAPI_MakeWire.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakePrism.hxx>
#include <gp_Circ.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <BRep_Builder.hxx>
#include <BRep_Tool.hxx>
#include <TopTools_IndexedDataMapOfShapeListOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Compound.hxx>
#include <Quantity_Color.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <XCAFDoc_ColorTool.hxx>
#include <gp_Trsf.hxx>

#include <gtest/gtest.h>

#include <array>
#include <algorithm>
#include <fstream>
#include <iterator>
#include <regex>
#include <set>
#include <string>
#include <vector>

namespace cadclash {
namespace {

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::string write_text(const std::string& name, const std::string& text) {
  const std::string path = testing::scratch_dir() + "/" + name;
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

// A board as OCCT-based exporters write one: a block placed twice with three faces coloured (two
// share a colour), a pin coloured as a whole with one face of its own colour, and a plain plate.
std::string write_styled_board() {
  testing::XcafTestDoc doc;
  const Handle(XCAFDoc_ShapeTool)& tool = doc.tool();
  const Handle(XCAFDoc_ColorTool) colours = XCAFDoc_DocumentTool::ColorTool(tool->Label());
  const auto name = testing::XcafTestDoc::name;
  auto at = [](double x, double y) {
    gp_Trsf t;
    t.SetTranslation(gp_Vec(x, y, 0));
    return TopLoc_Location(t);
  };
  auto colour_faces = [&](const TDF_Label& part, const TopoDS_Shape& shape, const std::vector<std::pair<int, Quantity_Color>>& faces) {
    TopTools_IndexedMapOfShape map;
    TopExp::MapShapes(shape, TopAbs_FACE, map);
    for (const auto& [f, colour] : faces) colours->SetColor(tool->AddSubShape(part, map(f)), colour, XCAFDoc_ColorSurf);
  };
  const TopoDS_Shape block_shape = BRepPrimAPI_MakeBox(4, 3, 2).Shape();
  const TDF_Label block = name(tool->AddShape(block_shape, Standard_False), "block");
  const Quantity_Color green(0.1, 0.7, 0.2, Quantity_TOC_RGB), red(0.8, 0.1, 0.1, Quantity_TOC_RGB);
  colour_faces(block, block_shape, {{1, red}, {2, green}, {5, green}});
  const TopoDS_Shape pin_shape = BRepPrimAPI_MakeCylinder(0.5, 6).Shape();
  const TDF_Label pin = name(tool->AddShape(pin_shape, Standard_False), "pin");
  colours->SetColor(pin, Quantity_Color(0.2, 0.2, 0.9, Quantity_TOC_RGB), XCAFDoc_ColorSurf);
  colour_faces(pin, pin_shape, {{2, Quantity_Color(0.9, 0.8, 0.1, Quantity_TOC_RGB)}});
  const TDF_Label plate = name(tool->AddShape(BRepPrimAPI_MakeBox(30, 20, 1.6).Shape(), Standard_False), "plate");
  const TDF_Label board = name(tool->NewShape(), "board");
  name(tool->AddComponent(board, plate, at(0, 0)), "PCB");
  name(tool->AddComponent(board, block, at(2, 2)), "U1");
  name(tool->AddComponent(board, block, at(12, 2)), "U2");
  name(tool->AddComponent(board, pin, at(20, 10)), "J1");
  return slurp(doc.write_step("styled_board.step"));
}

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

// The file's styled items in its main text and in its pieces, as split_step_text cuts it.
struct Cut {
  std::size_t main = 0, pieces = 0;
};
Cut styled_items(const std::string& text) {
  std::string why;
  const auto split = detail::split_step_text(text, true, why);
  EXPECT_TRUE(split.has_value()) << why;
  Cut cut;
  if (!split) return cut;
  cut.main = count(split->main_text, "=STYLED_ITEM(") + count(split->main_text, "= STYLED_ITEM(");
  for (const detail::StepPiece& piece : split->pieces) cut.pieces += count(piece.text, "=STYLED_ITEM(") + count(piece.text, "= STYLED_ITEM(");
  return cut;
}

// The file read by the reader alone and by 2 and 3 processes: the same model, colours included;
// at least `colours` distinct ones on its surfaces.
void expect_same_when_split(const std::string& path, std::size_t colours) {
  ImportOptions options;
  options.transfer_workers = 1;
  const ImportResult alone = import_file(path, options);
  ASSERT_TRUE(alone.complete);
  std::set<std::array<float, 3>> seen;
  for (const Surface& s : alone.model.surfaces)
    if (s.provenance.colour) seen.insert(*s.provenance.colour);
  EXPECT_GE(seen.size(), colours);
  for (const int workers : {2, 3}) {
    SCOPED_TRACE(workers);
    options.transfer_workers = workers;
    const ImportResult spread = import_file(path, options);
    EXPECT_EQ(spread.files.at(0).transfer_workers, static_cast<std::size_t>(workers));
    EXPECT_EQ(testing_import::messages(spread), testing_import::messages(alone));
    EXPECT_TRUE(testing_import::same_bytes(testing_import::everything(spread), testing_import::everything(alone)));
  }
}

std::int64_t largest_id(const std::string& text) {
  std::int64_t largest = 0;
  static const std::regex id(R"(\n#(\d+) ?=)");
  for (auto it = std::sregex_iterator(text.begin(), text.end(), id); it != std::sregex_iterator(); ++it)
    largest = std::max<std::int64_t>(largest, std::stoll((*it)[1].str()));
  return largest;
}

// The text with `statements` added as #next, #next + 1, ... before the DATA section's end; "@k" in
// a statement names the k-th one added.
std::string with_statements(const std::string& text, const std::vector<std::string>& statements) {
  const std::int64_t next = largest_id(text) + 1;
  std::string added;
  for (std::size_t k = 0; k < statements.size(); ++k) {
    std::string s = statements[k];
    for (std::size_t at = s.find('@'); at != std::string::npos; at = s.find('@')) {
      const std::size_t digit = at + 1;
      s.replace(at, 2, '#' + std::to_string(next + (s[digit] - '0')));
    }
    added += '#';
    added += std::to_string(next + static_cast<std::int64_t>(k)) + " = " + s + ";\n";
  }
  std::string out = text;
  out.insert(out.rfind("ENDSEC;"), added);
  return out;
}

// The id of the first STYLED_ITEM that styles a face, and the face.
std::pair<std::string, std::string> first_styled_face(const std::string& text) {
  static const std::regex styled(R"(#(\d+) = STYLED_ITEM\('[^']*',\(#\d+\),(#\d+)\);)");
  for (auto it = std::sregex_iterator(text.begin(), text.end(), styled); it != std::sregex_iterator(); ++it)
    if (text.find("\n" + (*it)[2].str() + " = ADVANCED_FACE(") != std::string::npos) return {(*it)[1].str(), (*it)[2].str()};
  ADD_FAILURE() << "no styled face";
  return {};
}

TEST(CadStyles, StyledFacesGoIntoTheirPiecesWithTheSameColours) {
  const std::string text = write_styled_board();
  // The writer styles the block's faces on their own (3), the pin as a whole (1) and the pin's face
  // by an OVER_RIDING_STYLED_ITEM of the pin's, which stays with it in the main text.
  const Cut cut = styled_items(text);
  EXPECT_EQ(cut.pieces, 3u);
  EXPECT_EQ(cut.main, 1u);
  expect_same_when_split(write_text("styled_board.step", text), 4);
}

// A piece's weight (what the pieces are shared out by) is its bytes and, for each face of n bounds,
// 2 n^2 / 3: counted here from the pieces' own text.
// A plate drilled `holes` times (its two large faces have holes + 1 bounds each) beside a block.
std::string write_drilled_board(int holes) {
  testing::XcafTestDoc doc;
  const Handle(XCAFDoc_ShapeTool)& tool = doc.tool();
  const auto name = testing::XcafTestDoc::name;
  BRepBuilderAPI_MakeFace face(BRepBuilderAPI_MakePolygon(gp_Pnt(0, 0, 0), gp_Pnt(40, 0, 0), gp_Pnt(40, 10, 0),
                                                          gp_Pnt(0, 10, 0), Standard_True).Wire());
  for (int k = 0; k < holes; ++k) {
    const gp_Circ circle(gp_Ax2(gp_Pnt(2.0 + 3.0 * k, 5, 0), gp_Dir(0, 0, 1)), 0.5);
    face.Add(TopoDS::Wire(BRepBuilderAPI_MakeWire(BRepBuilderAPI_MakeEdge(circle).Edge()).Wire().Reversed()));
  }
  const TDF_Label plate = name(tool->AddShape(BRepPrimAPI_MakePrism(face.Face(), gp_Vec(0, 0, 1.6)).Shape(), Standard_False), "plate");
  const TDF_Label block = name(tool->AddShape(BRepPrimAPI_MakeBox(4, 3, 2).Shape(), Standard_False), "block");
  const TDF_Label board = name(tool->NewShape(), "board");
  name(tool->AddComponent(board, plate, TopLoc_Location()), "PCB");
  gp_Trsf t;
  t.SetTranslation(gp_Vec(2, 2, 1.6));
  name(tool->AddComponent(board, block, TopLoc_Location(t)), "U1");
  return slurp(doc.write_step("drilled_board.step"));
}

TEST(CadSplit, APiecesWeightCountsItsFacesWires) {
  std::string why;
  const auto split = detail::split_step_text(write_drilled_board(12), false, why);
  ASSERT_TRUE(split.has_value()) << why;
  const std::regex face(R"(=\s*(ADVANCED_FACE|FACE_SURFACE)\s*\(\s*'[^']*'\s*,\s*\(([^)]*)\))");
  std::size_t faces = 0;
  for (const detail::StepPiece& piece : split->pieces) {
    std::size_t wires = 0;
    for (auto it = std::sregex_iterator(piece.text.begin(), piece.text.end(), face); it != std::sregex_iterator(); ++it) {
      const std::string bounds = (*it)[2];
      const auto n = static_cast<std::size_t>(std::count(bounds.begin(), bounds.end(), '#'));
      wires += n * n * 2 / 3;
      ++faces;
    }
    EXPECT_EQ(piece.weight, piece.bytes + wires);
  }
  EXPECT_GT(faces, 6u + 12u);
  // The plate's piece: its two drilled faces of 13 bounds weigh 2 x 112.
  const auto heaviest = std::max_element(split->pieces.begin(), split->pieces.end(),
                                         [](const auto& a, const auto& b) { return a.weight - a.bytes < b.weight - b.bytes; });
  EXPECT_GE(heaviest->weight - heaviest->bytes, 2u * 112u);
}

// The pieces go to the workers by weight, not bytes: largest first onto the least loaded.
TEST(CadSplit, PiecesAreSharedOutByWeight) {
  std::vector<detail::StepPiece> pieces(4);
  const std::size_t bytes[] = {10, 60, 50, 40}, weights[] = {100, 60, 50, 40};
  for (std::size_t p = 0; p < 4; ++p) pieces[p].bytes = bytes[p], pieces[p].weight = weights[p];
  using Shares = std::vector<std::vector<std::size_t>>;
  EXPECT_EQ(detail::share_pieces(pieces, {0, 1, 2, 3}, 2), (Shares{{0, 3}, {1, 2}}));
  EXPECT_EQ(detail::share_pieces(pieces, {1, 2, 3}, 2), (Shares{{1}, {2, 3}}));
  EXPECT_EQ(detail::share_pieces(pieces, {0, 1, 2, 3}, 8).size(), 4u);
}

// An invisible styled face, and a face styled twice (the style ReadColors reads last wins), keep
// their styled items in the main text, in file order.
TEST(CadStyles, StylesTheMainTextStillNeedsStayThere) {
  const std::string text = write_styled_board();
  const auto [item, face] = first_styled_face(text);
  const std::string invisible = with_statements(text, {"INVISIBILITY((#" + item + "))"});
  EXPECT_EQ(styled_items(invisible).main, 2u);
  expect_same_when_split(write_text("styled_invisible.step", invisible), 4);
  const std::string twice = with_statements(
      text, {"COLOUR_RGB('',0.,0.,1.)", "FILL_AREA_STYLE_COLOUR('',@0)", "FILL_AREA_STYLE('',(@1))",
             "SURFACE_STYLE_FILL_AREA(@2)", "SURFACE_SIDE_STYLE('',(@3))", "SURFACE_STYLE_USAGE(.BOTH.,@4)",
             "PRESENTATION_STYLE_ASSIGNMENT((@5))", "STYLED_ITEM('',(@6)," + face + ")"});
  EXPECT_EQ(styled_items(twice).main, 3u);
  expect_same_when_split(write_text("styled_twice.step", twice), 4);
}

// Per part, the continuity OCCT recorded between the two faces of each edge (a seam: the face with
// itself), sorted: what XSControl_TransferReader::ShapeResult's EncodeRegularity leaves on the shapes.
std::vector<std::vector<int>> edge_regularity(const ImportResult& r) {
  std::vector<std::vector<int>> out;
  for (const Part& part : r.model.parts) {
    const auto* brep = dynamic_cast<const BrepSource*>(part.source.get());
    out.emplace_back();
    if (brep == nullptr) continue;
    TopoDS_Compound faces;
    BRep_Builder builder;
    builder.MakeCompound(faces);
    for (std::uint32_t f = 0; f < brep->face_count(); ++f) builder.Add(faces, brep->face(f));
    TopTools_IndexedDataMapOfShapeListOfShape edges;
    TopExp::MapShapesAndAncestors(faces, TopAbs_EDGE, TopAbs_FACE, edges);
    for (int e = 1; e <= edges.Extent(); ++e) {
      const TopoDS_Edge& edge = TopoDS::Edge(edges.FindKey(e));
      const TopTools_ListOfShape& around = edges.FindFromIndex(e);
      const TopoDS_Face& first = TopoDS::Face(around.First());
      const TopoDS_Face& last = TopoDS::Face(around.Last());
      out.back().push_back(static_cast<int>(BRep_Tool::Continuity(edge, first, last)));
    }
    std::sort(out.back().begin(), out.back().end());
  }
  return out;
}

TEST(CadSplit, EdgeRegularityIsTheWholeFilesOne) {
  const std::string path = write_text("regularity_board.step", write_styled_board());
  ImportOptions options;
  options.transfer_workers = 1;
  const auto alone = edge_regularity(import_file(path, options));
  bool smooth = false;  // the pin's seam joins its side to itself smoothly
  for (const auto& part : alone) smooth = smooth || std::any_of(part.begin(), part.end(), [](int c) { return c > GeomAbs_C0; });
  EXPECT_TRUE(smooth);
  options.transfer_workers = 2;
  const ImportResult spread = import_file(path, options);
  ASSERT_GT(spread.files.at(0).pieces, 1u);
  EXPECT_EQ(edge_regularity(spread), alone);
}

}  // namespace
}  // namespace cadclash
