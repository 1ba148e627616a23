// STEP face entities transferred one by one into loose faces of one part (recover_loose_faces), and
// the fault injection the isolated reader's tests place there.
#include "readers.h"
#include "step_attempt.h"
#include "step_model_repairs.h"

#include <BRep_Builder.hxx>
#include <Interface_Graph.hxx>
#include <Standard_Failure.hxx>
#include <StepShape_Face.hxx>
#include <TopExp.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS_Compound.hxx>
#include <XSControl_TransferReader.hxx>
#include <XSControl_WorkSession.hxx>

#include <atomic>
#include <csignal>

#include <unistd.h>

namespace cadclash::detail {
namespace {

std::atomic<std::int64_t> crash_injected_at{-1};  // see set_step_crash_injection_for_testing
std::atomic<std::int64_t> hang_injected_at{-1};   // see set_step_hang_injection_for_testing

}  // namespace

void set_step_crash_injection_for_testing(std::int64_t face_id) { crash_injected_at.store(face_id, std::memory_order_relaxed); }
void set_step_hang_injection_for_testing(std::int64_t face_id) { hang_injected_at.store(face_id, std::memory_order_relaxed); }

void recover_loose_faces(STEPControl_Reader& step, const Handle(StepData_StepModel)& model, const std::string& path,
                         const EntityLabelFn& label, const AttemptRun& run, const std::string& why, Transfer& result) {
  TopoDS_Compound faces;
  BRep_Builder builder;
  builder.MakeCompound(faces);
  std::size_t tried = 0, made = 0;
  run.mark(kLoose);
  const Interface_Graph graph(model);
  for (Standard_Integer i = 1; i <= model->NbEntities(); ++i) {
    const Handle(Standard_Transient) entity = model->Value(i);
    if (entity.IsNull() || !entity->IsKind(STANDARD_TYPE(StepShape_Face))) continue;
    ++tried;
    if (const Standard_Integer broken = first_broken_reference(graph, model, entity); broken > 0) {
      const bool itself = model->Value(broken) == entity;
      result.diagnostics.push_back(
          {Severity::Error, path, 0, label(entity),
           itself ? std::string("face entity could not be read whole; dropped")
                  : "face entity refers to #" + std::to_string(label(model->Value(broken))) +
                        ", which could not be read whole; dropped"});
      continue;
    }
    if (run.skip != nullptr && run.skip->count(label(entity))) continue;  // read_step names it
    mark_entity_begin(run.mark, label(entity));
    if (label(entity) == crash_injected_at.load(std::memory_order_relaxed)) std::raise(SIGSEGV);
    if (label(entity) == hang_injected_at.load(std::memory_order_relaxed))
      for (;;) pause();  // only a signal ends it: the time limit's SIGKILL
    try {
      step.ClearShapes();
      if (step.TransferEntity(entity) && step.NbShapes() > 0) {
        TopTools_IndexedMapOfShape map;
        TopExp::MapShapes(step.Shape(1), TopAbs_FACE, map);
        for (Standard_Integer f = 1; f <= map.Extent(); ++f) builder.Add(faces, map(f));
        ++made;
      } else {
        result.diagnostics.push_back({Severity::Error, path, 0, label(entity), "face entity could not be made; dropped"});
      }
    } catch (const Standard_Failure&) {
      result.diagnostics.push_back({Severity::Error, path, 0, label(entity), "face entity could not be made; dropped"});
    }
    mark_entity_end(run.mark);
  }
  run.mark(kTransferred);
  if (made == 0) return;
  run.mark(kShapes);
  const Handle(XSControl_WorkSession) ws = step.WS();
  const FaceEntityMap tags = map_face_entities(ws->TransferReader()->TransientProcess(),
                                               [&](const Handle(Standard_Transient)& entity, FaceEntity& out) {
                                                 if (!entity->IsKind(STANDARD_TYPE(StepShape_Face))) return false;
                                                 out.id = label(entity);
                                                 return true;
                                               });
  result.set_loose(faces, tags, why + "; " + std::to_string(made) + " of " + std::to_string(tried) +
                                    " face entities recovered as loose faces of one part");
}

}  // namespace cadclash::detail
