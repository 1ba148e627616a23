// Shape representations transferred in forked workers and bound back (step_parallel_transfer.h).
#include "step_parallel_transfer.h"

#include "cadclash/internal/byte_io.h"
#include "isolated_run.h"

#include <BRep_Builder.hxx>
#include <BinTools.hxx>
#include <Interface_CheckIterator.hxx>
#include <Interface_EntityIterator.hxx>
#include <Interface_Graph.hxx>
#include <Standard_Failure.hxx>
#include <StepBasic_DimensionalExponents.hxx>
#include <StepBasic_MeasureWithUnit.hxx>
#include <StepBasic_NamedUnit.hxx>
#include <StepGeom_CartesianPoint.hxx>
#include <StepGeom_Direction.hxx>
#include <StepGeom_Placement.hxx>
#include <StepGeom_Vector.hxx>
#include <StepRepr_CharacterizedDefinition.hxx>
#include <StepRepr_PropertyDefinition.hxx>
#include <StepRepr_RepresentationContext.hxx>
#include <StepRepr_RepresentationItem.hxx>
#include <StepRepr_RepresentedDefinition.hxx>
#include <StepRepr_ShapeAspect.hxx>
#include <StepShape_NonManifoldSurfaceShapeRepresentation.hxx>
#include <StepShape_ShapeDefinitionRepresentation.hxx>
#include <StepShape_ShapeRepresentation.hxx>
#include <TopExp.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS_Compound.hxx>
#include <TopoDS_Iterator.hxx>
#include <TransferBRep.hxx>
#include <TransferBRep_ShapeBinder.hxx>
#include <Transfer_ActorOfTransientProcess.hxx>
#include <Transfer_TransientProcess.hxx>
#include <XSControl_TransferReader.hxx>

#include <algorithm>
#include <iterator>
#include <numeric>
#include <sstream>
#include <unordered_set>
#include <vector>

