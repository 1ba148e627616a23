// Import + tessellation time of a STEP file at three deflections, next to OCCT's own reading and
// BRepMesh_IncrementalMesh on the same shapes in the same run. Not a test: it prints numbers.
//   tessellate_timing [file.stp] [repeats]     (default data/external/as1-tu-203.stp, 3 repeats; best of the repeats)
#include "cadclash/import.h"

#include <BRepMesh_IncrementalMesh.hxx>
#include <BRepTools.hxx>
#include <IMeshTools_Parameters.hxx>
#include <STEPControl_Reader.hxx>
#include <TopoDS_Shape.hxx>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>

namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

int main(int argc, char** argv) {
  const std::string path = argc > 1 ? argv[1] : std::string(CADCLASH_DATA_DIR) + "/external/as1-tu-203.stp";
  const int repeats = argc > 2 ? std::max(1, std::atoi(argv[2])) : 3;
  std::printf("%s, best of %d\n", path.c_str(), repeats);
  std::printf("%-10s %14s %14s %14s %14s %14s %12s\n", "deflection", "cadclash [s]", "no-verify [s]", "occt read [s]",
              "occt mesh [s]", "occt total [s]", "triangles");
  for (double deflection : {0.1, 0.01, 0.001}) {
    double ours = 1e300, ours_plain = 1e300, read = 1e300, mesh = 1e300;
    std::size_t triangles = 0;
    for (int r = 0; r < repeats; ++r) {
      cadclash::ImportOptions o;
      o.tessellation.linear_deflection = deflection;
      auto t0 = std::chrono::steady_clock::now();
      const cadclash::ImportResult result = cadclash::import_file(path, o);
      ours = std::min(ours, seconds_since(t0));
      triangles = cadclash::triangle_count(result.model);

      o.tessellation.verify_deflection = false;
      t0 = std::chrono::steady_clock::now();
      const cadclash::ImportResult plain = cadclash::import_file(path, o);
      ours_plain = std::min(ours_plain, seconds_since(t0));

      t0 = std::chrono::steady_clock::now();
      STEPControl_Reader reader;
      if (reader.ReadFile(path.c_str()) != IFSelect_RetDone) {
        std::fprintf(stderr, "OCCT cannot read %s\n", path.c_str());
        return 1;
      }
      reader.TransferRoots();
      const TopoDS_Shape shape = reader.OneShape();
      read = std::min(read, seconds_since(t0));
      IMeshTools_Parameters params;
      params.Deflection = deflection;
      params.Angle = o.tessellation.angular_deflection;
      params.InParallel = Standard_True;
      t0 = std::chrono::steady_clock::now();
      BRepMesh_IncrementalMesh mesher(shape, params);
      mesh = std::min(mesh, seconds_since(t0));
    }
    std::printf("%-10g %14.3f %14.3f %14.3f %14.3f %14.3f %12zu\n", deflection, ours, ours_plain, read, mesh, read + mesh,
                triangles);
  }
  return 0;
}
