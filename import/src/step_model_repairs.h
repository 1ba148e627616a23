// Repairs of a parsed STEP model's entity graph, made before OCCT transfers it: OCCT's translators
// crash on some entities it read (broken ones, deep MAPPED_ITEM chains) and drop assembly cycles
// without a word. Each repair says what it took out. Internal to cadclash::import.
#pragma once

#include "cad_transfer.h"
#include "cad_xcaf.h"

#include <Interface_Graph.hxx>
#include <StepData_StepModel.hxx>

#include <string>

namespace cadclash::detail {

// The first entity `entity` refers to, directly or not, that the file reader could not read
// whole (an error entity: missing or malformed parameters), or 0. OCCT's geometry translators
// dereference such entities' missing fields without checking (AXIS2_PLACEMENT_3D without a
// location crashed StepToGeom::MakeAxis2Placement), so a face reaching one is not transferred.
Standard_Integer first_broken_reference(const Interface_Graph& graph, const Handle(StepData_StepModel)& model,
                                        const Handle(Standard_Transient)& entity);

// Takes out of the model, before the transfer, every face of a shell and then every item of a shape
// representation that reaches an entity the reader could not read whole, with one error per
// dropped entity. Used only after OCCT crashed on the file: OCCT reads many such entities well.
// Faces first, so a solid loses only its bad faces; an item is dropped only if it still reaches one.
void drop_broken_shapes(const Handle(StepData_StepModel)& model, const EntityLabelFn& label, const std::string& path,
                        Transfer& result);

// OCCT transfers a MAPPED_ITEM by recursing into the representation it maps, three stack frames per
// level, so a long (or cyclic) chain of MAPPED_ITEMs overflows the stack. Takes every MAPPED_ITEM
// that heads a chain deeper than 64 levels (kMaxMappedItemNesting) out of the representations that
// hold it, with an error naming the head of each chain.
void cut_deep_mapped_items(const Handle(StepData_StepModel)& model, const EntityLabelFn& label, const std::string& path,
                           Transfer& result);

// A NEXT_ASSEMBLY_USAGE_OCCURRENCE that makes a product its own ancestor: OCCT's transfer then drops
// the products on the cycle and every root that reaches it without a word, so name each usage that
// closes a cycle (found by an iterative depth-first walk, in file order, so the report is stable).
void report_assembly_cycles(const Handle(StepData_StepModel)& model, const EntityLabelFn& label, const std::string& path,
                            Transfer& result);

}  // namespace cadclash::detail
