#include "convert.h"

#include <cmath>
#include <cstring>

namespace cadclash::py {

pyb::array_t<double> pose_to_array(const Pose& pose) {
  pyb::array_t<double> out({4, 4});
  auto m = out.mutable_unchecked<2>();
  const Eigen::Matrix4d& h = pose.matrix();
  for (pyb::ssize_t r = 0; r < 4; ++r)
    for (pyb::ssize_t c = 0; c < 4; ++c) m(r, c) = h(r, c);
  return out;
}

Pose pose_from_matrix(const pyb::handle& matrix) {
  const auto a = pyb::array_t<double, pyb::array::c_style | pyb::array::forcecast>::ensure(matrix);
  if (!a || a.ndim() != 2 || a.shape(0) != 4 || a.shape(1) != 4)
    throw pyb::value_error("a pose must be a 4x4 matrix or (translation, quaternion)");
  auto v = a.unchecked<2>();
  Eigen::Matrix4d h;
  for (pyb::ssize_t r = 0; r < 4; ++r)
    for (pyb::ssize_t c = 0; c < 4; ++c) {
      if (!std::isfinite(v(r, c))) throw pyb::value_error("pose matrix has a non-finite entry");
      h(r, c) = v(r, c);
    }
  if (h(3, 0) != 0.0 || h(3, 1) != 0.0 || h(3, 2) != 0.0 || h(3, 3) != 1.0)
    throw pyb::value_error("pose matrix: the last row must be (0, 0, 0, 1)");
  const Eigen::Matrix3d r = h.topLeftCorner<3, 3>();
  // Rigid only: the narrow phase maps B into A's frame with the inverse pose and keeps distances.
  if (!(r.transpose() * r).isApprox(Eigen::Matrix3d::Identity(), 1e-6) || r.determinant() < 0.0)
    throw pyb::value_error("pose matrix: the upper-left 3x3 must be a rotation (orthonormal, determinant +1)");
  Pose p = Pose::Identity();
  p.matrix() = h;
  return p;
}

namespace {

std::vector<double> finite_sequence(const pyb::handle& h, std::size_t n, const char* what) {
  const auto a = pyb::array_t<double, pyb::array::c_style | pyb::array::forcecast>::ensure(h);
  if (!a || a.ndim() != 1 || static_cast<std::size_t>(a.shape(0)) != n)
    throw pyb::value_error(std::string(what) + " must have " + std::to_string(n) + " numbers");
  std::vector<double> out(a.data(), a.data() + n);
  for (double x : out)
    if (!std::isfinite(x)) throw pyb::value_error(std::string(what) + " has a non-finite value");
  return out;
}

}  // namespace

Pose pose_from_translation_quaternion(const pyb::handle& translation, const pyb::handle& quaternion) {
  const std::vector<double> t = finite_sequence(translation, 3, "translation (tx, ty, tz)");
  const std::vector<double> q = finite_sequence(quaternion, 4, "quaternion (qw, qx, qy, qz)");
  Eigen::Quaterniond quat(q[0], q[1], q[2], q[3]);
  const double n = quat.norm();
  if (!(n > 1e-12)) throw pyb::value_error("quaternion (qw, qx, qy, qz) is zero");
  quat.coeffs() /= n;
  Pose p = Pose::Identity();
  p.linear() = quat.toRotationMatrix();
  p.translation() = Vec3(t[0], t[1], t[2]);
  return p;
}

pyb::list diagnostics_to_list(std::span<const Diagnostic> ds) {
  pyb::list out;
  for (const Diagnostic& d : ds)
    out.append(pyb::make_tuple(d.severity == Severity::Error ? "error" : "warning", d.file, d.line, d.step_id,
                               d.message, format_diagnostic(d)));
  return out;
}

pyb::dict counters_to_dict(const CollideCounters& c) {
  pyb::dict d;
  for (const CounterField& f : kCounterFields) d[f.name] = c.*f.member;
  return d;
}

pyb::dict model_memory_to_dict(const SceneMemory& m) {
  pyb::dict d;
  d["triangles"] = m.triangles;
  d["vertices"] = m.vertices;
  d["hierarchies"] = m.hierarchies;
  d["instances"] = m.instances;
  d["triangle_count"] = m.triangle_count;
  return d;
}

pyb::dict timings_to_dict(const CollideTimings& t) {
  pyb::dict d;
  for (const TimingField& f : kTimingFields) d[f.name] = t.*f.member;
  return d;
}

pyb::object within_or_none(ContactWithin w) {
  return w == ContactWithin::Unknown ? pyb::object(pyb::none()) : pyb::object(pyb::str(contact_within_name(w)));
}

pyb::array_t<std::uint32_t> triangle_pairs_array(const std::vector<std::array<std::uint32_t, 2>>& pairs) {
  pyb::array_t<std::uint32_t> tri({static_cast<pyb::ssize_t>(pairs.size()), pyb::ssize_t{2}});
  if (!pairs.empty()) std::memcpy(tri.mutable_data(), pairs.data(), pairs.size() * sizeof(pairs[0]));
  return tri;
}

namespace {

std::int64_t id_or_minus_one(std::uint32_t id) { return id == kInvalidId ? -1 : static_cast<std::int64_t>(id); }

}  // namespace

pyb::tuple report_to_tuple(const Report& report, QueryReport record) {
  pyb::list pairs;
  for (const SurfacePairResult& p : report.pairs) {
    pyb::array_t<std::uint32_t> tri = triangle_pairs_array(p.triangle_pairs);
    pyb::object exact = p.exact_distance ? pyb::object(pyb::float_(*p.exact_distance)) : pyb::object(pyb::none());
    pairs.append(pyb::make_tuple(p.instance_a, p.instance_b, id_or_minus_one(p.surface_a), id_or_minus_one(p.surface_b),
                                 contact_class_name(p.contact), p.intersecting, p.distance, p.penetration, exact,
                                 tri, decided_by_name(p.decided_by), p.distance_lo, p.distance_hi,
                                 within_or_none(p.within)));
  }
  pyb::list unexamined;
  for (const auto& [a, b] : report.unexamined_pairs) unexamined.append(pyb::make_tuple(a, b));
  return pyb::make_tuple(pairs, counters_to_dict(report.counters), timings_to_dict(report.timings),
                         diagnostics_to_list(report.diagnostics), report.complete, report.stopped_by, unexamined,
                         report.memory_charged, model_memory_to_dict(report.model_memory), std::move(record));
}

}  // namespace cadclash::py
