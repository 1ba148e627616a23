// OBJ export: one `g` per surface and instance, in world coordinates.
//
// Each instance's copy of each surface is written placed, so any OBJ viewer shows the assembly as
// it stands. The group name is "<instance path>/<surface name>" (unique, since instance paths are;
// whitespace becomes '_', as a group name is one word), and the comment line before it,
// "# cadclash-surface {json}", gives the exact names, ids and provenance. Coordinates are written in
// the shortest form that reads back to the same double, so a re-import is exact.
#include "writers.h"

#include "cadclash/report.h"

#include <charconv>
#include <fstream>

namespace cadclash::detail {
namespace {

void append_double(std::string& out, double v) {
  char buf[32];
  const auto [ptr, ec] = std::to_chars(buf, buf + sizeof buf, v == 0.0 ? 0.0 : v);  // no "-0"
  (void)ec;
  out.append(buf, ptr);
}

std::string one_word(std::string s) {
  for (char& c : s)
    if (c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f' || c == '#') c = '_';
  return s;
}

}  // namespace

std::vector<Diagnostic> write_obj(const Model& model, const std::string& path) {
  std::vector<Diagnostic> diags;
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) return {{Severity::Error, path, 0, -1, "cannot open the file for writing"}};

  std::string text =
      "# cadclash 0.1.0 surface-tagged OBJ, millimetres, world coordinates\n"
      "# g <instance path>/<surface name>; the comment before each group holds its ids and provenance\n";
  std::size_t vertex_base = 1, groups = 0;
  std::vector<bool> skipped(model.surfaces.size(), false);
  for (InstanceId iid = 0; iid < model.instances.size(); ++iid) {
    const Instance& instance = model.instances[iid];
    const Part& part = model.parts[instance.part];
    for (SurfaceId sid = part.first_surface; sid < part.first_surface + part.surface_count; ++sid) {
      const Surface& s = model.surfaces[sid];
      if (!s.has_triangles || s.mesh.triangles.empty()) {
        skipped[sid] = true;
        continue;
      }
      nlohmann::json j = provenance_json(s);
      j["instance"] = instance.path;
      j["instance_id"] = iid;
      j["part"] = part.name;
      j["part_id"] = instance.part;
      j["surface_id"] = sid;
      text += "# cadclash-surface " + j.dump() + "\ng " + one_word(instance.path + "/" + s.name) + '\n';
      for (const Vec3& local : s.mesh.vertices) {
        const Vec3 p = instance.pose * local;
        text += "v ";
        append_double(text, p.x());
        text += ' ';
        append_double(text, p.y());
        text += ' ';
        append_double(text, p.z());
        text += '\n';
      }
      for (const auto& t : s.mesh.triangles)
        text += "f " + std::to_string(vertex_base + t[0]) + ' ' + std::to_string(vertex_base + t[1]) + ' ' +
                std::to_string(vertex_base + t[2]) + '\n';
      vertex_base += s.mesh.vertices.size();
      ++groups;
      if (text.size() > (1u << 22)) {
        out.write(text.data(), static_cast<std::streamsize>(text.size()));
        text.clear();
      }
    }
  }
  out.write(text.data(), static_cast<std::streamsize>(text.size()));
  out.close();
  if (!out) return {{Severity::Error, path, 0, -1, "write error"}};
  for (SurfaceId sid = 0; sid < skipped.size(); ++sid)
    if (skipped[sid])
      diags.push_back({Severity::Warning, path, 0, -1,
                       "surface " + std::to_string(sid) + " '" + model.surfaces[sid].name + "' has no triangles; not written"});
  std::vector<bool> placed(model.parts.size(), false);
  for (const Instance& i : model.instances) placed[i.part] = true;
  for (PartId pid = 0; pid < model.parts.size(); ++pid)
    if (!placed[pid] && model.parts[pid].surface_count > 0)
      diags.push_back({Severity::Warning, path, 0, -1,
                       "part " + std::to_string(pid) + " '" + model.parts[pid].name + "' has no instance; not written"});
  if (groups == 0) diags.push_back({Severity::Error, path, 0, -1, "nothing to write: no instance places a surface with triangles"});
  return diags;
}

}  // namespace cadclash::detail
