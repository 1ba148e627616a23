// collide_only: cadclash::collide on triangles from your own source — no OpenCASCADE, no assimp.
// Builds two unit cubes as parts with one surface per face, places the second so they overlap, and
// prints every colliding surface pair.
//   collide_only            → prints the pairs, returns 0 when the overlap is found, 1 otherwise
#include <cadclash/collide.h>

#include <cstdio>
#include <string>

namespace {

// Appends a part holding an axis-aligned box [lo, hi] with one two-triangle surface per face,
// named "-x", "+x", "-y", "+y", "-z", "+z"; each surface must carry its triangles and its AABB.
cadclash::PartId add_box_part(cadclash::Model& model, const std::string& name, const cadclash::Vec3& lo,
                              const cadclash::Vec3& hi) {
  const cadclash::PartId part = static_cast<cadclash::PartId>(model.parts.size());
  cadclash::Part p;
  p.name = name;
  p.first_surface = static_cast<cadclash::SurfaceId>(model.surfaces.size());
  p.surface_count = 6;
  model.parts.push_back(p);

  const char* names[6] = {"-x", "+x", "-y", "+y", "-z", "+z"};
  for (int axis = 0; axis < 3; ++axis) {
    for (int side = 0; side < 2; ++side) {
      // The face's plane and its two in-plane axes, ordered so the normal points outwards.
      const int u = (axis + (side == 0 ? 2 : 1)) % 3, v = (axis + (side == 0 ? 1 : 2)) % 3;
      const double w = side == 0 ? lo[axis] : hi[axis];
      cadclash::Surface s;
      s.name = names[2 * axis + side];
      s.part = part;
      s.provenance.kind = cadclash::SourceKind::MeshFile;
      s.provenance.face_index = 2 * axis + side;
      for (const auto& [cu, cv] : {std::pair{0, 0}, {1, 0}, {1, 1}, {0, 1}}) {
        cadclash::Vec3 corner;
        corner[axis] = w;
        corner[u] = cu ? hi[u] : lo[u];
        corner[v] = cv ? hi[v] : lo[v];
        s.mesh.vertices.push_back(corner);
      }
      s.mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
      s.has_triangles = true;
      s.aabb = cadclash::mesh_aabb(s.mesh);
      model.surfaces.push_back(std::move(s));
    }
  }
  return part;
}

}  // namespace

int main() {
  cadclash::Model model;
  const cadclash::PartId cube = add_box_part(model, "cube", {0, 0, 0}, {1, 1, 1});

  // Two instances of the same part; the second one shifted by (0.5, 0.25, 0.25) mm.
  model.instances.push_back({"/cube::1", cube, cadclash::Pose::Identity()});
  cadclash::Pose shifted = cadclash::Pose::Identity();
  shifted.translate(cadclash::Vec3(0.5, 0.25, 0.25));
  model.instances.push_back({"/cube::2", cube, shifted});

  cadclash::CollideOptions options;
  options.tolerance = 1e-6;
  const cadclash::Report report = cadclash::collide(model, 0, 1, options);

  for (const cadclash::Diagnostic& d : report.diagnostics)
    std::fprintf(stderr, "%s\n", cadclash::format_diagnostic(d).c_str());
  std::printf("%zu colliding surface pairs\n", report.pairs.size());
  for (const cadclash::SurfacePairResult& p : report.pairs) {
    const auto side = [&](cadclash::InstanceId i, cadclash::SurfaceId s) {
      return model.instances[i].path + " " + (s == cadclash::kInvalidId ? "(whole)" : model.surfaces[s].name);
    };
    std::printf("%s <-> %s: %s, penetration %.3g mm\n", side(p.instance_a, p.surface_a).c_str(),
                side(p.instance_b, p.surface_b).c_str(), cadclash::contact_class_name(p.contact),
                p.penetration);
  }
  return report.pairs.empty() || cadclash::has_error(report.diagnostics) ? 1 : 0;
}
