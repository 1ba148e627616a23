// A surface's name and provenance as JSON: the OBJ comment lines and the .glb extras. The JSON is
// cadclash::report's (provenance_json / provenance_from_json); this keeps the exporters' interface.
#include "mesh_export.h"

#include "cadclash/report.h"

namespace cadclash::detail {

nlohmann::json surface_provenance_json(const Surface& s) { return provenance_json(s); }

void surface_provenance_from_json(const nlohmann::json& j, Surface& s) {
  if (const std::optional<ReportError> e = provenance_from_json(j, s))
    throw nlohmann::json::other_error::create(501, "surface provenance " + format_report_error(*e), &j);
}

}  // namespace cadclash::detail
