#include "cadclash/testing/truth.h"

#include "cadclash/tessellate.h"

#include <BRepExtrema_DistShapeShape.hxx>
#include <Standard_Failure.hxx>
#include <TopLoc_Location.hxx>
#include <TopoDS_Face.hxx>
#include <gp_Trsf.hxx>

#include <nlohmann/json.hpp>

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <sstream>
#include <tuple>
#include <utility>

namespace cadclash::truth {

gp_Trsf to_trsf(const Pose& pose) {
  const Eigen::Matrix3d& r = pose.linear();
  const Vec3& t = pose.translation();
  gp_Trsf trsf;
  trsf.SetValues(r(0, 0), r(0, 1), r(0, 2), t.x(), r(1, 0), r(1, 1), r(1, 2), t.y(), r(2, 0), r(2, 1), r(2, 2),
                 t.z());
  return trsf;
}

namespace {

// Bump when the meaning of a cached file changes.
constexpr int kCacheVersion = 2;  // 2: contact is distance <= tolerance + εa + εb

Aabb world_box(const Aabb& local, const Pose& pose) {
  Aabb world;
  if (local.isEmpty()) return world;
  for (int corner = 0; corner < 8; ++corner) world.extend(pose * local.corner(static_cast<Aabb::CornerType>(corner)));
  return world;
}

// Boxes within `gap` of each other along every axis (a superset of "within gap in Euclidean distance").
bool boxes_within(const Aabb& a, const Aabb& b, double gap) {
  if (a.isEmpty() || b.isEmpty()) return false;
  return ((a.min() - b.max()).array() <= gap).all() && ((b.min() - a.max()).array() <= gap).all();
}

const BrepSource* brep_of(const Model& m, PartId p) {
  return dynamic_cast<const BrepSource*>(m.parts[p].source.get());
}

double placed_face_distance(const TopoDS_Face& fa, const Pose& pa, const TopoDS_Face& fb, const Pose& pb) {
  try {
    const TopoDS_Shape a = fa.Moved(TopLoc_Location(to_trsf(pa)));
    const TopoDS_Shape b = fb.Moved(TopLoc_Location(to_trsf(pb)));
    BRepExtrema_DistShapeShape dist(a, b, Extrema_ExtFlag_MIN);
    if (dist.IsDone() && dist.NbSolution() > 0) return dist.Value();
  } catch (const Standard_Failure&) {
  }
  return std::numeric_limits<double>::infinity();
}

}  // namespace

double exact_face_distance(const Model& model, InstanceId a, SurfaceId sa, InstanceId b, SurfaceId sb) {
  const Surface& fa = model.surfaces[sa];
  const Surface& fb = model.surfaces[sb];
  const BrepSource* src_a = brep_of(model, fa.part);
  const BrepSource* src_b = brep_of(model, fb.part);
  if (!src_a || !src_b) return std::numeric_limits<double>::infinity();
  return placed_face_distance(src_a->face(sa - model.parts[fa.part].first_surface), model.instances[a].pose,
                              src_b->face(sb - model.parts[fb.part].first_surface), model.instances[b].pose);
}

namespace {

std::string tolerance_text(double t) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.17g", t);
  return buf;
}

}  // namespace

double effective_uncertainty(const Model& model, SurfaceId s) {
  const Surface& surf = model.surfaces[s];
  if (surf.uncertainty > 0.0) return surf.uncertainty;
  const Part& part = model.parts[surf.part];
  Aabb box;
  for (SurfaceId k = part.first_surface; k < part.first_surface + part.surface_count; ++k)
    box.extend(model.surfaces[k].aabb);
  if (box.isEmpty()) return 0.0;
  return 0x1p-24 * box.min().cwiseAbs().cwiseMax(box.max().cwiseAbs()).norm();
}

double contact_threshold(const Model& model, SurfaceId a, SurfaceId b, double tolerance) {
  return tolerance + effective_uncertainty(model, a) + effective_uncertainty(model, b);
}

bool within(const MeasuredPair& p) { return p.distance <= p.threshold; }

