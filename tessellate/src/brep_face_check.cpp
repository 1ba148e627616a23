// BRepCheck of one face, in pieces when it has many wires (brep_internal.h, face_is_valid).
#include "brep_internal.h"

#include <BRepCheck_Analyzer.hxx>
#include <BRepTools.hxx>
#include <BRep_Builder.hxx>
#include <Bnd_Box2d.hxx>
#include <Precision.hxx>
#include <Standard_Failure.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Iterator.hxx>

#include <algorithm>
#include <numeric>
#include <vector>

namespace cadclash::detail {
namespace {

bool analyzer_says_valid(const TopoDS_Shape& shape) {
  try {
    return BRepCheck_Analyzer(shape, Standard_True).IsValid() == Standard_True;
  } catch (const Standard_Failure&) {
    return false;
  }
}

struct WireBox {
  TopoDS_Wire wire;
  double u0, u1, v0, v1;
};

constexpr std::size_t kManyWires = 32;

std::size_t wire_count(const TopoDS_Face& face) {
  std::size_t n = 0;
  for (TopoDS_Iterator it(face); it.More(); it.Next()) n += it.Value().ShapeType() == TopAbs_WIRE ? 1 : 0;
  return n;
}

}  // namespace

bool face_has_many_wires(const TopoDS_Face& face) { return wire_count(face) >= kManyWires; }

bool face_is_valid(const TopoDS_Face& face) {
  // BRepCheck_Face classifies every wire against every other (ClassifyWires), with an exact
  // point-in-wire test each time: a board plate with 1,407 drilled holes took 18 s per face. Two
  // wires whose parameter boxes are apart can neither cross nor hold one another, so such a face is
  // checked as pieces instead: the outer wire with each cluster of inner wires whose boxes overlap.
  // Every check BRepCheck makes of a face is then made of the piece that holds what it looks at (a
  // wire, a pair of wires, an edge on the surface), so the face is valid when every piece is.
  std::vector<TopoDS_Wire> wires;
  for (TopoDS_Iterator it(face); it.More(); it.Next())
    if (it.Value().ShapeType() == TopAbs_WIRE) wires.push_back(TopoDS::Wire(it.Value()));
  if (wires.size() < kManyWires) return analyzer_says_valid(face);
  std::vector<WireBox> inner;
  TopoDS_Wire outer;
  try {
    outer = BRepTools::OuterWire(face);
    if (outer.IsNull()) return analyzer_says_valid(face);
    for (const TopoDS_Wire& w : wires) {
      if (w.IsSame(outer)) continue;
      WireBox b{w, 0, 0, 0, 0};
      BRepTools::UVBounds(face, w, b.u0, b.u1, b.v0, b.v1);
      if (!(b.u0 <= b.u1 && b.v0 <= b.v1)) return analyzer_says_valid(face);
      inner.push_back(b);
    }
  } catch (const Standard_Failure&) {
    return analyzer_says_valid(face);
  }
  if (inner.size() + 1 != wires.size()) return analyzer_says_valid(face);  // the outer wire twice, or none
  // Clusters of overlapping boxes (grown by the parametric confusion, so touching boxes join): a
  // sweep along u, joining each box with those still open that overlap it in v.
  const double grow = 10.0 * Precision::PConfusion();
  std::vector<std::size_t> order(inner.size()), parent(inner.size());
  std::iota(order.begin(), order.end(), 0);
  std::iota(parent.begin(), parent.end(), 0);
  auto root = [&parent](std::size_t a) {
    while (parent[a] != a) a = parent[a] = parent[parent[a]];
    return a;
  };
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return inner[a].u0 < inner[b].u0; });
  std::vector<std::size_t> open;
  for (const std::size_t k : order) {
    const WireBox& b = inner[k];
    open.erase(std::remove_if(open.begin(), open.end(), [&](std::size_t o) { return inner[o].u1 + grow < b.u0 - grow; }),
               open.end());
    for (const std::size_t o : open)
      if (inner[o].v0 - grow <= b.v1 + grow && b.v0 - grow <= inner[o].v1 + grow) parent[root(o)] = root(k);
    open.push_back(k);
  }
  std::vector<std::vector<std::size_t>> clusters(inner.size());
  for (std::size_t k = 0; k < inner.size(); ++k) clusters[root(k)].push_back(k);
  BRep_Builder builder;
  for (const std::vector<std::size_t>& cluster : clusters) {
    if (cluster.empty()) continue;
    TopoDS_Face piece = TopoDS::Face(face.EmptyCopied());
    builder.Add(piece, outer);
    for (const std::size_t k : cluster) builder.Add(piece, inner[k].wire);
    if (!analyzer_says_valid(piece)) return false;
  }
  return true;
}

}  // namespace cadclash::detail
