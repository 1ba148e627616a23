// Poses recomputed from a STEP file's numbers (step_placements.h).
#include "step_placements.h"
#include "step_statements.h"

#include <Geom_Axis2Placement.hxx>
#include <Geom_Direction.hxx>
#include <Interface_EntityIterator.hxx>
#include <Interface_Graph.hxx>
#include <Precision.hxx>
#include <STEPConstruct_Assembly.hxx>
#include <StepGeom_Axis2Placement3d.hxx>
#include <StepGeom_CartesianPoint.hxx>
#include <StepGeom_Direction.hxx>
#include <StepGeom_CartesianTransformationOperator3d.hxx>
#include <StepRepr_ItemDefinedTransformation.hxx>
#include <StepRepr_NextAssemblyUsageOccurrence.hxx>
#include <StepRepr_ProductDefinitionShape.hxx>
#include <StepRepr_Representation.hxx>
#include <StepRepr_ShapeRepresentationRelationshipWithTransformation.hxx>
#include <StepShape_ContextDependentShapeRepresentation.hxx>
#include <TDF_Label.hxx>
#include <TDF_Tool.hxx>
#include <TopLoc_Location.hxx>
#include <TransferBRep.hxx>
#include <XCAFDoc_DocumentTool.hxx>
#include <XCAFDoc_ShapeTool.hxx>
#include <gp.hxx>
#include <gp_Ax3.hxx>

#include <openssl/evp.h>

#include <algorithm>
#include <cassert>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <map>
#include <memory>
#include <set>
#include <unordered_set>

