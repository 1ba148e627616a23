// Steps 4 and 6 of the certified decision (decide_steps.h): finer triangles where they can show a
// gap, and the corroboration of an exact value above T. Refinement is the expensive evidence (a
// BRepMesh run per face), so it is asked only where it can separate a pair, and only of the face
// whose own surface cannot bound the gap.
#include "decide_steps.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace cadclash::detail {

bool bounds_by_shape(const Surface& s) {
  return s.analytic.shape == SurfaceShape::Plane || s.analytic.shape == SurfaceShape::Cylinder ||
         s.analytic.shape == SurfaceShape::Sphere;
}

std::vector<SurfaceId> faces_to_refine(const Model& m, const DecideTask& t) {
  // A board's face at a hole the other face reaches through bounds the gap by the other's triangles
  // alone (hole_bound): finer triangles of the board cannot help there.
  const bool ha = at_hole(m, t, true), hb = at_hole(m, t, false);
  if (ha != hb) return {ha ? t.sb : t.sa};
  const bool a = bounds_by_shape(m.surfaces[t.sa]), b = bounds_by_shape(m.surfaces[t.sb]);
  if (a && !b) return {t.sb};
  if (b && !a) return {t.sa};
  return {t.sa, t.sb};
}

bool refinement_can_separate(const Model& m, const DecideTask& t, const Pending& p) {
  if (t.outcome == nullptr || t.outcome->intersecting) return false;
  double band = t.roundoff;
  for (SurfaceId s : faces_to_refine(m, t)) band += refinement_deflection(m.surfaces[s]);
  return t.outcome->distance > p.threshold + band;
}

FaceView finer_view(const Model& m, std::span<const SurfaceBvh> bvh, const std::vector<RefinedSurface>& cache,
                    SurfaceId s) {
  if (s < cache.size() && cache[s].ok) return FaceView{cache[s].surface, cache[s].bvh};
  return FaceView{m.surfaces[s], bvh[s]};
}

Aabb reach_region(const DecideTask& t, const Surface& a, const Surface& b, bool of_a, double margin) {
  const Aabb other = of_a ? transform_box(own_box(b), t.t_ab()) : transform_box(own_box(a), t.t_ba());
  return (of_a ? own_box(a) : own_box(b)).intersection(pad_box(other, margin));
}

namespace {

// The interval of two faces' triangles (finer ones), tightened by the plane, cylinder or sphere of
// either side: a part standing off a flat face by more than the other face's band is proved apart.
Interval finer_interval(const Model& m, std::span<const double> slack, const DecideTask& t, FaceView fa, FaceView fb, Pending& p,
                        const CollideOptions& o, CollideCounters& c, PairOutcome& out, double& band,
                        double outside = std::numeric_limits<double>::infinity()) {
  band = fa.surface.deflection + fb.surface.deflection + t.roundoff;
  const double reach = p.threshold + band;
  out = pair_outcome(fa.surface, fa.bvh, fb.surface, fb.bvh, t.t_ab(), t.t_ba(), reach, o.clearance, c);
  Interval d = mesh_interval(out, band, reach);
  if (!out.intersecting)
    d.lo = std::max({d.lo, analytic_bound(fa.surface, fb.surface, slack[t.sa], slack[t.sb], t, p.threshold),
                     hole_bound(m, t, fa.surface, fb.surface, slack, p.threshold)});
  // The triangles of a region stand for the faces' points there; the points outside are farther.
  d.lo = std::min(d.lo, outside);
  d = {std::max(p.d.lo, d.lo), std::min(p.d.hi, d.hi)};
  if (d.lo > d.hi) d.lo = d.hi;  // cannot happen for sound bounds; keep the interval ordered
  return d;
}

}  // namespace

// Step 4: the same interval on finer triangles (of the faces faces_to_refine picked).
void refined_step(const Model& m, std::span<const double> slack, const DecideTask& t, FaceView fa, FaceView fb, Pending& p,
                  const CollideOptions& o, CollideCounters& c, double outside) {
  PairOutcome out;
  double band = 0.0;
  p.d = finer_interval(m, slack, t, fa, fb, p, o, c, out, band, outside);
  p.band = band;
  settle(p, verdict(p.d, p.threshold), DecidedBy::Refined, &out, o.clearance);
  // A contact proved on finer triangles is penetrating only when they prove it.
  if (p.settled && p.cls == ContactClass::Touching && certainly_penetrating(out, p.threshold, band))
    p.cls = ContactClass::Penetrating;
  // Later steps read the finer outcome against the finer whole faces (finer_view): an outcome on a
  // region's triangles is not kept for them.
  if (std::isinf(outside)) p.fine = std::move(out);
}

// Corroborates an exact value above T: the finer triangles' lower bound proves the pair apart, their
// upper bound or a witness on them proves it in contact (BRepExtrema missed), else it stays open.
void corroborate(const Model& m, std::span<const double> slack, const DecideTask& t, FaceView fa, FaceView fb,
                 Pending& p, const CollideOptions& o, CollideCounters& c) {
  // The surfaces' parameters first (exact mode has not asked them yet): a lower bound for free.
  if (t.outcome != nullptr) analytic(m, slack, t, p, o);
  if (!p.settled && !p.fine) refined_step(m, slack, t, fa, fb, p, o, c);
  // Settled apart here: the exact value is the measured distance, the finer triangles' lower bound
  // its corroboration; it is reported as decided by the exact faces.
  if (p.settled && p.exact) p.by = DecidedBy::Exact;
  if (p.settled || !p.fine) return;
  witness_step(m, slack, t, fa, fb, &*p.fine, p.band, p, o, c);
  if (p.settled || !p.exact) return;
  // Deeper, for this pair alone: a band below half the exact value's margin over T proves it apart
  // if OCCT's value is right (and shows the contact if OCCT missed it). Not below a hundredth of the
  // model's deflection: the triangles grow with the inverse deflection, and past that a pair would
  // cost seconds; such knife-edge pairs are reported undecided with their interval.
  const double margin = *p.exact - p.threshold - t.roundoff;
  const double target = 0.25 * margin;
  const double floor = 1e-2 * std::max(m.surfaces[t.sa].deflection, m.surfaces[t.sb].deflection);
  if (!(target > floor) || !(target < std::max(fa.surface.deflection, fb.surface.deflection))) return;
  // Only the faces refinement helps (faces_to_refine); a plane, cylinder or sphere keeps its own.
  const std::vector<SurfaceId> which = faces_to_refine(m, t);
  auto deeper = [&](SurfaceId s, FaceView view, std::optional<RefinedSurface>& keep) {
    if (std::find(which.begin(), which.end(), s) == which.end()) return view;
    keep = refine_to(m, s, target);
    return keep->ok ? FaceView{keep->surface, keep->bvh} : view;
  };
  std::optional<RefinedSurface> ka, kb;
  const FaceView da = deeper(t.sa, fa, ka), db = deeper(t.sb, fb, kb);
  PairOutcome out;
  double band = 0.0;
  p.d = finer_interval(m, slack, t, da, db, p, o, c, out, band);
  settle(p, verdict(p.d, p.threshold), DecidedBy::Exact, t.outcome, o.clearance);
  if (!p.settled) witness_step(m, slack, t, da, db, &out, band, p, o, c);
}

}  // namespace cadclash::detail
