// save_brep_source / load_brep_source: a B-rep part's source as bytes, for the import cache.
#include "brep_internal.h"

#include "cadclash/internal/byte_io.h"

#include <BRep_Builder.hxx>
#include <BinTools.hxx>
#include <Standard_Failure.hxx>
#include <TopExp.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Compound.hxx>
#include <TopoDS_Iterator.hxx>

#include <cassert>
#include <sstream>

namespace cadclash {
namespace {

// "CCBREP" and the layout's version: bumped whenever the fields below change.
constexpr std::uint64_t kMagic = 0x0001'5045'5242'4343ULL;

}  // namespace

std::string save_brep_source(const BrepSource& source) {
  const BrepSource::Impl& impl = *source.impl_;
  const std::shared_lock<std::shared_mutex> lock(impl.mutex);
  detail::ByteWriter o;
  o.u64(kMagic);
  o.str(impl.part_name);
  o.str(impl.source_file);
  o.f64(impl.default_deflection);
  o.f64(impl.angular_deflection);
  o.u64(impl.verify_deflection ? 1 : 0);
  const std::size_t n = impl.faces.size();
  o.u64(n);
  for (std::size_t i = 0; i < n; ++i) {
    o.u64(static_cast<std::uint64_t>(impl.entity_ids[i]));
    o.u64((impl.exact_faces[i] != 0 ? 1 : 0) | (i < impl.outside_range.size() && impl.outside_range[i] ? 2 : 0));
    const Aabb& b = impl.boxes[i];
    for (int k = 0; k < 3; ++k) o.f64(b.min()[k]);
    for (int k = 0; k < 3; ++k) o.f64(b.max()[k]);
  }
  // The faces as one compound: edges and vertices they share stay shared, each face keeps its
  // location and orientation, and their triangulations (with parameters and the polygons on them)
  // come back bit for bit.
  TopoDS_Compound compound;
  BRep_Builder builder;
  builder.MakeCompound(compound);
  for (const TopoDS_Face& f : impl.faces) builder.Add(compound, f);
  std::ostringstream shape;
  BinTools::Write(compound, shape, Standard_True, Standard_True, BinTools_FormatVersion_CURRENT);
  o.str(shape.str());
  return std::move(o.out);
}

std::shared_ptr<BrepSource> load_brep_source(std::string_view bytes, std::string& why) {
  detail::ByteReader in{bytes};
  if (in.u64() != kMagic || !in.ok) {
    why = "not a stored B-rep part of this version";
    return nullptr;
  }
  auto impl = std::make_unique<BrepSource::Impl>();
  impl->part_name = in.str();
  impl->source_file = in.str();
  impl->default_deflection = in.f64();
  impl->angular_deflection = in.f64();
  impl->verify_deflection = in.u64() != 0;
  const std::uint64_t n = in.count(8 * 8);
  impl->entity_ids.resize(n);
  impl->exact_faces.resize(n);
  impl->outside_range.resize(n);
  impl->boxes.resize(n);
  for (std::size_t i = 0; i < n && in.ok; ++i) {
    impl->entity_ids[i] = static_cast<std::int64_t>(in.u64());
    const std::uint64_t flags = in.u64();
    impl->exact_faces[i] = (flags & 1) != 0 ? 1 : 0;
    impl->outside_range[i] = (flags & 2) != 0 ? 1 : 0;
    Vec3 lo, hi;
    for (int k = 0; k < 3; ++k) lo[k] = in.f64();
    for (int k = 0; k < 3; ++k) hi[k] = in.f64();
    impl->boxes[i] = Aabb(lo, hi);
  }
  const std::string shape_bytes = in.str();
  if (!in.ok || in.at != bytes.size()) {
    why = "the stored B-rep part is cut short or too long";
    return nullptr;
  }
  try {
    std::istringstream stream(shape_bytes);
    TopoDS_Shape compound;
    BinTools::Read(compound, stream);
    // The compound's direct children, in the order they were added (TopExp::MapShapes would merge
    // two faces that are the same face, which a part never holds but a damaged file might).
    for (TopoDS_Iterator it(compound); it.More(); it.Next()) {
      if (it.Value().ShapeType() != TopAbs_FACE) throw Standard_Failure("a stored face is not a face");
      impl->faces.push_back(TopoDS::Face(it.Value()));
    }
  } catch (const Standard_Failure& e) {
    why = std::string("OCCT could not read the stored faces: ") + e.GetMessageString();
    return nullptr;
  }
  if (impl->faces.size() != n) {
    why = "the stored B-rep part has " + std::to_string(impl->faces.size()) + " faces, its header says " + std::to_string(n);
    return nullptr;
  }
  return std::make_shared<BrepSource>(std::move(impl));
}

void relabel_brep_faces(BrepSource& source, std::span<const std::int64_t> entity_ids, const std::string& source_file) {
  BrepSource::Impl& impl = *source.impl_;
  assert(entity_ids.size() == impl.faces.size());
  const std::lock_guard<std::shared_mutex> lock(impl.mutex);
  impl.entity_ids.assign(entity_ids.begin(), entity_ids.end());
  impl.source_file = source_file;
}

}  // namespace cadclash
