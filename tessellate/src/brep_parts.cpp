// add_brep_parts: B-rep shapes into parts and surfaces (healing, exact boxes, eager tessellation).
#include "brep_internal.h"

#include "cadclash/internal/progress_meter.h"

#include <BRepAdaptor_Surface.hxx>
#include <BRepCheck_Analyzer.hxx>
#include <BRepLib.hxx>
#include <BRepTools.hxx>
#include <BRep_Tool.hxx>
#include <BRep_Builder.hxx>
#include <ShapeFix_Face.hxx>
#include <Standard_Failure.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopTools_ListOfShape.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Compound.hxx>

#include <algorithm>
#include <cassert>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <exception>
#include <mutex>
#include <shared_mutex>

namespace cadclash {
namespace {

constexpr double kNearMiss = 4.0;

// ShapeFix_Face on an invalid face; returns true and replaces `face` when the fix changed it.
bool heal_face(TopoDS_Face& face) {
  try {
    ShapeFix_Face fix(face);
    fix.Perform();
    TopoDS_Face fixed = fix.Face();
    if (fixed.IsNull() || fixed.IsSame(face)) return false;
    fixed.Orientation(face.Orientation());
    face = fixed;
    return true;
  } catch (const Standard_Failure&) {
    return false;
  }
}

// Why the face's triangles may not match the file exactly: it failed BRepCheck, and ShapeFix_Face
// changed it (valid now or not) or could not.
std::string heal_message(const std::string& part, std::size_t face, bool changed, bool valid) {
  std::string m = "face " + std::to_string(face) + " of part '" + part + "' failed BRepCheck; ";
  if (!changed) return m + "ShapeFix_Face could not change it, so it is tessellated as read";
  return m + (valid ? "healed with ShapeFix_Face" : "ShapeFix_Face changed it but it is still invalid");
}

std::string failure_message(const BrepSource::Impl& impl, std::size_t face, const std::string& why) {
  return "face " + std::to_string(face) + " of part '" + impl.part_name + "' could not be tessellated (" + why +
         "); its surface is kept without triangles";
}

}  // namespace

namespace {

// STEP files carry no parameter curves for edges on planes: OCCT projects the edge onto the plane
// every time one is asked for (BRep_Tool::CurveOnPlane), and the face classifier behind the witness
// queries asks on every call near an edge. Stored once here, before anything reads the faces in
// parallel, they are the same curves OCCT would compute (and BRepMesh reads the same ones).
void store_plane_pcurves(const std::vector<TopoDS_Face>& faces) {
  for (const TopoDS_Face& face : faces) {
    try {
      if (BRepAdaptor_Surface(face, Standard_False).GetType() != GeomAbs_Plane) continue;
      TopTools_ListOfShape edges;
      for (TopExp_Explorer e(face, TopAbs_EDGE); e.More(); e.Next()) edges.Append(e.Current());
      BRepLib::BuildPCurveForEdgesOnPlane(edges, face);
    } catch (const Standard_Failure&) {
      // Left as it was: OCCT computes the curves on demand, as before.
    }
  }
}

// Healing: only faces BRepCheck rejects are touched, one at a time, so face indices and the file's
// entity ids stay attached to the same faces. Per face: 1 when it was healed.
// Faces marked in `far` (a vertex past the supported range: dropped with an error once their exact
// boxes are taken) are neither checked nor healed.
std::vector<char> heal_invalid_faces(const BrepPartInput& in, BrepSource::Impl& impl, const std::vector<char>& far,
                                     bool parallel, std::vector<Diagnostic>& diagnostics) {
  const std::size_t n = impl.faces.size();
  std::vector<char> healed(n, 0);
  const bool any_far = std::any_of(far.begin(), far.end(), [](char c) { return c != 0; });
  // One check of the whole part, and the faces one by one only when it fails. A part holding a face
  // with many wires (a board plate with its holes) is checked face by face at once: the whole
  // part's check would compare all of that face's wires pairwise, and only faces are healed here,
  // so the faces' verdicts decide the same.
  const bool by_face = any_far || std::any_of(impl.faces.begin(), impl.faces.end(), detail::face_has_many_wires);
  bool whole_valid = false;
  if (!by_face) {
    try {
      whole_valid = BRepCheck_Analyzer(*in.shape, Standard_True).IsValid() == Standard_True;
    } catch (const Standard_Failure&) {
    }
  }
  if (whole_valid) return healed;
  // The faces' checks only read them (BRepCheck runs its own in parallel on one shape's faces);
  // on threads when this part is checked alone (a re-run whose one changed part is a drilled
  // board plate: its two large faces and its holes' walls). The healing writes: in face order.
  std::vector<char> valid(n, 1);
#pragma omp parallel for schedule(dynamic, 1) if (parallel && n > 1)
  for (std::ptrdiff_t k = 0; k < static_cast<std::ptrdiff_t>(n); ++k) {
    const auto i = static_cast<std::size_t>(k);
    if (!far[i]) valid[i] = detail::face_is_valid(impl.faces[i]) ? 1 : 0;
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (far[i] || valid[i]) continue;
    healed[i] = heal_face(impl.faces[i]) ? 1 : 0;
    const bool fixed = healed[i] != 0 && detail::face_is_valid(impl.faces[i]);
    diagnostics.push_back(Diagnostic{Severity::Warning, in.source_file, 0, impl.entity_ids[i],
                                     heal_message(in.name, i, healed[i] != 0, fixed)});
  }
  return healed;
}

// The triangles of every face of the part at `deflection` (eager import): faces left without them
// are listed as errors and make the import incomplete.
void mesh_faces(BrepSource::Impl& impl, double deflection, const TessellationOptions& options,
                const detail::MeshDeadline& deadline, std::span<Surface> surfaces, std::vector<Diagnostic>& diagnostics,
                bool& complete) {
  const std::size_t n = impl.faces.size();
  // One BRepMesh call over all faces of the part: shared edges are discretised once and BRepMesh
  // spreads the faces over threads.
  TopoDS_Compound compound;
  BRep_Builder builder;
  builder.MakeCompound(compound);
  for (std::size_t i = 0; i < n; ++i)
    if (!impl.outside_range[i]) builder.Add(compound, impl.faces[i]);
  std::string why;
  const bool meshed =
      detail::run_brepmesh(compound, deflection, options.angular_deflection, options.parallel, why, deadline);
  (void)meshed;  // faces left without triangles are retried one by one below

  std::vector<char> good(n, 0);
#pragma omp parallel for schedule(dynamic, 4) if (options.parallel && n > 8)
  for (std::ptrdiff_t k = 0; k < static_cast<std::ptrdiff_t>(n); ++k) {
    const auto i = static_cast<std::size_t>(k);
    if (impl.outside_range[i]) {  // dropped in prepare_part: stays without triangles
      good[i] = 1;
      continue;
    }
    double achieved = 0.0;
    if (detail::read_face_triangles(impl.faces[i], options.verify_deflection, surfaces[i].mesh, achieved)) {
      surfaces[i].deflection = achieved;
      // A near miss is re-meshed finer below; a face whose measured error is far above the request
      // (large trimmed NURBS faces, where a finer BRepMesh costs minutes) keeps its honest figure.
      good[i] = !options.verify_deflection || achieved <= deflection || achieved > kNearMiss * deflection ? 1 : 0;
    }
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (good[i] == 0) {
      double achieved = 0.0;
      std::string face_why;
      if (detail::mesh_face_to(impl.faces[i], deflection, options.angular_deflection, options.verify_deflection,
                               surfaces[i].mesh, achieved, face_why, deadline)) {
        surfaces[i].deflection = achieved;
        good[i] = 1;
      } else {
        surfaces[i].mesh = {};
        diagnostics.push_back(Diagnostic{Severity::Error, impl.source_file, 0, impl.entity_ids[i],
                                         failure_message(impl, i, face_why.empty() ? why : face_why)});
        complete = false;
      }
    }
    if (good[i] != 0) {
      // A plane bounded by lines: its triangles are the face; what BRepMesh or the centroid
      // measure reports is rounding.
      if (surfaces[i].exact_triangles) surfaces[i].deflection = 0.0;
      surfaces[i].has_triangles = true;
      surfaces[i].aabb.extend(mesh_aabb(surfaces[i].mesh));
    }
  }
}

}  // namespace

namespace {

// One part on its way into the model: made by prepare_part, meshed by mesh_faces, appended in input
// order, so the model and the diagnostics are the same whether parts are done in parallel or not.
struct PartWork {
  std::unique_ptr<BrepSource::Impl> impl;
  std::vector<Surface> surfaces;
  std::vector<Diagnostic> diagnostics;
  bool complete = true;
  double deflection = 0.0;
};

// Faces whose exact box reaches past cadclash::kMaxLength (model.h) are dropped, each with an error
// naming its entity and the coordinate: no query could certify an answer about them. They keep
// their index and an empty box and get no triangles.
void drop_faces_outside_range(const BrepPartInput& in, BrepSource::Impl& impl, PartWork& w) {
  const std::size_t n = impl.faces.size();
  impl.outside_range.assign(n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    const Aabb& b = impl.boxes[i];
    if (b.isEmpty()) continue;
    const double largest = std::max(b.min().cwiseAbs().maxCoeff(), b.max().cwiseAbs().maxCoeff());
    if (in_supported_range(largest)) continue;
    impl.outside_range[i] = 1;
    impl.boxes[i] = Aabb();
    char value[40];
    std::snprintf(value, sizeof value, "%.6g", largest);
    w.diagnostics.push_back(Diagnostic{Severity::Error, in.source_file, 0, impl.entity_ids[i],
                                       "face " + std::to_string(i) + " of part '" + in.name + "' reaches a coordinate of " +
                                           value + " mm, outside the supported range (magnitude <= 2^128, about 3.4e38 "
                                           "mm); the face is dropped"});
    w.complete = false;
  }
}

// Faces, healing, exact boxes and face facts of one part, whose id will be `part_id`.
void prepare_part(const BrepPartInput& in, const TessellationOptions& options, PartId part_id, PartWork& w) {
  assert(in.shape != nullptr);
  w.impl = std::make_unique<BrepSource::Impl>();
  BrepSource::Impl& impl = *w.impl;
  impl.part_name = in.name;
  impl.source_file = in.source_file;
  impl.angular_deflection = options.angular_deflection;
  impl.verify_deflection = options.verify_deflection;

  TopTools_IndexedMapOfShape map;
  TopExp::MapShapes(*in.shape, TopAbs_FACE, map);
  const auto n = static_cast<std::size_t>(map.Extent());
  impl.faces.reserve(n);
  for (Standard_Integer i = 1; i <= map.Extent(); ++i) impl.faces.push_back(TopoDS::Face(map(i)));
  impl.entity_ids.resize(n, -1);
  for (std::size_t i = 0; i < n && i < in.tags.size(); ++i) impl.entity_ids[i] = in.tags[i].entity_id;

  // A face with a vertex past the supported range is dropped below (drop_faces_outside_range): no
  // BRepCheck warning about a face that is not kept.
  std::vector<char> far(n, 0);
  for (std::size_t i = 0; i < n; ++i)
    for (TopExp_Explorer ex(impl.faces[i], TopAbs_VERTEX); ex.More() && !far[i]; ex.Next()) {
      const gp_Pnt p = BRep_Tool::Pnt(TopoDS::Vertex(ex.Current()));
      far[i] = !in_supported_range(std::max({std::abs(p.X()), std::abs(p.Y()), std::abs(p.Z())}));
    }
  const std::vector<char> healed = heal_invalid_faces(in, impl, far, options.parallel, w.diagnostics);
  store_plane_pcurves(impl.faces);

  impl.boxes.resize(n);
  Aabb part_box;
#pragma omp parallel for schedule(dynamic, 8) if (options.parallel && n > 16)
  for (std::ptrdiff_t i = 0; i < static_cast<std::ptrdiff_t>(n); ++i)
    impl.boxes[static_cast<std::size_t>(i)] = detail::face_aabb(impl.faces[static_cast<std::size_t>(i)]);
  drop_faces_outside_range(in, impl, w);
  for (const Aabb& b : impl.boxes)
    if (!b.isEmpty()) part_box.extend(b);
  w.deflection = options.linear_deflection;
  if (options.relative) {
    const double diagonal = part_box.isEmpty() ? 0.0 : part_box.diagonal().norm();
    w.deflection = diagonal > 0.0 ? options.linear_deflection * diagonal : options.linear_deflection;
  }
  impl.default_deflection = w.deflection;

  w.surfaces.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    Surface& s = w.surfaces[i];
    s.name = "face" + std::to_string(i);
    s.part = part_id;
    s.provenance.kind = in.kind;
    s.provenance.source_file = in.source_file;
    s.provenance.face_index = static_cast<std::int32_t>(i);
    s.provenance.healed = healed[i] != 0;
    if (i < in.tags.size()) {
      s.provenance.step_id = in.tags[i].entity_id;
      s.provenance.source_name = in.tags[i].name;
      s.provenance.colour = in.tags[i].colour;
    }
    s.aabb = impl.boxes[i];
    if (impl.outside_range[i]) {
      s.has_triangles = true;  // none: the face is left out of every query
      continue;
    }
    detail::describe_face(impl.faces[i], s);
  }
  impl.exact_faces.resize(n);
  for (std::size_t i = 0; i < n; ++i) impl.exact_faces[i] = w.surfaces[i].exact_triangles ? 1 : 0;
}

// Whether two of the parts share an edge: healing and the plane pcurves write into edges, so such
// parts are done one after another. Parts of a file are distinct shapes, but a file may let two
// products reach one edge entity.
template <class Shapes>
bool shapes_share_edges(const Shapes& shapes) {
  TopTools_IndexedMapOfShape all;
  int sum = 0;
  for (const TopoDS_Shape& shape : shapes) {
    TopTools_IndexedMapOfShape edges;
    TopExp::MapShapes(shape, TopAbs_EDGE, edges);
    sum += edges.Extent();
    for (Standard_Integer e = 1; e <= edges.Extent(); ++e) all.Add(edges(e));
  }
  return all.Extent() != sum;
}


// A part's faces as one compound (what its edges are).
TopoDS_Shape faces_compound(const BrepSource::Impl& impl) {
  TopoDS_Compound compound;
  BRep_Builder builder;
  builder.MakeCompound(compound);
  for (const TopoDS_Face& f : impl.faces) builder.Add(compound, f);
  return compound;
}

// f(0) ... f(n - 1), on OpenMP threads when `parallel` (a part per thread at a time: the OpenMP loops
// inside a part then run on that thread, BRepMesh's own threads still in parallel). What f throws
// is thrown again here, the first part's first.
template <class F>
void for_each_part(std::size_t n, bool parallel, const F& f) {
  std::vector<std::exception_ptr> failed(n);
#pragma omp parallel for schedule(dynamic, 1) if (parallel && n > 1)
  for (std::ptrdiff_t k = 0; k < static_cast<std::ptrdiff_t>(n); ++k) {
    try {
      f(static_cast<std::size_t>(k));
    } catch (...) {
      failed[static_cast<std::size_t>(k)] = std::current_exception();
    }
  }
  for (const std::exception_ptr& e : failed)
    if (e) std::rethrow_exception(e);
}

}  // namespace