namespace cadclash::detail {
namespace {

// Entities that many representations share without sharing any topology: coordinates, directions,
// placements, contexts and units. OCCT makes new objects of them for every use, so two
// representations that meet only there can be transferred apart.
bool shared_without_topology(const Handle(Standard_Transient)& e) {
  return e->IsKind(STANDARD_TYPE(StepGeom_CartesianPoint)) || e->IsKind(STANDARD_TYPE(StepGeom_Direction)) ||
         e->IsKind(STANDARD_TYPE(StepGeom_Vector)) || e->IsKind(STANDARD_TYPE(StepGeom_Placement)) ||
         e->IsKind(STANDARD_TYPE(StepRepr_RepresentationContext)) || e->IsKind(STANDARD_TYPE(StepBasic_NamedUnit)) ||
         e->IsKind(STANDARD_TYPE(StepBasic_MeasureWithUnit)) || e->IsKind(STANDARD_TYPE(StepBasic_DimensionalExponents));
}

// Whether a shape definition describes a shape aspect with this representation: OCCT skips such a
// representation when its items are already made (a sub-shape of the product's shape) and adds it
// otherwise, so binding its items ahead would change what OCCT makes.
bool describes_shape_aspect(const Interface_Graph& graph, const Handle(Standard_Transient)& rep) {
  for (Interface_EntityIterator it = graph.Sharings(rep); it.More(); it.Next()) {
    const Handle(StepShape_ShapeDefinitionRepresentation) sdr =
        Handle(StepShape_ShapeDefinitionRepresentation)::DownCast(it.Value());
    if (sdr.IsNull()) continue;
    const Handle(StepRepr_PropertyDefinition) property = sdr->Definition().PropertyDefinition();
    if (!property.IsNull() && !property->Definition().ShapeAspect().IsNull()) return true;
  }
  return false;
}

struct Groups {
  std::vector<std::vector<Standard_Integer>> reps;  // per group, entity numbers of its representations, ascending
  std::vector<std::size_t> cost;                    // per group, entities its items reach
};

// The file's shape representations that OCCT would make shapes of, grouped so that no two groups
// reach a common entity (beyond shared_without_topology ones). Empty with `why` when some
// representation must stay with the reader.
Groups group_representations(const Handle(StepData_StepModel)& model, const Interface_Graph& graph,
                             const Handle(Transfer_ActorOfTransientProcess)& actor, std::string& why) {
  const Standard_Integer n = model->NbEntities();
  std::vector<Standard_Integer> reps, aspects;
  for (Standard_Integer e = 1; e <= n; ++e) {
    const Handle(Standard_Transient)& entity = model->Value(e);
    if (!entity->IsKind(STANDARD_TYPE(StepShape_ShapeRepresentation)) || !actor->Recognize(entity)) continue;
    if (entity->IsKind(STANDARD_TYPE(StepShape_NonManifoldSurfaceShapeRepresentation))) {
      why = "a non-manifold surface representation is healed as a whole";
      return {};
    }
    (describes_shape_aspect(graph, entity) ? aspects : reps).push_back(e);
  }
  // Union-find over the representations, joined where their items reach one entity.
  std::vector<std::size_t> parent(reps.size());
  std::iota(parent.begin(), parent.end(), 0);
  auto root = [&parent](std::size_t r) {
    while (parent[r] != r) r = parent[r] = parent[parent[r]];
    return r;
  };
  std::vector<std::int64_t> owner(static_cast<std::size_t>(n) + 1, -1);
  std::vector<std::size_t> reached(reps.size(), 0);
  std::vector<Handle(Standard_Transient)> stack;
  for (std::size_t r = 0; r < reps.size(); ++r) {
    const Handle(StepRepr_Representation) rep = Handle(StepRepr_Representation)::DownCast(model->Value(reps[r]));
    if (rep->Items().IsNull()) continue;
    for (Standard_Integer i = 1; i <= rep->NbItems(); ++i) stack.push_back(rep->ItemsValue(i));
    while (!stack.empty()) {
      const Handle(Standard_Transient) e = stack.back();
      stack.pop_back();
      const Standard_Integer number = e.IsNull() ? 0 : model->Number(e);
      if (number <= 0 || shared_without_topology(e)) continue;
      std::int64_t& own = owner[static_cast<std::size_t>(number)];
      if (own == static_cast<std::int64_t>(r)) continue;
      if (own >= 0) {
        parent[root(static_cast<std::size_t>(own))] = root(r);
        continue;  // the rest below it is the owner's, now joined
      }
      own = static_cast<std::int64_t>(r);
      ++reached[r];
      for (Interface_EntityIterator it = graph.Shareds(e); it.More(); it.Next()) stack.push_back(it.Value());
    }
  }
  // A shape aspect's representation (validation properties) names items of the product's own
  // representation, which OCCT has made by then: it finds them made and skips the aspect, as it does
  // when they were bound here. One with items no other representation reaches would be added.
  for (const Standard_Integer a : aspects) {
    const Handle(StepRepr_Representation) rep = Handle(StepRepr_Representation)::DownCast(model->Value(a));
    for (Standard_Integer i = 1; !rep->Items().IsNull() && i <= rep->NbItems(); ++i) {
      const Handle(StepRepr_RepresentationItem) item = rep->ItemsValue(i);
      if (item.IsNull() || shared_without_topology(item)) continue;
      if (owner[static_cast<std::size_t>(model->Number(item))] < 0) {
        why = "a shape aspect has a representation with shapes of its own";
        return {};
      }
    }
  }
  // A representation reached from another's items (a mapped item's) is that one's.
  for (std::size_t r = 0; r < reps.size(); ++r)
    if (const std::int64_t own = owner[static_cast<std::size_t>(reps[r])]; own >= 0 && own != static_cast<std::int64_t>(r))
      parent[root(static_cast<std::size_t>(own))] = root(r);
  Groups groups;
  std::vector<std::int64_t> group_of(reps.size(), -1);
  for (std::size_t r = 0; r < reps.size(); ++r) {
    std::int64_t& g = group_of[root(r)];
    if (g < 0) {
      g = static_cast<std::int64_t>(groups.reps.size());
      groups.reps.emplace_back();
      groups.cost.push_back(0);
    }
    groups.reps[static_cast<std::size_t>(g)].push_back(reps[r]);
    groups.cost[static_cast<std::size_t>(g)] += reached[r];
  }
  return groups;
}

// The groups spread over `workers` by largest first onto the least loaded (ties: lower index),
// each worker's representations in file order.
std::vector<std::vector<Standard_Integer>> assign(const Groups& groups, std::size_t workers) {
  std::vector<std::size_t> order(groups.reps.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return groups.cost[a] > groups.cost[b]; });
  std::vector<std::vector<Standard_Integer>> share(workers);
  std::vector<std::size_t> load(workers, 0);
  for (const std::size_t g : order) {
    const auto w = static_cast<std::size_t>(std::min_element(load.begin(), load.end()) - load.begin());
    load[w] += groups.cost[g] + 1;
    share[w].insert(share[w].end(), groups.reps[g].begin(), groups.reps[g].end());
  }
  for (auto& s : share) std::sort(s.begin(), s.end());
  return share;
}

bool excluded_from_bindings(const Handle(Standard_Transient)& e) {
  // Representations are the reader's to make (with the placements of its own transfer path);
  // placement items give no shape.
  return e->IsKind(STANDARD_TYPE(StepRepr_Representation)) || e->IsKind(STANDARD_TYPE(StepGeom_Placement));
}

// In the worker: transfers `reps` and returns what was bound, as bytes ("" when a fail was reported).
std::string transfer_share(const Handle(StepData_StepModel)& model, const Handle(XSControl_WorkSession)& ws,
                           const std::vector<Standard_Integer>& reps) {
  const Handle(XSControl_TransferReader) reader = ws->TransferReader();
  for (const Standard_Integer r : reps) reader->TransferOne(model->Value(r), Standard_False);
  const Handle(Transfer_TransientProcess) process = reader->TransientProcess();
  if (process.IsNull() || !process->CheckList(Standard_True).IsEmpty(Standard_True)) return {};
  ShapeBindings out;
  for (Standard_Integer i = 1; i <= process->NbMapped(); ++i) {
    const Handle(Standard_Transient)& entity = process->Mapped(i);
    if (entity.IsNull() || excluded_from_bindings(entity)) continue;
    const TopoDS_Shape shape = TransferBRep::ShapeResult(process->MapItem(i));
    if (!shape.IsNull()) out.bind(model->Number(entity), shape);
  }
  return out.bytes();
}

}  // namespace

