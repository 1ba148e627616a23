// One file's ImportResult as bytes and back: the contents of an import cache entry.
#include "cadclash/internal/byte_io.h"
#include "import_cache.h"

namespace cadclash::detail {
namespace {

// A B-rep part whose file this process has not read (import_from_description): it knows the
// deflection its faces will be meshed at, which is all a plan asks of an unmeshed face.
class StandInSource final : public SurfaceSource {
 public:
  explicit StandInSource(double deflection) : deflection_(deflection) {}
  bool triangulate(std::uint32_t local_index, double, TriangleMesh&, double&, Diagnostic& error) override {
    error = {Severity::Error, {}, 0, -1,
             "face " + std::to_string(local_index) + ": its file was not read in this process"};
    return false;
  }
  double default_deflection() const override { return deflection_; }

 private:
  double deflection_;
};

void put_vec(ByteWriter& w, const Vec3& v) {
  for (int k = 0; k < 3; ++k) w.f64(v[k]);
}

Vec3 get_vec(ByteReader& r) {
  Vec3 v;
  for (int k = 0; k < 3; ++k) v[k] = r.f64();
  return v;
}

void put_surface(ByteWriter& w, const Surface& s) {
  w.str(s.name);
  w.u64(s.part);
  const Provenance& p = s.provenance;
  w.u64(static_cast<std::uint64_t>(p.kind));
  w.str(p.source_file);
  w.i64(p.step_id);
  w.i64(p.face_index);
  w.str(p.source_name);
  w.u64(p.parent);
  w.u64(p.colour ? 1 : 0);
  if (p.colour)
    for (const float c : *p.colour) w.f64(c);
  w.u64((p.healed ? 1 : 0) | (p.repaired ? 2 : 0) | (s.exact_triangles ? 4 : 0) | (s.has_triangles ? 8 : 0) |
        static_cast<std::uint64_t>(s.uncertainty_source) << 4);
  put_vec(w, s.aabb.min());
  put_vec(w, s.aabb.max());
  w.f64(s.deflection);
  w.f64(s.uncertainty);
  w.f64(s.tolerance);
  w.u64(static_cast<std::uint64_t>(s.analytic.shape));
  put_vec(w, s.analytic.origin);
  put_vec(w, s.analytic.axis);
  w.f64(s.analytic.radius);
  w.f64(s.analytic.radius2);
  w.u64(s.mesh.vertices.size());
  for (const Vec3& v : s.mesh.vertices) put_vec(w, v);
  w.u64(s.mesh.triangles.size());
  for (const auto& t : s.mesh.triangles) w.u64(std::uint64_t{t[0]} | std::uint64_t{t[1]} << 32), w.u64(t[2]);
}

bool get_surface(ByteReader& r, Surface& s) {
  s.name = r.str();
  s.part = static_cast<PartId>(r.u64());
  Provenance& p = s.provenance;
  const std::uint64_t kind = r.u64();
  if (kind > static_cast<std::uint64_t>(SourceKind::Segment)) return false;
  p.kind = static_cast<SourceKind>(kind);
  p.source_file = r.str();
  p.step_id = r.i64();
  p.face_index = static_cast<std::int32_t>(r.i64());
  p.source_name = r.str();
  p.parent = static_cast<SurfaceId>(r.u64());
  if (r.u64() != 0) {
    std::array<float, 3> c{};
    for (float& x : c) x = static_cast<float>(r.f64());
    p.colour = c;
  }
  const std::uint64_t flags = r.u64();
  p.healed = (flags & 1) != 0;
  p.repaired = (flags & 2) != 0;
  s.exact_triangles = (flags & 4) != 0;
  s.has_triangles = (flags & 8) != 0;
  const std::uint64_t source = flags >> 4 & 3;
  s.uncertainty_source = static_cast<UncertaintySource>(source);
  const Vec3 lo = get_vec(r), hi = get_vec(r);
  s.aabb = Aabb(lo, hi);
  s.deflection = r.f64();
  s.uncertainty = r.f64();
  s.tolerance = r.f64();
  const std::uint64_t shape = r.u64();
  if (shape > static_cast<std::uint64_t>(SurfaceShape::Torus)) return false;
  s.analytic.shape = static_cast<SurfaceShape>(shape);
  s.analytic.origin = get_vec(r);
  s.analytic.axis = get_vec(r);
  s.analytic.radius = r.f64();
  s.analytic.radius2 = r.f64();
  s.mesh.vertices.resize(r.count(24));
  for (Vec3& v : s.mesh.vertices) v = get_vec(r);
  s.mesh.triangles.resize(r.count(16));
  for (auto& t : s.mesh.triangles) {
    const std::uint64_t ab = r.u64(), c = r.u64();
    t = {static_cast<std::uint32_t>(ab), static_cast<std::uint32_t>(ab >> 32), static_cast<std::uint32_t>(c)};
    for (const std::uint32_t corner : t)
      if (corner >= s.mesh.vertices.size()) return false;
  }
  return r.ok;
}

}  // namespace

std::optional<std::string> save_import(const ImportResult& result, bool exact_faces, const PartEntries* in_entries) {
  ByteWriter w;
  write_diagnostics(w, result.diagnostics);
  w.u64(result.complete ? 1 : 0);
  const Model& m = result.model;
  for (const Part& part : m.parts)
    if (part.source && dynamic_cast<const BrepSource*>(part.source.get()) == nullptr) return std::nullopt;
  // The parts' exact faces written out on every thread (each part's on its own), then in order.
  auto entry_of = [&](const Part& part) -> const std::string* {
    if (in_entries == nullptr || !part.source) return nullptr;
    const auto it = in_entries->find(part.source.get());
    return it == in_entries->end() ? nullptr : &it->second;
  };
  std::vector<std::string> faces(exact_faces ? m.parts.size() : 0);
#pragma omp parallel for schedule(dynamic, 1) if (faces.size() > 1)
  for (std::ptrdiff_t i = 0; i < static_cast<std::ptrdiff_t>(faces.size()); ++i) {
    const Part& part = m.parts[static_cast<std::size_t>(i)];
    if (const auto* brep = dynamic_cast<const BrepSource*>(part.source.get()); brep && !entry_of(part))
      faces[static_cast<std::size_t>(i)] = save_brep_source(*brep);
  }
  w.u64(m.parts.size());
  for (std::size_t p = 0; p < m.parts.size(); ++p) {
    const Part& part = m.parts[p];
    w.str(part.name);
    w.str(part.source_file);
    w.u64(part.first_surface);
    w.u64(part.surface_count);
    if (!part.source) {
      w.u64(0);
      continue;
    }
    if (!exact_faces) {
      w.u64(2);
      w.f64(static_cast<const BrepSource&>(*part.source).default_deflection());
      continue;
    }
    if (const std::string* key = entry_of(part)) {
      w.u64(3);
      w.str(*key);
      continue;
    }
    w.u64(1);
    w.str(faces[p]);
  }
  w.u64(m.surfaces.size());
  for (const Surface& s : m.surfaces) put_surface(w, s);
  w.u64(m.instances.size());
  for (const Instance& instance : m.instances) {
    w.str(instance.path);
    w.u64(instance.part);
    const Eigen::Matrix4d& matrix = instance.pose.matrix();
    for (int k = 0; k < 16; ++k) w.f64(matrix.data()[k]);
  }
  return std::move(w.out);
}

bool load_import(std::string_view bytes, ImportResult& result, std::string& why, bool stand_ins,
                 std::vector<std::pair<PartId, std::string>>* referenced) {
  ByteReader r{bytes};
  why = "its contents are cut short or inconsistent";
  result.diagnostics = read_diagnostics(r);
  result.complete = r.u64() == 1;
  Model& m = result.model;
  m.parts.resize(r.count(40));
  std::vector<std::string> stored(m.parts.size());  // the exact faces of the parts that hold them
  std::vector<char> exact(m.parts.size(), 0);
  for (std::size_t p = 0; p < m.parts.size(); ++p) {
    Part& part = m.parts[p];
    part.name = r.str();
    part.source_file = r.str();
    part.first_surface = static_cast<SurfaceId>(r.u64());
    part.surface_count = static_cast<std::uint32_t>(r.u64());
    const std::uint64_t kind = r.u64();
    if (kind == 0 || !r.ok) continue;
    if (kind == 2 && stand_ins) {
      part.source = std::make_shared<StandInSource>(r.f64());
      continue;
    }
    if (kind == 3 && referenced != nullptr) {
      referenced->emplace_back(static_cast<PartId>(p), r.str());
      continue;
    }
    if (kind != 1) return false;
    stored[p] = r.str();
    exact[p] = 1;
    if (!r.ok) return false;
  }
  // Read back on every thread, each part's on its own; judged in order.
  std::vector<std::shared_ptr<BrepSource>> sources(m.parts.size());
  std::vector<std::string> source_why(m.parts.size());
#pragma omp parallel for schedule(dynamic, 1) if (m.parts.size() > 1)
  for (std::ptrdiff_t i = 0; i < static_cast<std::ptrdiff_t>(m.parts.size()); ++i) {
    const auto p = static_cast<std::size_t>(i);
    if (exact[p] != 0) sources[p] = load_brep_source(stored[p], source_why[p]);
  }
  for (std::size_t p = 0; p < m.parts.size(); ++p) {
    if (exact[p] == 0) continue;
    if (!sources[p]) {
      why = "part '" + m.parts[p].name + "': " + source_why[p];
      return false;
    }
    if (sources[p]->face_count() != m.parts[p].surface_count) return false;
    m.parts[p].source = std::move(sources[p]);
  }
  m.surfaces.resize(r.count(100));
  for (Surface& s : m.surfaces)
    if (!get_surface(r, s) || s.part >= m.parts.size()) return false;
  for (const Part& part : m.parts)
    if (std::uint64_t{part.first_surface} + part.surface_count > m.surfaces.size()) return false;
  m.instances.resize(r.count(8 * 18));
  for (Instance& instance : m.instances) {
    instance.path = r.str();
    instance.part = static_cast<PartId>(r.u64());
    Eigen::Matrix4d matrix;
    for (int k = 0; k < 16; ++k) matrix.data()[k] = r.f64();
    instance.pose.matrix() = matrix;
    if (instance.part >= m.parts.size()) return false;
  }
  return r.at_end();
}

}  // namespace cadclash::detail
