// The minimum distance between two placed B-rep faces, as BRepExtrema_DistShapeShape computes it,
// with one exit it lacks: a distance of exactly 0 cannot get smaller, so the search stops there.
//
// BRepExtrema_DistShapeShape (OCCT 7.6, Extrema_ExtFlag_MIN, single-threaded) starts from the
// distance of the two first vertices, then runs BRepExtrema_DistanceSS over the sub-shape pairs
// level by level (vertex–vertex, vertex–edge, edge–vertex, vertex–face, face–vertex, edge–edge,
// edge–face, face–edge, and face–face only while the distance exceeds Precision::Confusion()).
// Within a level it keeps the pairs whose boxes are within the current distance, sorts them by box
// distance and stops at the first one beyond it (7.6.3 deals each sorted list out to one running
// minimum per pool thread even when single-threaded; that changes which pairs beyond the minimum
// run, never the minimum). The answer is the smallest distance any computed pair gave. Touching faces — what exact verification mostly sees — reach 0 at the vertex–vertex or
// vertex–edge level, yet DistShapeShape still runs every edge–edge and edge–face pair whose boxes
// overlap, which is most of its time (as1's 376 verified pairs: 1.6 s of CPU, 0.7 s with this exit).
// The answer is the minimum over the computed pairs, and the pair that attains it is never pruned, so
// it is bit-identical to BRepExtrema_DistShapeShape::Value() (same kernel, pairs, boxes and order;
// tests/tessellate/test_exact_verification.cpp compares them).
#include "brep_internal.h"

#include <BRepBndLib.hxx>
#include <BRepExtrema_DistanceSS.hxx>
#include <BRep_Tool.hxx>
#include <Bnd_Box.hxx>
#include <Precision.hxx>
#include <TopExp.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS.hxx>

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

namespace cadclash::detail {
namespace {

// One shape's vertices, edges and faces (TopExp::MapShapes order) and their boxes.
struct SubShapes {
  std::array<TopTools_IndexedMapOfShape, 3> maps;  // 0 vertices, 1 edges, 2 faces
  std::array<std::vector<Bnd_Box>, 3> boxes;

  explicit SubShapes(const TopoDS_Shape& shape) {
    constexpr std::array<TopAbs_ShapeEnum, 3> kinds{TopAbs_VERTEX, TopAbs_EDGE, TopAbs_FACE};
    for (int k = 0; k < 3; ++k) {
      TopExp::MapShapes(shape, kinds[k], maps[k]);
      boxes[k].resize(static_cast<std::size_t>(maps[k].Extent()));
      for (int i = 1; i <= maps[k].Extent(); ++i) BRepBndLib::Add(maps[k](i), boxes[k][static_cast<std::size_t>(i - 1)]);
    }
  }
};

// The running minimum with DistShapeShape's rule for near-ties (within eps: kept as a solution).
struct Minimum {
  double enough = 0.0;  // a distance this small ends the search
  double eps = Precision::Confusion();
  double value = 1e30;  // DistShapeShape's start when a shape has no vertex
  bool found = false;   // some solution recorded (DistShapeShape's IsDone)

  void offer(double d) {
    if (d < value - eps) {
      value = d;
      found = true;
    } else if (std::abs(d - value) < eps) {
      found = true;
      value = std::min(value, d);
    }
  }
  bool done() const { return found && value <= enough; }
};

void vertex_vertex(const SubShapes& a, const SubShapes& b, Minimum& m) {
  for (int i = 1; i <= a.maps[0].Extent() && !m.done(); ++i) {
    const gp_Pnt p = BRep_Tool::Pnt(TopoDS::Vertex(a.maps[0](i)));
    for (int j = 1; j <= b.maps[0].Extent() && !m.done(); ++j) m.offer(p.Distance(BRep_Tool::Pnt(TopoDS::Vertex(b.maps[0](j)))));
  }
}

// DistShapeShape::DistanceMapMap for the sub-shapes of kind ka of `a` against kind kb of `b`.
void level(const SubShapes& a, int ka, const SubShapes& b, int kb, Minimum& m) {
  struct Candidate {
    int i, j;
    double box_distance;
  };
  std::vector<Candidate> candidates;
  const std::vector<Bnd_Box>& ba = a.boxes[static_cast<std::size_t>(ka)];
  const std::vector<Bnd_Box>& bb = b.boxes[static_cast<std::size_t>(kb)];
  for (std::size_t i = 0; i < ba.size(); ++i)
    for (std::size_t j = 0; j < bb.size(); ++j) {
      if (ba[i].IsVoid() || bb[j].IsVoid()) continue;
      const double d = ba[i].Distance(bb[j]);
      if (d - m.value < m.eps) candidates.push_back({static_cast<int>(i), static_cast<int>(j), d});
    }
  std::stable_sort(candidates.begin(), candidates.end(),
                   [](const Candidate& x, const Candidate& y) { return x.box_distance < y.box_distance; });
  for (const Candidate& c : candidates) {
    if (c.box_distance > m.value + m.eps || m.done()) break;
    const auto i = static_cast<std::size_t>(c.i), j = static_cast<std::size_t>(c.j);
    BRepExtrema_DistanceSS tool(a.maps[static_cast<std::size_t>(ka)](c.i + 1), b.maps[static_cast<std::size_t>(kb)](c.j + 1),
                                ba[i], bb[j], m.value, m.eps);
    if (tool.IsDone()) m.offer(tool.DistValue());
  }
}

}  // namespace

std::optional<double> min_distance(const TopoDS_Shape& a, const TopoDS_Shape& b, double enough) {
  const SubShapes sa(a), sb(b);
  Minimum m;
  m.enough = std::max(enough, 0.0);
  if (sa.maps[0].Extent() > 0 && sb.maps[0].Extent() > 0)
    m.value = BRep_Tool::Pnt(TopoDS::Vertex(sa.maps[0](1))).Distance(BRep_Tool::Pnt(TopoDS::Vertex(sb.maps[0](1))));
  vertex_vertex(sa, sb, m);
  constexpr std::array<std::array<int, 2>, 7> kLevels{{{0, 1}, {1, 0}, {0, 2}, {2, 0}, {1, 1}, {1, 2}, {2, 1}}};
  // Looking for any two points within `enough` (a contact), edge–face comes before edge–edge: a curved
  // edge tangent to the other face is found there in closed form for elementary curves and surfaces,
  // while edge–edge runs OCCT's global curve–curve optimiser on every pair first. The order changes
  // which pairs are computed before the search stops, never the minimum when it does not.
  constexpr std::array<std::array<int, 2>, 7> kContactLevels{{{0, 1}, {1, 0}, {0, 2}, {2, 0}, {1, 2}, {2, 1}, {1, 1}}};
  for (const auto& [ka, kb] : m.enough > 0.0 ? kContactLevels : kLevels) {
    if (m.done()) break;
    level(sa, ka, sb, kb, m);
  }
  if (!m.done() && std::abs(m.value) > m.eps) level(sa, 2, sb, 2, m);
  if (!m.found) return std::nullopt;
  return m.value;
}

}  // namespace cadclash::detail
