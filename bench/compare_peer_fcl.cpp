// FCL 0.7 mesh–mesh collision with every contact listed. The traversal is driven the way
// fcl::collide drives it for two BVHModels (collision_func_matrix: the oriented node for OBBRSS; for
// AABB a copy of both models moved into the world frame and rebuilt per query), so the time is
// fcl::collide's, with FCL's own statistics switched on to count the triangle tests.
#include "compare_peers.h"

#include <fcl/math/bv/AABB.h>
#include <fcl/math/bv/OBBRSS.h>
#include <fcl/math/bv/utility.h>
#include <fcl/geometry/bvh/BVH_model.h>
#include <fcl/narrowphase/collision_request.h>
#include <fcl/narrowphase/collision_result.h>
#include <fcl/narrowphase/detail/traversal/collision/mesh_collision_traversal_node.h>
#include <fcl/narrowphase/detail/traversal/collision_node.h>

#include <type_traits>
#include <vector>

namespace cadclash::bench {
namespace {

template <class BV>
class FclPeer final : public Peer {
 public:
  explicit FclPeer(std::string name) : name_(std::move(name)) {}
  std::string name() const override { return name_; }

  bool build(const Model& model, std::string& error) override {
    models_.clear();
    surface_of_.clear();
    bytes_ = 0;
    std::size_t triangles = 0;
    for (const Part& part : model.parts) {
      std::vector<fcl::Vector3d> points;
      std::vector<fcl::Triangle> tris;
      std::vector<SurfaceId> surface_of;
      for (SurfaceId s = part.first_surface; s < part.first_surface + part.surface_count; ++s) {
        const TriangleMesh& mesh = model.surfaces[s].mesh;
        const std::size_t base = points.size();
        points.insert(points.end(), mesh.vertices.begin(), mesh.vertices.end());
        for (const auto& t : mesh.triangles) {
          tris.emplace_back(base + t[0], base + t[1], base + t[2]);
          surface_of.push_back(s);
        }
      }
      auto m = std::make_shared<fcl::BVHModel<BV>>();
      if (!tris.empty()) {
        m->beginModel(static_cast<int>(tris.size()), static_cast<int>(points.size()));
        m->addSubModel(points, tris);
        m->endModel();
        bytes_ += static_cast<std::size_t>(m->getNumBVs()) * sizeof(fcl::BVNode<BV>) +
                  points.size() * sizeof(fcl::Vector3d) + tris.size() * (sizeof(fcl::Triangle) + sizeof(unsigned int));
      }
      triangles += tris.size();
      models_.push_back(std::move(m));
      surface_of_.push_back(std::move(surface_of));
    }
    triangles_ = triangles;
    if (triangles == 0) error = "no triangles";
    return triangles > 0;
  }

  double bytes_per_triangle() const override {
    return triangles_ ? static_cast<double>(bytes_) / static_cast<double>(triangles_) : -1.0;
  }

  PeerRun run(const Workload& w, const Subset& subset) override {
    PeerRun out;
    const Model& model = *w.model;
    // All contacts: the traversal stops only when num_max_contacts is reached.
    const fcl::CollisionRequestd request(std::size_t{1} << 40, false);
    std::vector<fcl::Contactd> contacts;
    for_each_step_pair(w, subset, [&](std::uint32_t step, InstanceId a, InstanceId b, const Pose& pa, const Pose& pb) {
      const PartId part_a = model.instances[a].part, part_b = model.instances[b].part;
      if (models_[part_a]->num_tris == 0 || models_[part_b]->num_tris == 0) return;
      fcl::CollisionResultd result;
      out.triangle_tests += traverse(*models_[part_a], pa, *models_[part_b], pb, request, result);
      result.getContacts(contacts);
      for (const fcl::Contactd& c : contacts)
        out.found.insert({step, a, b, surface_of_[part_a][static_cast<std::size_t>(c.b1)],
                          surface_of_[part_b][static_cast<std::size_t>(c.b2)]});
    });
    return out;
  }

 private:
  static std::uint64_t traverse(const fcl::BVHModel<BV>& a, const Pose& pa, const fcl::BVHModel<BV>& b,
                                const Pose& pb, const fcl::CollisionRequestd& request, fcl::CollisionResultd& result) {
    if constexpr (std::is_same_v<BV, fcl::OBBRSSd>) {
      fcl::detail::MeshCollisionTraversalNodeOBBRSS<double> node;
      fcl::detail::initialize(node, a, fcl::Transform3d(pa.matrix()), b, fcl::Transform3d(pb.matrix()), request, result);
      node.enable_statistics = true;
      fcl::detail::collide(&node);
      return static_cast<std::uint64_t>(node.num_leaf_tests);
    } else {
      fcl::BVHModel<BV> a_tmp(a), b_tmp(b);
      fcl::Transform3d ta(pa.matrix()), tb(pb.matrix());
      fcl::detail::MeshCollisionTraversalNode<BV> node;
      fcl::detail::initialize(node, a_tmp, ta, b_tmp, tb, request, result);
      node.enable_statistics = true;
      fcl::detail::collide(&node);
      return static_cast<std::uint64_t>(node.num_leaf_tests);
    }
  }

  std::string name_;
  std::vector<std::shared_ptr<fcl::BVHModel<BV>>> models_;  // per part
  std::vector<std::vector<SurfaceId>> surface_of_;          // per part, per triangle
  std::size_t bytes_ = 0, triangles_ = 0;
};

}  // namespace

std::unique_ptr<Peer> make_fcl_obbrss_peer() { return std::make_unique<FclPeer<fcl::OBBRSSd>>("FCL BVHModel<OBBRSS>"); }
std::unique_ptr<Peer> make_fcl_aabb_peer() { return std::make_unique<FclPeer<fcl::AABBd>>("FCL BVHModel<AABB>"); }

}  // namespace cadclash::bench
