// OCCT BRepExtrema_ShapeProximity on the parts' own faces, which carry the BRepMesh triangulation
// cadclash made from them (BrepSource meshes the faces in place), placed at the instances' poses.
// ShapeProximity builds its triangle sets and BVHs on every query: that cost is part of its time.
#include "compare_peers.h"

#include "cadclash/tessellate.h"

#include <BRepExtrema_ShapeProximity.hxx>
#include <BRep_Builder.hxx>
#include <BRep_Tool.hxx>
#include <Poly_Triangulation.hxx>
#include <TColStd_MapIteratorOfPackedMapOfInteger.hxx>
#include <TColStd_PackedMapOfInteger.hxx>
#include <TopLoc_Location.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Compound.hxx>
#include <gp_Trsf.hxx>

#include <unordered_map>
#include <vector>

namespace cadclash::bench {
namespace {

TopLoc_Location location(const Pose& p) {
  const Eigen::Matrix4d& m = p.matrix();
  gp_Trsf t;
  t.SetValues(m(0, 0), m(0, 1), m(0, 2), m(0, 3), m(1, 0), m(1, 1), m(1, 2), m(1, 3), m(2, 0), m(2, 1), m(2, 2),
              m(2, 3));
  return TopLoc_Location(t);
}

class OcctPeer final : public Peer {
 public:
  explicit OcctPeer(double tolerance) : tolerance_(tolerance) {}
  std::string name() const override {
    return tolerance_ > 0.0 ? "OCCT BRepExtrema_ShapeProximity, tolerance t" : "OCCT BRepExtrema_ShapeProximity, tolerance 0";
  }

  bool build(const Model& model, std::string& error) override {
    shapes_.clear();
    surface_of_.clear();
    for (const Part& part : model.parts) {
      auto* source = dynamic_cast<BrepSource*>(part.source.get());
      if (!source) {
        error = "part " + part.name + " has no B-rep faces";
        return false;
      }
      BRep_Builder builder;
      TopoDS_Compound compound;
      builder.MakeCompound(compound);
      std::unordered_map<const void*, SurfaceId> by_face;
      for (std::uint32_t k = 0; k < part.surface_count; ++k) {
        // Same triangles as cadclash's: the face must carry the triangulation its surface was read from.
        TopLoc_Location loc;
        const Handle(Poly_Triangulation) tri = BRep_Tool::Triangulation(source->face(k), loc);
        const std::size_t n = tri.IsNull() ? 0 : static_cast<std::size_t>(tri->NbTriangles());
        if (n != model.surfaces[part.first_surface + k].mesh.triangles.size()) {
          error = "face " + std::to_string(k) + " of part " + part.name + " carries " + std::to_string(n) +
                  " triangles, cadclash's surface " + std::to_string(model.surfaces[part.first_surface + k].mesh.triangles.size());
          return false;
        }
        builder.Add(compound, source->face(k));
        by_face.emplace(source->face(k).TShape().get(), part.first_surface + k);
      }
      shapes_.push_back(compound);
      surface_of_.push_back(std::move(by_face));
    }
    return true;
  }

  double bytes_per_triangle() const override { return -1.0; }

  PeerRun run(const Workload& w, const Subset& subset) override {
    PeerRun out;
    out.has_tests = false;
    const Model& model = *w.model;
    for_each_step_pair(w, subset, [&](std::uint32_t step, InstanceId a, InstanceId b, const Pose& pa, const Pose& pb) {
      const PartId part_a = model.instances[a].part, part_b = model.instances[b].part;
      BRepExtrema_ShapeProximity proximity(shapes_[part_a].Located(location(pa)), shapes_[part_b].Located(location(pb)),
                                           tolerance_);
      proximity.Perform();
      if (!proximity.IsDone()) return;
      // Faces are named back through their TShape; ShapeProximity lists only faces of the shapes it
      // was given, so the lookups cannot miss.
      for (BRepExtrema_MapOfIntegerPackedMapOfInteger::Iterator it(proximity.OverlapSubShapes1()); it.More(); it.Next()) {
        const SurfaceId sa = surface_of_[part_a].at(proximity.GetSubShape1(it.Key()).TShape().get());
        for (TColStd_MapIteratorOfPackedMapOfInteger jt(it.Value()); jt.More(); jt.Next())
          out.found.insert({step, a, b, sa, surface_of_[part_b].at(proximity.GetSubShape2(jt.Key()).TShape().get())});
      }
    });
    return out;
  }

 private:
  double tolerance_;
  std::vector<TopoDS_Shape> shapes_;                                    // per part: its faces
  std::vector<std::unordered_map<const void*, SurfaceId>> surface_of_;  // per part: face → surface
};

}  // namespace

std::unique_ptr<Peer> make_occt_peer(double tolerance) { return std::make_unique<OcctPeer>(tolerance); }

}  // namespace cadclash::bench