GroundTruth compute_ground_truth(const Model& model, double tolerance, int threads,
                                 const std::function<bool(InstanceId, InstanceId)>& keep) {
  const auto t0 = std::chrono::steady_clock::now();
  GroundTruth truth;
  truth.tolerance = tolerance;
  const std::size_t n = model.instances.size();
  // The largest threshold of any pair: the instance-level prefilter's gap.
  std::vector<double> eps(model.surfaces.size());
  double max_eps = 0.0;
  for (SurfaceId s = 0; s < model.surfaces.size(); ++s) max_eps = std::max(max_eps, eps[s] = effective_uncertainty(model, s));
  const double max_gap = tolerance + 2.0 * max_eps;
  std::vector<Aabb> instance_box(n);
  for (InstanceId i = 0; i < n; ++i) {
    const Instance& inst = model.instances[i];
    const Part& part = model.parts[inst.part];
    if (!brep_of(model, inst.part)) continue;
    for (SurfaceId s = part.first_surface; s < part.first_surface + part.surface_count; ++s)
      instance_box[i].extend(world_box(model.surfaces[s].aabb, inst.pose));
  }
  // Candidates in id order; each surface's world box is computed once per instance pair side.
  for (InstanceId a = 0; a < n; ++a) {
    for (InstanceId b = a + 1; b < n; ++b) {
      if (keep && !keep(a, b)) continue;
      if (!boxes_within(instance_box[a], instance_box[b], max_gap)) continue;
      const Instance& ia = model.instances[a];
      const Instance& ib = model.instances[b];
      const Part& pa = model.parts[ia.part];
      const Part& pb = model.parts[ib.part];
      std::vector<Aabb> boxes_b(pb.surface_count);
      for (std::uint32_t k = 0; k < pb.surface_count; ++k)
        boxes_b[k] = world_box(model.surfaces[pb.first_surface + k].aabb, ib.pose);
      bool any = false;
      for (std::uint32_t j = 0; j < pa.surface_count; ++j) {
        const Aabb box_a = world_box(model.surfaces[pa.first_surface + j].aabb, ia.pose);
        for (std::uint32_t k = 0; k < pb.surface_count; ++k) {
          const SurfaceId sa = pa.first_surface + j, sb = pb.first_surface + k;
          const double threshold = tolerance + eps[sa] + eps[sb];
          if (!boxes_within(box_a, boxes_b[k], threshold)) continue;
          truth.measured.push_back({a, b, sa, sb, 0.0, threshold});
          any = true;
        }
      }
      truth.instance_pairs += any;
    }
  }
  const auto count = static_cast<std::ptrdiff_t>(truth.measured.size());
  const int nthreads = threads > 0 ? threads : omp_get_max_threads();
  // Each pair works on its own placed copies (Moved); the shared geometry is only read.
#pragma omp parallel for num_threads(nthreads) schedule(dynamic, 1)
  for (std::ptrdiff_t k = 0; k < count; ++k) {
    MeasuredPair& p = truth.measured[static_cast<std::size_t>(k)];
    p.distance = exact_face_distance(model, p.instance_a, p.surface_a, p.instance_b, p.surface_b);
  }
  for (const MeasuredPair& p : truth.measured) truth.failed += !std::isfinite(p.distance);
  truth.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return truth;
}

GroundTruth with_tolerance(const GroundTruth& truth, const Model& model, double tolerance) {
  GroundTruth out = truth;
  out.tolerance = tolerance;
  for (MeasuredPair& p : out.measured) p.threshold = contact_threshold(model, p.surface_a, p.surface_b, tolerance);
  return out;
}

double instance_distance(const Model& model, InstanceId a, InstanceId b, double search) {
  const Instance& ia = model.instances[a];
  const Instance& ib = model.instances[b];
  const Part& pa = model.parts[ia.part];
  const Part& pb = model.parts[ib.part];
  double best = std::numeric_limits<double>::infinity();
  for (SurfaceId sa = pa.first_surface; sa < pa.first_surface + pa.surface_count; ++sa) {
    const Aabb box_a = world_box(model.surfaces[sa].aabb, ia.pose);
    for (SurfaceId sb = pb.first_surface; sb < pb.first_surface + pb.surface_count; ++sb)
      if (boxes_within(box_a, world_box(model.surfaces[sb].aabb, ib.pose), search))
        best = std::min(best, exact_face_distance(model, a, sa, b, sb));
  }
  return best;
}

std::string file_hash(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) return {};
  std::uint64_t h = 0xcbf29ce484222325ull;
  char buf[1 << 16];
  while (f) {
    f.read(buf, sizeof buf);
    for (std::streamsize i = 0; i < f.gcount(); ++i) {
      h ^= static_cast<unsigned char>(buf[i]);
      h *= 0x100000001b3ull;
    }
  }
  char out[17];
  std::snprintf(out, sizeof out, "%016llx", static_cast<unsigned long long>(h));
  return out;
}

std::string cache_path(const std::string& dir, const std::string& hash, double tolerance) {
  char t[64];
  std::snprintf(t, sizeof t, "%g", tolerance);
  return dir + "/truth-" + hash + "-t" + t + ".json";
}

