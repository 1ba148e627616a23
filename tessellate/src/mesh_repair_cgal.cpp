// The CGAL half of mesh repair and segmentation: the only translation unit that instantiates CGAL's
// Polygon_mesh_processing and Shape_detection templates (they compile slowly).
//
// Tags survive because nothing here reorders faces: orient_polygon_soup only reverses polygons and
// appends points, and polygon_soup_to_polygon_mesh on an empty Surface_mesh creates face i from
// polygon i. From then on a face property carries the tag and the input index; later steps only
// remove faces (marked removed, indices kept) or append them (hole filling).
#include "mesh_soup.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/border.h>
#include <CGAL/Polygon_mesh_processing/connected_components.h>
#include <CGAL/Polygon_mesh_processing/detect_features.h>
#include <CGAL/Polygon_mesh_processing/manifoldness.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/orientation.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/repair.h>
#include <CGAL/Polygon_mesh_processing/stitch_borders.h>
#include <CGAL/Polygon_mesh_processing/triangulate_hole.h>
#include <CGAL/Shape_detection/Region_growing/Region_growing.h>
#include <CGAL/Shape_detection/Region_growing/Region_growing_on_polygon_mesh.h>
#include <CGAL/Surface_mesh.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <map>
#include <set>

namespace cadclash::detail {

bool collinear_exact(const Vec3& a, const Vec3& b, const Vec3& c) {
  using P = CGAL::Exact_predicates_inexact_constructions_kernel::Point_3;
  return CGAL::collinear(P(a.x(), a.y(), a.z()), P(b.x(), b.y(), b.z()), P(c.x(), c.y(), c.z()));
}
namespace {

namespace PMP = CGAL::Polygon_mesh_processing;
using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = K::Point_3;
using Mesh = CGAL::Surface_mesh<Point>;
using VI = Mesh::Vertex_index;
using FI = Mesh::Face_index;
using HI = Mesh::Halfedge_index;
using EI = Mesh::Edge_index;

// Builds an oriented Surface_mesh whose face i is soup triangle i, and whose vertex k < points.size()
// is point k (orient_polygon_soup appends its copies). Returns false with `error`.
bool soup_to_mesh(const std::vector<Vec3>& in_points, const std::vector<Tri>& in_triangles, Mesh& mesh,
                  std::string& error) {
  std::vector<Point> points;
  points.reserve(in_points.size());
  for (const Vec3& p : in_points) points.emplace_back(p.x(), p.y(), p.z());
  std::vector<std::vector<std::size_t>> polygons;
  polygons.reserve(in_triangles.size());
  for (const Tri& t : in_triangles) polygons.push_back({t[0], t[1], t[2]});
  PMP::orient_polygon_soup(points, polygons);
  if (polygons.size() != in_triangles.size()) {
    error = "orient_polygon_soup changed the number of triangles";
    return false;
  }
  if (!PMP::is_polygon_soup_a_polygon_mesh(polygons)) {
    error = "the oriented triangles still do not form a valid halfedge mesh";
    return false;
  }
  PMP::polygon_soup_to_polygon_mesh(points, polygons, mesh);
  if (mesh.number_of_faces() != in_triangles.size()) {
    error = "polygon_soup_to_polygon_mesh dropped triangles";
    return false;
  }
  return true;
}

Vec3 to_vec(const Point& p) { return {p.x(), p.y(), p.z()}; }

// The three corner points of face f, in its winding.
std::array<Vec3, 3> face_points(const Mesh& mesh, FI f) {
  std::array<Vec3, 3> out;
  int i = 0;
  for (VI v : CGAL::vertices_around_face(mesh.halfedge(f), mesh)) {
    if (i < 3) out[static_cast<std::size_t>(i)] = to_vec(mesh.point(v));
    ++i;
  }
  return out;
}

// +1 when `q` is a rotation of `p`, -1 when it is a rotation of p reversed, 0 otherwise.
int same_winding(const std::array<Vec3, 3>& p, const std::array<Vec3, 3>& q) {
  for (int r = 0; r < 3; ++r) {
    if (q[0] == p[r] && q[1] == p[(r + 1) % 3] && q[2] == p[(r + 2) % 3]) return 1;
    if (q[0] == p[r] && q[1] == p[(r + 2) % 3] && q[2] == p[(r + 1) % 3]) return -1;
  }
  return 0;
}

std::array<Vec3, 3> soup_points(const TaggedSoup& soup, const Tri& t) {
  return {soup.points[t[0]], soup.points[t[1]], soup.points[t[2]]};
}

// Orients each connected component: a closed one outward (inward when it bounds a cavity, nested in
// an odd number of closed components), an open one as most of its input faces were wound.
void orient_components(Mesh& mesh, const TaggedSoup& soup, const Mesh::Property_map<FI, std::int64_t>& forigin) {
  auto [fcc, cc_created] = mesh.add_property_map<FI, std::size_t>("f:cadclash_cc", 0);
  (void)cc_created;
  const std::size_t n_cc = PMP::connected_components(mesh, fcc);
  std::vector<std::vector<FI>> cc_faces(n_cc);
  for (FI f : mesh.faces()) cc_faces[fcc[f]].push_back(f);
  struct Component {
    bool closed = true;
    double volume6 = 0.0;
    std::size_t agree = 0;  // faces whose winding matches the input's
    Aabb box;
    Vec3 probe = Vec3::Zero();  // centroid of the component's first face
  };
  std::vector<Component> cc(n_cc);
  for (std::size_t c = 0; c < n_cc; ++c) {
    Component& k = cc[c];
    for (FI f : cc_faces[c]) {
      for (HI h : CGAL::halfedges_around_face(mesh.halfedge(f), mesh))
        if (mesh.is_border(mesh.opposite(h))) k.closed = false;
      const std::array<Vec3, 3> p = face_points(mesh, f);
      k.volume6 += p[0].dot(p[1].cross(p[2]));
      for (const Vec3& v : p) k.box.extend(v);
      if (f == cc_faces[c].front()) k.probe = (p[0] + p[1] + p[2]) / 3.0;
      const std::array<Vec3, 3> q = soup_points(soup, soup.triangles[static_cast<std::size_t>(forigin[f])]);
      if (same_winding(q, p) > 0) ++k.agree;
    }
  }
  // A closed component nested inside an odd number of other closed components bounds a cavity and
  // faces inward; the others face outward. Nesting by the generalized winding number of the
  // component's probe point (|w| ~ 1 inside a closed surface, ~ 0 outside).
  for (std::size_t c = 0; c < n_cc; ++c) {
    Component& k = cc[c];
    bool reverse = 2 * k.agree < cc_faces[c].size();
    if (k.closed && k.volume6 != 0.0) {
      std::size_t depth = 0;
      for (std::size_t d = 0; d < n_cc; ++d) {
        if (d == c || !cc[d].closed || !cc[d].box.contains(k.box)) continue;
        double solid = 0.0;
        for (FI f : cc_faces[d]) {
          const std::array<Vec3, 3> p = face_points(mesh, f);
          const Vec3 a = p[0] - k.probe, b = p[1] - k.probe, e = p[2] - k.probe;
          const double la = a.norm(), lb = b.norm(), le = e.norm();
          solid += 2.0 * std::atan2(a.dot(b.cross(e)), la * lb * le + a.dot(b) * le + a.dot(e) * lb + b.dot(e) * la);
        }
        if (std::abs(solid) > 2.0 * CGAL_PI) ++depth;  // |w| > 0.5
      }
      reverse = (k.volume6 < 0.0) == (depth % 2 == 0);
    }
    if (reverse) PMP::reverse_face_orientations(cc_faces[c], mesh);
  }
  mesh.remove_property_map(fcc);
}

// Fills the border cycles of at most options.max_hole_edges edges (0: all), each hole's triangles
// tagged with the surface owning most of its border; counted per tag.
void fill_holes(Mesh& mesh, const MeshRepairOptions& options, Mesh::Property_map<FI, std::uint32_t>& ftag,
                Mesh::Property_map<FI, std::int64_t>& forigin, std::vector<TagCounts>& counts) {
  // Border cycles in order of their lowest halfedge index, so the result never depends on hashing.
  std::vector<HI> starts;
  std::vector<bool> seen(mesh.num_halfedges(), false);
  for (HI h : mesh.halfedges()) {
    if (!mesh.is_border(h) || seen[h.idx()]) continue;
    std::size_t length = 0;
    for (HI g : CGAL::halfedges_around_face(h, mesh)) {
      seen[g.idx()] = true;
      ++length;
    }
    if (options.max_hole_edges == 0 || length <= options.max_hole_edges) starts.push_back(h);
  }
  for (HI h : starts) {
    if (!mesh.is_border(h)) continue;  // an earlier fill closed it
    std::map<std::uint32_t, std::size_t> votes;
    for (HI g : CGAL::halfedges_around_face(h, mesh)) ++votes[ftag[mesh.face(mesh.opposite(g))]];
    std::uint32_t owner = votes.begin()->first;
    std::size_t best = 0;
    for (const auto& [tag, n] : votes)
      if (n > best) owner = tag, best = n;  // strict >: ties keep the lower tag
    std::vector<FI> added;
    PMP::triangulate_hole(mesh, h, std::back_inserter(added));
    if (added.empty()) continue;
    for (FI f : added) {
      ftag[f] = owner;
      forigin[f] = -1;
    }
    ++counts[owner].filled_holes;
    counts[owner].hole_faces += static_cast<std::uint32_t>(added.size());
  }
}

}  // namespace

MeshStageResult repair_soup_cgal(const TaggedSoup& soup, std::uint32_t tag_count, const MeshRepairOptions& options) {
  MeshStageResult r;
  r.counts.assign(tag_count, TagCounts{});
  Mesh mesh;
  if (!soup_to_mesh(soup.points, soup.triangles, mesh, r.error)) return r;
  const std::size_t n_in = soup.triangles.size();
  // Not structured bindings: clang 14 cannot capture them in the lambdas below.
  auto ftag = mesh.add_property_map<FI, std::uint32_t>("f:cadclash_tag", 0u).first;
  auto forigin = mesh.add_property_map<FI, std::int64_t>("f:cadclash_origin", -1).first;
  for (std::size_t i = 0; i < n_in; ++i) {
    FI f(static_cast<Mesh::size_type>(i));
    ftag[f] = soup.tags[i];
    forigin[f] = static_cast<std::int64_t>(i);
  }
  // Points orient_polygon_soup appended are copies made at non-manifold spots.
  const std::size_t n_points_in = soup.points.size();
  {
    std::vector<std::set<std::uint32_t>> users(mesh.number_of_vertices());
    for (FI f : mesh.faces())
      for (VI v : CGAL::vertices_around_face(mesh.halfedge(f), mesh))
        if (v.idx() >= n_points_in) users[v.idx()].insert(ftag[f]);
    for (const auto& u : users)
      for (std::uint32_t t : u) ++r.counts[t].duplicated_vertices;
  }

  auto border_edges_per_tag = [&](std::vector<std::uint32_t>& out) {
    out.assign(tag_count, 0);
    for (HI h : mesh.halfedges())
      if (mesh.is_border(h)) ++out[ftag[mesh.face(mesh.opposite(h))]];
  };

  if (options.stitch_borders) {
    std::vector<std::uint32_t> before, after;
    border_edges_per_tag(before);
    PMP::stitch_borders(mesh);
    border_edges_per_tag(after);
    for (std::uint32_t t = 0; t < tag_count; ++t) r.counts[t].stitched_edges = before[t] - after[t];
  }

  if (options.duplicate_non_manifold_vertices) {
    const std::size_t n_before = mesh.num_vertices();  // includes removed ones: new indices are >= this
    PMP::duplicate_non_manifold_vertices(mesh);
    std::vector<std::set<std::uint32_t>> users(mesh.num_vertices());
    for (FI f : mesh.faces())
      for (VI v : CGAL::vertices_around_face(mesh.halfedge(f), mesh))
        if (v.idx() >= n_before) users[v.idx()].insert(ftag[f]);
    for (const auto& u : users)
      for (std::uint32_t t : u) ++r.counts[t].duplicated_vertices;
  }

  if (options.orient) orient_components(mesh, soup, forigin);

  if (options.remove_negligible_components) {
    PMP::remove_connected_components_of_negligible_size(mesh);
    for (std::size_t i = 0; i < n_in; ++i) {
      FI f(static_cast<Mesh::size_type>(i));
      if (mesh.is_removed(f)) ++r.counts[soup.tags[i]].removed_component_faces;
    }
  }

  if (options.fill_holes) fill_holes(mesh, options, ftag, forigin, r.counts);

  // Output in face index order: input order first, then hole triangles.
  std::vector<std::uint32_t> vmap(mesh.num_vertices(), ~0u);
  for (FI f : mesh.faces()) {
    Tri t{};
    int i = 0;
    for (VI v : CGAL::vertices_around_face(mesh.halfedge(f), mesh)) {
      if (vmap[v.idx()] == ~0u) {
        vmap[v.idx()] = static_cast<std::uint32_t>(r.points.size());
        r.points.push_back(to_vec(mesh.point(v)));
      }
      if (i < 3) t[static_cast<std::size_t>(i)] = vmap[v.idx()];
      ++i;
    }
    if (i != 3) {
      r.error = "a repaired face is not a triangle";
      return r;
    }
    r.triangles.push_back(t);
    r.tags.push_back(ftag[f]);
    r.origin.push_back(forigin[f]);
    if (forigin[f] >= 0) {
      const std::array<Vec3, 3> q = soup_points(soup, soup.triangles[static_cast<std::size_t>(forigin[f])]);
      if (same_winding(q, face_points(mesh, f)) < 0) ++r.counts[ftag[f]].flipped_faces;
    }
  }
  r.ok = true;
  return r;
}

bool segment_soup_cgal(const std::vector<Vec3>& points, const std::vector<Tri>& triangles,
                       const SegmentOptions& options, std::vector<std::uint32_t>& patch, std::string& error) {
  patch.assign(triangles.size(), 0);
  if (triangles.empty()) return true;
  Mesh mesh;
  if (!soup_to_mesh(points, triangles, mesh, error)) return false;
  auto [feature, feature_created] = mesh.add_property_map<EI, bool>("e:cadclash_feature", false);
  (void)feature_created;
  PMP::detect_sharp_edges(mesh, options.sharp_angle_degrees, feature);

  if (options.planar) {
    double distance = options.planar_max_distance;
    if (distance <= 0.0) {
      Aabb box;
      for (const Vec3& p : points) box.extend(p);
      distance = 1e-3 * box.diagonal().norm();
    }
    using Neighbor_query = CGAL::Shape_detection::Polygon_mesh::One_ring_neighbor_query<Mesh>;
    using Region_type = CGAL::Shape_detection::Polygon_mesh::Least_squares_plane_fit_region<K, Mesh>;
    using Sorting = CGAL::Shape_detection::Polygon_mesh::Least_squares_plane_fit_sorting<K, Mesh, Neighbor_query>;
    using Region_growing =
        CGAL::Shape_detection::Region_growing<Mesh::Face_range, Neighbor_query, Region_type, Sorting::Seed_map>;
    Neighbor_query neighbors(mesh);
    // The point maps must be passed: their default-constructed value is a null Surface_mesh map.
    Region_type region_type(mesh, distance, std::clamp(options.planar_max_angle_degrees, 0.0, 90.0), 1,
                            mesh.points());
    Sorting sorting(mesh, neighbors, mesh.points());
    sorting.sort();
    const Mesh::Face_range face_range = mesh.faces();  // Region_growing keeps a reference to it
    Region_growing growing(face_range, neighbors, region_type, sorting.seed_map());
    std::vector<std::vector<std::size_t>> regions;
    growing.detect(std::back_inserter(regions));
    // Faces left out of every region get a region of their own.
    std::vector<std::size_t> region(mesh.number_of_faces(), ~std::size_t{0});
    for (std::size_t k = 0; k < regions.size(); ++k)
      for (std::size_t f : regions[k]) region[f] = k;
    for (EI e : mesh.edges()) {
      if (mesh.is_border(e)) continue;
      const std::size_t a = mesh.face(mesh.halfedge(e, 0)).idx(), b = mesh.face(mesh.halfedge(e, 1)).idx();
      if (region[a] != region[b] || region[a] == ~std::size_t{0}) feature[e] = true;
    }
  }

  auto [fpatch, patch_created] = mesh.add_property_map<FI, std::size_t>("f:cadclash_patch", 0);
  (void)patch_created;
  PMP::connected_components(mesh, fpatch, CGAL::parameters::edge_is_constrained_map(feature));
  for (std::size_t i = 0; i < triangles.size(); ++i)
    patch[i] = static_cast<std::uint32_t>(fpatch[FI(static_cast<Mesh::size_type>(i))]);
  return true;
}

}  // namespace cadclash::detail
