// detail::face_is_valid: BRepCheck's verdict on a face, made in pieces when the face has many wires
// (a board plate with its drilled holes). Plates with 40 holes (above the piece threshold) and a
// few damaged ones: the pieces' verdict is BRepCheck_Analyzer's on the whole face every time.
#include "brep_internal.h"

#include <BRepBuilderAPI_MakeEdge.hxx>
#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepBuilderAPI_MakePolygon.hxx>
#include <BRepBuilderAPI_MakeWire.hxx>
#include <Geom_Circle.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Wire.hxx>
#include <BRepCheck_Analyzer.hxx>
#include <GC_MakeCircle.hxx>
#include <gp_Ax2.hxx>
#include <gp_Pln.hxx>

#include <gtest/gtest.h>

#include <utility>
#include <vector>

namespace cadclash {
namespace {

TopoDS_Wire circle(double x, double y, double r) {
  const Handle(Geom_Circle) c = GC_MakeCircle(gp_Ax2(gp_Pnt(x, y, 0), gp_Dir(0, 0, 1)), r).Value();
  return BRepBuilderAPI_MakeWire(BRepBuilderAPI_MakeEdge(c).Edge()).Wire();
}

// A 100 x 60 plate in z = 0 with a hole of radius r at each centre (inner wires reversed, as holes
// are), and the `extra` wires as given.
TopoDS_Face plate(const std::vector<std::pair<double, double>>& holes, double r, const std::vector<TopoDS_Wire>& extra = {}) {
  BRepBuilderAPI_MakePolygon outline(gp_Pnt(0, 0, 0), gp_Pnt(100, 0, 0), gp_Pnt(100, 60, 0), gp_Pnt(0, 60, 0), Standard_True);
  BRepBuilderAPI_MakeFace face(gp_Pln(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), outline.Wire());
  for (const auto& [x, y] : holes) face.Add(TopoDS::Wire(circle(x, y, r).Reversed()));
  for (const TopoDS_Wire& w : extra) face.Add(w);
  return face.Face();
}

std::vector<std::pair<double, double>> grid(int columns, int rows) {
  std::vector<std::pair<double, double>> out;
  for (int i = 0; i < columns; ++i)
    for (int j = 0; j < rows; ++j) out.emplace_back(8.0 + 9.0 * i, 8.0 + 9.0 * j);
  return out;
}

bool brepcheck(const TopoDS_Face& f) { return BRepCheck_Analyzer(f, Standard_True).IsValid() == Standard_True; }

TEST(FaceCheck, PlateWithManyHolesIsCheckedInPiecesWithBRepChecksVerdict) {
  const std::vector<std::pair<double, double>> holes = grid(10, 4);  // 40 holes
  const TopoDS_Face good = plate(holes, 2.0);
  ASSERT_TRUE(detail::face_has_many_wires(good));
  EXPECT_TRUE(brepcheck(good));
  EXPECT_TRUE(detail::face_is_valid(good));

  // Each damaged plate: BRepCheck rejects the whole face, and so do the pieces.
  auto with_hole_at = [&](double x, double y) {
    std::vector<std::pair<double, double>> more = holes;
    more.emplace_back(x, y);
    return plate(more, 2.0);
  };
  const std::vector<std::pair<const char*, TopoDS_Face>> damaged{
      {"two holes that cross", with_hole_at(11.0, 8.0)},
      {"a hole inside a hole", plate(holes, 2.0, {TopoDS::Wire(circle(8.0, 8.0, 0.5).Reversed())})},
      {"a hole outside the plate", with_hole_at(150.0, 30.0)},
      {"a hole wound the wrong way", plate(holes, 2.0, {circle(60.0, 55.0, 2.0)})},
  };
  for (const auto& [what, face] : damaged) {
    SCOPED_TRACE(what);
    EXPECT_FALSE(brepcheck(face));
    EXPECT_FALSE(detail::face_is_valid(face));
  }
}

// Below the threshold the face is checked whole, as BRepCheck does.
TEST(FaceCheck, FewHolesAreCheckedWhole) {
  const TopoDS_Face few = plate(grid(2, 2), 2.0);
  EXPECT_FALSE(detail::face_has_many_wires(few));
  EXPECT_TRUE(detail::face_is_valid(few));
  std::vector<std::pair<double, double>> crossing = grid(2, 2);
  crossing.emplace_back(11.0, 8.0);
  EXPECT_FALSE(detail::face_is_valid(plate(crossing, 2.0)));
}

}  // namespace
}  // namespace cadclash
