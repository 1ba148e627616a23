// Dispatch by extension, and the multi-file scene.
#include "readers.h"

#include <algorithm>
#include <cassert>
#include <cctype>
#include <filesystem>
#include <system_error>

namespace cadclash {
namespace detail {

ImportResult failed_import(const std::string& path, std::string message) {
  ImportResult r;
  r.complete = false;
  r.diagnostics.push_back({Severity::Error, path, 0, -1, std::move(message)});
  return r;
}

}  // namespace detail

namespace {

std::string lower_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

}  // namespace

namespace {

ImportResult read_any(const std::string& path, const ImportOptions& options);

}  // namespace

ImportResult import_file(const std::string& path, const ImportOptions& options) {
  assert(options.model_tolerance >= 0.0);
  ImportResult r = read_any(path, options);
  if (options.model_tolerance > 0.0)
    for (Surface& s : r.model.surfaces)
      if (!r.model.parts[s.part].source) s.uncertainty = options.model_tolerance;
  return r;
}

namespace {

ImportResult read_any(const std::string& path, const ImportOptions& options) {
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(status)) return detail::failed_import(path, "no such file");
  if (std::filesystem::is_directory(status)) return detail::failed_import(path, "is a directory, not a file");

  const std::string ext = lower_extension(path);
  if (ext == ".stp" || ext == ".step") return detail::read_step(path, options);
  if (ext == ".igs" || ext == ".iges") return detail::read_iges(path, options);
  if (ext == ".brep" || ext == ".rle") return detail::read_brep(path, options);
  if (ext == ".obj") return detail::read_obj(path, options);
  if (ext == ".off") return detail::read_off(path, options);
  if (ext == ".glb" && detail::is_cadclash_glb(path)) return detail::read_cadclash_glb(path, options);
  return detail::read_assimp_mesh(path, options);
}

}  // namespace

ImportResult import_files(std::span<const std::string> paths, const ImportOptions& options) {
  if (paths.size() == 1) return import_file(paths.front(), options);
  ImportResult all;
  for (const std::string& path : paths) {
    ImportResult one = import_file(path, options);
    std::string prefix = "/";  // built in two steps: GCC 12 warns falsely (-Wrestrict) on "/" + string
    prefix += std::filesystem::path(path).filename().string();
    append_model(all.model, std::move(one.model), prefix);
    all.diagnostics.insert(all.diagnostics.end(), one.diagnostics.begin(), one.diagnostics.end());
    all.complete = all.complete && one.complete;
  }
  return all;
}

}  // namespace cadclash