namespace {

// Styles as bytes: the face's index and orientation, which colours are set, their linear RGB (and
// the surface's alpha) as Quantity_Color holds them, so they come back bit for bit.
using IndexedStyle = std::pair<std::int64_t, FaceStyle>;

void write_rgb(ByteWriter& w, const Quantity_Color& c) {
  w.f64(c.Red());
  w.f64(c.Green());
  w.f64(c.Blue());
}

void write_styles(ByteWriter& w, const std::vector<IndexedStyle>& styles) {
  w.u64(styles.size());
  for (const auto& [index, s] : styles) {
    w.i64(index);
    w.u64(static_cast<std::uint64_t>(s.face.Orientation()));
    w.u64((s.surface ? 1u : 0u) | (s.boundary ? 2u : 0u) | (s.curve ? 4u : 0u));
    if (s.surface) {
      write_rgb(w, s.surface->GetRGB());
      w.f64(s.surface->Alpha());
    }
    if (s.boundary) write_rgb(w, *s.boundary);
    if (s.curve) write_rgb(w, *s.curve);
  }
}

std::optional<Quantity_Color> read_rgb(ByteReader& r) {
  const double red = r.f64(), green = r.f64(), blue = r.f64();
  auto unit = [](double v) { return v >= 0.0 && v <= 1.0; };
  if (!r.ok || !unit(red) || !unit(green) || !unit(blue)) {
    r.ok = false;
    return std::nullopt;
  }
  return Quantity_Color(red, green, blue, Quantity_TOC_RGB);
}

// Styles with `face` null and its orientation in `orientation`; false when the bytes are not whole.
bool read_styles(ByteReader& r, std::vector<IndexedStyle>& styles) {
  styles.resize(r.ok ? r.count(24) : 0);
  for (auto& [index, s] : styles) {
    index = r.i64();
    const std::uint64_t orientation = r.u64(), set = r.u64();
    if (!r.ok || orientation > TopAbs_EXTERNAL || set > 7) return r.ok = false;
    s.face.Orientation(static_cast<TopAbs_Orientation>(orientation));
    if ((set & 1u) != 0) {
      const std::optional<Quantity_Color> rgb = read_rgb(r);
      const double alpha = r.f64();
      if (!rgb || !r.ok || !(alpha >= 0.0 && alpha <= 1.0)) return r.ok = false;
      s.surface = Quantity_ColorRGBA(*rgb, static_cast<float>(alpha));
    }
    if ((set & 2u) != 0 && !(s.boundary = read_rgb(r))) return false;
    if ((set & 4u) != 0 && !(s.curve = read_rgb(r))) return false;
  }
  return r.ok;
}

}  // namespace

void ShapeBindings::bind(std::int64_t key, const TopoDS_Shape& shape) {
  bindings_.push_back({key, index_of(shape), static_cast<std::uint64_t>(shape.Orientation())});
}

void ShapeBindings::tag(const TopoDS_Shape& face, const FaceEntity& entity, bool single) {
  tags_.push_back({index_of(face), entity, single});
}

void ShapeBindings::style(const FaceStyle& style) {
  styles_.emplace_back(index_of(style.face), style);
}

