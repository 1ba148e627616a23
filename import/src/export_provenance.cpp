// A surface's name and provenance as JSON: the OBJ comment lines and the .glb extras.
#include "mesh_export.h"

#include <array>

namespace cadclash::detail {

nlohmann::json surface_provenance_json(const Surface& s) {
  const Provenance& p = s.provenance;
  nlohmann::json j{{"name", s.name},
                   {"kind", source_kind_name(p.kind)},
                   {"step_id", p.step_id},
                   {"face_index", p.face_index},
                   {"source_name", p.source_name},
                   {"source_file", p.source_file},
                   {"deflection", s.deflection},
                   {"healed", p.healed},
                   {"repaired", p.repaired}};
  if (p.parent != kInvalidId) j["parent"] = p.parent;
  if (p.colour) j["colour"] = *p.colour;
  // B-rep surfaces carry a box around the exact surface, larger than their triangles' box.
  if (!s.aabb.isEmpty())
    j["aabb"] = {s.aabb.min().x(), s.aabb.min().y(), s.aabb.min().z(), s.aabb.max().x(), s.aabb.max().y(), s.aabb.max().z()};
  return j;
}

void surface_provenance_from_json(const nlohmann::json& j, Surface& s) {
  static constexpr std::array kKinds{SourceKind::StepFace,       SourceKind::IgesFace, SourceKind::BrepFace,
                                     SourceKind::ObjGroup,       SourceKind::OffColourGroup,
                                     SourceKind::MeshFile,       SourceKind::Segment};
  Provenance& p = s.provenance;
  s.name = j.at("name").get<std::string>();
  const std::string kind = j.at("kind").get<std::string>();
  bool known = false;
  for (SourceKind k : kKinds)
    if (kind == source_kind_name(k)) p.kind = k, known = true;
  if (!known) throw nlohmann::json::other_error::create(501, "unknown surface kind '" + kind + "'", &j);
  p.step_id = j.at("step_id").get<std::int64_t>();
  p.face_index = j.at("face_index").get<std::int32_t>();
  p.source_name = j.at("source_name").get<std::string>();
  p.source_file = j.at("source_file").get<std::string>();
  s.deflection = j.at("deflection").get<double>();
  p.healed = j.at("healed").get<bool>();
  p.repaired = j.at("repaired").get<bool>();
  p.parent = j.contains("parent") ? j.at("parent").get<SurfaceId>() : kInvalidId;
  if (j.contains("colour")) p.colour = j.at("colour").get<std::array<float, 3>>();
  else p.colour.reset();
  if (j.contains("aabb")) {
    const auto b = j.at("aabb").get<std::array<double, 6>>();
    s.aabb = Aabb(Vec3(b[0], b[1], b[2]), Vec3(b[3], b[4], b[5]));
  } else {
    s.aabb.setEmpty();
  }
}

}  // namespace cadclash::detail
