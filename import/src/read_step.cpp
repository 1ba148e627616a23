// STEP (AP203/AP214/AP242) through STEPCAFControl_Reader into an XCAF document.
#include "cad_transfer.h"
#include "cad_xcaf.h"
#include "isolated_run.h"
#include "mesh_common.h"
#include "readers.h"
#include "step_uncertainty.h"

#include <IFSelect_ReturnStatus.hxx>
#include <Interface_EntityIterator.hxx>
#include <Interface_Graph.hxx>
#include <Interface_Static.hxx>
#include <STEPCAFControl_Reader.hxx>
#include <StepShape_ConnectedFaceSet.hxx>
#include <StepShape_HArray1OfFace.hxx>
#include <StepShape_ShapeRepresentation.hxx>
#include <TDF_LabelSequence.hxx>
#include <XCAFDoc_DocumentTool.hxx>
#include <XCAFDoc_ShapeTool.hxx>
#include <STEPControl_Reader.hxx>
#include <Standard_Failure.hxx>
#include <StepData_StepModel.hxx>
#include <StepBasic_ProductDefinition.hxx>
#include <StepRepr_HArray1OfRepresentationItem.hxx>
#include <StepRepr_NextAssemblyUsageOccurrence.hxx>
#include <StepRepr_MappedItem.hxx>
#include <StepRepr_Representation.hxx>
#include <StepRepr_RepresentationItem.hxx>
#include <StepRepr_RepresentationMap.hxx>
#include <StepShape_Face.hxx>
#include <TCollection_HAsciiString.hxx>
#include <TDocStd_Document.hxx>
#include <XCAFApp_Application.hxx>
#include <XSControl_TransferReader.hxx>
#include <XSControl_WorkSession.hxx>
#include <BRep_Builder.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS_Compound.hxx>

#include <algorithm>
#include <atomic>
#include <csignal>
#include <functional>
#include <cctype>
#include <fstream>
#include <optional>
#include <set>
#include <sstream>
#include <string_view>
#include <unordered_map>
#include <unordered_set>
#include <utility>

#include <unistd.h>

