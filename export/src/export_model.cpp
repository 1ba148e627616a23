// export_model(): choose the writer by extension.
#include "writers.h"

#include <algorithm>
#include <cctype>
#include <filesystem>

namespace cadclash {

std::vector<Diagnostic> export_model(const Model& model, const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext == ".obj") return detail::write_obj(model, path);
  if (ext == ".glb") return detail::write_glb(model, path);
  return {{Severity::Error, path, 0, -1, "unknown output format '" + ext + "': use .obj or .glb"}};
}

}  // namespace cadclash