std::vector<PartId> add_brep_parts(Model& model, std::span<const BrepPartInput> parts,
                                   const TessellationOptions& options, bool lazy,
                                   std::vector<Diagnostic>& diagnostics, bool& complete, BrepPartTimings* timings,
                                   std::vector<std::size_t>* diagnostics_per_part) {
  assert(options.linear_deflection > 0.0);
  for (const BrepPartInput& in : parts) assert(in.shape != nullptr), (void)in;
  using Clock = std::chrono::steady_clock;
  auto seconds_since = [](Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); };
  const detail::MeshDeadline deadline = detail::MeshDeadline::after(options.time_limit_seconds);
  const bool in_parallel = options.parallel && parts.size() > 1 && !brep_inputs_share_edges(parts);
  const auto first_id = static_cast<PartId>(model.parts.size());
  std::vector<PartWork> work(parts.size());

  const Clock::time_point heal_start = Clock::now();
  std::vector<double> part_heal(parts.size(), 0.0);
  {
    detail::ProgressMeter meter(&options.progress, ProgressStage::CheckPart, parts.size(),
                                parts.empty() ? std::string() : parts.front().name);
    for_each_part(parts.size(), in_parallel, [&](std::size_t k) {
      const Clock::time_point part_start = Clock::now();
      prepare_part(parts[k], options, static_cast<PartId>(first_id + k), work[k]);
      part_heal[k] = seconds_since(part_start);
      meter.add(1, parts[k].name);
    });
    meter.finish();
  }
  if (timings) {
    timings->heal += seconds_since(heal_start);
    timings->part_heal.insert(timings->part_heal.end(), part_heal.begin(), part_heal.end());
  }

  const Clock::time_point mesh_start = Clock::now();
  if (!lazy) {
    detail::ProgressMeter meter(&options.progress, ProgressStage::TessellatePart, parts.size(),
                                parts.empty() ? std::string() : parts.front().name);
    for_each_part(parts.size(), in_parallel, [&](std::size_t k) {
      PartWork& w = work[k];
      if (!w.surfaces.empty())
        mesh_faces(*w.impl, w.deflection, options, deadline, w.surfaces, w.diagnostics, w.complete);
      meter.add(1, parts[k].name);
    });
    meter.finish();
  }
  if (timings) timings->tessellate += seconds_since(mesh_start);

  std::vector<PartId> ids;
  ids.reserve(parts.size());
  for (std::size_t k = 0; k < parts.size(); ++k) {
    PartWork& w = work[k];
    diagnostics.insert(diagnostics.end(), w.diagnostics.begin(), w.diagnostics.end());
    if (diagnostics_per_part) diagnostics_per_part->push_back(w.diagnostics.size());
    complete = complete && w.complete;
    Part part;
    part.name = parts[k].name;
    part.source_file = parts[k].source_file;
    part.first_surface = static_cast<SurfaceId>(model.surfaces.size());
    part.surface_count = static_cast<std::uint32_t>(w.surfaces.size());
    part.source = std::make_shared<BrepSource>(std::move(w.impl));
    ids.push_back(static_cast<PartId>(model.parts.size()));
    model.parts.push_back(std::move(part));
    for (Surface& s : w.surfaces) model.surfaces.push_back(std::move(s));
  }
  return ids;
}

