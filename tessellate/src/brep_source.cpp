// BrepSource: the exact faces of one part, tessellated on demand and measured exactly.
#include "brep_face_cache.h"
#include "brep_internal.h"

#include "cadclash/geometry.h"

#include <BRepAlgoAPI_Common.hxx>
#include <BRepBndLib.hxx>
#include <BRepTools.hxx>
#include <BRep_Builder.hxx>
#include <Bnd_Box.hxx>
#include <TopoDS_Iterator.hxx>
#include <TopoDS_Wire.hxx>
#include <BRepBuilderAPI_Copy.hxx>
#include <BRepBuilderAPI_MakeVertex.hxx>
#include <BRepExtrema_DistShapeShape.hxx>
#include <TopoDS_Vertex.hxx>
#include <gp_Pnt.hxx>

#include <Standard_Failure.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <TopExp_Explorer.hxx>
#include <TopLoc_Location.hxx>
#include <TopTools_ListOfShape.hxx>
#include <TopoDS.hxx>

#include <algorithm>
#include <cassert>
#include <mutex>
#include <shared_mutex>
#include <vector>

namespace cadclash {
namespace {

// Shared locks on both parts: either part's faces may be meshed by another thread meanwhile
// (triangulate holds the lock exclusively); distances only read the faces, so any number run at once.
class PairLock {
 public:
  PairLock(const BrepSource::Impl& a, const BrepSource::Impl& b)
      : a_(a.mutex, std::defer_lock), b_(b.mutex, std::defer_lock) {
    if (&a == &b) a_.lock();
    else std::lock(a_, b_);
  }

