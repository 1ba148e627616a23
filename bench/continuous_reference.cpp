#include "continuous_reference.h"

#include "cadclash/tessellate.h"

#include <BRepBndLib.hxx>
#include <BRepExtrema_DistShapeShape.hxx>
#include <Bnd_Box.hxx>
#include <Standard_Failure.hxx>
#include <TopLoc_Location.hxx>
#include <TopoDS_Face.hxx>
#include <gp_Trsf.hxx>

#include <algorithm>
#include <cmath>
#include <limits>
#include <omp.h>

namespace cadclash::bench {
namespace {

struct RefFace {
  TopoDS_Face face;
  Aabb box;        // part-local, OCCT's optimal box with the shape's tolerance
  double radius = 0.0;  // largest |p| over the box (part-local)
  double eps = 0.0;     // Surface::uncertainty
  SurfaceId id = kInvalidId;
};

gp_Trsf to_trsf(const Pose& p) {
  const auto& m = p.matrix();
  gp_Trsf t;
  t.SetValues(m(0, 0), m(0, 1), m(0, 2), m(0, 3), m(1, 0), m(1, 1), m(1, 2), m(1, 3), m(2, 0), m(2, 1), m(2, 2),
              m(2, 3));
  return t;
}

// The box of the 8 mapped corners, padded for their rounding.
Aabb mapped_box(const Aabb& b, const Pose& p) {
  Aabb out;
  for (int c = 0; c < 8; ++c) out.extend(p * b.corner(static_cast<Aabb::CornerType>(c)));
  const double pad = 1e-12 * (1.0 + std::max(out.min().cwiseAbs().maxCoeff(), out.max().cwiseAbs().maxCoeff()));
  out.min().array() -= pad;
  out.max().array() += pad;
  return out;
}

double gap(const Aabb& a, const Aabb& b) {
  double s = 0.0;
  for (int k = 0; k < 3; ++k) {
    const double g = std::max({0.0, b.min()[k] - a.max()[k], a.min()[k] - b.max()[k]});
    s += g * g;
  }
  return std::sqrt(s);
}

// The angle of the rotation from a's to b's (shortest arc), computed here, not by cadclash.
double turn_angle(const Pose& a, const Pose& b) {
  const Eigen::Matrix3d r = b.linear() * a.linear().transpose();
  return Eigen::AngleAxisd(r).angle();
}

}  // namespace

struct ContinuousReference::Impl {
  std::vector<std::vector<RefFace>> parts;  // per part
  const Model* model = nullptr;
  double eps_lo = std::numeric_limits<double>::infinity(), eps_hi = 0.0;
};

ContinuousReference::ContinuousReference(const Model& model) : impl_(std::make_unique<Impl>()) {
  impl_->model = &model;
  impl_->parts.resize(model.parts.size());
  for (PartId p = 0; p < model.parts.size(); ++p) {
    const Part& part = model.parts[p];
    const auto* brep = dynamic_cast<const BrepSource*>(part.source.get());
    if (brep == nullptr) continue;
    for (std::uint32_t k = 0; k < part.surface_count && k < brep->face_count(); ++k) {
      RefFace f;
      f.face = brep->face(k);
      Bnd_Box box;
      BRepBndLib::AddOptimal(f.face, box, false, true);
      if (box.IsVoid()) continue;
      double x0, y0, z0, x1, y1, z1;
      box.Get(x0, y0, z0, x1, y1, z1);
      f.box = Aabb(Vec3(x0, y0, z0), Vec3(x1, y1, z1));
      f.radius = f.box.min().cwiseAbs().cwiseMax(f.box.max().cwiseAbs()).norm();
      f.id = part.first_surface + k;
      f.eps = model.surfaces[f.id].uncertainty;
      impl_->eps_lo = std::min(impl_->eps_lo, f.eps);
      impl_->eps_hi = std::max(impl_->eps_hi, f.eps);
      impl_->parts[p].push_back(std::move(f));
    }
  }
}

ContinuousReference::~ContinuousReference() = default;

std::pair<double, double> ContinuousReference::uncertainty_range() const { return {impl_->eps_lo, impl_->eps_hi}; }

ReferenceSamples ContinuousReference::sample(InstanceId a, const Pose& a0, const Pose& a1, InstanceId b,
                                             const Pose& b0, const Pose& b1, double tolerance, int samples,
                                             int threads) const {
  const Model& model = *impl_->model;
  const auto& fa = impl_->parts[model.instances[a].part];
  const auto& fb = impl_->parts[model.instances[b].part];
  const int n = std::max(1, samples);
  ReferenceSamples out;
  out.contact.assign(static_cast<std::size_t>(n) + 1, 0);
  out.distance.assign(static_cast<std::size_t>(n) + 1, std::numeric_limits<double>::infinity());
  // The poses at every sample, and each side's OCCT placement.
  std::vector<Pose> pa(n + 1), pb(n + 1);
  std::vector<TopLoc_Location> la(n + 1), lb(n + 1);
  for (int j = 0; j <= n; ++j) {
    const double s = static_cast<double>(j) / n;
    pa[j] = interpolate_pose(a0, a1, s);
    pb[j] = interpolate_pose(b0, b1, s);
    la[j] = TopLoc_Location(to_trsf(pa[j]));
    lb[j] = TopLoc_Location(to_trsf(pb[j]));
  }
  // The arc each origin runs (a helix about the screw's axis) is at most its chord times
  // (angle / 2) / sin(angle / 2).
  auto arc = [](const Pose& p0, const Pose& p1, double turn) {
    const double chord = (p1.translation() - p0.translation()).norm();
    return turn > 1e-8 ? chord * (0.5 * turn) / std::sin(0.5 * turn) : chord * (1.0 + turn * turn);
  };
  const double turn_a = turn_angle(a0, a1), turn_b = turn_angle(b0, b1);
  const double move_a = arc(a0, a1, turn_a), move_b = arc(b0, b1, turn_b);
  const std::size_t pairs = fa.size() * fb.size();
#pragma omp parallel num_threads(std::max(1, threads))
  {
    ReferenceSamples mine;
    mine.contact.assign(static_cast<std::size_t>(n) + 1, 0);
    mine.distance.assign(static_cast<std::size_t>(n) + 1, std::numeric_limits<double>::infinity());
#pragma omp for schedule(dynamic, 1)
    for (std::size_t k = 0; k < pairs; ++k) {
      const RefFace& x = fa[k / fb.size()];
      const RefFace& y = fb[k % fb.size()];
      const double thr = tolerance + x.eps + y.eps;
      // Largest speed of a point of either face (per unit of s), with a margin.
      const double v = 1.05 * ((move_a + turn_a * x.radius) + (move_b + turn_b * y.radius)) + 1e-9;
      std::vector<char>* in_contact = nullptr;
      for (int j = 0; j <= n;) {
        double lower = gap(mapped_box(x.box, pa[j]), mapped_box(y.box, pb[j]));
        if (lower <= thr) {
          double d = 0.0;
          bool done = false;
          try {
            BRepExtrema_DistShapeShape dist;
            dist.SetFlag(Extrema_ExtFlag_MIN);  // the minimum only
            dist.LoadS1(x.face.Moved(la[j]));
            dist.LoadS2(y.face.Moved(lb[j]));
            dist.Perform();
            done = dist.IsDone() && dist.NbSolution() > 0;
            if (done) d = dist.Value();
          } catch (const Standard_Failure&) {
            done = false;
          }
          ++mine.exact_calls;
          if (!done) {
            ++mine.failures;
            d = 0.0;
          }
          mine.distance[j] = std::min(mine.distance[j], d);
          lower = d;
          if (d <= thr) {
            mine.contact[j] = 1;
            if (in_contact == nullptr) {
              in_contact = &mine.surfaces[{x.id, y.id}];
              in_contact->assign(static_cast<std::size_t>(n) + 1, 0);
            }
            (*in_contact)[j] = 1;
            ++j;
            continue;
          }
        }
        // Samples j + 1 .. j + skip are out of contact: d >= lower - v * i / n > thr for i <= skip.
        const double reach = (lower - thr) * n / v;
        const double skip = std::ceil(reach) - 1.0;
        j += 1 + static_cast<int>(std::clamp(skip, 0.0, static_cast<double>(n)));
      }
    }
#pragma omp critical
    {
      for (int j = 0; j <= n; ++j) {
        out.contact[j] |= mine.contact[j];
        out.distance[j] = std::min(out.distance[j], mine.distance[j]);
      }
      for (auto& [key, v] : mine.surfaces) out.surfaces[key] = std::move(v);
      out.exact_calls += mine.exact_calls;
      out.failures += mine.failures;
    }
  }
  return out;
}

}  // namespace cadclash::bench
