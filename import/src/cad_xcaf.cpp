// XCAF document → parts and instances; transfer-process face map; OCCT check lists as diagnostics.
#include "cad_xcaf.h"

#include "brep_part_cache.h"
#include "transfer_fix_context.h"

#include <Interface_Check.hxx>
#include <Message.hxx>
#include <Message_Messenger.hxx>
#include <Message_PrinterOStream.hxx>
#include <Quantity_Color.hxx>
#include <ShapeAlgo.hxx>
#include <ShapeAlgo_AlgoContainer.hxx>
#include <Standard_Failure.hxx>
#include <TCollection_AsciiString.hxx>
#include <TDF_Label.hxx>
#include <TDF_LabelSequence.hxx>
#include <TDF_Tool.hxx>
#include <TDataStd_Name.hxx>
#include <TopExp.hxx>
#include <TopLoc_Datum3D.hxx>
#include <TopLoc_Location.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TransferBRep.hxx>
#include <Transfer_Binder.hxx>
#include <XCAFDoc_DocumentTool.hxx>
#include <XCAFDoc_ShapeTool.hxx>
#include <XCAFPrs.hxx>
#include <XCAFPrs_IndexedDataMapOfShapeStyle.hxx>
#include <XCAFPrs_Style.hxx>
#include <XSAlgo.hxx>
#include <XSAlgo_AlgoContainer.hxx>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <string_view>
#include <unordered_map>

namespace cadclash::detail {
namespace {

std::string label_name(const TDF_Label& label) {
  Handle(TDataStd_Name) name;
  if (label.IsNull() || !label.FindAttribute(TDataStd_Name::GetID(), name)) return {};
  return TCollection_AsciiString(name->Get()).ToCString();
}

// A path component: '/' would split it, so it becomes '_'; an empty name becomes "unnamed".
std::string path_component(std::string name) {
  std::replace(name.begin(), name.end(), '/', '_');
  return name.empty() ? std::string("unnamed") : name;
}

// Names that say nothing a reader can use: empty, the label entries OCCT's XCAF writer gives an
// unnamed occurrence ("=>[0:1:1:9]"), and the shape types it gives an unnamed product ("SOLID").
bool generic_name(std::string_view name) {
  if (name.empty() || name == "unnamed" || name == "SOLID" || name == "COMPOUND" || name == "COMPSOLID" || name == "SHELL")
    return true;
  return name.size() >= 4 && name.substr(0, 3) == "=>[" && name.back() == ']';
}

// Applies the occurrence rule to one set of siblings (see import.h): a name that occurs more than
// once among them gets "::k" on every occurrence, k counting from 1 in file order and skipping any k
// that would repeat another sibling's name.
std::vector<std::string> sibling_components(const std::vector<std::string>& names) {
  std::map<std::string, int> total;
  for (const std::string& n : names) ++total[n];
  std::set<std::string> used;
  for (const std::string& n : names)
    if (total[n] == 1) used.insert(n);
  std::map<std::string, int> next;
  std::vector<std::string> out;
  out.reserve(names.size());
  for (const std::string& n : names) {
    if (total[n] == 1) {
      out.push_back(n);
      continue;
    }
    std::string candidate;
    do candidate = n + "::" + std::to_string(++next[n]);
    while (!used.insert(candidate).second);
    out.push_back(candidate);
  }
  return out;
}

}  // namespace

Pose pose_of_transformation(const gp_Trsf& trsf) {
  Pose pose = Pose::Identity();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) pose.matrix()(r, c) = trsf.Value(r + 1, c + 1) / trsf.ScaleFactor();
    pose.matrix()(r, 3) = trsf.Value(r + 1, 4);
  }
  return pose;
}

namespace {

// A location as the XCAF document's binary format reads it back (BinMXCAFDoc_LocationDriver over
// BinTools_LocationSet): the same chain of datums and powers, each datum's transformation made
// again from its twelve values by SetValues (which normalises a reflection's scale of -1 to +1 and
// negates its matrix); a datum met twice is one datum both times, as the format keeps it.
class StoredLocations {
 public:
  TopLoc_Location operator()(const TopLoc_Location& l) {
    if (l.IsIdentity()) return l;
    Handle(TopLoc_Datum3D)& datum = made_[l.FirstDatum().get()];
    if (datum.IsNull()) {
      const gp_Trsf& t = l.FirstDatum()->Transformation();
      gp_Trsf read;
      read.SetValues(t.Value(1, 1), t.Value(1, 2), t.Value(1, 3), t.Value(1, 4), t.Value(2, 1), t.Value(2, 2), t.Value(2, 3),
                     t.Value(2, 4), t.Value(3, 1), t.Value(3, 2), t.Value(3, 3), t.Value(3, 4));
      datum = new TopLoc_Datum3D(read);
    }
    return (*this)(l.NextLocation()) * TopLoc_Location(datum).Powered(l.FirstPower());
  }