 private:
  std::shared_lock<std::shared_mutex> a_, b_;
};

}  // namespace

const detail::FaceLocator& BrepSource::Impl::locator(std::uint32_t local_index) const {
  std::lock_guard<std::mutex> lock(locator_mutex);
  if (locators.size() != faces.size()) locators.resize(faces.size());
  if (!locators[local_index]) locators[local_index] = std::make_unique<const detail::FaceLocator>(faces[local_index]);
  return *locators[local_index];
}

BrepSource::BrepSource(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) { assert(impl_); }
BrepSource::~BrepSource() = default;

std::uint32_t BrepSource::face_count() const { return static_cast<std::uint32_t>(impl_->faces.size()); }

const TopoDS_Face& BrepSource::face(std::uint32_t local_index) const {
  assert(local_index < impl_->faces.size());
  return impl_->faces[local_index];
}

double BrepSource::default_deflection() const { return impl_->default_deflection; }

bool BrepSource::triangulate(std::uint32_t local_index, double deflection, TriangleMesh& out,
                             double& achieved_deflection, Diagnostic& error) {
  assert(local_index < impl_->faces.size());
  const double target = deflection > 0.0 ? deflection : impl_->default_deflection;
  std::string why;
  bool ok = false;
  if (local_index < impl_->outside_range.size() && impl_->outside_range[local_index]) {
    why = "it was dropped: outside the supported range";
  } else {
    std::lock_guard<std::shared_mutex> lock(impl_->mutex);
    // Finer than the part's own deflection is a refinement for one query: BRepMesh stores what it
    // makes in the face, so it meshes a copy (shared geometry, own topology), and the face keeps the
    // triangulation the model's surfaces, exporters and other readers of the shape were given.
    const bool refinement = deflection > 0.0 && deflection < impl_->default_deflection;
    const TopoDS_Face face =
        refinement ? TopoDS::Face(BRepBuilderAPI_Copy(impl_->faces[local_index], Standard_False, Standard_False).Shape())
                   : impl_->faces[local_index];
    ok = detail::mesh_face_to(face, target, impl_->angular_deflection, impl_->verify_deflection, out,
                              achieved_deflection, why);
  }
  if (ok && local_index < impl_->exact_faces.size() && impl_->exact_faces[local_index]) achieved_deflection = 0.0;
  if (!ok) {
    error = Diagnostic{Severity::Error, impl_->source_file, 0, impl_->entity_ids[local_index],
                       "face " + std::to_string(local_index) + " of part '" + impl_->part_name +
                           "' could not be tessellated (" + why + ")"};
  }
  return ok;
}

namespace {

// The face without the holes (inner wires) whose boxes miss `region`: its common part with the
// region's box is the same, and the Boolean then meets only the wires near it (a board's top face
// has hundreds of holes). The outer wire always stays.
TopoDS_Face without_far_holes(const TopoDS_Face& face, const Aabb& region) {
  const TopoDS_Wire outer = BRepTools::OuterWire(face);
  Bnd_Box near;
  near.Update(region.min().x(), region.min().y(), region.min().z(), region.max().x(), region.max().y(), region.max().z());
  std::vector<TopoDS_Shape> keep;
  bool dropped = false;
  for (TopoDS_Iterator it(face, Standard_False, Standard_False); it.More(); it.Next()) {
    if (it.Value().ShapeType() != TopAbs_WIRE) continue;
    if (!it.Value().IsSame(outer)) {
      Bnd_Box b;
      BRepBndLib::Add(it.Value(), b);  // with the edges' tolerances: never smaller than the wire
      if (b.IsOut(near)) {
        dropped = true;
        continue;
      }
    }
    keep.push_back(it.Value());
  }
  if (!dropped) return face;
  TopoDS_Face out = TopoDS::Face(face.EmptyCopied());
  BRep_Builder builder;
  for (const TopoDS_Shape& w : keep) builder.Add(out, w);
  return out;
}

}  // namespace

bool BrepSource::triangulate_region(std::uint32_t local_index, double deflection, const Aabb& region,
                                    TriangleMesh& out, double& achieved_deflection, Diagnostic& error) {
  assert(local_index < impl_->faces.size() && deflection > 0.0 && !region.isEmpty());
  std::string why;
  bool ok = false;
  out = TriangleMesh{};
  achieved_deflection = 0.0;
  if (local_index < impl_->outside_range.size() && impl_->outside_range[local_index]) {
    why = "it was dropped: outside the supported range";
  } else {
    // Read-only on the part: the Boolean works on a copy (shared geometry, own topology) and is told
    // not to touch its arguments; BRepMesh writes into the copy's pieces only.
    std::shared_lock<std::shared_mutex> lock(impl_->mutex);
    try {
      const TopoDS_Shape face = without_far_holes(
          TopoDS::Face(BRepBuilderAPI_Copy(impl_->faces[local_index], Standard_False, Standard_False).Shape()), region);
      const TopoDS_Shape box = BRepPrimAPI_MakeBox(gp_Pnt(region.min().x(), region.min().y(), region.min().z()),
                                                   gp_Pnt(region.max().x(), region.max().y(), region.max().z()))
                                   .Shape();
      BRepAlgoAPI_Common common;
      TopTools_ListOfShape args, tools;
      args.Append(face);
      tools.Append(box);
      common.SetArguments(args);
      common.SetTools(tools);
      common.SetNonDestructive(Standard_True);
      common.SetRunParallel(Standard_False);
      common.Build();
      if (!common.IsDone() || common.HasErrors()) {
        why = "the Boolean common with the region failed";
      } else {
        ok = true;
        for (TopExp_Explorer x(common.Shape(), TopAbs_FACE); x.More() && ok; x.Next()) {
          TriangleMesh piece;
          double got = 0.0;
          ok = detail::mesh_face_to(TopoDS::Face(x.Current()), deflection, impl_->angular_deflection,
                                    impl_->verify_deflection, piece, got, why);
          if (!ok) break;
          const auto base = static_cast<std::uint32_t>(out.vertices.size());
          out.vertices.insert(out.vertices.end(), piece.vertices.begin(), piece.vertices.end());
          for (auto t : piece.triangles) out.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
          achieved_deflection = std::max(achieved_deflection, got);
        }
      }
    } catch (const Standard_Failure& e) {
      why = std::string("OCCT failed: ") + e.GetMessageString();
      ok = false;
    }
  }
  if (!ok) {
    out = TriangleMesh{};
    error = Diagnostic{Severity::Error, impl_->source_file, 0, impl_->entity_ids[local_index],
                       "part of face " + std::to_string(local_index) + " of part '" + impl_->part_name +
                           "' could not be tessellated (" + why + ")"};
  }
  return ok;
}

std::optional<double> BrepSource::point_distance(std::uint32_t local_index, const Vec3& point) const {
  const Impl& a = *impl_;
  assert(local_index < a.faces.size());
  std::shared_lock<std::shared_mutex> lock(a.mutex);
  try {
    const gp_Pnt p(point.x(), point.y(), point.z());
    if (auto near = detail::face_point_witness(detail::face_surface(a, local_index), a.faces[local_index],
                                               detail::face_locator(a, local_index), a.boxes[local_index], p))
      return near;
    const TopoDS_Vertex v = BRepBuilderAPI_MakeVertex(p);
    BRepExtrema_DistShapeShape dist(v, a.faces[local_index], Extrema_ExtFlag_MIN);
    if (!dist.IsDone() || dist.NbSolution() == 0) return std::nullopt;
    return dist.Value();
  } catch (const Standard_Failure&) {
    return std::nullopt;
  }
}

std::optional<SurfaceSource::SurfacePoint> BrepSource::surface_point(std::uint32_t local_index,
                                                                     const Vec3& point) const {
  const Impl& a = *impl_;
  assert(local_index < a.faces.size());
  std::shared_lock<std::shared_mutex> lock(a.mutex);
  try {
    return detail::face_surface_point(detail::face_surface(a, local_index), a.faces[local_index], a.boxes[local_index],
                                      gp_Pnt(point.x(), point.y(), point.z()));
  } catch (const Standard_Failure&) {
    return std::nullopt;
  }
}

std::optional<std::array<double, 2>> BrepSource::height_range(std::uint32_t local_index, const Vec3& origin,
                                                              const Vec3& normal) const {
  const Impl& a = *impl_;
  assert(local_index < a.faces.size());
  std::shared_lock<std::shared_mutex> lock(a.mutex);
  try {
    return detail::face_height_range(a.faces[local_index], origin, normal);
  } catch (const Standard_Failure&) {
    return std::nullopt;
  }
}

std::optional<SurfaceSource::BezierPatches> BrepSource::bezier_patches(std::uint32_t local_index) const {
  const Impl& a = *impl_;
  assert(local_index < a.faces.size());
  std::shared_lock<std::shared_mutex> lock(a.mutex);
  try {
    return detail::face_bezier_patches(a.faces[local_index]);
  } catch (const Standard_Failure&) {
    return std::nullopt;
  }
}

std::shared_ptr<const std::vector<SurfaceSource::CircularHole>> BrepSource::circular_holes(
    std::uint32_t local_index) const {
  const Impl& a = *impl_;
  assert(local_index < a.faces.size());
  Impl::HolesSlot* slot = nullptr;
  {
    std::lock_guard<std::mutex> lock(a.holes_mutex);
    if (!a.holes) a.holes = std::make_unique<Impl::HolesSlot[]>(a.faces.size());
    slot = &a.holes[local_index];
  }
  // Once per face; a second thread asking meanwhile waits for it (a board's face has hundreds).
  std::call_once(slot->made, [&] {
    auto made = std::make_shared<std::vector<CircularHole>>();
    std::shared_lock<std::shared_mutex> lock(a.mutex);
    try {
      *made = detail::face_circular_holes(a.faces[local_index], a.locator(local_index));
    } catch (const Standard_Failure&) {
      made->clear();  // no hole is known: the certificate is not offered
    }
    slot->holes = std::move(made);
  });
  return slot->holes;
}

std::optional<SurfaceSource::SurfacePoint> BrepSource::edge_support(std::uint32_t local_index, const Vec3& direction,
                                                                    const Vec3& near) const {
  const Impl& a = *impl_;
  assert(local_index < a.faces.size());
  std::shared_lock<std::shared_mutex> lock(a.mutex);
  try {
    return detail::face_edge_support(detail::face_locator(a, local_index), a.boxes[local_index], direction,
                                     gp_Pnt(near.x(), near.y(), near.z()));
  } catch (const Standard_Failure&) {
    return std::nullopt;
  }
}

std::optional<double> BrepSource::boundary_distance(std::uint32_t local_index, const Vec3& point) const {
  const Impl& a = *impl_;
  assert(local_index < a.faces.size());
  std::shared_lock<std::shared_mutex> lock(a.mutex);
  try {
    return detail::face_boundary_witness(detail::face_locator(a, local_index), a.boxes[local_index],
                                         gp_Pnt(point.x(), point.y(), point.z()));
  } catch (const Standard_Failure&) {
    return std::nullopt;
  }
}

std::optional<double> BrepSource::edge_distance(std::uint32_t local_a, const Pose& pose_a, const SurfaceSource& other,
                                                std::uint32_t local_b, const Pose& pose_b, const Vec3& near_a,
                                                const Vec3& near_b) const {
  const auto* other_brep = dynamic_cast<const BrepSource*>(&other);
  if (other_brep == nullptr) return std::nullopt;
  const Impl& a = *impl_;
  const Impl& b = *other_brep->impl_;
  assert(local_a < a.faces.size() && local_b < b.faces.size());
  const PairLock lock(a, b);
  try {
    return detail::edge_pair_witness(detail::face_locator(a, local_a), detail::to_trsf(pose_a), gp_Pnt(near_a.x(), near_a.y(), near_a.z()),
                                     detail::face_locator(b, local_b), detail::to_trsf(pose_b), gp_Pnt(near_b.x(), near_b.y(), near_b.z()));
  } catch (const Standard_Failure&) {
    return std::nullopt;
  }
}

std::optional<double> BrepSource::exact_distance(std::uint32_t local_a, const Pose& pose_a, const SurfaceSource& other,
                                                 std::uint32_t local_b, const Pose& pose_b, double max_distance,
                                                 double enough) const {
  const auto* other_brep = dynamic_cast<const BrepSource*>(&other);
  if (other_brep == nullptr) return std::nullopt;
  const Impl& a = *impl_;
  const Impl& b = *other_brep->impl_;
  assert(local_a < a.faces.size() && local_b < b.faces.size());

  const double boxes_apart = box_distance(placed_box(a.boxes[local_a], pose_a), placed_box(b.boxes[local_b], pose_b));
  if (!a.boxes[local_a].isEmpty() && !b.boxes[local_b].isEmpty() && boxes_apart > max_distance) return boxes_apart;

  const PairLock lock(a, b);
  try {
    // Moved() shares the face's geometry and only composes the location: nothing is copied.
    const TopoDS_Shape fa = a.faces[local_a].Moved(TopLoc_Location(detail::to_trsf(pose_a)));
    const TopoDS_Shape fb = b.faces[local_b].Moved(TopLoc_Location(detail::to_trsf(pose_b)));
    return detail::min_distance(fa, fb, enough);
  } catch (const Standard_Failure&) {
    return std::nullopt;
  }
}

}  // namespace cadclash