namespace cadclash::detail {
namespace {

AxisIds axis_ids(const Handle(StepGeom_Axis2Placement3d)& a, const EntityLabelFn& label) {
  AxisIds out;
  out.id = label(a);
  if (!a->Location().IsNull()) out.location = label(a->Location());
  if (a->HasAxis() && !a->Axis().IsNull()) out.axis = label(a->Axis());
  if (a->HasRefDirection() && !a->RefDirection().IsNull()) out.ref = label(a->RefDirection());
  return out;
}

bool holds(const Handle(StepRepr_Representation)& rep, const Handle(Standard_Transient)& item) {
  if (rep.IsNull()) return false;
  for (Standard_Integer i = 1; i <= rep->NbItems(); ++i)
    if (rep->ItemsValue(i) == item) return true;
  return false;
}

void write_axis(ByteWriter& w, const AxisIds& a) {
  w.i64(a.id);
  w.i64(a.location);
  w.i64(a.axis);
  w.i64(a.ref);
}

AxisIds read_axis(ByteReader& r) {
  AxisIds a;
  a.id = r.i64();
  a.location = r.i64();
  a.axis = r.i64();
  a.ref = r.i64();
  return a;
}

void write_components(ByteWriter& w, const std::vector<ComponentPlacement>& c) {
  w.u64(c.size());
  for (const ComponentPlacement& p : c) {
    w.str(p.label);
    write_axis(w, p.origin);
    write_axis(w, p.target);
    w.u64(p.inverted ? 1 : 0);
  }
}

bool read_components(ByteReader& r, std::vector<ComponentPlacement>& c) {
  c.resize(r.count(8 * 9));
  for (ComponentPlacement& p : c) {
    p.label = r.str();
    p.origin = read_axis(r);
    p.target = read_axis(r);
    p.inverted = r.u64() == 1;
  }
  return r.ok;
}

// StepToGeom::MakeAxis2Placement on the numbers (OCCT 7.6), the length factor 1: a file in other
// units than millimetres fails the check of the poses it was read with and is never recomputed.
Handle(Geom_Axis2Placement) make_axis(const AxisIds& a, const PlacementValues& values) {
  const auto point = values.find(a.location);
  if (point == values.end()) return nullptr;
  const gp_Pnt p(point->second[0], point->second[1], point->second[2]);
  // StepToGeom::MakeDirection: no direction of an infinite or null vector.
  auto direction = [&](std::int64_t id) -> Handle(Geom_Direction) {
    const auto it = values.find(id);
    if (it == values.end()) return nullptr;
    const auto [x, y, z] = it->second;
    if (Precision::IsInfinite(x) || Precision::IsInfinite(y) || Precision::IsInfinite(z)) return nullptr;
    if (!(gp_XYZ(x, y, z).SquareModulus() > gp::Resolution() * gp::Resolution())) return nullptr;
    return new Geom_Direction(x, y, z);
  };
  gp_Dir n(0., 0., 1.);
  if (a.axis >= 0)
    if (const Handle(Geom_Direction) d = direction(a.axis); !d.IsNull()) n = d->Dir();
  gp_Ax2 ax2;
  bool fallback = true;
  if (a.ref >= 0) {
    if (const Handle(Geom_Direction) d = direction(a.ref); !d.IsNull()) {
      const gp_Dir vx = d->Dir();
      if (!n.IsParallel(vx, Precision::Angular())) {
        ax2 = gp_Ax2(p, n, vx);
        fallback = false;
      }
    }
  }
  if (fallback) ax2 = gp_Ax2(p, n);
  return new Geom_Axis2Placement(ax2);
}

// The component's location: STEPControl_ActorRead's ComputeTransformation and ApplyTransformation,
// and with `stored` as the document brought back from the isolated reader's child has it.
std::optional<TopLoc_Location> component_location(const ComponentPlacement& c, const PlacementValues& values, bool stored) {
  const Handle(Geom_Axis2Placement) origin = make_axis(c.origin, values);
  const Handle(Geom_Axis2Placement) target = make_axis(c.target, values);
  if (origin.IsNull() || target.IsNull()) return std::nullopt;
  const gp_Ax3 from(origin->Ax2());
  const gp_Ax3 to(target->Ax2());
  gp_Trsf trsf;
  trsf.SetTransformation(to, from);
  if (trsf.Form() == gp_Identity) return TopLoc_Location();
  if (c.inverted) trsf.Invert();
  if (stored) {
    // As the XCAF document's binary format reads a location back (BinTools_LocationSet): from the
    // twelve values, which SetValues normalises (a reflection's scale of -1 becomes +1 and its
    // matrix negated: the same values, other signs of zero in what is made of them).
    gp_Trsf read;
    read.SetValues(trsf.Value(1, 1), trsf.Value(1, 2), trsf.Value(1, 3), trsf.Value(1, 4), trsf.Value(2, 1), trsf.Value(2, 2),
                   trsf.Value(2, 3), trsf.Value(2, 4), trsf.Value(3, 1), trsf.Value(3, 2), trsf.Value(3, 3), trsf.Value(3, 4));
    return TopLoc_Location(read);
  }
  return TopLoc_Location(trsf);
}


// "(x,y,z)" at text[i] (spaces allowed around the numbers): the three numbers and the position
// after ')'; nullopt otherwise.
std::optional<std::pair<std::array<double, 3>, std::size_t>> three_numbers(std::string_view text, std::size_t i) {
  if (i >= text.size() || text[i] != '(') return std::nullopt;
  const std::size_t close = text.find(')', i);
  if (close == std::string_view::npos) return std::nullopt;
  const std::string inside(text.substr(i + 1, close - i - 1));
  std::array<double, 3> v{};
  const char* at = inside.c_str();
  for (int k = 0; k < 3; ++k) {
    char* end = nullptr;
    v[static_cast<std::size_t>(k)] = std::strtod(at, &end);
    if (end == at) return std::nullopt;
    at = end;
    while (step_space(*at)) ++at;
    if (k < 2 && *at++ != ',') return std::nullopt;
  }
  if (*at != '\0') return std::nullopt;
  return std::pair{v, close + 1};
}

// A SHA-256 fed piece by piece.
class Hasher {
 public:
  Hasher() : ctx_(EVP_MD_CTX_new(), EVP_MD_CTX_free) { EVP_DigestInit_ex(ctx_.get(), EVP_sha256(), nullptr); }
  void add(std::string_view s) { EVP_DigestUpdate(ctx_.get(), s.data(), s.size()); }
  std::string hex() {
    unsigned char d[EVP_MAX_MD_SIZE];
    unsigned int n = 0;
    EVP_DigestFinal_ex(ctx_.get(), d, &n);
    static constexpr char digits[] = "0123456789abcdef";
    std::string out;
    for (unsigned int k = 0; k < n; ++k) {
      out += digits[d[k] >> 4];
      out += digits[d[k] & 15];
    }
    return out;
  }