 private:
  std::unordered_map<const TopLoc_Datum3D*, Handle(TopLoc_Datum3D)> made_;
};

struct Walker {
  Handle(XCAFDoc_ShapeTool) shapes;
  const std::string& file;
  std::optional<StoredLocations> stored;  // the components' locations as a stored document has them
  std::map<std::string, std::size_t> part_of_label;  // TDF entry → index in `leaves`
  std::vector<TDF_Label> leaves;
  std::vector<std::string> leaf_names;  // the part name of each of `leaves` (see import.h)
  std::vector<Instance> instances;  // part = index into `leaves`
  std::vector<Diagnostic>& diagnostics;
  std::vector<std::string> products{};  // the product names from the root down to the label visited
  std::vector<std::string> chain{};      // the component label entries from the root down to the label visited
  std::vector<std::vector<std::string>> chains{};  // per instance, its chain

  void visit(const TDF_Label& label, const TopLoc_Location& location, const std::string& path, int depth) {
    products.push_back(label_name(label));
    visit_named(label, location, path, depth);
    products.pop_back();
  }

  // A leaf's part name: its product's, or when that is generic the nearest ancestor's that is not.
  std::string part_name() const {
    for (auto it = products.rbegin(); it != products.rend(); ++it)
      if (!generic_name(*it)) return *it;
    return products.back();
  }

  void visit_named(const TDF_Label& label, const TopLoc_Location& location, const std::string& path, int depth) {
    if (depth > 64) {
      diagnostics.push_back({Severity::Error, file, 0, -1, "assembly nesting deeper than 64 levels at " + path + "; cut there"});
      return;
    }
    if (XCAFDoc_ShapeTool::IsAssembly(label)) {
      TDF_LabelSequence components;
      XCAFDoc_ShapeTool::GetComponents(label, components, Standard_False);
      std::vector<TDF_Label> referred;
      std::vector<std::string> names;
      for (Standard_Integer i = 1; i <= components.Length(); ++i) {
        TDF_Label ref;
        if (!XCAFDoc_ShapeTool::GetReferredShape(components(i), ref)) ref = components(i);
        // The instance's own name (STEP: the NEXT_ASSEMBLY_USAGE_OCCURRENCE's), else its product's.
        std::string name = label_name(components(i));
        if (name.empty()) name = label_name(ref);
        referred.push_back(ref);
        names.push_back(path_component(name));
      }
      const std::vector<std::string> parts = sibling_components(names);
      for (std::size_t i = 0; i < referred.size(); ++i) {
        const TDF_Label& component = components(static_cast<Standard_Integer>(i) + 1);
        const TopLoc_Location own = XCAFDoc_ShapeTool::GetLocation(component);
        const TopLoc_Location child = location * (stored ? (*stored)(own) : own);
        TCollection_AsciiString entry;
        TDF_Tool::Entry(component, entry);
        chain.emplace_back(entry.ToCString());
        // An only child with a generic name adds nothing to its parent's path, which stays unique.
        visit(referred[i], child, referred.size() == 1 && generic_name(names[i]) ? path : path + "/" + parts[i], depth + 1);
        chain.pop_back();
      }
      return;
    }
    TCollection_AsciiString entry;
    TDF_Tool::Entry(label, entry);
    auto [it, inserted] = part_of_label.try_emplace(entry.ToCString(), leaves.size());
    if (inserted) {
      leaves.push_back(label);
      leaf_names.push_back(part_name());
    }
    const gp_Trsf& trsf = location.Transformation();
    if (std::abs(trsf.ScaleFactor() - 1.0) > 1e-9) {
      diagnostics.push_back({Severity::Warning, file, 0, -1,
                             "instance " + path + " is placed with scale factor " + std::to_string(trsf.ScaleFactor()) +
                                 "; the scale is dropped from its pose"});
    }
    Instance instance;
    instance.path = path;
    instance.part = static_cast<PartId>(it->second);
    const Pose pose = pose_of_transformation(trsf);
    for (int r = 0; r < 3; ++r) {
      if (in_supported_range(pose.translation()[r])) continue;
      char value[40];
      std::snprintf(value, sizeof value, "%.6g", pose.translation()[r]);
      diagnostics.push_back({Severity::Error, file, 0, -1,
                             "instance " + path + " is placed " + value +
                                 " mm from the origin, outside the supported range (magnitude <= 2^128, about "
                                 "3.4e38 mm); the instance is dropped"});
      return;
    }
    instance.pose = pose;
    instances.push_back(std::move(instance));
    chains.push_back(chain);
  }
};

// Face colours of a part: a face's own colour (`side`'s first), else the colour of the nearest
// enclosing shape (shell, solid, compound) that has one.
std::unordered_map<const void*, std::array<float, 3>> part_face_colours(
    const TDF_Label& label, const std::vector<std::pair<const void*, std::array<float, 3>>>* side) {
  std::unordered_map<const void*, std::array<float, 3>> out;
  if (side != nullptr)
    for (const auto& [face, rgb] : *side) out.try_emplace(face, rgb);
  XCAFPrs_IndexedDataMapOfShapeStyle styles;
  try {
    XCAFPrs::CollectStyleSettings(label, TopLoc_Location(), styles);
  } catch (const Standard_Failure&) {
    return out;
  }
  std::vector<Standard_Integer> order;
  for (Standard_Integer i = 1; i <= styles.Extent(); ++i) order.push_back(i);
  // Most specific first: TopAbs_FACE > SHELL > SOLID > COMPSOLID > COMPOUND in the enum.
  std::stable_sort(order.begin(), order.end(), [&](Standard_Integer a, Standard_Integer b) {
    return styles.FindKey(a).ShapeType() > styles.FindKey(b).ShapeType();
  });
  for (Standard_Integer i : order) {
    const XCAFPrs_Style& style = styles.FindFromIndex(i);
    if (!style.IsSetColorSurf()) continue;
    Standard_Real r = 0, g = 0, b = 0;
    style.GetColorSurf().Values(r, g, b, Quantity_TOC_sRGB);
    TopTools_IndexedMapOfShape faces;
    TopExp::MapShapes(styles.FindKey(i), TopAbs_FACE, faces);
    for (Standard_Integer f = 1; f <= faces.Extent(); ++f)
      out.try_emplace(faces(f).TShape().get(), std::array<float, 3>{static_cast<float>(r), static_cast<float>(g), static_cast<float>(b)});
  }
  return out;
}

}  // namespace

