// segment_surfaces(): the Model side of segmentation — patch labels from the CGAL stage, then each
// split surface replaced in place by its patches. The CGAL steps live in mesh_repair_cgal.cpp.
#include "mesh_soup_clean.h"

#include <algorithm>
#include <cassert>
#include <unordered_map>

namespace cadclash {
namespace {

using detail::Tri;

// Patch number per triangle of `mesh`, numbered by lowest triangle index. Returns the patch count,
// or 0 with `error` when CGAL could not mesh the surface.
std::uint32_t label_patches(const TriangleMesh& mesh, const SegmentOptions& options, std::vector<std::uint32_t>& label,
                            std::string& error) {
  const std::size_t n = mesh.triangles.size();
  constexpr std::uint32_t kNone = ~0u;
  // Join equal points so a soup (every triangle with its own corners) has adjacency.
  std::vector<Vec3> points;
  detail::PointMerger merger;
  std::vector<std::uint32_t> merged(mesh.vertices.size(), kNone);
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v)
    if (detail::finite_point(mesh.vertices[v])) merged[v] = merger.add(mesh.vertices[v], points);

  std::vector<Tri> clean;
  std::vector<std::size_t> clean_to_input;
  std::vector<std::size_t> twin(n, SIZE_MAX);  // duplicates: the clean triangle they repeat
  std::vector<bool> degenerate(n, false);
  std::unordered_map<detail::TriKey, std::size_t, detail::TriKeyHash> first_of;
  for (std::size_t i = 0; i < n; ++i) {
    const Tri& t = mesh.triangles[i];
    assert(t[0] < mesh.vertices.size() && t[1] < mesh.vertices.size() && t[2] < mesh.vertices.size());
    const Tri g{merged[t[0]], merged[t[1]], merged[t[2]]};
    if (g[0] == kNone || g[1] == kNone || g[2] == kNone || g[0] == g[1] || g[1] == g[2] || g[0] == g[2]) {
      degenerate[i] = true;
      continue;
    }
    auto [it, inserted] = first_of.try_emplace(detail::TriKey(g), clean.size());
    if (!inserted) {
      twin[i] = it->second;
      continue;
    }
    clean.push_back(g);
    clean_to_input.push_back(i);
  }

  std::vector<std::uint32_t> clean_patch;
  if (!detail::segment_soup_cgal(points, clean, options, clean_patch, error)) return 0;

  // Raw labels: clean triangles first, then the loose ones.
  std::vector<std::uint32_t> raw(n, kNone);
  std::uint32_t next_raw = 0;
  for (std::size_t c = 0; c < clean.size(); ++c) {
    raw[clean_to_input[c]] = clean_patch[c];
    next_raw = std::max(next_raw, clean_patch[c] + 1);
  }
  std::vector<std::uint32_t> lowest_clean_at_point(points.size(), kNone);  // lowest clean triangle (input index)
  for (std::size_t c = 0; c < clean.size(); ++c)
    for (std::uint32_t p : clean[c])
      if (lowest_clean_at_point[p] == kNone) lowest_clean_at_point[p] = static_cast<std::uint32_t>(clean_to_input[c]);
  for (std::size_t i = 0; i < n; ++i) {
    if (twin[i] != SIZE_MAX) {
      raw[i] = clean_patch[twin[i]];
    } else if (degenerate[i]) {
      std::uint32_t best = kNone;
      for (std::uint32_t v : mesh.triangles[i])
        if (merged[v] != kNone && lowest_clean_at_point[merged[v]] != kNone)
          best = std::min(best, lowest_clean_at_point[merged[v]]);
      raw[i] = best != kNone ? raw[best] : next_raw++;
    }
  }
  // Renumber by first appearance in input order.
  std::vector<std::uint32_t> renumber(next_raw, kNone);
  std::uint32_t count = 0;
  label.assign(n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    if (renumber[raw[i]] == kNone) renumber[raw[i]] = count++;
    label[i] = renumber[raw[i]];
  }
  return count;
}

// The triangles of `parent` labelled `k`, in input order, with the vertices they use (first use order).
TriangleMesh extract_patch(const TriangleMesh& parent, const std::vector<std::uint32_t>& label, std::uint32_t k) {
  TriangleMesh out;
  std::vector<std::uint32_t> index(parent.vertices.size(), ~0u);
  for (std::size_t i = 0; i < parent.triangles.size(); ++i) {
    if (label[i] != k) continue;
    Tri t{};
    for (std::size_t c = 0; c < 3; ++c) {
      const std::uint32_t v = parent.triangles[i][c];
      if (index[v] == ~0u) {
        index[v] = static_cast<std::uint32_t>(out.vertices.size());
        out.vertices.push_back(parent.vertices[v]);
      }
      t[c] = index[v];
    }
    out.triangles.push_back(t);
  }
  return out;
}

}  // namespace

