// repair_meshes(): the Model side of mesh repair — per-part tagged soups in, per-surface counts and
// rebuilt surfaces out. The CGAL steps live in mesh_repair_cgal.cpp.
#include "mesh_soup_clean.h"

#include <algorithm>
#include <cassert>

namespace cadclash {
namespace {

using detail::Tri;

void add_counts(SurfaceRepairStats& into, const SurfaceRepairStats& s) {
  into.triangles_before += s.triangles_before;
  into.triangles_after += s.triangles_after;
  into.vertices_before += s.vertices_before;
  into.vertices_after += s.vertices_after;
  into.merged_points += s.merged_points;
  into.unused_points += s.unused_points;
  into.degenerate_faces += s.degenerate_faces;
  into.collinear_faces += s.collinear_faces;
  into.duplicate_faces += s.duplicate_faces;
  into.flipped_faces += s.flipped_faces;
  into.stitched_edges += s.stitched_edges;
  into.duplicated_vertices += s.duplicated_vertices;
  into.removed_component_faces += s.removed_component_faces;
  into.filled_holes += s.filled_holes;
  into.hole_faces += s.hole_faces;
  into.changed = into.changed || s.changed;
}

// The part's surfaces as one soup for CGAL, each triangle tagged with its surface (local index), the
// points merged across surfaces; what is dropped on the way (unused, merged, degenerate, collinear,
// duplicate) is counted in `stats` (one entry per surface, sized by the caller).
detail::TaggedSoup gather_soup(const Model& model, const Part& part, std::vector<SurfaceRepairStats>& stats) {
  const std::uint32_t n_tags = part.surface_count;
  detail::TaggedSoup soup;
  detail::PointMerger part_points;
  std::unordered_set<detail::TriKey, detail::TriKeyHash> seen_triangles;
  for (std::uint32_t local = 0; local < n_tags; ++local) {
    const SurfaceId sid = part.first_surface + local;
    const Surface& surface = model.surfaces[sid];
    SurfaceRepairStats& st = stats[local];
    st.surface = sid;
    if (!surface.has_triangles) continue;
    const TriangleMesh& mesh = surface.mesh;
    st.vertices_before = static_cast<std::uint32_t>(mesh.vertices.size());
    st.triangles_before = static_cast<std::uint32_t>(mesh.triangles.size());

    std::vector<bool> used(mesh.vertices.size(), false);
    for (const Tri& t : mesh.triangles)
      for (std::uint32_t v : t) {
        assert(v < mesh.vertices.size() && "triangle index out of range in a Model");
        used[v] = true;
      }
    detail::PointMerger own_points;
    std::vector<Vec3> own_scratch;
    std::vector<std::uint32_t> to_part(mesh.vertices.size(), ~0u);
    for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
      if (!used[v]) {
        ++st.unused_points;
        continue;
      }
      const std::size_t before = own_scratch.size();
      own_points.add(mesh.vertices[v], own_scratch);
      if (own_scratch.size() == before) ++st.merged_points;
      if (detail::finite_point(mesh.vertices[v])) to_part[v] = part_points.add(mesh.vertices[v], soup.points);
    }
    for (const Tri& t : mesh.triangles) {
      const Tri g{to_part[t[0]], to_part[t[1]], to_part[t[2]]};
      if (g[0] == ~0u || g[1] == ~0u || g[2] == ~0u || g[0] == g[1] || g[1] == g[2] || g[0] == g[2]) {
        ++st.degenerate_faces;
        continue;
      }
      if (detail::collinear_exact(soup.points[g[0]], soup.points[g[1]], soup.points[g[2]])) {
        ++st.collinear_faces;
        continue;
      }
      if (!seen_triangles.insert(detail::TriKey(g)).second) {
        ++st.duplicate_faces;
        continue;
      }
      soup.triangles.push_back(g);
      soup.tags.push_back(local);
    }
  }
  return soup;
}

// Each surface rebuilt from the repaired triangles carrying its tag, vertices in order of first use.
std::vector<TriangleMesh> rebuild_by_tag(const detail::MeshStageResult& r, std::uint32_t n_tags) {
  std::vector<TriangleMesh> rebuilt(n_tags);
  std::vector<std::uint32_t> local_index(r.points.size(), ~0u);
  std::vector<std::uint32_t> stamp(r.points.size(), ~0u);
  std::vector<std::vector<std::size_t>> by_tag(n_tags);
  for (std::size_t i = 0; i < r.triangles.size(); ++i) by_tag[r.tags[i]].push_back(i);
  for (std::uint32_t tag = 0; tag < n_tags; ++tag) {
    TriangleMesh& out = rebuilt[tag];
    for (std::size_t i : by_tag[tag]) {
      Tri t{};
      for (int c = 0; c < 3; ++c) {
        const std::uint32_t p = r.triangles[i][static_cast<std::size_t>(c)];
        if (stamp[p] != tag) {
          stamp[p] = tag;
          local_index[p] = static_cast<std::uint32_t>(out.vertices.size());
          out.vertices.push_back(r.points[p]);
        }
        t[static_cast<std::size_t>(c)] = local_index[p];
      }
      out.triangles.push_back(t);
    }
  }
  return rebuilt;
}

// Repairs one mesh part; appends one stats entry per surface with triangles.
void repair_part(Model& model, PartId pid, const MeshRepairOptions& options, MeshRepairReport& report) {
  const Part& part = model.parts[pid];
  const std::uint32_t n_tags = part.surface_count;
  std::vector<SurfaceRepairStats> stats(n_tags);
  const detail::TaggedSoup soup = gather_soup(model, part, stats);

  detail::MeshStageResult r;
  if (soup.triangles.empty()) {  // nothing left for CGAL: every surface ends up empty
    r.ok = true;
    r.counts.assign(n_tags, detail::TagCounts{});
  } else {
    r = detail::repair_soup_cgal(soup, n_tags, options);
  }
  if (!r.ok) {
    report.diagnostics.push_back({Severity::Warning, part.source_file, 0, -1,
                                  "part '" + part.name + "' left unrepaired: " + r.error});
    return;
  }

  std::vector<TriangleMesh> rebuilt = rebuild_by_tag(r, n_tags);

  bool part_changed = false;
  for (std::uint32_t local = 0; local < n_tags; ++local) {
    Surface& surface = model.surfaces[part.first_surface + local];
    if (!surface.has_triangles) continue;
    SurfaceRepairStats& st = stats[local];
    const detail::TagCounts& c = r.counts[local];
    st.flipped_faces = c.flipped_faces;
    st.stitched_edges = c.stitched_edges;
    st.duplicated_vertices = c.duplicated_vertices;
    st.removed_component_faces = c.removed_component_faces;
    st.filled_holes = c.filled_holes;
    st.hole_faces = c.hole_faces;
    TriangleMesh& out = rebuilt[local];
    st.vertices_after = static_cast<std::uint32_t>(out.vertices.size());
    st.triangles_after = static_cast<std::uint32_t>(out.triangles.size());
    st.changed = out.vertices != surface.mesh.vertices || out.triangles != surface.mesh.triangles;
    if (st.changed) {
      surface.mesh = std::move(out);
      surface.aabb = mesh_aabb(surface.mesh);
      surface.provenance.repaired = true;
      part_changed = true;
    }
    report.per_surface.push_back(st);
    add_counts(report.total, st);
  }
  if (part_changed) ++report.parts_repaired;
}

}  // namespace

MeshRepairReport repair_meshes(Model& model, const MeshRepairOptions& options) {
  MeshRepairReport report;
  report.total.surface = kInvalidId;
  for (PartId pid = 0; pid < model.parts.size(); ++pid) {
    const Part& part = model.parts[pid];
    assert(part.first_surface + part.surface_count <= model.surfaces.size());
    if (part.source || part.surface_count == 0) continue;
    repair_part(model, pid, options, report);
  }
  std::sort(report.per_surface.begin(), report.per_surface.end(),
            [](const SurfaceRepairStats& a, const SurfaceRepairStats& b) { return a.surface < b.surface; });
  return report;
}

}  // namespace cadclash