 private:
  std::unique_ptr<EVP_MD_CTX, void (*)(EVP_MD_CTX*)> ctx_;
};

}  // namespace

std::optional<std::vector<ComponentPlacement>> component_placements(const Handle(TDocStd_Document)& doc,
                                                                    const Handle(Transfer_TransientProcess)& process,
                                                                    const XCAFDoc_DataMapOfShapeLabel& shapes,
                                                                    const EntityLabelFn& label) {
  if (doc.IsNull() || process.IsNull() || process->Model().IsNull()) return std::nullopt;
  const Handle(XCAFDoc_ShapeTool) tool = XCAFDoc_DocumentTool::ShapeTool(doc->Main());
  const Interface_Graph& graph = process->Graph();
  const Handle(Interface_InterfaceModel) model = process->Model();
  std::vector<ComponentPlacement> out;
  std::set<std::string> seen;
  for (Standard_Integer e = 1; e <= model->NbEntities(); ++e) {
    const Handle(StepRepr_NextAssemblyUsageOccurrence) nauo = Handle(StepRepr_NextAssemblyUsageOccurrence)::DownCast(model->Value(e));
    if (nauo.IsNull()) continue;
    // The occurrence's shape relationship, found as STEPControl_ActorRead finds it.
    Handle(StepShape_ContextDependentShapeRepresentation) cdsr;
    std::size_t found = 0;
    for (Interface_EntityIterator pds = graph.Sharings(nauo); pds.More(); pds.Next()) {
      if (!pds.Value()->IsKind(STANDARD_TYPE(StepRepr_ProductDefinitionShape))) continue;
      for (Interface_EntityIterator c = graph.Sharings(pds.Value()); c.More(); c.Next()) {
        const auto one = Handle(StepShape_ContextDependentShapeRepresentation)::DownCast(c.Value());
        if (one.IsNull()) continue;
        cdsr = one;
        ++found;
      }
    }
    if (found != 1 || cdsr->RepresentationRelation().IsNull()) return std::nullopt;
    const auto rr = Handle(StepRepr_ShapeRepresentationRelationshipWithTransformation)::DownCast(cdsr->RepresentationRelation());
    if (rr.IsNull()) return std::nullopt;
    const Handle(StepRepr_ItemDefinedTransformation) idt = rr->TransformationOperator().ItemDefinedTransformation();
    if (idt.IsNull()) return std::nullopt;
    Handle(StepGeom_Axis2Placement3d) origin = Handle(StepGeom_Axis2Placement3d)::DownCast(idt->TransformItem1());
    Handle(StepGeom_Axis2Placement3d) target = Handle(StepGeom_Axis2Placement3d)::DownCast(idt->TransformItem2());
    if (origin.IsNull() || target.IsNull()) return std::nullopt;
    // ComputeTransformation's correction of axes given in each other's representation.
    const bool ok_origin = holds(rr->Rep1(), origin), ok_target = holds(rr->Rep2(), target);
    if ((!ok_origin || !ok_target) && holds(rr->Rep2(), origin) && holds(rr->Rep1(), target)) std::swap(origin, target);
    const Handle(Transfer_Binder) binder = process->Find(nauo);
    if (binder.IsNull() || !binder->HasResult()) return std::nullopt;
    const TopoDS_Shape shape = TransferBRep::ShapeResult(process, binder);
    // As STEPCAFControl_Reader::FindInstance finds it.
    TDF_Label component;
    if (shape.IsNull()) return std::nullopt;
    if (shapes.IsBound(shape)) component = shapes(shape);
    else if (!tool->Search(shape, component, Standard_True, Standard_True, Standard_False)) return std::nullopt;
    if (!XCAFDoc_ShapeTool::IsComponent(component)) return std::nullopt;
    TCollection_AsciiString entry;
    TDF_Tool::Entry(component, entry);
    if (!seen.insert(entry.ToCString()).second) return std::nullopt;
    ComponentPlacement p;
    p.label = entry.ToCString();
    p.origin = axis_ids(origin, label);
    p.target = axis_ids(target, label);
    p.inverted = STEPConstruct_Assembly::CheckSRRReversesNAUO(graph, cdsr) == Standard_True;
    if (p.origin.location < 0 || p.target.location < 0) return std::nullopt;
    out.push_back(std::move(p));
  }
  return out;
}

void write_component_placements(ByteWriter& w, const std::optional<std::vector<ComponentPlacement>>& c) {
  w.u64(c ? 1 : 0);
  if (c) write_components(w, *c);
}

bool read_component_placements(ByteReader& r, std::optional<std::vector<ComponentPlacement>>& c) {
  c.reset();
  if (r.u64() != 1) return r.ok;
  return read_components(r, c.emplace());
}

std::vector<std::int64_t> Placements::value_ids() const {
  std::set<std::int64_t> ids;
  for (const ComponentPlacement& c : components)
    for (const AxisIds& a : {c.origin, c.target})
      for (const std::int64_t id : {a.location, a.axis, a.ref})
        if (id >= 0) ids.insert(id);
  return {ids.begin(), ids.end()};
}

std::vector<std::int64_t> Placements::axis_ids() const {
  std::set<std::int64_t> ids;
  for (const ComponentPlacement& c : components) ids.insert({c.origin.id, c.target.id});
  return {ids.begin(), ids.end()};
}

std::optional<Placements> file_placements(const std::vector<ComponentPlacement>& placed,
                                          const std::vector<std::vector<std::string>>& chains) {
  std::map<std::string, std::uint32_t> index;
  Placements out;
  for (const ComponentPlacement& c : placed) index.emplace(c.label, static_cast<std::uint32_t>(index.size()));
  out.components = placed;
  for (const std::vector<std::string>& chain : chains) {
    std::vector<std::uint32_t>& ids = out.chains.emplace_back();
    for (const std::string& entry : chain) {
      const auto it = index.find(entry);
      if (it == index.end()) return std::nullopt;
      ids.push_back(it->second);
    }
  }
  return out;
}

std::string save_placements(const Placements& p) {
  ByteWriter w;
  write_components(w, p.components);
  w.u64(p.stored ? 1 : 0);
  w.u64(p.chains.size());
  for (const auto& chain : p.chains) {
    w.u64(chain.size());
    for (const std::uint32_t c : chain) w.u64(c);
  }
  return std::move(w.out);
}

bool load_placements(std::string_view bytes, Placements& p) {
  ByteReader r{bytes};
  if (!read_components(r, p.components)) return false;
  p.stored = r.u64() == 1;
  p.chains.resize(r.count(8));
  for (auto& chain : p.chains) {
    chain.resize(r.count(8));
    for (std::uint32_t& c : chain) {
      const std::uint64_t v = r.u64();
      if (v >= p.components.size()) return false;
      c = static_cast<std::uint32_t>(v);
    }
  }
  return r.ok && r.at == bytes.size();
}

std::optional<std::vector<Pose>> placement_poses(const Placements& p, const PlacementValues& values) {
  std::vector<TopLoc_Location> locations;
  locations.reserve(p.components.size());
  for (const ComponentPlacement& c : p.components) {
    std::optional<TopLoc_Location> l = component_location(c, values, p.stored);
    if (!l) return std::nullopt;
    locations.push_back(*l);
  }
  std::vector<Pose> out;
  out.reserve(p.chains.size());
  for (const auto& chain : p.chains) {
    // Composed as the walk composes them: from the root down.
    TopLoc_Location location;
    for (const std::uint32_t c : chain) location = location * locations[c];
    const gp_Trsf& trsf = location.Transformation();
    if (std::abs(trsf.ScaleFactor() - 1.0) > 1e-9) return std::nullopt;
    const Pose pose = pose_of_transformation(trsf);
    for (int r = 0; r < 3; ++r)
      if (!in_supported_range(pose.translation()[r])) return std::nullopt;
    out.push_back(pose);
  }
  return out;
}

namespace {

bool ends_with(std::string_view s, std::string_view tail) {
  return s.size() >= tail.size() && s.substr(s.size() - tail.size()) == tail;
}

}  // namespace

namespace {

// One pass over the text: the numbers of the statements `ids` and where they stand, and, with
// `axes`, which of them place occurrences and nothing else (free_values); nullopt when the text
// cannot be scanned or one of `ids` is missing or not a CARTESIAN_POINT / DIRECTION('name',(x,y,z)).
// A set of ids asked for every statement and reference of the text: a bitmap over the ids up to the
// largest (a few MB at most), where hashing each of millions of ids was most of a pass.
class IdSet {
 public:
  explicit IdSet(std::span<const std::int64_t> ids) {
    std::int64_t largest = -1;
    for (const std::int64_t id : ids) largest = std::max(largest, id);
    if (largest >= 0 && largest < (std::int64_t{1} << 27)) {
      bits_.assign(static_cast<std::size_t>(largest) + 1, false);
      for (const std::int64_t id : ids)
        if (id >= 0 && !bits_[static_cast<std::size_t>(id)]) {
          bits_[static_cast<std::size_t>(id)] = true;
          ++size_;
        }
    } else {
      sparse_.insert(ids.begin(), ids.end());
      size_ = sparse_.size();
    }
  }
  std::size_t size() const { return size_; }  // distinct ids
  bool count(std::int64_t id) const {
    if (!sparse_.empty()) return sparse_.count(id) > 0;
    return id >= 0 && static_cast<std::size_t>(id) < bits_.size() && bits_[static_cast<std::size_t>(id)];
  }

