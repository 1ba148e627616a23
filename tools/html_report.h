// The self-contained HTML clash report of `cadclash check --html`.
#pragma once

#include "cadclash/collide.h"

#include <nlohmann/json.hpp>

#include <ostream>
#include <span>
#include <string>

namespace cadclash::cli {

struct HtmlPath;  // html_path.h

// True when this build embeds the viewer (CMake option CADCLASH_HTML_VIEWER, ON by default). The
// viewer is three.js bundled from npm at build time; a build without node can turn it off, and
// then `--html` is a usage error.
bool html_report_available();

// Writes one HTML file that shows `report` over `model` offline: the viewer script, each part's
// triangles once (base64 little-endian Float32 positions and Uint16/Uint32 indices, part-local,
// grouped by surface) with the instance transforms, and the pair table.
// `poses[i]` places instance i (the poses the report was computed with); it must hold one pose
// per instance. `meta` is the JSON report's header: its "files", "settings", "summary" and
// "diagnostics" are shown. Surfaces without triangles (lazy, or failed) are sent empty.
// `path` (a path checked continuously, or null) adds the time slider: the page then places the
// moving instances at the time shown and colours the surfaces the timeline has in contact then.
// Precondition: html_report_available(); every id in `report` and `path` is valid for `model`.
// Returns false when `os` failed.
bool write_html_report(std::ostream& os, const Model& model, std::span<const Pose> poses, const Report& report,
                       const nlohmann::json& meta, const HtmlPath* path = nullptr);

// What `check --html FILE` does after the query: tessellates the surfaces a lazy query never reached
// (the page shows every surface) at their part's load deflection, takes the instance
// poses from `scene` (a trajectory leaves them at its last step), and writes the page to `path`.
// `motion`: as write_html_report's `path`. Prints tessellation failures and write errors to stderr.
// Returns false when `path` was not written.
bool save_html_report(const std::string& path, Model& model, const Scene& scene, const Report& report,
                      const nlohmann::json& meta, const HtmlPath* motion = nullptr);

}  // namespace cadclash::cli
