// cadclash info: what a file holds — parts, instances, surfaces, triangles.
#include "cli_common.h"

#include "cadclash/report.h"

#include <nlohmann/json.hpp>

#include <iostream>
#include <memory>

namespace cadclash::cli {
namespace {

struct InfoOptions {
  InputOptions in;
  bool json = false;
  bool surfaces = false;
  int threads = 0;  // --threads; 0 = every core
};

// The report's surface fields (cadclash/report.h), the name, the triangle count and the repair flags.
nlohmann::json info_surface_json(const Surface& s) {
  nlohmann::json j = surface_json(s);
  j["name"] = s.name;
  j["triangles"] = s.mesh.triangles.size();
  if (s.provenance.healed) j["healed"] = true;
  if (s.provenance.repaired) j["repaired"] = true;
  return j;
}

// What --repair changed in one surface: its non-zero counts.
nlohmann::json repair_json(const SurfaceRepairStats& s) {
  nlohmann::json j = nlohmann::json::object();
  auto put = [&](const char* key, std::uint32_t n) {
    if (n) j[key] = n;
  };
  put("merged_points", s.merged_points);
  put("unused_points", s.unused_points);
  put("degenerate_faces", s.degenerate_faces);
  put("duplicate_faces", s.duplicate_faces);
  put("flipped_faces", s.flipped_faces);
  put("stitched_edges", s.stitched_edges);
  put("duplicated_vertices", s.duplicated_vertices);
  put("removed_component_faces", s.removed_component_faces);
  put("filled_holes", s.filled_holes);
  put("hole_faces", s.hole_faces);
  return j;
}

// Repair counts of each final surface (null when repair did not look at it). Repair ran before
// segmentation, so a patch shows the counts of the surface it was cut from.
std::vector<const SurfaceRepairStats*> repair_per_final_surface(const Model& m, const MeshRepairReport& repair,
                                                                 const SegmentReport& segment) {
  std::vector<const SurfaceRepairStats*> out(m.surfaces.size(), nullptr);
  for (const SurfaceRepairStats& s : repair.per_surface) {
    if (segment.surfaces.empty()) {
      if (s.surface < out.size()) out[s.surface] = &s;
      continue;
    }
    const SurfaceSegments& seg = segment.surfaces[s.surface];
    for (SurfaceId f = seg.first; f < seg.first + seg.count; ++f) out[f] = &s;
  }
  return out;
}

int run_info(const InfoOptions& o) {
  MeshRepairReport repair;
  SegmentReport segment;
  ImportResult r = import_inputs(o.in, &repair, &segment);
  const Model& m = r.model;
  const std::vector<const SurfaceRepairStats*> repaired = repair_per_final_surface(m, repair, segment);
  if (o.json) {
    nlohmann::json j;
    j["files"] = o.in.files;
    j["complete"] = r.complete;
    for (const Part& p : m.parts) {
      nlohmann::json jp{{"name", p.name}, {"source_file", p.source_file}, {"surfaces", nlohmann::json::array()}};
      for (SurfaceId s = p.first_surface; s < p.first_surface + p.surface_count; ++s) {
        jp["surfaces"].push_back(info_surface_json(m.surfaces[s]));
        if (repaired[s] && repaired[s]->changed) jp["surfaces"].back()["repair"] = repair_json(*repaired[s]);
      }
      j["parts"].push_back(jp);
    }
    if (o.in.repair) j["repair"] = repair_json(repair.total);
    if (o.in.segment) j["segment"] = {{"surfaces_split", segment.surfaces_split}, {"patches", segment.patches}};
    for (const Instance& i : m.instances) j["instances"].push_back({{"path", i.path}, {"part", i.part}});
    for (const Diagnostic& d : r.diagnostics) j["diagnostics"].push_back(format_diagnostic(d));
    std::cout << report_text(j);  // as the check report: invalid UTF-8 in file text replaced
  } else {
    std::size_t instance_faces = 0;
    for (const Instance& i : m.instances) instance_faces += m.parts[i.part].surface_count;
    std::cout << m.parts.size() << " parts, " << m.instances.size() << " instances, " << m.surfaces.size()
              << " surfaces (" << instance_faces << " over instances), " << triangle_count(m) << " triangles\n";
    if (o.in.repair) {
      std::size_t changed = 0;
      for (const SurfaceRepairStats& st : repair.per_surface) changed += st.changed ? 1 : 0;
      std::cout << "repair: " << changed << " of " << repair.per_surface.size() << " mesh surfaces changed";
      const nlohmann::json counts = repair_json(repair.total);  // outlives the loop, unlike a temporary
      for (const auto& [key, n] : counts.items()) std::cout << ' ' << key << '=' << n;
      std::cout << '\n';
    }
    if (o.in.segment)
      std::cout << "segment: " << segment.surfaces_split << " surfaces split into " << segment.patches << " patches\n";
    std::cout << "\nInstances:\n";
    for (const Instance& i : m.instances) {
      const Part& p = m.parts[i.part];
      std::cout << "  " << i.path << "  part '" << p.name << "'  " << p.surface_count << " surfaces\n";
    }
    std::cout << "\nParts:\n";
    for (PartId pid = 0; pid < m.parts.size(); ++pid) {
      const Part& p = m.parts[pid];
      std::size_t tris = 0;
      for (SurfaceId s = p.first_surface; s < p.first_surface + p.surface_count; ++s) tris += m.surfaces[s].mesh.triangles.size();
      std::cout << "  [" << pid << "] " << p.name << "  " << p.surface_count << " surfaces, " << tris << " triangles  ("
                << p.source_file << ")\n";
      if (!o.surfaces) continue;
      for (SurfaceId s = p.first_surface; s < p.first_surface + p.surface_count; ++s) {
        const Surface& surf = m.surfaces[s];
        std::cout << "      " << surf.name << "  " << source_kind_name(surf.provenance.kind);
        if (surf.provenance.step_id >= 0) std::cout << " #" << surf.provenance.step_id;
        std::cout << "  " << surf.mesh.triangles.size() << " triangles";
        if (surf.deflection > 0) std::cout << ", deflection " << surf.deflection;
        if (surf.provenance.healed) std::cout << ", healed";
        if (surf.provenance.repaired) std::cout << ", repaired";
        if (repaired[s] && repaired[s]->changed) {
          const nlohmann::json counts = repair_json(*repaired[s]);
          for (const auto& [key, n] : counts.items()) std::cout << ' ' << key << '=' << n;
        }
        std::cout << '\n';
      }
    }
    if (!r.complete) std::cout << "\nINCOMPLETE: some input was dropped; see the messages above.\n";
  }
  return has_error(r.diagnostics) ? kExitInputError : kExitOk;
}

}  // namespace

void register_info(CLI::App& app) {
  auto o = std::make_shared<InfoOptions>();
  CLI::App* cmd = app.add_subcommand("info", "List parts, instances, surfaces and triangle counts");
  add_input_options(*cmd, o->in);
  add_threads_option(*cmd, o->threads, "files read at once and meshing");
  cmd->add_flag("--json", o->json, "Print JSON instead of text");
  cmd->add_flag("--surfaces", o->surfaces, "List every surface of every part");
  cmd->callback([o] {
    hold_threads(o->threads);
    if (int code = run_info(*o); code != kExitOk) throw CLI::RuntimeError(code);
  });
}

}  // namespace cadclash::cli