namespace {

// The part's BrepSource when it has one (a B-rep part), else null.
BrepSource* brep_source_of(const Model& model, PartId p) {
  return dynamic_cast<BrepSource*>(model.parts[p].source.get());
}

bool holds_triangles(const Model& model, PartId p) {
  const Part& part = model.parts[p];
  for (SurfaceId s = part.first_surface; s < part.first_surface + part.surface_count; ++s)
    if (model.surfaces[s].has_triangles) return true;
  return false;
}

}  // namespace

std::size_t tessellate_parts(Model& model, std::span<const PartId> parts, std::vector<Diagnostic>& diagnostics,
                             bool& complete) {
  std::vector<PartId> todo;
  std::vector<BrepSource*> sources;
  for (PartId p : parts) {
    assert(p < model.parts.size());
    BrepSource* source = brep_source_of(model, p);
    if (source == nullptr || model.parts[p].surface_count == 0 || holds_triangles(model, p)) continue;
    if (std::find(todo.begin(), todo.end(), p) != todo.end()) continue;
    todo.push_back(p);
    sources.push_back(source);
  }
  std::vector<TopoDS_Shape> shapes;
  for (BrepSource* source : sources) shapes.push_back(faces_compound(*source->impl_));
  const bool in_parallel = todo.size() > 1 && !shapes_share_edges(shapes);
  std::vector<std::vector<Diagnostic>> found(todo.size());
  std::vector<char> whole(todo.size(), 1);
  for_each_part(todo.size(), in_parallel, [&](std::size_t k) {
    BrepSource::Impl& impl = *sources[k]->impl_;
    const Part& part = model.parts[todo[k]];
    TessellationOptions options;  // what add_brep_parts was given, as the source keeps it
    options.linear_deflection = impl.default_deflection;
    options.angular_deflection = impl.angular_deflection;
    options.verify_deflection = impl.verify_deflection;
    bool part_complete = true;
    std::lock_guard<std::shared_mutex> lock(impl.mutex);
    mesh_faces(impl, impl.default_deflection, options, detail::MeshDeadline{},
               std::span<Surface>(model.surfaces).subspan(part.first_surface, part.surface_count), found[k],
               part_complete);
    whole[k] = part_complete ? 1 : 0;
  });
  for (std::size_t k = 0; k < todo.size(); ++k) {
    diagnostics.insert(diagnostics.end(), found[k].begin(), found[k].end());
    complete = complete && whole[k] != 0;
  }
  return todo.size();
}