SegmentReport segment_surfaces(Model& model, const SegmentOptions& options) {
  assert(options.sharp_angle_degrees > 0.0 && options.sharp_angle_degrees < 180.0);
  SegmentReport report;
  const std::size_t n_in = model.surfaces.size();
  std::vector<bool> mesh_surface(n_in, false);
  for (const Part& p : model.parts) {
    assert(p.first_surface + p.surface_count <= n_in);
    if (!p.source)
      for (SurfaceId s = p.first_surface; s < p.first_surface + p.surface_count; ++s) mesh_surface[s] = true;
  }

  std::vector<Surface> out;
  out.reserve(n_in);
  report.surfaces.reserve(n_in);
  for (SurfaceId sid = 0; sid < n_in; ++sid) {
    Surface& parent = model.surfaces[sid];
    SurfaceSegments seg{sid, static_cast<SurfaceId>(out.size()), 1};
    std::vector<std::uint32_t> label;
    std::uint32_t k = 1;
    if (mesh_surface[sid] && parent.has_triangles && parent.mesh.triangles.size() > 1) {
      std::string error;
      k = label_patches(parent.mesh, options, label, error);
      if (k == 0) {
        report.diagnostics.push_back({Severity::Warning, parent.provenance.source_file, 0, parent.provenance.step_id,
                                      "surface '" + parent.name + "' kept whole: " + error});
        k = 1;
      }
    }
    if (k <= 1) {
      out.push_back(std::move(parent));
    } else {
      for (std::uint32_t j = 0; j < k; ++j) {
        Surface patch;
        patch.name = parent.name + "/patch-" + std::to_string(j);
        patch.part = parent.part;
        patch.provenance = parent.provenance;
        patch.provenance.kind = SourceKind::Segment;
        patch.provenance.parent = sid;
        patch.deflection = parent.deflection;
        patch.uncertainty = parent.uncertainty;
        patch.uncertainty_source = parent.uncertainty_source;
        patch.tolerance = parent.tolerance;
        patch.exact_triangles = parent.exact_triangles;
        patch.has_triangles = true;
        patch.mesh = extract_patch(parent.mesh, label, j);
        patch.aabb = mesh_aabb(patch.mesh);
        out.push_back(std::move(patch));
      }
      seg.count = k;
      ++report.surfaces_split;
      report.patches += k;
    }
    report.surfaces.push_back(seg);
  }

  for (Part& p : model.parts) {
    if (p.surface_count == 0) {
      p.first_surface = p.first_surface < n_in ? report.surfaces[p.first_surface].first : static_cast<SurfaceId>(out.size());
      continue;
    }
    const SurfaceSegments& first = report.surfaces[p.first_surface];
    const SurfaceSegments& last = report.surfaces[p.first_surface + p.surface_count - 1];
    p.first_surface = first.first;
    p.surface_count = last.first + last.count - first.first;
  }
  model.surfaces = std::move(out);
  return report;
}

}  // namespace cadclash