std::optional<GroundTruth> load_ground_truth(const std::string& path, const Model& model, double tolerance) {
  std::ifstream f(path, std::ios::binary);
  if (!f) return std::nullopt;
  nlohmann::json j = nlohmann::json::parse(f, nullptr, false);
  if (j.is_discarded() || j.value("version", 0) != kCacheVersion ||
      j.value("tolerance", std::string()) != tolerance_text(tolerance))
    return std::nullopt;
  std::map<std::string, InstanceId> by_path;
  for (InstanceId i = 0; i < model.instances.size(); ++i) by_path[model.instances[i].path] = i;
  auto surface = [&](InstanceId i, std::int64_t face) -> SurfaceId {
    const Part& p = model.parts[model.instances[i].part];
    return face >= 0 && face < p.surface_count ? p.first_surface + static_cast<SurfaceId>(face) : kInvalidId;
  };
  GroundTruth truth;
  truth.tolerance = tolerance;
  truth.from_cache = true;
  truth.instance_pairs = j.value("instance_pairs", 0ull);
  try {
    for (const nlohmann::json& e : j.at("pairs")) {
      const auto a = by_path.find(e.at(0).get<std::string>());
      const auto b = by_path.find(e.at(2).get<std::string>());
      if (a == by_path.end() || b == by_path.end()) return std::nullopt;
      MeasuredPair p{a->second, b->second, surface(a->second, e.at(1).get<std::int64_t>()),
                     surface(b->second, e.at(3).get<std::int64_t>()),
                     e.at(4).is_null() ? std::numeric_limits<double>::infinity() : e.at(4).get<double>(), 0.0};
      if (p.surface_a == kInvalidId || p.surface_b == kInvalidId || p.instance_a >= p.instance_b) return std::nullopt;
      p.threshold = contact_threshold(model, p.surface_a, p.surface_b, tolerance);
      truth.failed += !std::isfinite(p.distance);
      truth.measured.push_back(p);
    }
  } catch (const nlohmann::json::exception&) {
    return std::nullopt;
  }
  std::sort(truth.measured.begin(), truth.measured.end(), [](const MeasuredPair& x, const MeasuredPair& y) {
    return std::tie(x.instance_a, x.instance_b, x.surface_a, x.surface_b) <
           std::tie(y.instance_a, y.instance_b, y.surface_a, y.surface_b);
  });
  return truth;
}

bool save_ground_truth(const std::string& path, const Model& model, const GroundTruth& truth) {
  nlohmann::json pairs = nlohmann::json::array();
  for (const MeasuredPair& p : truth.measured) {
    const Surface& sa = model.surfaces[p.surface_a];
    const Surface& sb = model.surfaces[p.surface_b];
    pairs.push_back({model.instances[p.instance_a].path, sa.provenance.face_index, model.instances[p.instance_b].path,
                     sb.provenance.face_index,
                     std::isfinite(p.distance) ? nlohmann::json(p.distance) : nlohmann::json(nullptr)});
  }
  const nlohmann::json j{{"version", kCacheVersion},
                         {"what", "exact face distances (BRepExtrema_DistShapeShape) of the box-prefiltered "
                                  "face pairs: [instance a, face index a, instance b, face index b, distance]"},
                         {"tolerance", tolerance_text(truth.tolerance)},
                         {"instance_pairs", truth.instance_pairs},
                         {"seconds", truth.seconds},
                         {"pairs", std::move(pairs)}};
  std::ofstream f(path, std::ios::binary);
  f << j.dump(1) << '\n';
  return static_cast<bool>(f);
}

double Score::recall() const { return truth == 0 ? 1.0 : double(hits) / double(truth); }
double Score::precision() const { return reported == 0 ? 1.0 : double(hits) / double(reported); }

Score score(const GroundTruth& truth, std::vector<PairKey> reported) {
  std::sort(reported.begin(), reported.end());
  reported.erase(std::unique(reported.begin(), reported.end()), reported.end());
  std::vector<PairKey> real;
  for (const MeasuredPair& p : truth.measured)
    if (within(p)) real.push_back({p.instance_a, p.instance_b, p.surface_a, p.surface_b});
  std::sort(real.begin(), real.end());
  Score s;
  s.truth = real.size();
  s.reported = reported.size();
  std::set_difference(real.begin(), real.end(), reported.begin(), reported.end(), std::back_inserter(s.missed));
  std::set_difference(reported.begin(), reported.end(), real.begin(), real.end(), std::back_inserter(s.false_pairs));
  s.hits = s.truth - s.missed.size();
  return s;
}

}  // namespace cadclash::truth