void release_part_triangles(Model& model, std::span<const PartId> parts) {
  for (PartId p : parts) {
    assert(p < model.parts.size());
    BrepSource* source = brep_source_of(model, p);
    if (source == nullptr) continue;
    BrepSource::Impl& impl = *source->impl_;
    {
      std::lock_guard<std::shared_mutex> lock(impl.mutex);
      for (const TopoDS_Face& f : impl.faces) BRepTools::Clean(f);
    }
    const Part& part = model.parts[p];
    for (SurfaceId s = part.first_surface; s < part.first_surface + part.surface_count; ++s) {
      model.surfaces[s].mesh = TriangleMesh{};
      model.surfaces[s].has_triangles = false;
    }
  }
}

bool brep_parts_share_edges(const Model& model) {
  std::vector<TopoDS_Shape> shapes;
  for (PartId p = 0; p < model.parts.size(); ++p)
    if (const BrepSource* source = brep_source_of(model, p)) shapes.push_back(faces_compound(*source->impl_));
  return shapes_share_edges(shapes);
}

bool brep_inputs_share_edges(std::span<const BrepPartInput> parts) {
  std::vector<TopoDS_Shape> shapes;
  for (const BrepPartInput& in : parts) shapes.push_back(*in.shape);
  return shapes_share_edges(shapes);
}

}  // namespace cadclash