FaceEntityMap map_face_entities(const Handle(Transfer_TransientProcess)& process, const FaceEntityFn& describe,
                                const std::vector<FaceTag>& extra) {
  FaceEntityMap map;
  if (process.IsNull()) return map;
  // Entities whose result is exactly one face claim it first; an entity whose result holds several
  // faces (a shell, a solid, a face split by healing) only tags faces no face entity claimed.
  for (int pass = 0; pass < 2; ++pass) {
    for (const FaceTag& tag : extra)
      if (tag.single == (pass == 0)) map.try_emplace(tag.tshape, tag.entity);
    for (Standard_Integer i = 1; i <= process->NbMapped(); ++i) {
      const Handle(Standard_Transient)& entity = process->Mapped(i);
      const TopoDS_Shape shape = TransferBRep::ShapeResult(process->MapItem(i));
      if (shape.IsNull() || (shape.ShapeType() == TopAbs_FACE) != (pass == 0)) continue;
      FaceEntity info;
      if (entity.IsNull() || !describe(entity, info)) continue;
      TopTools_IndexedMapOfShape faces;
      TopExp::MapShapes(shape, TopAbs_FACE, faces);
      for (Standard_Integer f = 1; f <= faces.Extent(); ++f) map.try_emplace(faces(f).TShape().get(), info);
    }
  }
  return map;
}

std::size_t append_checks(const Interface_CheckIterator& checks, const Handle(Interface_InterfaceModel)& model,
                          const EntityLabelFn& label, const std::string& file, const std::string& what,
                          bool warnings, std::vector<Diagnostic>& out, std::size_t limit) {
  std::size_t fails = 0, appended = 0, dropped = 0;
  for (checks.Start(); checks.More(); checks.Next()) {
    const Handle(Interface_Check)& check = checks.Value();
    if (check.IsNull()) continue;
    std::int64_t id = -1;
    Handle(Standard_Transient) entity = check->Entity();
    if (entity.IsNull() && !model.IsNull() && checks.Number() > 0 && checks.Number() <= model->NbEntities())
      entity = model->Value(checks.Number());
    if (!entity.IsNull()) id = label(entity);
    auto add = [&](Severity severity, const char* text) {
      if (appended >= limit) {
        ++dropped;
        return;
      }
      out.push_back({severity, file, 0, id, what + ": " + text});
      ++appended;
    };
    for (Standard_Integer i = 1; i <= check->NbFails(); ++i) {
      ++fails;
      add(Severity::Error, check->CFail(i));
    }
    if (warnings)
      for (Standard_Integer i = 1; i <= check->NbWarnings(); ++i) add(Severity::Warning, check->CWarning(i));
  }
  if (dropped > 0)
    out.push_back({fails > 0 ? Severity::Error : Severity::Warning, file, 0, -1,
                   what + ": " + std::to_string(dropped) + " more messages not listed"});
  return fails;
}

