// The parts of CAD import shared by the STEP, IGES and BREP readers: walking an XCAF document into
// parts and instances, face tags from the transfer process, OCCT check lists as diagnostics.
// Internal to cadclash::import.
#pragma once

#include "cadclash/import.h"
#include "cadclash/tessellate.h"

#include <Interface_CheckIterator.hxx>
#include <Interface_InterfaceModel.hxx>
#include <TDocStd_Document.hxx>
#include <TopoDS_Shape.hxx>
#include <gp_Trsf.hxx>
#include <Transfer_TransientProcess.hxx>

#include <array>
#include <functional>
#include <string>
#include <unordered_map>
#include <vector>

namespace cadclash::detail {

// What the file says about one face entity.
struct FaceEntity {
  std::int64_t id = -1;  // STEP #id / IGES directory entry number
  std::string name;
};

// Face TShape → its entity, built once per file from every mapped entity of the transfer process.
using FaceEntityMap = std::unordered_map<const void*, FaceEntity>;

// Maps entity → (id, name) for an entity that is a face of the format; returns false to skip it.
using FaceEntityFn = std::function<bool(const Handle(Standard_Transient)&, FaceEntity&)>;

// A face's entity found elsewhere (another process's transfer): `single` when the entity's result
// was that face alone, else it held several faces.
struct FaceTag {
  const void* tshape = nullptr;
  FaceEntity entity;
  bool single = true;
};

// `extra` tags join the process's own: single-face results claim faces first, then the others.
FaceEntityMap map_face_entities(const Handle(Transfer_TransientProcess)& process, const FaceEntityFn& describe,
                                const std::vector<FaceTag>& extra = {});

// The label number of an entity as the file writes it (#N for STEP, DE number for IGES); -1 if none.
using EntityLabelFn = std::function<std::int64_t(const Handle(Standard_Transient)&)>;

// Appends one diagnostic per fail (as Error) and, when `warnings`, per warning of `checks`, naming the
// entity by `label`. At most `limit` are appended; a final line counts the rest. Returns the number of fails.
std::size_t append_checks(const Interface_CheckIterator& checks, const Handle(Interface_InterfaceModel)& model,
                          const EntityLabelFn& label, const std::string& file, const std::string& what,
                          bool warnings, std::vector<Diagnostic>& out, std::size_t limit = 40);

// `side`: colours of faces the document would hold as sub-shape colours of a part, kept beside it
// (a STEP piece's styled faces, step_attempt.cpp): they come first, as the most specific.
struct SideColour {
  std::string part;   // the part's label entry ("0:1:1:5")
  TopoDS_Shape face;  // a face of the part's shape
  std::array<float, 3> rgb{};  // sRGB, as the document's surface colour reads
};

// One distinct leaf shape of a walked document: a part before it is checked, healed and tessellated.
struct WalkedPart {
  std::string name;
  std::vector<BrepFaceTag> tags;  // per face, in TopExp::MapShapes order
  TopoDS_Shape shape;             // null when the part has none (`dropped`), or until made from `packed`
  // The shape as BinTools writes it without triangles (what a part's cache key hashes), when a
  // reader's child sent each part on its own (cad_transfer.cpp); empty otherwise.
  std::string packed;
  bool dropped = false;  // no shape: said in the walk's diagnostics, its instances left out
};

// A document walked into its parts and instances: what a reader's child sends back instead of the
// document (cad_transfer.h).
struct WalkedDocument {
  std::vector<Diagnostic> diagnostics;  // the walk's, in the order it says them
  bool complete = true;
  std::vector<WalkedPart> parts;                 // in the walk's order
  std::vector<Instance> instances;               // part: an index into `parts`
  std::vector<std::vector<std::string>> chains;  // per instance: the component label entries from the root down to it
};

// Walks the document's free shapes: one instance per leaf occurrence with its full path and
// placement, one part per distinct leaf shape (shared by all its instances), each face tagged from
// `faces` (by TShape) and the document's colours (`side`'s first). With `stored_locations`, the
// instances are placed as they would be in the document stored in OCCT's binary format and read
// back (each placement's transformation made again from its twelve values), as a reader's child
// places them (cad_transfer.h), so that they do not depend on where the walk ran. Throws what OCCT
// throws.
WalkedDocument walk_xcaf_document(const Handle(TDocStd_Document)& doc, const std::string& file, SourceKind kind,
                                  const FaceEntityMap& faces, const std::vector<SideColour>& side, bool stored_locations);

// The walked parts checked, healed and tessellated as the options say (through the import cache
// when it has one) into `result`, with the walk's diagnostics and the instances of every part kept.
// `timings`, when given, gets add_brep_parts' seconds added; `chains`, when given, gets the chain
// of every instance kept, in order.
void add_walked_document(WalkedDocument&& walked, const std::string& file, SourceKind kind, const ImportOptions& options,
                         ImportResult& result, BrepPartTimings* timings = nullptr,
                         std::vector<std::vector<std::string>>* chains = nullptr);

// An instance's pose from its location's transformation, as walk_xcaf_document makes it (the scale
// divided out of the rotation part: the walk warns about a scale).
Pose pose_of_transformation(const gp_Trsf& trsf);

// The file's stem ("dir/part.brep" → "part").
std::string cad_file_stem(const std::string& path);

// Silences OCCT's default message printers: library code never prints, and every OCCT message that
// matters reaches the caller through the check lists. Installs the shape processing that
// TransferHealing switches. Idempotent; call before reading.
void prepare_occt_exchange();

// While one lives, STEP and IGES transfers on this thread (and in processes forked from it) run
// OCCT's shape healing or not (ImportOptions::transfer_healing); the previous setting comes back
// when it ends. Without one: healing, as OCCT does.
class TransferHealing {
 public:
  explicit TransferHealing(bool on);
  ~TransferHealing();
  TransferHealing(const TransferHealing&) = delete;
  TransferHealing& operator=(const TransferHealing&) = delete;

 private:
  bool before_;
};

// This thread's setting (TransferHealing).
bool transfer_healing_on();

}  // namespace cadclash::detail