 private:
  std::vector<bool> bits_;
  std::unordered_set<std::int64_t> sparse_;
  std::size_t size_ = 0;
};

struct NumberScan {
  PlacementValues values;
  std::map<std::size_t, std::pair<std::size_t, std::int64_t>> spans;  // by where the numbers begin: their end and id
  std::vector<std::int64_t> free;                                    // with axes: ascending
};
std::optional<NumberScan> scan_numbers(std::string_view text, std::span<const std::int64_t> ids,
                                       std::span<const std::int64_t> axes) {
  const IdSet wanted(ids), axis_set(axes);
  NumberScan out;
  std::unordered_set<std::int64_t> bound;  // values referenced by a statement other than an axis
  std::unordered_set<std::int64_t> fixed;  // axes referenced by a statement that uses them for more than placing occurrences
  std::unordered_map<std::int64_t, std::vector<std::int64_t>> of_axis;  // the values each axis references
  std::vector<std::int64_t> refs;  // the statement's, as they are read
  const auto statement = [&](const StatementSpan& s) {
    if (!axes.empty()) {
      const bool axis = axis_set.count(s.id) > 0;
      // An axis placement that is an item of a shape representation and used by an item-defined
      // transformation is skipped by OCCT's transfer of the representation: it places nothing else.
      const bool places_only = s.type == "ITEM_DEFINED_TRANSFORMATION" ||
                               (ends_with(s.type, "SHAPE_REPRESENTATION") && s.type != "CONTEXT_DEPENDENT_SHAPE_REPRESENTATION");
      for (const std::int64_t ref : refs) {
        if (wanted.count(ref)) {
          if (axis) of_axis[s.id].push_back(ref);
          else bound.insert(ref);
        }
        if (axis_set.count(ref) && !places_only) fixed.insert(ref);
      }
      refs.clear();
    }
    if (!wanted.count(s.id)) return true;
    // TYPE('name',(x,y,z))
    if (s.type != "CARTESIAN_POINT" && s.type != "DIRECTION") return false;
    const std::size_t end = s.end;
    std::size_t i = s.after_type;
    auto skip = [&] {
      while (i < end && step_space(text[i])) ++i;
    };
    skip();
    if (i >= end || text[i++] != '(') return false;
    skip();
    if (i >= end || text[i] != '\'') return false;
    for (++i; i < end; ++i)
      if (text[i] == '\'') {
        if (i + 1 < end && text[i + 1] == '\'') ++i;
        else break;
      }
    ++i;
    skip();
    if (i >= end || text[i++] != ',') return false;
    skip();
    const auto numbers = three_numbers(text.substr(0, end), i);
    if (!numbers || !out.values.emplace(s.id, numbers->first).second) return false;  // not three numbers, or defined twice
    out.spans.emplace(i, std::pair{numbers->second, s.id});
    return true;
  };
  std::string why;
  const auto reference = [&](std::int64_t ref) {
    if (!axes.empty()) refs.push_back(ref);
  };
  if (!for_each_statement(text, statement, reference, why) || out.values.size() != wanted.size()) return std::nullopt;
  if (!axes.empty()) {
    for (const auto& [axis, refs_of] : of_axis)
      if (fixed.count(axis)) bound.insert(refs_of.begin(), refs_of.end());
    for (const std::int64_t id : ids)
      if (!bound.count(id)) out.free.push_back(id);
    std::sort(out.free.begin(), out.free.end());
  }
  return out;
}

// SHA-256 (hex) of the text with the numbers of `free` left out.
std::string skeleton_of(std::string_view text, const NumberScan& scan, std::span<const std::int64_t> free) {
  const std::unordered_set<std::int64_t> left_out(free.begin(), free.end());
  Hasher hash;
  std::size_t kept = 0;  // the text before this is hashed (or left out)
  for (const auto& [begin, to] : scan.spans) {
    if (!left_out.count(to.second)) continue;
    hash.add(text.substr(kept, begin - kept));
    hash.add("()");
    kept = to.first;
  }
  hash.add(text.substr(kept));
  return hash.hex();
}

}  // namespace

std::optional<FreePlacementText> free_placement_text(std::string_view text, std::span<const std::int64_t> ids,
                                                     std::span<const std::int64_t> axes) {
  assert(!axes.empty());
  std::optional<NumberScan> scan = scan_numbers(text, ids, axes);
  if (!scan) return std::nullopt;
  FreePlacementText out;
  out.free = std::move(scan->free);
  out.text.skeleton = skeleton_of(text, *scan, out.free);
  out.text.values = std::move(scan->values);
  return out;
}

std::optional<PlacementText> placement_text(std::string_view text, std::span<const std::int64_t> ids,
                                            std::span<const std::int64_t> free) {
  std::optional<NumberScan> scan = scan_numbers(text, ids, {});
  if (!scan) return std::nullopt;
  PlacementText out;
  out.skeleton = skeleton_of(text, *scan, free);
  out.values = std::move(scan->values);
  return out;
}

}  // namespace cadclash::detail
