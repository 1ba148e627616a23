// The replacement context OCCT's healing at transfer works in. OCCT heals every shape a STEP or IGES
// reader transfers with a ShapeFix_Shape (XSAlgo_AlgoContainer::ProcessShape's default processing)
// whose fixes record what they rebuilt in a ShapeBuild_ReShape, and ask it for the current form of a
// shape with Apply(). ShapeFix_Wire's self-intersection fix asks for the whole face once per wire
// of the face (ShapeFix_IntersectionTool::FixSelfIntersectWire, for its vertices' largest
// tolerance), and each such Apply walks every wire, edge and vertex of the face: quadratic in a
// face's wires. A board plate drilled 1,407 times spent 54 % of its transfer there.
// Internal to cadclash::import.
#pragma once

#include <ShapeAlgo_ToolContainer.hxx>
#include <ShapeBuild_ReShape.hxx>
#include <TopLoc_Location.hxx>
#include <TopoDS_Shape.hxx>

#include <cstddef>
#include <unordered_map>
#include <vector>

namespace cadclash::detail {

// A ShapeBuild_ReShape whose Apply() returns what ShapeBuild_ReShape's returns, with the same
// records and status, for every shape. What it adds: a wire of a face with many wires that Apply()
// found unchanged (nothing recorded for it or below it) is remembered, and while nothing is recorded
// for any shape below it and its structure (every child's TShape, location and orientation, down to
// the vertices) is what it was, Apply() of that wire answers at once: the wire itself and the status
// ShapeBuild_ReShape left. Anything recorded for a shape below a remembered wire (Replace, Remove)
// or a change of ModeConsiderLocation forgets it.
class WireRememberingReShape : public ShapeBuild_ReShape {
 public:
  // A face with at least this many wires has its wires remembered; fewer cost little to walk.
  static constexpr int kManyWires = 16;

  using ShapeBuild_ReShape::Apply;
  TopoDS_Shape Apply(const TopoDS_Shape& shape, const TopAbs_ShapeEnum until = TopAbs_SHAPE) override;

  // Apply() calls on a wire answered from memory / walked, since construction (for tests).
  std::size_t answered_from_memory() const { return answered_; }
  std::size_t walked() const { return walked_; }

 protected:
  void replace(const TopoDS_Shape& shape, const TopoDS_Shape& newshape, const TReplacementKind kind) override;

 private:
  struct Node {
    const TopoDS_TShape* tshape;
    TopLoc_Location location;
    TopAbs_Orientation orientation;
    int children;
  };
  struct Key {
    const TopoDS_TShape* tshape;
    TopLoc_Location location;
    TopAbs_Orientation orientation;
    bool operator==(const Key& other) const;
  };
  struct KeyHash {
    std::size_t operator()(const Key& key) const;
  };
  struct Remembered {
    TopoDS_Shape wire;        // holds the TShapes the nodes point to
    std::vector<Node> nodes;  // the wire's structure, depth first
    Standard_Integer status;
  };

  static void record_structure(const TopoDS_Shape& shape, std::vector<Node>& nodes);
  static bool same_structure(const TopoDS_Shape& shape, const std::vector<Node>& nodes, std::size_t& at);
  TopoDS_Shape apply_wire(const TopoDS_Shape& wire);
  void remember(const TopoDS_Shape& wire, Standard_Integer status);
  void forget();

  int inside_many_wires_ = 0;  // Apply() calls under way on faces with kManyWires or more
  bool remembered_mode_ = false;
  std::unordered_map<Key, Remembered, KeyHash> remembered_;
  // Every TShape in a remembered wire (the wire's own included) -> the wires holding it.
  std::unordered_map<const TopoDS_TShape*, std::vector<Key>> holders_;
  std::size_t answered_ = 0, walked_ = 0;
};

// A context as ShapeFix_Shape::Init makes its own (ModeConsiderLocation on), remembering.
Handle(ShapeBuild_ReShape) make_transfer_fix_context();

// The tools OCCT's default healing at transfer takes its ShapeFix_Shape from
// (ShapeAlgo::AlgoContainer()->ToolContainer()->FixShape()): a ShapeFix_Shape that works in a
// WireRememberingReShape. prepare_occt_exchange() installs them.
Handle(ShapeAlgo_ToolContainer) transfer_fix_tools();

}  // namespace cadclash::detail
