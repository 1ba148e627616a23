// cadclash info: what a file holds — parts, instances, surfaces, triangles.
#include "cli_common.h"

#include <nlohmann/json.hpp>

#include <iostream>
#include <memory>

namespace cadclash::cli {
namespace {

struct InfoOptions {
  InputOptions in;
  bool json = false;
  bool surfaces = false;
};

nlohmann::json surface_json(const Surface& s) {
  nlohmann::json j{{"name", s.name},
                   {"kind", source_kind_name(s.provenance.kind)},
                   {"face_index", s.provenance.face_index},
                   {"triangles", s.mesh.triangles.size()},
                   {"deflection", s.deflection}};
  if (s.provenance.step_id >= 0) j["step_id"] = s.provenance.step_id;
  if (!s.provenance.source_name.empty()) j["source_name"] = s.provenance.source_name;
  if (s.provenance.healed) j["healed"] = true;
  if (s.provenance.repaired) j["repaired"] = true;
  return j;
}

int run_info(const InfoOptions& o) {
  ImportResult r = import_inputs(o.in);
  const Model& m = r.model;
  if (o.json) {
    nlohmann::json j;
    j["files"] = o.in.files;
    j["complete"] = r.complete;
    for (const Part& p : m.parts) {
      nlohmann::json jp{{"name", p.name}, {"source_file", p.source_file}, {"surfaces", nlohmann::json::array()}};
      for (SurfaceId s = p.first_surface; s < p.first_surface + p.surface_count; ++s)
        jp["surfaces"].push_back(surface_json(m.surfaces[s]));
      j["parts"].push_back(jp);
    }
    for (const Instance& i : m.instances) j["instances"].push_back({{"path", i.path}, {"part", i.part}});
    for (const Diagnostic& d : r.diagnostics) j["diagnostics"].push_back(format_diagnostic(d));
    std::cout << j.dump(2) << '\n';
  } else {
    std::size_t instance_faces = 0;
    for (const Instance& i : m.instances) instance_faces += m.parts[i.part].surface_count;
    std::cout << m.parts.size() << " parts, " << m.instances.size() << " instances, " << m.surfaces.size()
              << " surfaces (" << instance_faces << " over instances), " << triangle_count(m) << " triangles\n";
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
  cmd->add_flag("--json", o->json, "Print JSON instead of text");
  cmd->add_flag("--surfaces", o->surfaces, "List every surface of every part");
  cmd->callback([o] {
    if (int code = run_info(*o); code != kExitOk) throw CLI::RuntimeError(code);
  });
}

}  // namespace cadclash::cli
