// OCCT's native .brep through BRepTools::Read: one part named after the file, one instance.
#include "cad_transfer.h"
#include "isolated_run.h"
#include "readers.h"

#include <BRepTools.hxx>
#include <BRep_Builder.hxx>
#include <Standard_Failure.hxx>
#include <TopoDS_Shape.hxx>

#include <chrono>
#include <fstream>
#include <optional>
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

// The shape as a loose part (no entity ids, no note: a .brep is one part by design). Runs in the
// isolated reader's child.
Transfer read_brep_shape(const std::string& path) {
  Transfer t;
  t.kind = SourceKind::BrepFace;
  auto fail = [&](std::string message) {
    t.diagnostics.push_back({Severity::Error, path, 0, -1, std::move(message)});
    t.complete = false;
    return std::move(t);
  };
  try {
    if (!has_topology_header(path)) return fail("not an OCCT .brep: no 'CASCADE Topology' header in its first 64 KB");
    TopoDS_Shape shape;
    BRep_Builder builder;
    const auto read_start = std::chrono::steady_clock::now();
    const bool read = BRepTools::Read(shape, path.c_str(), builder);
    t.read_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - read_start).count();
    if (!read || shape.IsNull())
      return fail("cannot read BREP file (not an OCCT .brep, or damaged)");
    // Triangulations stored in the file were made with unknown settings; ours follow the options.
    BRepTools::Clean(shape, Standard_True);
    t.loose = shape;
  } catch (const Standard_Failure& e) {
    record_occt_failure(t, path, "BREP", e);
  }
  return t;
}

}  // namespace

// Read in the isolated reader's child, which sends the shape back in OCCT's binary format
// (cad_transfer.h): this process never parses the file.
ImportResult read_brep(const std::string& path, const ImportOptions& options) {
  prepare_occt_exchange();
  const ReaderClock clock(options.reader_time_limit_seconds);
  std::optional<Diagnostic> unapplied = unapplied_time_limit(path, options);
  IsolatedTransfer run = transfer_in_child(path, options.isolate_cad_readers, clock.left(),
                                           [&](const Mark&) { return read_brep_shape(path); });
  ImportResult result;
  if (run.child.timed_out) {
    result = failed_import(path, clock.stopped_message("reading the file", -1));
  } else if (run.child.crashed) {
    result = failed_import(path, "OCCT crashed with " + run.child.how +
                                     " while reading the BREP file (in an isolated reader); nothing could be read");
  } else {
    const bool shape = !run.transfer.loose.IsNull();
    result = finish_transfer(std::move(run.transfer), path, options);
    if (shape && result.model.parts.size() == 1 && result.model.parts[0].surface_count == 0)
      result.diagnostics.push_back({Severity::Warning, path, 0, -1, "the shape has no faces"});
  }
  if (run.warning) result.diagnostics.insert(result.diagnostics.begin(), *run.warning);
  if (unapplied) result.diagnostics.insert(result.diagnostics.begin(), *unapplied);
  return result;
}

}  // namespace cadclash::detail
