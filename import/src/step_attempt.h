// One attempt at reading a STEP file, run in the isolated reader's child (isolated_run.h). read_step
// makes attempts until one gives faces: OCCT's translators crash on some malformed entities, and
// each later attempt avoids more of the file. Internal to cadclash::import.
#pragma once

#include "cad_transfer.h"
#include "cad_xcaf.h"
#include "isolated_run.h"
#include "step_split_text.h"

#include <STEPControl_Reader.hxx>
#include <StepData_StepModel.hxx>

#include <cstdint>
#include <set>
#include <string>

namespace cadclash::detail {

// One way through the file. The plain transfer comes first; the others exist because OCCT's
// translators crash on some malformed entities (see read_step).
enum class Attempt {
  Whole,               // every product, as the file says
  WithoutBrokenFaces,  // the same, after taking out the faces and shape items that reach broken entities
  LooseFaces,          // no products: each face entity on its own (recover_loose_faces)
};

// Marks the child reports, so read_step can tell how far a crashed attempt got: the file was
// parsed, shapes were transferred, the transfer made at least one face, and faces were transferred
// one by one (no products).
inline constexpr char kParsed = 'P', kTransferred = 'T', kShapes = 'S', kLoose = 'L';

struct AttemptRun {
  Attempt attempt = Attempt::Whole;
  Mark mark = [](char) {};
  const std::set<std::int64_t>* skip = nullptr;  // LooseFaces: face entities (#id) an earlier child crashed on
  // Whole: processes that read the file at once, for files of at least `parallel_min_bytes`; 1 =
  // this process alone. With `split`, the text is cut into pieces that they parse and transfer
  // (step_split_text.h); else, or when it cannot be cut, they transfer the shapes of the parsed
  // file (step_parallel_transfer.h). Only in an isolated reader's child, which has one thread.
  std::size_t workers = 1;
  std::size_t parallel_min_bytes = 0;
  bool split = true;
  // The import cache's directory (ImportOptions::cache_dir; empty = none): a file of at least
  // `parallel_min_bytes` is cut even for one worker, and pieces the cache holds are not read.
  std::string cache_dir;
  const std::string* text = nullptr;  // the file's bytes, when the caller has read them (read_step)
};

// In a piece's worker: parses `piece` (step_split_text.h), transfers its representations and
// returns the shapes of the ids `piece.bind` names and the tags of every face, as ShapeBindings'
// bytes; "" when anything failed or an id got no shape.
std::string read_step_piece(const std::string& path, const StepPiece& piece);

// Reads and transfers the file one way (`run.attempt`), tessellating nothing.
Transfer read_step_attempt(const std::string& path, const AttemptRun& run);

// When no product can be transferred (a cut-off file loses its product structure, which OCCT
// writes last), every face entity is transferred on its own into one part named after the file.
// Faces that reach an entity the reader could not read whole, or that are in `run.skip`, are left
// out; `why` starts the note that says how many faces were recovered.
void recover_loose_faces(STEPControl_Reader& step, const Handle(StepData_StepModel)& model, const std::string& path,
                         const EntityLabelFn& label, const AttemptRun& run, const std::string& why, Transfer& result);

}  // namespace cadclash::detail
