// The surface-tagged model: the small operations every module shares.
#include "cadclash/collide.h"

#include "budget.h"
#include "team_loop.h"

#include <omp.h>

#include <cassert>
#include <map>

namespace cadclash {

std::string format_diagnostic(const Diagnostic& d) {
  // Appended piece by piece: GCC 12 warns falsely (-Wrestrict) on "literal" + std::string.
  std::string out = d.file.empty() ? std::string("<input>") : d.file;
  if (d.line > 0) {
    out += ':';
    out += std::to_string(d.line);
  }
  out += ": ";
  if (d.step_id >= 0) {
    out += '#';
    out += std::to_string(d.step_id);
    out += ": ";
  }
  out += d.severity == Severity::Error ? "error: " : "warning: ";
  out += d.message;
  return out;
}

bool has_error(std::span<const Diagnostic> ds) {
  for (const Diagnostic& d : ds)
    if (d.severity == Severity::Error) return true;
  return false;
}

const char* source_kind_name(SourceKind kind) {
  switch (kind) {
    case SourceKind::StepFace: return "step-face";
    case SourceKind::IgesFace: return "iges-face";
    case SourceKind::BrepFace: return "brep-face";
    case SourceKind::ObjGroup: return "obj-group";
    case SourceKind::OffColourGroup: return "off-colour-group";
    case SourceKind::MeshFile: return "mesh";
    case SourceKind::Segment: return "segment";
  }
  return "unknown";
}

const char* uncertainty_source_name(UncertaintySource source) {
  switch (source) {
    case UncertaintySource::Coordinates: return "coordinates";
    case UncertaintySource::OcctTolerance: return "occt tolerance";
    case UncertaintySource::Declared: return "declared";
    case UncertaintySource::Given: return "given";
  }
  return "unknown";
}

void append_model(Model& into, Model from, const std::string& path_prefix) {
  const auto part_shift = static_cast<PartId>(into.parts.size());
  const auto surface_shift = static_cast<SurfaceId>(into.surfaces.size());
  for (Part& p : from.parts) {
    p.first_surface += surface_shift;
    into.parts.push_back(std::move(p));
  }
  for (Surface& s : from.surfaces) {
    s.part += part_shift;
    if (s.provenance.parent != kInvalidId) s.provenance.parent += surface_shift;
    into.surfaces.push_back(std::move(s));
  }
  for (Instance& i : from.instances) {
    i.part += part_shift;
    if (!path_prefix.empty()) i.path = path_prefix + i.path;
    into.instances.push_back(std::move(i));
  }
}

Aabb mesh_aabb(const TriangleMesh& mesh) {
  Aabb box;
  for (const auto& t : mesh.triangles)
    for (std::uint32_t v : t) box.extend(mesh.vertices[v]);
  return box;
}

std::vector<Diagnostic> require_triangles(Model& model, std::span<const SurfaceId> surfaces,
                                          double deflection, int threads) {
  return detail::require_triangles(model, surfaces, deflection, threads, detail::Deadline());
}

std::vector<Diagnostic> detail::require_triangles(Model& model, std::span<const SurfaceId> surfaces,
                                                  double deflection, int threads, const Deadline& deadline,
                                                  std::vector<SurfaceId>* failed) {
  // Group the missing surfaces by part: a source is thread-safe across parts, not within one.
  std::map<PartId, std::vector<SurfaceId>> by_part;
  for (SurfaceId s : surfaces) {
    assert(s < model.surfaces.size());
    const Surface& surf = model.surfaces[s];
    if (!surf.has_triangles && model.parts[surf.part].source) by_part[surf.part].push_back(s);
  }
  std::vector<std::pair<PartId, std::vector<SurfaceId>>> work(by_part.begin(), by_part.end());
  if (!work.empty()) ++model.revision;
  std::vector<std::vector<Diagnostic>> errors(work.size());
  std::vector<std::vector<SurfaceId>> failed_ids(work.size());

  const auto nwork = static_cast<std::ptrdiff_t>(work.size());
  dynamic_loop(nwork, threads > 0 ? threads : omp_get_max_threads(), true, [&](std::ptrdiff_t w) {
    const auto& [part_id, ids] = work[static_cast<std::size_t>(w)];
    const Part& part = model.parts[part_id];
    for (SurfaceId s : ids) {
      if (deadline.expired()) break;
      Surface& surf = model.surfaces[s];
      TriangleMesh mesh;
      double achieved = 0.0;
      Diagnostic error;
      if (part.source->triangulate(s - part.first_surface, deflection, mesh, achieved, error)) {
        surf.mesh = std::move(mesh);
        surf.deflection = achieved;
        surf.has_triangles = true;
      } else {
        errors[static_cast<std::size_t>(w)].push_back(std::move(error));
        failed_ids[static_cast<std::size_t>(w)].push_back(s);
      }
    }
  });
  std::vector<Diagnostic> out;
  for (auto& e : errors) out.insert(out.end(), e.begin(), e.end());
  if (failed != nullptr)
    for (const auto& f : failed_ids) failed->insert(failed->end(), f.begin(), f.end());
  return out;
}

std::size_t triangle_count(const Model& model) {
  std::size_t n = 0;
  for (const Surface& s : model.surfaces) n += s.mesh.triangles.size();
  return n;
}

}  // namespace cadclash
