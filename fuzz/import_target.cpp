#include "import_target.h"
#include "valid_utf8.h"

#include "cadclash/import.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <string_view>
#include <unistd.h>

namespace cadclash::fuzz {
namespace {

[[noreturn]] void fail(const std::string& what) {
  std::fprintf(stderr, "fuzz: contract broken: %s\n", what.c_str());
  std::fflush(stderr);
  std::abort();
}

// One scratch file per process (libFuzzer's -jobs run several processes), removed at exit.
std::string scratch_path(const char* extension) {
  const char* dir = std::getenv("TMPDIR");
  std::string path = std::string(dir && *dir ? dir : "/tmp") + "/cadclash-fuzz-" + std::to_string(::getpid()) + extension;
  static std::string registered;
  if (registered.empty()) {
    registered = path;
    std::atexit([] { std::remove(registered.c_str()); });
  }
  return path;
}

}  // namespace

void import_bytes(const std::uint8_t* data, std::size_t size, const char* extension) {
  const std::string path = scratch_path(extension);
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
    if (!out) fail("cannot write the scratch file " + path);
  }
  ImportOptions options;
  // Coarse and serial: the target is our reader code, not BRepMesh's effort or its thread pool.
  options.tessellation = tessellation_preset(TessellationPreset::Coarse);
  options.tessellation.parallel = false;
  ImportResult result;
  try {
    result = import_file(path, options);
  } catch (const std::exception& e) {
    fail(std::string("import_file threw: ") + e.what());
  } catch (...) {
    fail("import_file threw a non-standard exception");
  }

  for (const Surface& s : result.model.surfaces) {
    for (const Vec3& v : s.mesh.vertices)
      if (!std::isfinite(v.x()) || !std::isfinite(v.y()) || !std::isfinite(v.z()))
        fail("surface '" + s.name + "' has a vertex that is not finite");
    for (const auto& t : s.mesh.triangles)
      for (std::uint32_t v : t)
        if (v >= s.mesh.vertices.size()) fail("surface '" + s.name + "' has a triangle index out of range");
  }
  if (result.model.surfaces.empty() && !has_error(result.diagnostics))
    fail("an empty model without an error diagnostic");
  for (const Diagnostic& d : result.diagnostics) {
    if (d.file != path) fail("a diagnostic names '" + d.file + "' instead of the file read");
    if (d.message.empty()) fail("an empty diagnostic message");
    if (!valid_utf8(d.message)) fail("a diagnostic message is not valid UTF-8: " + format_diagnostic(d));
  }
}

}  // namespace cadclash::fuzz
