// WireRememberingReShape: ShapeBuild_ReShape's Apply() without walking, again and again, the wires of
// a face with many holes that nothing has changed.
//
// Why the answer is the same: ShapeBuild_ReShape::Apply(wire) (OCCT 7.6) is a function of the
// wire's structure (each child's TShape, location and orientation, down to the vertices), of what is
// recorded for those TShapes, and of ModeConsiderLocation. When it returns the wire itself nothing
// was rebuilt, so it recorded nothing; its status is whatever its last inner call left. Later
// records reach us through replace() (Replace and Remove both go there); a record for any TShape of
// a remembered wire forgets the wire (Clear() only removes records: what was unchanged stays so).
// The structure is compared node by node before a remembered answer is given, because ShapeFix
// also edits edges in place (ShapeFix_Wire's FixConnected puts a shared vertex into the edges with
// BRep_Builder).
#include "transfer_fix_context.h"

#include <ShapeFix_Shape.hxx>
#include <TopoDS_Iterator.hxx>

#include <climits>
#include <functional>

namespace cadclash::detail {
namespace {

// Keeps a count of Apply() calls under way on faces with many wires, exceptions included (OCCT's
// healing throws Standard_Failure and catches it further up).
class Inside {
 public:
  Inside(int& depth, bool counts) : depth_(depth), counts_(counts) { depth_ += counts_; }
  ~Inside() { depth_ -= counts_; }
  Inside(const Inside&) = delete;
  Inside& operator=(const Inside&) = delete;

 private:
  int& depth_;
  int counts_;
};

class RememberingFixTools final : public ShapeAlgo_ToolContainer {
 public:
  Handle(ShapeFix_Shape) FixShape() const override {
    Handle(ShapeFix_Shape) fix = new ShapeFix_Shape;
    fix->SetContext(make_transfer_fix_context());  // Init() keeps a context it is given
    return fix;
  }
};

}  // namespace

bool WireRememberingReShape::same_structure(const TopoDS_Shape& shape, const std::vector<Node>& nodes,
                                            std::size_t& at) {
  if (at >= nodes.size()) return false;
  const auto& node = nodes[at++];
  if (node.tshape != shape.TShape().get() || node.orientation != shape.Orientation() ||
      !node.location.IsEqual(shape.Location()))
    return false;
  int children = 0;
  // Raw children (no cumulated location or orientation): what the nodes recorded.
  for (TopoDS_Iterator it(shape, Standard_False, Standard_False); it.More(); it.Next(), ++children)
    if (children >= node.children || !same_structure(it.Value(), nodes, at)) return false;
  return children == node.children;
}

void WireRememberingReShape::record_structure(const TopoDS_Shape& shape, std::vector<Node>& nodes) {
  const std::size_t at = nodes.size();
  nodes.push_back({shape.TShape().get(), shape.Location(), shape.Orientation(), 0});
  int children = 0;
  for (TopoDS_Iterator it(shape, Standard_False, Standard_False); it.More(); it.Next(), ++children)
    record_structure(it.Value(), nodes);
  nodes[at].children = children;
}

bool WireRememberingReShape::Key::operator==(const Key& other) const {
  return tshape == other.tshape && orientation == other.orientation && location.IsEqual(other.location);
}

std::size_t WireRememberingReShape::KeyHash::operator()(const Key& key) const {
  return std::hash<const void*>()(key.tshape) ^ (static_cast<std::size_t>(key.location.HashCode(INT_MAX)) << 3) ^
         static_cast<std::size_t>(key.orientation);
}

TopoDS_Shape WireRememberingReShape::Apply(const TopoDS_Shape& shape, const TopAbs_ShapeEnum until) {
  // Only the whole walk (until = TopAbs_SHAPE, what ShapeFix asks) is remembered.
  if (shape.IsNull() || until != TopAbs_SHAPE) return ShapeBuild_ReShape::Apply(shape, until);
  switch (shape.ShapeType()) {
    case TopAbs_FACE: {
      Inside inside(inside_many_wires_, shape.NbChildren() >= kManyWires);
      return ShapeBuild_ReShape::Apply(shape, until);
    }
    case TopAbs_WIRE:
      if (inside_many_wires_ > 0) return apply_wire(shape);
      return ShapeBuild_ReShape::Apply(shape, until);
    default:
      return ShapeBuild_ReShape::Apply(shape, until);
  }
}

TopoDS_Shape WireRememberingReShape::apply_wire(const TopoDS_Shape& wire) {
  if (remembered_mode_ != ModeConsiderLocation()) {
    forget();
    remembered_mode_ = ModeConsiderLocation();
  }
  const auto found = remembered_.find(Key{wire.TShape().get(), wire.Location(), wire.Orientation()});
  if (found != remembered_.end()) {
    std::size_t at = 0;
    if (same_structure(wire, found->second.nodes, at) && at == found->second.nodes.size()) {
      ++answered_;
      myStatus = found->second.status;
      return wire;
    }
    remembered_.erase(found);
  }
  ++walked_;
  TopoDS_Shape result = ShapeBuild_ReShape::Apply(wire, TopAbs_SHAPE);
  if (result.IsEqual(wire)) remember(wire, myStatus);
  return result;
}

void WireRememberingReShape::remember(const TopoDS_Shape& wire, Standard_Integer status) {
  Remembered entry{wire, {}, status};
  record_structure(wire, entry.nodes);
  const Key key{wire.TShape().get(), wire.Location(), wire.Orientation()};
  for (const Node& node : entry.nodes) holders_[node.tshape].push_back(key);
  remembered_.insert_or_assign(key, std::move(entry));
}

void WireRememberingReShape::forget() {
  remembered_.clear();
  holders_.clear();
}

void WireRememberingReShape::replace(const TopoDS_Shape& shape, const TopoDS_Shape& newshape,
                                     const TReplacementKind kind) {
  ShapeBuild_ReShape::replace(shape, newshape, kind);
  if (shape.IsNull() || holders_.empty()) return;
  const auto holders = holders_.find(shape.TShape().get());
  if (holders == holders_.end()) return;
  for (const Key& key : holders->second) remembered_.erase(key);
  holders_.erase(holders);
}

Handle(ShapeBuild_ReShape) make_transfer_fix_context() {
  Handle(ShapeBuild_ReShape) context = new WireRememberingReShape;
  context->ModeConsiderLocation() = Standard_True;
  return context;
}

Handle(ShapeAlgo_ToolContainer) transfer_fix_tools() {
  static const Handle(ShapeAlgo_ToolContainer) tools = new RememberingFixTools;
  return tools;
}

}  // namespace cadclash::detail
