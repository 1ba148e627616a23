// A CAD file read and transferred, not yet tessellated: what the isolated reader's child process
// hands back to the caller's process as bytes (isolated_run.h), so OCCT's file translators run only
// in the child. Internal to cadclash::import.
#pragma once

#include "cad_xcaf.h"
#include "isolated_run.h"
#include "step_placements.h"

#include <Standard_Failure.hxx>
#include <TopoDS_Shape.hxx>
#include <XSControl_TransferReader.hxx>
#include <XSControl_WorkSession.hxx>

#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace cadclash::detail {

struct Transfer {
  std::vector<Diagnostic> diagnostics;  // everything said so far about the file
  bool complete = true;
  SourceKind kind = SourceKind::StepFace;
  // The length uncertainty the file declares (mm; STEP's UNCERTAINTY_MEASURE_WITH_UNIT, 0 when none):
  // finish_transfer makes it the floor of every face's model uncertainty (OCCT does not apply it).
  double declared_uncertainty = 0.0;
  // Seconds the reader spent parsing the file (ImportTimings::read), measured where it ran.
  double read_seconds = 0.0;
  // Processes that made the shapes (1: the reader alone) and the seconds they took (step_parallel_transfer.h).
  std::size_t parallel_workers = 1;
  double parallel_seconds = 0.0;
  // The text was cut into pieces and a piece's worker failed: nothing else here holds; read_step
  // reads the file again without cutting it.
  bool split_failed = false;
  double split_seconds = 0.0;  // from the start of reading until the pieces' workers started (not sent back)
  // The text cut into this many pieces (0: not cut), of which the import cache held this many.
  std::size_t pieces = 0, pieces_cached = 0;
  PieceCosts piece_costs;  // of a read in pieces (FileImport::piece_costs)
  // Products: an XCAF document (closed by the destructor) and the entities of its faces, as the
  // reader made them; then walked into parts and instances (walk_transfer), which is what a child
  // sends back (the document stays in the child).
  Handle(TDocStd_Document) doc;
  FaceEntityMap faces;
  std::vector<SideColour> side_colours;  // face colours kept beside the document (walk_xcaf_document)
  std::optional<WalkedDocument> walked;
  // STEP products: every occurrence's component and placement (step_placements.h); nullopt when
  // one is placed otherwise, or not STEP.
  std::optional<std::vector<ComponentPlacement>> placements;
  bool unpacked = false;  // brought back from a child process (unpack_transfer)
  // Or loose faces of one part: a compound, the entity #id of each face in TopExp::MapShapes order,
  // and the error that says how many were recovered (none for a .brep's shape, one part by design).
  TopoDS_Shape loose;
  std::vector<std::int64_t> loose_ids;
  std::string loose_note;

  Transfer() = default;
  Transfer(const Transfer&) = delete;
  Transfer& operator=(const Transfer&) = delete;
  Transfer(Transfer&&) = default;
  Transfer& operator=(Transfer&&) = default;
  ~Transfer();

  // Closes the document and forgets the faces: for a transfer that failed or was cut short.
  void discard_shapes();

  // Makes `faces` the loose faces, each tagged with its entity from `entities` (by TShape).
  void set_loose(const TopoDS_Shape& compound, const FaceEntityMap& entities, std::string note);
};

// What a reader's transfer keeps when OCCT threw while reading the `format` file ("STEP", "IGES",
// "BREP"): an error with OCCT's message, and no shapes, since a transfer cut short keeps nothing.
void record_occt_failure(Transfer& t, const std::string& path, const std::string& format, const Standard_Failure& e);

// A new XCAF document that pack_transfer can store. Throws Standard_Failure if OCCT cannot make one.
Handle(TDocStd_Document) new_xcaf_document();

// The products of a file `reader` has read, transferred into a new XCAF document `t.doc`: the step
// the STEP and IGES readers share. Every fail of OCCT's transfer check list (session `ws`) becomes an
// error naming its entity by `label`, as "<format> transfer" (and t.complete = false). Returns the
// transfer process, which tags the faces with their entities (map_face_entities); std::nullopt when
// the transfer failed, with an error saying so and no shapes left in `t`. Throws what OCCT throws.
// CafReader: STEPCAFControl_Reader or IGESCAFControl_Reader.
template <class CafReader>
std::optional<Handle(Transfer_TransientProcess)> transfer_document(CafReader& reader, const Handle(XSControl_WorkSession)& ws,
                                                                   const Handle(Interface_InterfaceModel)& model,
                                                                   const EntityLabelFn& label, const std::string& path,
                                                                   const std::string& format, Transfer& t) {
  t.doc = new_xcaf_document();
  const bool transferred = reader.Transfer(t.doc) == Standard_True;
  const Handle(Transfer_TransientProcess) process =
      ws.IsNull() || ws->TransferReader().IsNull() ? Handle(Transfer_TransientProcess)() : ws->TransferReader()->TransientProcess();
  if (!process.IsNull() &&
      append_checks(process->CheckList(Standard_True), model, label, path, format + " transfer", false, t.diagnostics) > 0)
    t.complete = false;
  if (!transferred) {
    t.diagnostics.push_back({Severity::Error, path, 0, -1, format + " transfer failed; no shape could be made"});
    t.complete = false;
    t.discard_shapes();
    return std::nullopt;
  }
  return process;
}

// The document walked (walk_xcaf_document) into t.walked, when there is one and it was not, with
// its instances placed as the document stored and read back places them when `as_stored` (a
// child's walk: the poses of an isolated read, whatever process walks). What OCCT throws while
// walking is an error and leaves no shapes (record_occt_failure).
void walk_transfer(Transfer& t, const std::string& path, bool as_stored);

// The transfer as bytes (its walked parts in OCCT's binary shape format, plus our tags and
// diagnostics). The parts go each on its own, with the bytes that key them in the cache
// (WalkedPart::packed), unless two of them share a sub-shape, a surface or a curve (then all in one
// compound, as they were), written on up to `threads` threads. Precondition: a document, if any,
// has been walked.
std::string pack_transfer(const Transfer& t, std::size_t threads = 1);

// Back from pack_transfer's bytes; false (and `why`) if they are not whole.
bool unpack_transfer(const std::string& bytes, Transfer& t, std::string& why);

// A transfer made in a child process (run_in_child) and brought back; made here when `isolate` is
// false. When no child could be started or its bytes could not be read back, the transfer is made
// here instead and `warning` says so. The child is stopped after `time_limit_seconds` (> 0; 0 = none).
struct IsolatedTransfer {
  ChildRun child;       // child.crashed: `transfer` is empty
  Transfer transfer;
  std::optional<Diagnostic> warning;
};
IsolatedTransfer transfer_in_child(const std::string& path, bool isolate, double time_limit_seconds,
                                   const std::function<Transfer(const Mark&)>& transfer);

// Tessellates the walked transfer's parts into the model (add_walked_document / add_brep_parts).
ImportResult finish_transfer(Transfer&& t, const std::string& path, const ImportOptions& options);

}  // namespace cadclash::detail