namespace cadclash::detail {
namespace {

const char* status_text(IFSelect_ReturnStatus status) {
  switch (status) {
    case IFSelect_RetVoid: return "the file holds no data";
    case IFSelect_RetDone: return "read";
    case IFSelect_RetError: return "the file could not be opened or is not STEP";
    case IFSelect_RetFail: return "the file could not be parsed";
    case IFSelect_RetStop: return "reading was stopped";
  }
  return "unknown status";
}

// The FILE_SCHEMA names of the header and the line they are on; empty when there is none.
std::pair<std::vector<std::string>, std::int64_t> header_schemas(const std::string& text) {
  const std::string header = text.substr(0, 64 * 1024);
  const std::size_t at = header.find("FILE_SCHEMA");
  if (at == std::string::npos) return {{}, 0};
  const auto line = 1 + std::count(header.begin(), header.begin() + static_cast<std::ptrdiff_t>(at), '\n');
  const std::size_t end = header.find(';', at);
  std::vector<std::string> names;
  const std::string list = header.substr(at, end == std::string::npos ? std::string::npos : end - at);
  for (std::size_t q = list.find('\''); q != std::string::npos;) {
    const std::size_t close = list.find('\'', q + 1);
    if (close == std::string::npos) break;
    names.push_back(list.substr(q + 1, close - q - 1));
    q = list.find('\'', close + 1);
  }
  return {names, line};
}

bool known_schema(std::string name) {
  std::transform(name.begin(), name.end(), name.begin(), [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  for (const char* prefix : {"AUTOMOTIVE_DESIGN", "CONFIG_CONTROL_DESIGN", "CONFIGURATION_CONTROL_3D_DESIGN",
                             "AP203_CONFIGURATION_CONTROLLED", "AP214", "AP242_MANAGED_MODEL_BASED_3D_ENGINEERING",
                             "AP209_MULTIDISCIPLINARY", "STRUCTURAL_ANALYSIS_DESIGN"})
    if (name.rfind(prefix, 0) == 0) return true;
  return false;
}

// A truncated file cut back to its last complete entity and closed properly, with the line of the
// cut; nullopt when the file is not truncated (it ends with END-ISO-10303-21).
std::optional<std::pair<std::string, std::int64_t>> close_truncated(const std::string& source) {
  if (source.find("END-ISO-10303-21") != std::string::npos) return std::nullopt;
  const std::size_t data = source.find("DATA;");
  if (data == std::string::npos) return std::nullopt;
  std::string text = source;
  std::size_t cut = text.rfind(");", std::string::npos);
  while (cut != std::string::npos && cut > data) {
    const std::size_t after = cut + 2;
    if (after >= text.size() || text[after] == '\n' || text[after] == '\r') break;
    cut = cut == 0 ? std::string::npos : text.rfind(");", cut - 1);
  }
  if (cut == std::string::npos || cut < data) cut = data + 3;  // keep "DATA;" only
  text.resize(cut + 2);
  const auto line = 1 + std::count(text.begin(), text.end(), '\n');
  text += "\nENDSEC;\nEND-ISO-10303-21;\n";
  return std::make_pair(std::move(text), static_cast<std::int64_t>(line));
}

// References to entities the file does not define, replaced by '$' (unset) in a copy of the text.
// OCCT may bind such a reference to an unrelated entity instead of leaving it null: a cut-up file
// whose ORIENTED_EDGE named a vanished edge got itself as its edge and OCCT's own load check
// (RWStepShape_RWEdgeLoop::Check) recursed until the stack overflowed (fuzz_step). Unset, the
// parameter is reported by OCCT as missing and the entity is left out as for any bad parameter.
// Returns nullopt when every reference resolves.
struct UnsetReferences {
  std::string text;
  std::vector<Diagnostic> diagnostics;
};
std::optional<UnsetReferences> unset_undefined_references(const std::string& text, const std::string& path) {
  const std::size_t data = text.find("DATA;");
  if (data == std::string::npos) return std::nullopt;
  // Pass 1: defined ids ("#N =" at the start of a statement, outside strings).
  std::unordered_set<std::int64_t> defined;
  auto read_id = [&](std::size_t& i) -> std::int64_t {  // text[i] == '#'; advances past the digits
    std::int64_t id = 0;
    std::size_t j = i + 1;
    while (j < text.size() && std::isdigit(static_cast<unsigned char>(text[j])) && id < (std::int64_t{1} << 50))
      id = id * 10 + (text[j++] - '0');
    const bool any = j > i + 1;
    i = j;
    return any ? id : -1;
  };
  bool in_string = false, statement_start = true;
  for (std::size_t i = data + 5; i < text.size();) {
    const char c = text[i];
    if (in_string) {
      in_string = c != '\'';  // '' inside a string closes and reopens it: same result
      ++i;
    } else if (c == '\'') {
      in_string = true;
      statement_start = false;
      ++i;
    } else if (c == '#' && statement_start) {
      std::size_t j = i;
      const std::int64_t id = read_id(j);
      while (j < text.size() && std::isspace(static_cast<unsigned char>(text[j]))) ++j;
      if (id >= 0 && j < text.size() && text[j] == '=') defined.insert(id);
      statement_start = false;
      i = j;
    } else {
      if (c == ';') statement_start = true;
      else if (!std::isspace(static_cast<unsigned char>(c))) statement_start = false;
      ++i;
    }
  }
  // Pass 2: copy the text, unsetting references to ids not defined.
  UnsetReferences out;
  out.text.reserve(text.size());
  out.text.append(text, 0, data + 5);
  std::int64_t line = 1 + std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(data + 5), '\n');
  std::int64_t current = -1;  // the entity being read
  std::size_t unset = 0;
  in_string = false;
  statement_start = true;
  for (std::size_t i = data + 5; i < text.size();) {
    const char c = text[i];
    if (c == '\n') ++line;
    if (in_string || c == '\'') {
      in_string = in_string ? c != '\'' : true;
      statement_start = false;
      out.text += c;
      ++i;
      continue;
    }
    if (c != '#') {
      if (c == ';') statement_start = true;
      else if (!std::isspace(static_cast<unsigned char>(c))) statement_start = false;
      out.text += c;
      ++i;
      continue;
    }
    const std::size_t begin = i;
    const std::int64_t id = read_id(i);
    if (statement_start || id < 0 || defined.count(id) > 0) {
      if (statement_start) current = id;
      out.text.append(text, begin, i - begin);
    } else {
      out.text += '$';
      if (++unset <= 20)
        out.diagnostics.push_back({Severity::Error, path, line, current,
                                   "reference to #" + std::to_string(id) +
                                       " is unresolved: the file defines no such entity; read as unset"});
    }
    statement_start = false;
  }
  if (unset == 0) return std::nullopt;
  if (unset > 20)
    out.diagnostics.push_back({Severity::Error, path, 0, -1,
                               std::to_string(unset - 20) + " more unresolved references, read as unset"});
  return out;
}

// Representation contexts without a usable length unit, as diagnostics naming the context's #id.
// OCCT knows the complex context entity only with its GLOBAL_UNIT_ASSIGNED_CONTEXT, so without one it
// drops the entity and reports only that the representations using it have an "illegal type"
// parameter (an error); with a unit list that holds no LENGTH_UNIT it says nothing and reads the
// lengths as millimetres (a warning). Read from the text (entity id → instance text).
std::vector<Diagnostic> unit_context_problems(const std::string& text, const std::string& path) {
  std::unordered_map<std::int64_t, std::string_view> entities;
  std::vector<std::int64_t> contexts;
  std::size_t i = text.find("DATA;");
  while (i != std::string::npos && i < text.size()) {
    i = text.find('#', i);
    if (i == std::string::npos) break;
    std::size_t j = i + 1;
    std::int64_t id = 0;
    while (j < text.size() && std::isdigit(static_cast<unsigned char>(text[j])) && id < (std::int64_t{1} << 50))
      id = id * 10 + (text[j++] - '0');
    std::size_t k = j;
    while (k < text.size() && std::isspace(static_cast<unsigned char>(text[k]))) ++k;
    if (j == i + 1 || k >= text.size() || text[k] != '=') {
      i = j;
      continue;
    }
    bool quoted = false;  // ';' inside a string does not end the entity ('' is an escaped quote)
    std::size_t end = k;
    for (; end < text.size() && (quoted || text[end] != ';'); ++end)
      if (text[end] == '\'') quoted = !quoted;
    const std::string_view body(text.data() + k + 1, end - k - 1);
    entities[id] = body;
    if (body.find("GEOMETRIC_REPRESENTATION_CONTEXT") != std::string_view::npos &&
        body.find("REPRESENTATION_CONTEXT(2)") == std::string_view::npos)  // 2D parameter spaces need no unit
      contexts.push_back(id);
    i = end;
  }
  std::vector<Diagnostic> out;
  for (const std::int64_t id : contexts) {
    const std::string_view body = entities[id];
    const std::size_t at = body.find("GLOBAL_UNIT_ASSIGNED_CONTEXT");
    if (at == std::string_view::npos) {
      out.push_back({Severity::Error, path, 0, id,
                     "representation context without GLOBAL_UNIT_ASSIGNED_CONTEXT: its lengths have no unit, so "
                     "OCCT rejects it and every shape representation placed in it"});
      continue;
    }
    // The unit list: the #ids in the parentheses after the keyword.
    const std::size_t open = body.find('(', at), close = body.find(')', at);
    bool length = false;
    for (std::size_t h = body.find('#', open); h != std::string_view::npos && h < close; h = body.find('#', h + 1)) {
      std::int64_t ref = 0;
      for (std::size_t d = h + 1; d < body.size() && std::isdigit(static_cast<unsigned char>(body[d])) &&
                                  ref < (std::int64_t{1} << 50); ++d)  // the bound of the ids above: no overflow
        ref = ref * 10 + (body[d] - '0');
      const auto unit = entities.find(ref);
      length = length || (unit != entities.end() && unit->second.find("LENGTH_UNIT") != std::string_view::npos);
    }
    if (!length)
      out.push_back({Severity::Warning, path, 0, id,
                     "representation context whose GLOBAL_UNIT_ASSIGNED_CONTEXT names no LENGTH_UNIT: its lengths "
                     "have no stated unit; read as millimetres"});
  }
  return out;
}

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

// Whether the document holds at least one face: products without any mean the attempt gave nothing.
bool has_faces(const Handle(TDocStd_Document)& doc) {
  TDF_LabelSequence free;
  XCAFDoc_DocumentTool::ShapeTool(doc->Main())->GetFreeShapes(free);
  for (Standard_Integer i = 1; i <= free.Length(); ++i)
    if (TopExp_Explorer(XCAFDoc_ShapeTool::GetShape(free(i)), TopAbs_FACE).More()) return true;
  return false;
}

// When no product can be transferred (a cut-off file loses its product structure, which OCCT
// writes last), every face entity is transferred on its own into one part named after the file.
// The first entity `entity` refers to, directly or not, that the file reader could not read
// whole (an error entity: missing or malformed parameters), or 0. OCCT's geometry translators
// dereference such entities' missing fields without checking (AXIS2_PLACEMENT_3D without a
// location crashed StepToGeom::MakeAxis2Placement), so a face reaching one is not transferred.
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

// One way through the file. The plain transfer comes first; the others exist because OCCT's
// translators crash on some malformed entities (see read_step).
enum class Attempt {
  Whole,               // every product, as the file says
  WithoutBrokenFaces,  // the same, after taking out the faces and shape items that reach broken entities
  LooseFaces,          // no products: each face entity on its own (recover_loose_faces)
};

// Marks a child reports (isolated_run.h): the file was parsed, shapes were transferred, the
// transfer made at least one face, and faces were transferred one by one (no products).
constexpr char kParsed = 'P', kTransferred = 'T', kShapes = 'S', kLoose = 'L';

std::atomic<std::int64_t> crash_injected_at{-1};  // see set_step_crash_injection_for_testing
std::atomic<std::int64_t> hang_injected_at{-1};   // see set_step_hang_injection_for_testing

struct AttemptRun {
  Attempt attempt = Attempt::Whole;
  Mark mark = [](char) {};
  const std::set<std::int64_t>* skip = nullptr;  // LooseFaces: face entities (#id) an earlier child crashed on
};

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

// Takes out of the model, before the transfer, every face of a shell and then every item of a shape
// representation that reaches an entity the reader could not read whole, with one error per
// dropped entity. Used only after OCCT crashed on the file: OCCT reads many such entities well.
// Faces first, so a solid loses only its bad faces; an item is dropped only if it still reaches one.
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

// OCCT transfers a MAPPED_ITEM by recursing into the representation it maps, three stack frames per
// level, so a long (or cyclic) chain of MAPPED_ITEMs overflows the stack. Before the transfer, every
// MAPPED_ITEM that heads a chain deeper than this is taken out of the representations that hold it.
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

// A NEXT_ASSEMBLY_USAGE_OCCURRENCE that makes a product its own ancestor: OCCT's transfer then drops
// the products on the cycle and every root that reaches it without a word, so name each usage that
// closes a cycle (found by an iterative depth-first walk, in file order, so the report is stable).
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
  enum class Mark { Open, Done };
  std::unordered_map<Pd, Mark> mark;
  for (const Pd root : parents) {
    if (mark.count(root)) continue;
    std::vector<std::pair<Pd, std::size_t>> stack{{root, 0}};
    mark[root] = Mark::Open;
    while (!stack.empty()) {
      auto& [pd, next] = stack.back();
      const auto found = children.find(pd);
      if (found == children.end() || next == found->second.size()) {
        mark[pd] = Mark::Done;
        stack.pop_back();
        continue;
      }
      const auto [child, usage] = found->second[next++];
      const auto seen = mark.find(child);
      if (seen == mark.end()) {
        mark[child] = Mark::Open;
        stack.emplace_back(child, 0);
      } else if (seen->second == Mark::Open) {
        result.diagnostics.push_back({Severity::Error, path, 0, label(model->Value(usage)),
                                      "NEXT_ASSEMBLY_USAGE_OCCURRENCE closes a cycle: it makes product definition #" +
                                          std::to_string(label(Handle(Standard_Transient)(const_cast<StepBasic_ProductDefinition*>(child)))) +
                                          " its own ancestor; the products on the cycle and the roots above them are dropped"});
        result.complete = false;
      }
    }
  }
}

// Reads and transfers the file one way (`run.attempt`), tessellating nothing.
Transfer read_step_attempt(const std::string& path, const AttemptRun& run) {
  prepare_occt_exchange();
  Transfer result;
  try {
    STEPCAFControl_Reader reader;  // its constructor registers the STEP controller and its parameters
    Interface_Static::SetCVal("xstep.cascade.unit", "MM");
    reader.SetColorMode(Standard_True);
    reader.SetNameMode(Standard_True);
    reader.SetLayerMode(Standard_False);
    reader.SetPropsMode(Standard_False);
    reader.SetGDTMode(Standard_False);
    reader.SetMatMode(Standard_False);
    reader.SetViewMode(Standard_False);

    // One read of the text for every scan below; OCCT reads the file (or a corrected copy) itself.
    std::string text;
    const bool readable = static_cast<bool>(std::ifstream(path));
    {
      std::ifstream in(path, std::ios::binary);
      std::stringstream buffer;
      buffer << in.rdbuf();
      text = buffer.str();
    }
    const auto [schemas, schema_line] = header_schemas(text);
    for (const std::string& schema : schemas) {
      if (!known_schema(schema)) {
        result.diagnostics.push_back({Severity::Error, path, schema_line, -1,
                                      "FILE_SCHEMA '" + printable_token(schema) +
                                          "' is not a STEP AP203/AP214/AP242 schema; read as AP214 anyway"});
        result.complete = false;
      }
    }
    STEPControl_Reader& step = reader.ChangeReader();
    // OCCT reads a copy when references must be unset first (see unset_undefined_references).
    auto read_text = [&](const std::string& source, bool whole_file) {
      if (auto unset = unset_undefined_references(source, path)) {
        result.diagnostics.insert(result.diagnostics.end(), unset->diagnostics.begin(), unset->diagnostics.end());
        result.complete = false;
        std::istringstream stream(unset->text);
        return step.ReadStream(path.c_str(), stream);
      }
      if (whole_file) return reader.ReadFile(path.c_str());
      std::istringstream stream(source);
      return step.ReadStream(path.c_str(), stream);
    };
    const auto truncated = close_truncated(text);
    IFSelect_ReturnStatus status = IFSelect_RetVoid;
    if (!readable) {
      status = reader.ReadFile(path.c_str());  // OCCT's own message for a file it cannot open
    } else if (truncated) {
      result.diagnostics.push_back({Severity::Error, path, truncated->second, -1,
                                    "STEP file is truncated (no END-ISO-10303-21); read up to its last complete entity, "
                                    "which ends on this line"});
      result.complete = false;
      status = read_text(truncated->first, false);
    } else {
      status = read_text(text, true);
    }
    const Handle(StepData_StepModel) model = step.StepModel();
    const EntityLabelFn label = [&model](const Handle(Standard_Transient)& entity) -> std::int64_t {
      if (model.IsNull()) return -1;
      const Standard_Integer id = model->IdentLabel(entity);
      return id > 0 ? id : -1;
    };
    const Handle(XSControl_WorkSession) ws = step.WS();
    std::size_t load_fails = 0;
    if (!ws.IsNull() && !model.IsNull() && model->NbEntities() > 0)
      load_fails = append_checks(ws->ModelCheckList(Standard_False), model, label, path, "STEP syntax", false,
                                 result.diagnostics);
    if (status != IFSelect_RetDone) {
      result.diagnostics.push_back({Severity::Error, path, 0, -1, std::string("cannot read STEP file: ") + status_text(status)});
      result.complete = false;
      return result;
    }
    run.mark(kParsed);
    if (load_fails > 0) result.complete = false;
    for (Diagnostic& d : unit_context_problems(text, path)) {
      if (d.severity == Severity::Error) result.complete = false;
      result.diagnostics.push_back(std::move(d));
    }
    result.declared_uncertainty = declared_length_uncertainty(text, path, result.diagnostics);
    if (model.IsNull() || model->NbEntities() == 0) {
      result.diagnostics.push_back({Severity::Error, path, 0, -1, "STEP file has an empty DATA section"});
      result.complete = false;
      return result;
    }
    if (run.attempt == Attempt::LooseFaces) {
      recover_loose_faces(step, model, path, label, run, "the products could not be transferred", result);
      return result;
    }
    if (reader.NbRootsForTransfer() == 0) {
      recover_loose_faces(step, model, path, label, run, "no product structure could be read", result);
      if (!result.loose.IsNull()) return result;
      result.diagnostics.push_back({Severity::Error, path, 0, -1,
                                    "STEP file holds no shape to transfer (no product with a shape representation "
                                    "that this reader's schema knows)"});
      result.complete = false;
      return result;
    }

    if (run.attempt == Attempt::WithoutBrokenFaces) drop_broken_shapes(model, label, path, result);
    cut_deep_mapped_items(model, label, path, result);
    report_assembly_cycles(model, label, path, result);

    result.doc = new_xcaf_document();
    const bool transferred = reader.Transfer(result.doc) == Standard_True;
    const Handle(Transfer_TransientProcess) process =
        ws.IsNull() || ws->TransferReader().IsNull() ? Handle(Transfer_TransientProcess)() : ws->TransferReader()->TransientProcess();
    if (!process.IsNull() &&
        append_checks(process->CheckList(Standard_True), model, label, path, "STEP transfer", false, result.diagnostics) > 0)
      result.complete = false;
    run.mark(kTransferred);
    if (!transferred) {
      result.diagnostics.push_back({Severity::Error, path, 0, -1, "STEP transfer failed; no shape could be made"});
      result.complete = false;
      result.discard_shapes();
      return result;
    }
    if (has_faces(result.doc)) run.mark(kShapes);
    result.faces = map_face_entities(process, [&](const Handle(Standard_Transient)& entity, FaceEntity& out) {
      if (!entity->IsKind(STANDARD_TYPE(StepShape_Face))) return false;
      out.id = label(entity);
      const Handle(StepRepr_RepresentationItem) item = Handle(StepRepr_RepresentationItem)::DownCast(entity);
      if (!item.IsNull() && !item->Name().IsNull()) out.name = item->Name()->ToCString();
      return true;
    });
  } catch (const Standard_Failure& e) {
    result.diagnostics.push_back({Severity::Error, path, 0, -1, std::string("OCCT failed while reading STEP: ") + e.GetMessageString()});
    result.complete = false;
    result.discard_shapes();  // a transfer cut short keeps nothing
  }
  return result;
}

}  // namespace

void set_step_crash_injection_for_testing(std::int64_t face_id) { crash_injected_at.store(face_id, std::memory_order_relaxed); }
void set_step_hang_injection_for_testing(std::int64_t face_id) { hang_injected_at.store(face_id, std::memory_order_relaxed); }

// OCCT's translators dereference the missing parameters of malformed entities (StepToGeom::MakeLine
// on a LINE whose point was cut off), so each attempt runs in a child process, which sends back the
// transferred document (cad_transfer.h): a crash there costs the attempt, not the caller's process,
// and this process never runs OCCT's STEP code on the file.
ImportResult read_step(const std::string& path, const ImportOptions& options) {
  prepare_occt_exchange();
  std::vector<Diagnostic> notes;  // how the attempts went, first in the result
  std::optional<Transfer> faceless;  // the first attempt that finished without a face
  auto finish = [&](Transfer transfer) {
    // What the faceless attempt said (its transfer's checks) stays, without repeating what this one says.
    if (faceless) {
      std::unordered_set<std::string> said;
      for (const Diagnostic& d : transfer.diagnostics) said.insert(format_diagnostic(d));
      for (const Diagnostic& d : faceless->diagnostics)
        if (!said.count(format_diagnostic(d))) notes.push_back(d);
    }
    ImportResult result = finish_transfer(std::move(transfer), path, options);
    for (const Diagnostic& d : notes) result.complete = result.complete && d.severity != Severity::Error;
    result.diagnostics.insert(result.diagnostics.begin(), notes.begin(), notes.end());
    return result;
  };
  Attempt attempt = Attempt::Whole;
  std::set<std::int64_t> skip;  // face entities a child crashed on, each one
  constexpr std::size_t kMaxSkips = 20;
  const ReaderClock clock(options.reader_time_limit_seconds);
  if (auto warning = unapplied_time_limit(path, options)) notes.push_back(*warning);
  for (;;) {
    IsolatedTransfer run = transfer_in_child(path, options.isolate_cad_readers, clock.left(),
                                             [&](const Mark& mark) { return read_step_attempt(path, {attempt, mark, &skip}); });
    if (run.warning) notes.push_back(*run.warning);
    const ChildRun& child = run.child;
    const bool parsed = child.marks.find(kParsed) != std::string::npos;
    if (!child.crashed) {
      if (child.marks.find(kShapes) != std::string::npos) return finish(std::move(run.transfer));
      const bool loose = attempt == Attempt::LooseFaces || child.marks.find(kLoose) != std::string::npos;
      if (!faceless) faceless.emplace(std::move(run.transfer));
      if (loose || !parsed) break;
      // OCCT made nothing of the products: each face entity on its own may still give some.
      notes.push_back({Severity::Error, path, 0, -1,
                       attempt == Attempt::Whole
                           ? "the file's products gave no face; read again as loose faces"
                           : "without the faces that reach entities OCCT could not read whole, no face was left; read again as loose faces"});
      attempt = Attempt::LooseFaces;
      continue;
    }
    const char* stage = !parsed ? "parsing the file"
                        : attempt == Attempt::LooseFaces ? "transferring its faces one by one"
                        : attempt == Attempt::Whole ? "transferring its shapes"
                                                    : "transferring its shapes without the broken faces";
    const std::int64_t in_progress = entity_in_progress(child.marks);
    if (child.timed_out) {
      // Another attempt would meet the same slow entity: what earlier attempts made is all there is.
      notes.push_back({Severity::Error, path, 0, in_progress, clock.stopped_message(stage, in_progress)});
      break;
    }
    if (attempt == Attempt::LooseFaces && in_progress >= 0 && skip.size() < kMaxSkips && skip.insert(in_progress).second) {
      notes.push_back({Severity::Error, path, 0, in_progress,
                       "OCCT crashed with " + child.how + " while transferring this face entity on its own (in an isolated reader); dropped"});
      continue;
    }
    const char* next = !parsed || attempt == Attempt::LooseFaces ? "nothing more could be read"
                       : attempt == Attempt::Whole ? "read again without the faces that reach entities it could not read whole"
                                                   : "read again as loose faces";
    notes.push_back({Severity::Error, path, 0, -1,
                     std::string("OCCT crashed with ") + child.how + " while " + stage + " (in an isolated reader); " + next});
    if (!parsed || attempt == Attempt::LooseFaces) break;
    attempt = attempt == Attempt::Whole ? Attempt::WithoutBrokenFaces : Attempt::LooseFaces;
  }
  if (faceless) {
    Transfer best = std::move(*faceless);
    faceless.reset();
    return finish(std::move(best));
  }
  Transfer nothing;
  nothing.complete = false;
  nothing.diagnostics.push_back({Severity::Error, path, 0, -1, "no shape could be read from the STEP file"});
  return finish(std::move(nothing));
}

}  // namespace cadclash::detail