WalkedDocument walk_xcaf_document(const Handle(TDocStd_Document)& doc, const std::string& file, SourceKind kind,
                                  const FaceEntityMap& faces, const std::vector<SideColour>& side, bool stored_locations) {
  WalkedDocument out;
  std::unordered_map<std::string, std::vector<std::pair<const void*, std::array<float, 3>>>> side_of;  // by part
  for (const SideColour& c : side) side_of[c.part].emplace_back(c.face.TShape().get(), c.rgb);
  Walker walker{XCAFDoc_DocumentTool::ShapeTool(doc->Main()), file, {}, {}, {}, {}, {}, out.diagnostics};
  if (stored_locations) walker.stored.emplace();
  TDF_LabelSequence roots;
  walker.shapes->GetFreeShapes(roots);
  std::vector<std::string> names;
  for (Standard_Integer i = 1; i <= roots.Length(); ++i) names.push_back(path_component(label_name(roots(i))));
  const std::vector<std::string> components = sibling_components(names);
  for (Standard_Integer i = 1; i <= roots.Length(); ++i)
    walker.visit(roots(i), TopLoc_Location(), "/" + components[static_cast<std::size_t>(i - 1)], 0);

  out.parts.resize(walker.leaves.size());
  for (std::size_t p = 0; p < walker.leaves.size(); ++p) {
    const TDF_Label& label = walker.leaves[p];
    WalkedPart& part = out.parts[p];
    part.shape = XCAFDoc_ShapeTool::GetShape(label);
    part.name = walker.leaf_names[p];
    if (part.name.empty()) part.name = "part" + std::to_string(p);
    const std::unordered_map<const void*, std::array<float, 3>> colours = [&] {
      if (side_of.empty()) return part_face_colours(label, nullptr);
      TCollection_AsciiString entry;
      TDF_Tool::Entry(label, entry);
      const auto it = side_of.find(entry.ToCString());
      return part_face_colours(label, it == side_of.end() ? nullptr : &it->second);
    }();
    TopTools_IndexedMapOfShape face_map;
    if (!part.shape.IsNull()) TopExp::MapShapes(part.shape, TopAbs_FACE, face_map);
    part.tags.resize(static_cast<std::size_t>(face_map.Extent()));
    std::size_t untagged = 0;
    for (Standard_Integer f = 1; f <= face_map.Extent(); ++f) {
      BrepFaceTag& tag = part.tags[static_cast<std::size_t>(f - 1)];
      const void* key = face_map(f).TShape().get();
      if (auto it = faces.find(key); it != faces.end()) {
        tag.entity_id = it->second.id;
        tag.name = it->second.name;
      } else {
        ++untagged;
      }
      if (auto it = colours.find(key); it != colours.end()) tag.colour = it->second;
    }
    if (face_map.Extent() == 0)
      out.diagnostics.push_back({Severity::Warning, file, 0, -1, "part '" + part.name + "' has no faces"});
    if (untagged > 0 && kind != SourceKind::BrepFace)
      out.diagnostics.push_back({Severity::Warning, file, 0, -1,
                                 "part '" + part.name + "': " + std::to_string(untagged) +
                                     " faces could not be traced to a file entity"});
  }
  for (WalkedPart& part : out.parts) {
    if (!part.shape.IsNull()) continue;
    part.dropped = true;
    out.diagnostics.push_back({Severity::Error, file, 0, -1, "part '" + part.name + "' has no shape; dropped"});
    out.complete = false;
  }
  out.instances = std::move(walker.instances);
  out.chains = std::move(walker.chains);
  return out;
}

