// One STEP file's shapes transferred on several processes: the parsed model is shared copy-on-write
// by forked workers, each transfers a share of the file's shape representations, and their shapes
// come back bound to their entities in the reader's transfer process. OCCT's own transfer then
// finds every representation item already made (STEPControl_ActorRead asks IsBound before it
// transfers an item) and only builds the assembly, names and colours. Internal to cadclash::import.
#pragma once

#include "cad_xcaf.h"
#include "isolated_run.h"

#include <Quantity_Color.hxx>
#include <Quantity_ColorRGBA.hxx>
#include <STEPControl_Reader.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS_Compound.hxx>
#include <Transfer_TransientProcess.hxx>
#include <StepData_StepModel.hxx>
#include <XSControl_WorkSession.hxx>

#include <cstddef>
#include <functional>
#include <optional>
#include <string_view>
#include <string>
#include <utility>
#include <vector>

namespace cadclash::detail {

// A styled face's colours, as STEPCAFControl_Reader::ReadColors sets them on the face's label: the
// surface colour (XCAFDoc_ColorSurf), then the boundary's and the curve's (XCAFDoc_ColorCurv).
struct FaceStyle {
  TopoDS_Shape face;
  std::optional<Quantity_ColorRGBA> surface;
  std::optional<Quantity_Color> boundary, curve;
};

// Shapes made in a worker, on their way back: each bound to a key (an entity's number or #id), and
// faces tagged with their entities; as bytes, one compound in OCCT's binary format (shared
// sub-shapes stay shared) and indices into it.
class ShapeBindings {
 public:
  void bind(std::int64_t key, const TopoDS_Shape& shape);
  void tag(const TopoDS_Shape& face, const FaceEntity& entity, bool single);
  void style(const FaceStyle& style);
  // The bytes read_bindings reads; `parse_seconds` is the worker's time for parsing.
  std::string bytes(double parse_seconds = 0.0) const;

 private:
  struct Binding {
    std::int64_t key = 0, shape = 0;
    std::uint64_t orientation = 0;
  };
  struct Tag {
    std::int64_t shape = 0;
    FaceEntity entity;
    bool single = true;
  };
  std::int64_t index_of(const TopoDS_Shape& shape);
  TopoDS_Compound compound_;
  TopTools_IndexedMapOfShape shapes_;  // of compound_'s children in turn (TopExp::MapShapes)
  std::vector<Binding> bindings_;
  std::vector<Tag> tags_;
  std::vector<std::pair<std::int64_t, FaceStyle>> styles_;  // the face's index, the style
};

// Every worker's bytes back, in worker order; false (and why) when a worker crashed, reported a
// failure (empty bytes) or sent incomplete bytes.
struct ReadBindings {
  std::vector<std::pair<std::int64_t, TopoDS_Shape>> shapes;
  std::vector<FaceTag> tags;
  std::vector<FaceStyle> styles;   // the workers' styled faces, in worker and file order
  std::vector<TopoDS_Shape> keep;  // what the tags' TShape pointers point into
  double parse_seconds = 0.0;      // the slowest worker's
};
bool read_bindings(const std::vector<ChildRun>& runs, ReadBindings& out, std::string& why);
// One ShapeBindings' bytes added to `out`; false (and why) when they are a failure or not whole.
bool read_binding_bytes(std::string_view bytes, ReadBindings& out, std::string& why);
// `more` added after what `out` holds: what reading their bytes into `out` after its own gives.
void append_bindings(ReadBindings& out, ReadBindings&& more);
// ShapeBindings' bytes with every key and face entity id replaced by id(it) (ids < 0 kept) and no
// parse time; nullopt when the bytes are not whole or `id` has no answer for one.
std::optional<std::string> renumber_bindings(std::string_view bytes,
                                             const std::function<std::optional<std::int64_t>(std::int64_t)>& id);

// Binds entities[k] to shapes[k].second in `process`; false (nothing bound) when an entity is null,
// repeated or already bound.
bool bind_all(const Handle(Transfer_TransientProcess)& process, const std::vector<Handle(Standard_Transient)>& entities,
              const std::vector<std::pair<std::int64_t, TopoDS_Shape>>& shapes, std::string& why);

// What the parallel transfer did, for the timings and the tests.
struct ParallelTransfer {
  bool used = false;          // the items were made by workers and bound; false: nothing was bound
  std::size_t workers = 0;    // processes that transferred
  std::size_t groups = 0;     // sets of representations that share no topology (the unit of work)
  std::string why_not;        // when not used: why (too small, one group, a worker failed, ...)
};

// Smallest file (bytes) the automatic choice (ImportOptions::transfer_workers == 0) reads on several
// processes: below it the forks and the shapes' round trip cost about what they share.
inline constexpr std::size_t kParallelReadMinBytes = 1 << 20;

// Transfers the shape representations of `model` (parsed, repaired, not yet transferred) on
// `workers` forked processes and binds what they made in the work session's transfer process, so
// that the reader's Transfer that follows makes the same shapes as it would alone. Representations
// that reach a common topological entity (directly or through mapped items) go to one worker, in
// file order. Nothing is bound (and why_not says why) when the file has fewer than two such groups,
// when `workers` < 2, when a non-manifold representation is present, or when any worker crashed,
// reported a failed entity, or bound an entity another worker bound: the reader then transfers
// everything itself, as without this step.
// Preconditions: the calling process has one thread (an isolated reader's child); `ws` holds `model`.
ParallelTransfer transfer_shapes_in_parallel(const Handle(StepData_StepModel)& model,
                                             const Handle(XSControl_WorkSession)& ws, std::size_t workers);

}  // namespace cadclash::detail