std::int64_t ShapeBindings::index_of(const TopoDS_Shape& shape) {
  if (compound_.IsNull()) BRep_Builder().MakeCompound(compound_);
  if (!shapes_.Contains(shape)) {
    BRep_Builder().Add(compound_, shape);
    TopExp::MapShapes(shape, shapes_);
  }
  return shapes_.FindIndex(shape);
}

std::string ShapeBindings::bytes(double parse_seconds) const {
  ByteWriter w;
  w.f64(parse_seconds);
  w.u64(bindings_.size());
  for (const Binding& b : bindings_) {
    w.i64(b.key);
    w.i64(b.shape);
    w.u64(b.orientation);
  }
  w.u64(tags_.size());
  for (const Tag& t : tags_) {
    w.i64(t.shape);
    w.i64(t.entity.id);
    w.str(t.entity.name);
    w.u64(t.single ? 1 : 0);
  }
  write_styles(w, styles_);
  std::ostringstream stored;
  if (!compound_.IsNull()) BinTools::Write(compound_, stored, Standard_False, Standard_False, BinTools_FormatVersion_CURRENT);
  w.str(stored.str());
  std::string out = "O";  // two steps: GCC 12 warns falsely (-Wrestrict) on "O" + string
  out += w.out;
  return out;
}

bool read_bindings(const std::vector<ChildRun>& runs, ReadBindings& out, std::string& why) {
  for (const ChildRun& run : runs) {
    if (!run.isolated || run.crashed) {
      why = "a worker " + (run.isolated ? "crashed (" + run.how + ")" : "could not start (" + run.how + ")");
      return false;
    }
    if (!read_binding_bytes(run.payload, out, why)) return false;
  }
  return true;
}

namespace {

// ShapeBindings' bytes up to its shapes, and where the shapes start.
struct BindingHead {
  double parse_seconds = 0.0;
  std::vector<IndexedStyle> styles;
  struct Raw {
    std::int64_t key, shape;
    std::uint64_t orientation;
  };
  std::vector<Raw> bindings;
  struct RawTag {
    std::int64_t shape;
    FaceEntity entity;
    bool single;
  };
  std::vector<RawTag> tags;
};

bool read_head(ByteReader& r, BindingHead& h) {
  h.parse_seconds = r.f64();
  h.bindings.resize(r.ok ? r.count(24) : 0);
  for (BindingHead::Raw& b : h.bindings) b = {r.i64(), r.i64(), r.u64()};
  h.tags.resize(r.ok ? r.count(32) : 0);
  for (BindingHead::RawTag& t : h.tags) {
    t.shape = r.i64();
    t.entity.id = r.i64();
    t.entity.name = r.str();
    t.single = r.u64() == 1;
  }
  return read_styles(r, h.styles);
}

}  // namespace

bool read_binding_bytes(std::string_view payload, ReadBindings& out, std::string& why) {
  if (payload.empty() || payload[0] != 'O') {
    why = "a worker reported a failed entity";
    return false;
  }
  ByteReader r{payload.substr(1)};
  BindingHead head;
  read_head(r, head);
  out.parse_seconds = std::max(out.parse_seconds, head.parse_seconds);
  std::istringstream stored(r.str());
  TopoDS_Shape all;
  try {
    if (r.ok && !stored.str().empty()) BinTools::Read(all, stored);
  } catch (const Standard_Failure&) {
    r.ok = false;
  }
  if (!r.ok || r.at != payload.size() - 1) {
    why = "a worker's shapes came back incomplete";
    return false;
  }
  TopTools_IndexedMapOfShape shapes;
  if (!all.IsNull())
    for (TopoDS_Iterator it(all); it.More(); it.Next()) TopExp::MapShapes(it.Value(), shapes);
  auto valid = [&](std::int64_t i) { return i >= 1 && i <= shapes.Extent(); };
  for (const BindingHead::Raw& b : head.bindings) {
    if (!valid(b.shape) || b.orientation > TopAbs_EXTERNAL) {
      why = "a worker's shapes came back incomplete";
      return false;
    }
    out.shapes.emplace_back(b.key, shapes(static_cast<Standard_Integer>(b.shape)).Oriented(static_cast<TopAbs_Orientation>(b.orientation)));
  }
  for (BindingHead::RawTag& t : head.tags) {
    if (!valid(t.shape)) {
      why = "a worker's shapes came back incomplete";
      return false;
    }
    out.tags.push_back({shapes(static_cast<Standard_Integer>(t.shape)).TShape().get(), std::move(t.entity), t.single});
  }
  for (auto& [index, style] : head.styles) {
    if (!valid(index)) {
      why = "a worker's shapes came back incomplete";
      return false;
    }
    style.face = shapes(static_cast<Standard_Integer>(index)).Oriented(style.face.Orientation());
    out.styles.push_back(std::move(style));
  }
  out.keep.push_back(all);
  return true;
}

