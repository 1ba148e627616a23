// OCCT's native .brep through BRepTools::Read: one part named after the file, one instance.
#include "cad_xcaf.h"
#include "isolated_run.h"
#include "readers.h"

#include <BRepTools.hxx>
#include <BRep_Builder.hxx>
#include <Standard_Failure.hxx>
#include <TopoDS_Shape.hxx>

#include <fstream>
#include <string>

namespace cadclash::detail {
namespace {

// BRepTools::Read prints "File was not written with this version of the topology" to stdout (which
// would corrupt `info --json`) when it finds no topology header, so look for that header first.
bool has_topology_header(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string head(64 * 1024, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(in.gcount()));
  return head.find("CASCADE Topology V") != std::string::npos;
}

// `probe`: stop after reading the shape (see read_isolated).
ImportResult read_brep_once(const std::string& path, const ImportOptions& options, bool probe) {
  ImportResult result;
  try {
    if (!has_topology_header(path))
      return failed_import(path, "not an OCCT .brep: no 'CASCADE Topology' header in its first 64 KB");
    TopoDS_Shape shape;
    BRep_Builder builder;
    if (!BRepTools::Read(shape, path.c_str(), builder) || shape.IsNull())
      return failed_import(path, "cannot read BREP file (not an OCCT .brep, or damaged)");
    // Triangulations stored in the file were made with unknown settings; ours follow the options.
    BRepTools::Clean(shape, Standard_True);
    if (probe) return result;
    BrepPartInput in;
    in.shape = &shape;
    in.name = cad_file_stem(path);
    in.source_file = path;
    in.kind = SourceKind::BrepFace;
    const std::vector<PartId> ids = add_brep_parts(result.model, std::span<const BrepPartInput>(&in, 1), options.tessellation,
                                                   options.lazy, result.diagnostics, result.complete);
    if (result.model.parts[ids[0]].surface_count == 0)
      result.diagnostics.push_back({Severity::Warning, path, 0, -1, "the shape has no faces"});
    Instance instance;
    instance.path = "/" + in.name;
    instance.part = ids[0];
    result.model.instances.push_back(std::move(instance));
  } catch (const Standard_Failure& e) {
    return failed_import(path, std::string("OCCT failed while reading BREP: ") + e.GetMessageString());
  }
  return result;
}

}  // namespace

ImportResult read_brep(const std::string& path, const ImportOptions& options) {
  prepare_occt_exchange();
  return read_isolated(path, "BREP", options, [&](bool probe) { return read_brep_once(path, options, probe); });
}

}  // namespace cadclash::detail
