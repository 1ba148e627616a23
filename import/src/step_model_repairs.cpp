// Repairs of a parsed STEP model before OCCT transfers it (step_model_repairs.h says why).
#include "step_model_repairs.h"

#include <Interface_EntityIterator.hxx>
#include <StepBasic_ProductDefinition.hxx>
#include <StepRepr_HArray1OfRepresentationItem.hxx>
#include <StepRepr_MappedItem.hxx>
#include <StepRepr_NextAssemblyUsageOccurrence.hxx>
#include <StepRepr_Representation.hxx>
#include <StepRepr_RepresentationItem.hxx>
#include <StepRepr_RepresentationMap.hxx>
#include <StepShape_ConnectedFaceSet.hxx>
#include <StepShape_Face.hxx>
#include <StepShape_HArray1OfFace.hxx>
#include <StepShape_ShapeRepresentation.hxx>

#include <algorithm>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <vector>

namespace cadclash::detail {
namespace {

using StepItems = Handle(StepRepr_HArray1OfRepresentationItem);

// Leaves only `kept` (a subsequence of its items) in `rep`; no items at all when `kept` is empty.
void keep_items(const Handle(StepRepr_Representation)& rep, const std::vector<Handle(StepRepr_RepresentationItem)>& kept) {
  if (kept.size() == static_cast<std::size_t>(rep->Items()->Length())) return;
  StepItems shorter;
  if (!kept.empty()) {
    shorter = new StepRepr_HArray1OfRepresentationItem(1, static_cast<Standard_Integer>(kept.size()));
    for (std::size_t i = 0; i < kept.size(); ++i) shorter->SetValue(static_cast<Standard_Integer>(i) + 1, kept[i]);
  }
  rep->SetItems(shorter);
}

// The deepest chain of MAPPED_ITEMs left to OCCT's transfer; cut_deep_mapped_items cuts deeper ones.
constexpr int kMaxMappedItemNesting = 64;

// Mapped items held directly by the representation that `item` maps.
std::vector<const StepRepr_MappedItem*> mapped_children(const StepRepr_MappedItem* item) {
  std::vector<const StepRepr_MappedItem*> out;
  const Handle(StepRepr_RepresentationMap) source = item->MappingSource();
  if (source.IsNull() || source->MappedRepresentation().IsNull()) return out;
  const StepItems items = source->MappedRepresentation()->Items();
  if (items.IsNull()) return out;
  for (Standard_Integer i = items->Lower(); i <= items->Upper(); ++i)
    if (const auto* child = dynamic_cast<const StepRepr_MappedItem*>(items->Value(i).get())) out.push_back(child);
  return out;
}

}  // namespace

Standard_Integer first_broken_reference(const Interface_Graph& graph, const Handle(StepData_StepModel)& model,
                                        const Handle(Standard_Transient)& entity) {
  std::vector<Handle(Standard_Transient)> stack{entity};
  std::unordered_set<Standard_Integer> seen;
  while (!stack.empty()) {
    const Handle(Standard_Transient) e = stack.back();
    stack.pop_back();
    const Standard_Integer n = model->Number(e);
    if (n <= 0 || !seen.insert(n).second) continue;
    if (model->IsErrorEntity(n)) return n;
    for (Interface_EntityIterator it = graph.Shareds(e); it.More(); it.Next()) stack.push_back(it.Value());
  }
  return 0;
}

void drop_broken_shapes(const Handle(StepData_StepModel)& model, const EntityLabelFn& label, const std::string& path,
                        Transfer& result) {
  std::size_t dropped = 0;
  auto report = [&](const Handle(Standard_Transient)& entity, Standard_Integer broken, const std::string& from) {
    if (++dropped > 40) return;
    const bool itself = model->Value(broken) == entity;
    result.diagnostics.push_back(
        {Severity::Error, path, 0, label(entity),
         (itself ? std::string("entity could not be read whole")
                 : "entity refers to #" + std::to_string(label(model->Value(broken))) + ", which could not be read whole") +
             "; dropped from " + from + " after OCCT crashed on the file"});
  };
  {
    const Interface_Graph graph(model);
    for (Standard_Integer e = 1; e <= model->NbEntities(); ++e) {
      const Handle(StepShape_ConnectedFaceSet) shell = Handle(StepShape_ConnectedFaceSet)::DownCast(model->Value(e));
      if (shell.IsNull() || shell->CfsFaces().IsNull()) continue;
      const Handle(StepShape_HArray1OfFace) faces = shell->CfsFaces();
      std::vector<Handle(StepShape_Face)> kept;
      std::vector<std::pair<Standard_Integer, Standard_Integer>> bad;  // face index, broken entity
      for (Standard_Integer i = faces->Lower(); i <= faces->Upper(); ++i) {
        const Standard_Integer broken = first_broken_reference(graph, model, faces->Value(i));
        if (broken == 0) kept.push_back(faces->Value(i));
        else bad.emplace_back(i, broken);
      }
      if (bad.empty() || kept.empty()) continue;  // a shell with no good face goes with its item below
      for (const auto& [i, broken] : bad) report(faces->Value(i), broken, "shell #" + std::to_string(label(shell)));
      const Handle(StepShape_HArray1OfFace) shorter = new StepShape_HArray1OfFace(1, static_cast<Standard_Integer>(kept.size()));
      for (std::size_t i = 0; i < kept.size(); ++i) shorter->SetValue(static_cast<Standard_Integer>(i) + 1, kept[i]);
      shell->SetCfsFaces(shorter);
    }
  }
  const Interface_Graph graph(model);  // anew: the shells changed
  for (Standard_Integer e = 1; e <= model->NbEntities(); ++e) {
    const Handle(StepShape_ShapeRepresentation) rep = Handle(StepShape_ShapeRepresentation)::DownCast(model->Value(e));
    if (rep.IsNull() || rep->Items().IsNull()) continue;
    const StepItems items = rep->Items();
    std::vector<Handle(StepRepr_RepresentationItem)> kept;
    for (Standard_Integer i = items->Lower(); i <= items->Upper(); ++i) {
      const Standard_Integer broken = first_broken_reference(graph, model, items->Value(i));
      if (broken == 0) kept.push_back(items->Value(i));
      else report(items->Value(i), broken, "shape representation #" + std::to_string(label(rep)));
    }
    keep_items(rep, kept);
  }
  if (dropped > 40)
    result.diagnostics.push_back({Severity::Error, path, 0, -1, std::to_string(dropped - 40) + " more entities dropped"});
  if (dropped > 0) result.complete = false;
}

void cut_deep_mapped_items(const Handle(StepData_StepModel)& model, const EntityLabelFn& label, const std::string& path,
                           Transfer& result) {
  // Height of each mapped item (longest chain of mapped items below and including it), found without
  // recursion; an item met again while still open lies on a cycle and counts as infinitely deep.
  constexpr int kCycle = 1 << 30;
  std::unordered_map<const StepRepr_MappedItem*, int> height;
  for (Standard_Integer e = 1; e <= model->NbEntities(); ++e) {
    const auto* root = dynamic_cast<const StepRepr_MappedItem*>(model->Value(e).get());
    if (root == nullptr || height.count(root)) continue;
    struct Frame { const StepRepr_MappedItem* item; std::vector<const StepRepr_MappedItem*> children; std::size_t next; int best; };
    std::vector<Frame> stack{{root, mapped_children(root), 0, 1}};
    height[root] = -1;  // open
    while (!stack.empty()) {
      Frame& top = stack.back();
      if (top.next < top.children.size()) {
        const StepRepr_MappedItem* child = top.children[top.next++];
        const auto found = height.find(child);
        if (found == height.end()) {
          height[child] = -1;
          stack.push_back({child, mapped_children(child), 0, 1});
        } else {
          top.best = std::max(top.best, found->second < 0 ? kCycle : std::min(kCycle, found->second + 1));
        }
        continue;
      }
      const int h = top.best;
      height[top.item] = h;
      stack.pop_back();
      if (!stack.empty()) stack.back().best = std::max(stack.back().best, std::min(kCycle, h + 1));
    }
  }
  std::unordered_set<const StepRepr_MappedItem*> cut, below_cut;
  for (const auto& [item, h] : height)
    if (h > kMaxMappedItemNesting) {
      cut.insert(item);
      for (const StepRepr_MappedItem* child : mapped_children(item)) below_cut.insert(child);
    }
  if (cut.empty()) return;
  // Report the heads of the cut chains, in file order; on a pure cycle every cut item lies below
  // another, so the first one in the file is reported instead.
  std::vector<Standard_Integer> heads;
  Standard_Integer first = 0;
  for (Standard_Integer e = 1; e <= model->NbEntities(); ++e) {
    const auto* item = dynamic_cast<const StepRepr_MappedItem*>(model->Value(e).get());
    if (item == nullptr || !cut.count(item)) continue;
    if (first == 0) first = e;
    if (!below_cut.count(item)) heads.push_back(e);
  }
  if (heads.empty()) heads.push_back(first);
  for (const Standard_Integer e : heads) {
    const int h = height[dynamic_cast<const StepRepr_MappedItem*>(model->Value(e).get())];
    result.diagnostics.push_back({Severity::Error, path, 0, label(model->Value(e)),
                                  h >= kCycle ? std::string("MAPPED_ITEM is part of a cycle of mapped representations; its shape is dropped")
                                              : "MAPPED_ITEM nests " + std::to_string(h) + " levels of mapped representations (more than " +
                                                    std::to_string(kMaxMappedItemNesting) + "); its shape is dropped"});
  }
  result.complete = false;
  for (Standard_Integer e = 1; e <= model->NbEntities(); ++e) {
    const Handle(StepRepr_Representation) rep = Handle(StepRepr_Representation)::DownCast(model->Value(e));
    if (rep.IsNull() || rep->Items().IsNull()) continue;
    const StepItems items = rep->Items();
    std::vector<Handle(StepRepr_RepresentationItem)> kept;
    for (Standard_Integer i = items->Lower(); i <= items->Upper(); ++i)
      if (!cut.count(dynamic_cast<const StepRepr_MappedItem*>(items->Value(i).get()))) kept.push_back(items->Value(i));
    keep_items(rep, kept);
  }
}

void report_assembly_cycles(const Handle(StepData_StepModel)& model, const EntityLabelFn& label, const std::string& path,
                            Transfer& result) {
  using Pd = const StepBasic_ProductDefinition*;
  std::unordered_map<Pd, std::vector<std::pair<Pd, Standard_Integer>>> children;  // child, usage entity
  std::vector<Pd> parents;
  for (Standard_Integer e = 1; e <= model->NbEntities(); ++e) {
    const Handle(StepRepr_NextAssemblyUsageOccurrence) usage = Handle(StepRepr_NextAssemblyUsageOccurrence)::DownCast(model->Value(e));
    if (usage.IsNull() || usage->RelatingProductDefinition().IsNull() || usage->RelatedProductDefinition().IsNull()) continue;
    const Pd parent = usage->RelatingProductDefinition().get();
    if (!children.count(parent)) parents.push_back(parent);
    children[parent].emplace_back(usage->RelatedProductDefinition().get(), e);
  }
  enum class Visit { Open, Done };
  std::unordered_map<Pd, Visit> visit;
  for (const Pd root : parents) {
    if (visit.count(root)) continue;
    std::vector<std::pair<Pd, std::size_t>> stack{{root, 0}};
    visit[root] = Visit::Open;
    while (!stack.empty()) {
      auto& [pd, next] = stack.back();
      const auto found = children.find(pd);
      if (found == children.end() || next == found->second.size()) {
        visit[pd] = Visit::Done;
        stack.pop_back();
        continue;
      }
      const auto [child, usage] = found->second[next++];
      const auto seen = visit.find(child);
      if (seen == visit.end()) {
        visit[child] = Visit::Open;
        stack.emplace_back(child, 0);
      } else if (seen->second == Visit::Open) {
        result.diagnostics.push_back({Severity::Error, path, 0, label(model->Value(usage)),
                                      "NEXT_ASSEMBLY_USAGE_OCCURRENCE closes a cycle: it makes product definition #" +
                                          std::to_string(label(Handle(Standard_Transient)(const_cast<StepBasic_ProductDefinition*>(child)))) +
                                          " its own ancestor; the products on the cycle and the roots above them are dropped"});
        result.complete = false;
      }
    }
  }
}

}  // namespace cadclash::detail