void append_bindings(ReadBindings& out, ReadBindings&& more) {
  auto append = [](auto& to, auto& from) {
    to.insert(to.end(), std::make_move_iterator(from.begin()), std::make_move_iterator(from.end()));
  };
  append(out.shapes, more.shapes);
  append(out.tags, more.tags);
  append(out.styles, more.styles);
  append(out.keep, more.keep);
  out.parse_seconds = std::max(out.parse_seconds, more.parse_seconds);
}

std::optional<std::string> renumber_bindings(std::string_view payload, const std::function<std::optional<std::int64_t>(std::int64_t)>& id) {
  if (payload.empty() || payload[0] != 'O') return std::nullopt;
  ByteReader r{payload.substr(1)};
  BindingHead head;
  if (!read_head(r, head)) return std::nullopt;
  const std::string shapes = r.str();
  if (!r.ok || r.at != payload.size() - 1) return std::nullopt;
  ByteWriter w;
  w.f64(0.0);
  w.u64(head.bindings.size());
  for (const BindingHead::Raw& b : head.bindings) {
    const std::optional<std::int64_t> key = id(b.key);
    if (!key) return std::nullopt;
    w.i64(*key);
    w.i64(b.shape);
    w.u64(b.orientation);
  }
  w.u64(head.tags.size());
  for (const BindingHead::RawTag& t : head.tags) {
    const std::optional<std::int64_t> entity = t.entity.id < 0 ? std::optional<std::int64_t>(t.entity.id) : id(t.entity.id);
    if (!entity) return std::nullopt;
    w.i64(t.shape);
    w.i64(*entity);
    w.str(t.entity.name);
    w.u64(t.single ? 1 : 0);
  }
  write_styles(w, head.styles);
  w.str(shapes);
  std::string out = "O";
  out += w.out;
  return out;
}

bool bind_all(const Handle(Transfer_TransientProcess)& process, const std::vector<Handle(Standard_Transient)>& entities,
              const std::vector<std::pair<std::int64_t, TopoDS_Shape>>& shapes, std::string& why) {
  std::unordered_set<const Standard_Transient*> seen;
  for (const Handle(Standard_Transient)& e : entities)
    if (e.IsNull() || !seen.insert(e.get()).second || process->IsBound(e)) {
      why = "two workers made one entity";
      return false;
    }
  for (std::size_t k = 0; k < entities.size(); ++k) process->Bind(entities[k], new TransferBRep_ShapeBinder(shapes[k].second));
  return true;
}

ParallelTransfer transfer_shapes_in_parallel(const Handle(StepData_StepModel)& model,
                                             const Handle(XSControl_WorkSession)& ws, std::size_t workers) {
  ParallelTransfer out;
  if (workers < 2) {
    out.why_not = "one worker";
    return out;
  }
  const Handle(XSControl_TransferReader) reader = ws->TransferReader();
  const Handle(Transfer_TransientProcess) process = reader.IsNull() ? nullptr : reader->TransientProcess();
  if (process.IsNull() || reader->Actor().IsNull()) {
    out.why_not = "no transfer process";
    return out;
  }
  // The graph the reader's transfer would build anyway, built once here and shared by the workers.
  const Interface_Graph& graph = ws->Graph();
  process->SetGraph(ws->HGraph());
  const Groups groups = group_representations(model, graph, reader->Actor(), out.why_not);
  out.groups = groups.reps.size();
  if (out.groups < 2) {
    if (out.why_not.empty()) out.why_not = out.groups == 0 ? "no shape representation" : "one group of shapes";
    return out;
  }
  const std::vector<std::vector<Standard_Integer>> share = assign(groups, std::min(workers, out.groups));
  const std::vector<ChildRun> runs = run_in_children(share.size(), [&](std::size_t k, const Mark&) {
    return transfer_share(model, ws, share[k]);
  });
  ReadBindings bound;
  if (!read_bindings(runs, bound, out.why_not)) return out;
  std::vector<Handle(Standard_Transient)> entities;
  for (const auto& [number, shape] : bound.shapes) {
    if (number < 1 || number > model->NbEntities()) {
      out.why_not = "a worker named an entity the file does not have";
      return out;
    }
    entities.push_back(model->Value(static_cast<Standard_Integer>(number)));
  }
  if (!bind_all(process, entities, bound.shapes, out.why_not)) return out;
  out.used = true;
  out.workers = share.size();
  return out;
}

}  // namespace cadclash::detail