void add_walked_document(WalkedDocument&& walked, const std::string& file, SourceKind kind, const ImportOptions& options,
                         ImportResult& result, BrepPartTimings* timings, std::vector<std::vector<std::string>>* chains) {
  result.diagnostics.insert(result.diagnostics.end(), std::make_move_iterator(walked.diagnostics.begin()),
                            std::make_move_iterator(walked.diagnostics.end()));
  result.complete = result.complete && walked.complete;
  std::vector<BrepPartInput> inputs;
  std::vector<std::size_t> input_of;
  std::vector<std::string> packed;  // per input, when the parts came packed apart
  std::vector<TopoDS_Shape> unpacked;
  bool apart = false;
  for (std::size_t p = 0; p < walked.parts.size(); ++p) {
    WalkedPart& part = walked.parts[p];
    if (part.dropped) continue;
    apart = apart || !part.packed.empty();
    input_of.push_back(p);
    BrepPartInput& in = inputs.emplace_back();
    in.shape = &part.shape;
    in.name = std::move(part.name);
    in.source_file = file;
    in.kind = kind;
    in.tags = std::move(part.tags);
  }
  std::optional<PackedShapes> shapes;
  if (apart) {
    packed.reserve(inputs.size());
    unpacked.resize(inputs.size());
    for (std::size_t k = 0; k < inputs.size(); ++k) {
      WalkedPart& part = walked.parts[input_of[k]];
      packed.push_back(std::move(part.packed));
      unpacked[k] = part.shape;
      inputs[k].shape = &unpacked[k];
    }
    shapes = PackedShapes{packed, unpacked};
  }
  std::size_t cached = 0;
  auto record = std::make_shared<CacheRecord>();
  record->dir = options.cache_dir;
  record->max_bytes = options.cache_max_bytes;
  const std::vector<PartId> ids = add_brep_parts_cached(result.model, inputs, options, result.diagnostics, result.complete,
                                                        timings, &cached, record.get(), shapes ? &*shapes : nullptr);
  if (!result.files.empty()) {
    result.files.back().parts_cached = cached;
    if (!record->parts.empty() || !record->part_keys.empty()) result.files.back().cache_record = std::move(record);
  }
  std::vector<PartId> id_of_leaf(walked.parts.size(), kInvalidId);
  for (std::size_t k = 0; k < ids.size(); ++k) id_of_leaf[input_of[k]] = ids[k];
  for (std::size_t k = 0; k < walked.instances.size(); ++k) {
    Instance& instance = walked.instances[k];
    const PartId id = id_of_leaf[instance.part];
    if (id == kInvalidId) continue;  // its part was dropped and reported in the walk
    instance.part = id;
    result.model.instances.push_back(std::move(instance));
    if (chains) chains->push_back(std::move(walked.chains[k]));
  }
}

std::string cad_file_stem(const std::string& path) { return std::filesystem::path(path).stem().string(); }

namespace {

thread_local bool t_transfer_healing = true;

// OCCT's STEP and IGES actors heal each transferred shape through the global algorithm container's
// ProcessShape; this one runs it only when the reading thread asks for it. A container, not a
// resource file: Interface_Static's sequence names are global to the process, and the resource
// manager ShapeProcess loads is a static shared by every thread.
//
// OCCT takes the healing's parameters from the resource file the environment names for the
// reader's resource ("STEP": CSF_STEPDefaults; "IGES": CSF_IGESDefaults) and heals with its own
// defaults when none is named (Debian names none). Asked for a resource no environment names, it
// always heals with those defaults: the same file gives the same faces on every machine.
constexpr const char* kNoHealingResource = "cadclash-default-healing";

class SwitchedHealing final : public XSAlgo_AlgoContainer {
 public:
  TopoDS_Shape ProcessShape(const TopoDS_Shape& shape, const Standard_Real precision, const Standard_Real max_tolerance,
                            const Standard_CString /*resource*/, const Standard_CString sequence,
                            Handle(Standard_Transient)& info, const Message_ProgressRange& progress,
                            const Standard_Boolean non_manifold) const override {
    if (!t_transfer_healing) return shape;
    return XSAlgo_AlgoContainer::ProcessShape(shape, precision, max_tolerance, kNoHealingResource, sequence, info,
                                              progress, non_manifold);
  }
};

}  // namespace

void prepare_occt_exchange() {
  static std::once_flag once;
  std::call_once(once, [] {
    const Handle(Message_Messenger)& messenger = Message::DefaultMessenger();
    if (!messenger.IsNull()) messenger->RemovePrinters(STANDARD_TYPE(Message_PrinterOStream));
    XSAlgo::Init();  // ShapeAlgo::Init() too
    XSAlgo::SetAlgoContainer(new SwitchedHealing);
    // The healing's ShapeFix_Shape works in a context that does not walk a face's unchanged wires
    // once per wire (transfer_fix_context.h): the same shapes, a drilled board plate's transfer
    // in half the time.
    ShapeAlgo::AlgoContainer()->SetToolContainer(transfer_fix_tools());
  });
}

TransferHealing::TransferHealing(bool on) : before_(t_transfer_healing) { t_transfer_healing = on; }
TransferHealing::~TransferHealing() { t_transfer_healing = before_; }
bool transfer_healing_on() { return t_transfer_healing; }

}  // namespace cadclash::detail
