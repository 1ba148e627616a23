// The hull step of the certified decision (decide_steps.h, hull_step): both faces' surfaces as
// rational Bézier patches, halved until a plane separates every pair of pieces (a lower bound), or
// a point where one surface crosses the other proves contact.
#include "decide_steps.h"
#include "patch_gap.h"

#include "cadclash/geometry.h"

#include <algorithm>
#include <cmath>

namespace cadclash::detail {

namespace {

// Whether the face's triangles (points of the face, up to its slack) lie in the box of its
// patches' control points, as they must when the patches hold the face: a check of the source's
// conversion, not a proof of it. Faces without triangles pass.
bool patches_hold_triangles(const Surface& s, const SurfaceSource::BezierPatches& patches, double slack) {
  if (!s.has_triangles) return true;
  Aabb box;
  for (const auto& p : patches.patches)
    for (const Vec3& q : p.points) box.extend(q);
  const Aabb padded = pad_box(box, slack + patches.rounding + kRelativePad * (1.0 + box_magnitude(box)));
  for (const Vec3& v : s.mesh.vertices)
    if (!padded.contains(v)) return false;
  return true;
}

// Where A's surface crosses B's near `x0` (a point of A's surface, A's frame): B's signed height
// (SurfaceSource::surface_point: the foot point and normal) taken at points of A's surface along two
// tangent directions of A, out to `reach` on either side; where it changes sign, bisection (each
// midpoint put back on A's surface) to the crossing. Returns the last point of A's surface found, or
// nullopt without a sign change. A point to try as a witness, not a proof.
std::optional<Vec3> crossing_near(const SurfaceSource& src_a, std::uint32_t local_a, const SurfaceSource& src_b,
                                  std::uint32_t local_b, const Pose& t_ba, const Vec3& x0, double reach) {
  auto on_a = [&](const Vec3& x) -> std::optional<Vec3> {
    const auto f = src_a.surface_point(local_a, x);
    if (!f) return std::nullopt;
    return f->point;
  };
  auto height = [&](const Vec3& x) -> std::optional<double> {
    const Vec3 xb = t_ba * x;
    const auto f = src_b.surface_point(local_b, xb);
    if (!f) return std::nullopt;
    return f->normal.dot(xb - f->point);
  };
  const auto f0 = src_a.surface_point(local_a, x0);
  const auto h0 = height(x0);
  if (!f0 || !h0) return std::nullopt;
  if (*h0 == 0.0) return x0;
  const Vec3 n = f0->normal;
  const Vec3 t1 = (std::abs(n.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY()).cross(n).normalized();
  const Vec3 t2 = n.cross(t1);
  for (const Vec3& t : {t1, t2})
    for (double side : {1.0, -1.0})
      for (double s = reach / 1024.0; s <= reach; s *= 2.0) {
        const auto x1 = on_a(x0 + side * s * t);
        const auto h1 = x1 ? height(*x1) : std::nullopt;
        if (!h1) break;
        if ((*h1 > 0.0) == (*h0 > 0.0) && *h1 != 0.0) continue;
        Vec3 lo = x0, hi = *x1;  // B's height has the sign of h0 at lo, the other at hi
        Vec3 mid = hi;
        for (int k = 0; k < 60 && (hi - lo).squaredNorm() > 0.0; ++k) {
          const auto m = on_a(0.5 * (lo + hi));
          const auto hm = m ? height(*m) : std::nullopt;
          if (!hm) return mid;
          mid = *m;
          if (*hm == 0.0) return mid;
          ((*hm > 0.0) == (*h0 > 0.0) ? lo : hi) = mid;
        }
        return mid;
      }
  return std::nullopt;
}

}  // namespace

bool hull_step(const Model& m, std::span<const Pose> poses, std::span<const double> slack, const DecideTask& t,
               Pending& p, const CollideOptions& o, CollideCounters& c) {
  // A face without triangles is decided on the exact distance (its interval is [d*, d*]).
  if (t.outcome == nullptr) return false;
  const Surface& a = m.surfaces[t.sa];
  const Surface& b = m.surfaces[t.sb];
  const Part& pa = m.parts[a.part];
  const Part& pb = m.parts[b.part];
  if (!pa.source || !pb.source) return false;
  const std::uint32_t local_a = t.sa - pa.first_surface, local_b = t.sb - pb.first_surface;
  const auto patches_a = pa.source->bezier_patches(local_a);
  if (!patches_a) return false;
  const auto patches_b = pb.source->bezier_patches(local_b);
  if (!patches_b) return false;
  if (!patches_hold_triangles(a, *patches_a, slack[t.sa]) || !patches_hold_triangles(b, *patches_b, slack[t.sb]))
    return false;
  PatchGapOptions go;
  // The faces are within ε of their surfaces: the surfaces must be more than T + εa + εb apart.
  const double slack_ab = slack[t.sa] + slack[t.sb] + t.roundoff;
  go.threshold = p.threshold + slack_ab;
  go.pose_magnitude = poses[t.ia].translation().norm() + poses[t.ib].translation().norm();
  const PatchGap found = patch_gap(*patches_a, *patches_b, t.t_ab(), go);
  if (found.gap) {
    const double lb = *found.gap - slack_ab;
    if (!(lb > p.threshold)) return false;
    p.d.lo = std::max(p.d.lo, lb);
    settle(p, Verdict::Apart, DecidedBy::Analytic, t.outcome, o.clearance);
    return true;
  }
  if (!found.near) return false;
  // Where the search stopped the surfaces come within its pieces' size of each other: any point x
  // bounds d* <= d(x, face A) + d(x, face B), each realised by a point of that face. That point, or
  // where A's surface crosses B's next to it (faces that cross at a small angle come within T of
  // each other only along a narrow band).
  auto proves = [&](const Vec3& x) {
    c.witness_queries += 2;
    const auto da = pa.source->point_distance(local_a, x);
    if (!da || !(*da + t.roundoff <= p.threshold)) return false;
    const auto db = pb.source->point_distance(local_b, t.t_ba() * x);
    if (!db) return false;
    const double hi = *da + *db + 2.0 * t.roundoff;
    if (!(hi <= p.threshold)) return false;
    p.d.hi = std::min(p.d.hi, hi);
    p.d.lo = std::min(p.d.lo, p.d.hi);
    settle(p, Verdict::Contact, DecidedBy::Exact, t.outcome, o.clearance);
    return true;
  };
  if (proves(*found.near)) return true;
  ++c.witness_queries;
  const auto cross = crossing_near(*pa.source, local_a, *pb.source, local_b, t.t_ba(), *found.near,
                                   own_box(a).diagonal().norm());
  return cross && proves(*cross);
}

}  // namespace cadclash::detail
