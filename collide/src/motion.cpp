// Motion between two poses of a path (trajectory.h, "Motion between steps"): the interpolated pose
// and a bound on how far a part's points travel over a stretch of it.
#include "cadclash/trajectory.h"
#include "closest.h"
#include "restricted_check.h"
#include "screw.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <tuple>
#include <utility>
#include <vector>

namespace cadclash {
namespace {

using detail::Screw;
using detail::screw_of;
using detail::turn;
using detail::rotation_of;

constexpr double kUnit = std::numeric_limits<double>::epsilon() / 2.0;  // 2^-53

// The velocity (per unit of s) of the world point x under the screw w of a motion from pose a: the
// turn's angle * axis x (x - t_a) plus the velocity of a's origin, axis x drift + d axis.
Vec3 velocity_at(const Screw& w, const Pose& a, const Vec3& x) {
  return (w.local.angle * w.axis).cross(x - a.translation()) + w.axis.cross(w.drift) + w.along * w.axis;
}

}  // namespace

Pose interpolate_pose(const Pose& a, const Pose& b, double s) {
  assert(s >= 0.0 && s <= 1.0);
  const Screw w = screw_of(a, b);
  const double angle = w.local.angle;
  const Eigen::Quaterniond step(Eigen::AngleAxisd(s * angle, w.local.axis));  // constant angular speed
  Pose out = Pose::Identity();
  out.linear() = (w.qa * step).normalized().toRotationMatrix();
  // Exact at both ends. In between a's origin turns about the axis through c and shifts along it:
  // (R_s - I)(P t_a - c) + s d axis, with (R_s - I) v = 2 sin(s angle / 2) (cos(s angle / 2)
  // axis x v - sin(s angle / 2) v) for v across the axis, and P t_a - c = drift / angle.
  if (s == 0.0 || s == 1.0) {
    out.translation() = s == 0.0 ? a.translation() : b.translation();
    return out;
  }
  const double h = 0.5 * s * angle;
  const double chord = angle == 0.0 ? s : 2.0 * std::sin(h) / angle;  // 2 sin(h) / angle, s at angle 0
  out.translation() = a.translation() + chord * (std::cos(h) * w.axis.cross(w.drift) - std::sin(h) * w.drift) +
                      (s * w.along) * w.axis;
  return out;
}

double motion_angle(const Pose& a, const Pose& b) { return turn(rotation_of(a), rotation_of(b)).angle; }

double travel_bound(const Pose& a, const Pose& b, const Aabb& box, double s0, double s1) {
  assert(s0 >= 0.0 && s0 <= s1 && s1 <= 1.0 && !box.isEmpty());
  const Screw w = screw_of(a, b);
  const double angle = w.local.angle;
  // A point x of the part moves along a helix about the axis: speed hypot(|angle P(x - c)|, d) (the
  // turn's velocity is across the axis, the shift's along it), with
  // angle P(x - c) = angle P(R_a p) + drift for the part-local point p. Its largest over the box is
  // at a corner (the norm of an affine map is convex).
  double reach = 0.0, across = 0.0;
  for (int k = 0; k < 8; ++k) {
    const Vec3 p = box.corner(static_cast<Aabb::CornerType>(k));
    reach = std::max(reach, p.norm());
    const Vec3 r = a.linear() * p;
    across = std::max(across, (angle * (r - w.axis.dot(r) * w.axis) + w.drift).norm());
  }
  const double speed = std::hypot(across, w.along);
  // The speed's own rounding (a few ulps of its terms), and what the computed poses may be off the
  // motion (quaternions, rotation matrices, the turned and shifted origin): far above it, for both
  // ends.
  const double t = std::max(a.translation().norm(), b.translation().norm());
  const double slack = 64.0 * kUnit * (angle * reach + w.drift.norm() + std::abs(w.along)) + 64.0 * kUnit;
  const double poses = 2.0 * 256.0 * kUnit * (reach + t);
  return (s1 - s0) * (speed * (1.0 + 16.0 * kUnit) + slack) + poses;
}

// Each part moves along its screw, a constant twist (the velocity field x -> omega x (x - x0) +
// v(x0)), so in a's frame b's point at z moves at |v_b(z) - v_a(z)| <= |omega_b - omega_a| |z - p| +
// |v_b(p) - v_a(p)|, p the centre of b's box at s = 0, |z - p| at most its half diagonal plus b's
// travel over the motion. Parts moved by one displacement (a sub-assembly turned or pulled out) keep
// their gap: the two twists then differ by rounding only. Each side's rounding of its poses is
// travel_bound's over no motion.
double relative_travel_bound(const Pose& a0, const Pose& a1, const Aabb& box_a, const Pose& b0, const Pose& b1,
                             const Aabb& box_b, double s0, double s1) {
  assert(s0 >= 0.0 && s0 <= s1 && s1 <= 1.0 && !box_a.isEmpty() && !box_b.isEmpty());
  const Screw wa = screw_of(a0, a1), wb = screw_of(b0, b1);
  const Vec3 p = b0 * box_b.center();
  const Vec3 va = velocity_at(wa, a0, p), vb = velocity_at(wb, b0, p);
  const Vec3 oa = wa.local.angle * wa.axis, ob = wb.local.angle * wb.axis;
  const double spread = 0.5 * box_b.sizes().norm() + travel_bound(b0, b1, box_b, 0.0, 1.0);
  const double speed = (ob - oa).norm() * spread + (vb - va).norm();
  // The rounding of the velocities and of their differences: a few ulps of their terms.
  const double terms = oa.norm() * ((p - a0.translation()).norm() + spread) +
                       ob.norm() * ((p - b0.translation()).norm() + spread) + wa.drift.norm() + wb.drift.norm() +
                       std::abs(wa.along) + std::abs(wb.along);
  const double slack = 64.0 * kUnit * terms + 64.0 * kUnit;
  const double poses = travel_bound(a0, a1, box_a, s0, s0) + travel_bound(b0, b1, box_b, s0, s0);
  return (s1 - s0) * (speed * (1.0 + 16.0 * kUnit) + slack) + poses;
}

namespace {

// An instance pair (surfaces kInvalidId: any of its surface pairs, or containment) or one surface
// pair of it: the search settles both levels at once.
using PairKey = std::tuple<InstanceId, InstanceId, SurfaceId, SurfaceId>;

// The pairs a report has in contact (penetrating, touching, containment), and whether it is partial
// or undecided somewhere (then it proves nothing for its undecided pairs): each surface pair, and
// its instance pair.
struct Contacts {
  std::set<PairKey> contact;
  std::set<PairKey> open;  // in contact or undecided: not cleared
  // Per open surface key: a certified lower bound of its exact distance less the faces'
  // uncertainties (-inf for a check whose bounds are not certified), those uncertainties, and the
  // distance's upper bound less them (+inf: not certified). An instance key's come from its surface
  // keys' and `containment`.
  std::map<PairKey, double> margin, uncertainty, upper;
  std::set<PairKey> containment;          // instance keys open for a containment
  bool complete = true;
};

// `keys` (null: all): the pairs a check is about; the report's other pairs are left out, so a check
// restricted to them (restricted_check.h) and a whole one (a distributed run's) say the same.
Contacts contacts_of(const Report& r, bool certified, const std::set<PairKey>* keys) {
  Contacts c;
  c.complete = r.complete;
  for (const SurfacePairResult& p : r.pairs) {
    if (p.contact == ContactClass::Clearance) continue;
    // A pair's instance key may be settled while some of its surface pairs are not (a contact proved
    // at both ends of the stretch), and the other way round: each key takes the results it is about.
    // An instance key still open has every surface pair that can touch it in `keys` (the others were
    // proved apart over a stretch holding this one), so its state is theirs and its containment's.
    const bool containment = p.contact == ContactClass::Containment;
    const PairKey whole{p.instance_a, p.instance_b, kInvalidId, kInvalidId};
    const PairKey surface{p.instance_a, p.instance_b, p.surface_a, p.surface_b};
    const bool listed = !keys || containment || keys->count(surface) > 0;
    const bool about_whole = listed && (!keys || keys->count(whole) > 0);
    const bool about_surface = listed && !containment;
    if (!about_whole && !about_surface) continue;
    if (about_surface) {
      const double eps = p.uncertainty_a + p.uncertainty_b;
      c.margin[surface] = certified ? p.distance_lo - eps : -std::numeric_limits<double>::infinity();
      c.uncertainty[surface] = eps;
      c.upper[surface] = certified ? p.distance_hi - eps : std::numeric_limits<double>::infinity();
    }
    if (about_whole && containment) c.containment.insert(whole);
    for (const PairKey& k : {whole, surface}) {
      if (!(k == whole ? about_whole : about_surface)) continue;
      c.open.insert(k);
      if (p.contact != ContactClass::Undecided) c.contact.insert(k);
    }
  }
  return c;
}

}  // namespace

MotionResult check_motion(Scene& scene, const Model& model, std::span<const InstanceId> moving,
                          std::span<const Pose> from, std::span<const Pose> to, const CollideOptions& options,
                          const MotionOptions& motion) {
  assert(moving.size() == from.size() && moving.size() == to.size() && motion.resolution > 0.0);
  // Each moving instance's part box (part-local): its surfaces' boxes.
  std::vector<Aabb> boxes(moving.size());
  for (std::size_t i = 0; i < moving.size(); ++i) {
    const Part& part = model.parts[model.instances[moving[i]].part];
    for (SurfaceId s = part.first_surface; s < part.first_surface + part.surface_count; ++s)
      boxes[i].extend(model.surfaces[s].aabb.isEmpty() ? mesh_aabb(model.surfaces[s].mesh) : model.surfaces[s].aabb);
  }
  // A pair moves apart or together over [s0, s1] by at most its two sides' travel (a side that does
  // not move: none), and, when both move, by at most how far one moves relative to the other
  // (relative_travel_bound: parts moved together keep their gap, wherever the assembly is placed).
  std::map<InstanceId, std::size_t> index;
  for (std::size_t i = 0; i < moving.size(); ++i) index.emplace(moving[i], i);
  auto pair_travel = [&](InstanceId a, InstanceId b, double s0, double s1) {
    const auto ia = index.find(a), ib = index.find(b);
    auto own = [&](const auto& it) {
      if (it == index.end() || boxes[it->second].isEmpty()) return 0.0;
      return travel_bound(from[it->second], to[it->second], boxes[it->second], s0, s1);
    };
    const double apart = own(ia) + own(ib);
    if (ia == index.end() || ib == index.end() || boxes[ia->second].isEmpty() || boxes[ib->second].isEmpty()) return apart;
    const std::size_t i = ia->second, j = ib->second;
    return std::min(apart, relative_travel_bound(from[i], to[i], boxes[i], from[j], to[j], boxes[j], s0, s1));
  };
  // A surface pair of a moving part and one that stays moves apart or together by at most the moving
  // face's own travel (its box's: within the part's); other pairs by the instance pair's.
  auto key_travel = [&](const PairKey& k, double s0, double s1) {
    const auto [a, b, sa, sb] = k;
    const double whole = pair_travel(a, b, s0, s1);
    const auto ia = index.find(a), ib = index.find(b);
    if (sa == kInvalidId || (ia == index.end()) == (ib == index.end())) return whole;
    const std::size_t i = ia != index.end() ? ia->second : ib->second;
    const Surface& face = model.surfaces[ia != index.end() ? sa : sb];
    const Aabb box = face.aabb.isEmpty() ? mesh_aabb(face.mesh) : face.aabb;
    if (box.isEmpty()) return whole;
    return std::min(whole, travel_bound(from[i], to[i], box, s0, s1));
  };
  // Any pair's: at most the two largest.
  auto travel_over = [&](double s0, double s1) {
    double first = 0.0, second = 0.0;
    for (std::size_t i = 0; i < moving.size(); ++i) {
      if (boxes[i].isEmpty()) continue;
      const double t = travel_bound(from[i], to[i], boxes[i], s0, s1);
      if (t > first) second = std::exchange(first, t);
      else second = std::max(second, t);
    }
    return first + second;
  };
  // The largest travel of the pairs a check is about: `keys` (null: any pair of a moving instance,
  // against one that stays or another that moves). With many moving instances, the two largest.
  constexpr std::size_t kPairwise = 64;
  auto travel_of = [&](const std::set<PairKey>* keys, double s0, double s1) {
    double worst = 0.0;
    if (keys) {
      std::set<std::pair<InstanceId, InstanceId>> seen;
      for (const PairKey& k : *keys)
        if (seen.insert({std::get<0>(k), std::get<1>(k)}).second)
          worst = std::max(worst, pair_travel(std::get<0>(k), std::get<1>(k), s0, s1));
      return worst;
    }
    if (moving.size() > kPairwise) return travel_over(s0, s1);
    for (std::size_t i = 0; i < moving.size(); ++i) {
      worst = std::max(worst, pair_travel(moving[i], kInvalidId, s0, s1));
      for (std::size_t j = i + 1; j < moving.size(); ++j) worst = std::max(worst, pair_travel(moving[i], moving[j], s0, s1));
    }
    return worst;
  };
  MotionResult out;
  // At the ends, the poses given (the steps' own, whose checks a path has made already); between
  // them interpolate_pose's, which differ from those at the ends by its rounding only (travel_bound
  // covers it).
  auto place = [&](double s) {
    for (std::size_t i = 0; i < moving.size(); ++i)
      scene.set_pose(moving[i], s == 0.0 ? from[i] : s == 1.0 ? to[i] : interpolate_pose(from[i], to[i], s));
  };
  const bool certified = options.decision != DecisionMode::Fast;
  // A surface pair of a moving instance and one that stays is apart over a stretch by at least
  // screw_gap: what the turn cannot change (screw.h). Certified checks only (a fast check's contact
  // band is its own).
  std::vector<detail::Screw> screws;
  for (std::size_t i = 0; i < moving.size(); ++i) screws.push_back(screw_of(from[i], to[i]));
  // What the screw keeps of a surface pair (nothing when both sides move, or neither). It only
  // reads, so a check's threads can ask it (proved_apart, below); a few box transforms, computed
  // again per candidate rather than shared through a locked cache.
  auto keep_of = [&](InstanceId a, InstanceId b, SurfaceId sa, SurfaceId sb) {
    const auto ia = index.find(a), ib = index.find(b);
    if ((ia == index.end()) == (ib == index.end())) return detail::ScrewKeep{};
    const bool a_moves = ia != index.end();
    const std::size_t i = a_moves ? ia->second : ib->second;
    return detail::screw_keep(model, a_moves ? sa : sb, from[i], screws[i], a_moves ? sb : sa, scene.pose(a_moves ? b : a));
  };
  // `extra`: by this much more than T (in units of the pair's shift per unit of s).
  auto apart_by = [&](const detail::ScrewKeep& keep, double uncertainty, double s0, double s1, double extra) {
    return keep.known && detail::screw_gap(keep, s0, s1) > options.tolerance + uncertainty + extra * std::abs(keep.shift);
  };
  std::map<PairKey, detail::ScrewKeep> keeps;  // per surface pair asked about: what its screw keeps
  auto held_apart = [&](const PairKey& k, double uncertainty, double s0, double s1, double extra = 0.0) {
    const auto [a, b, sa, sb] = k;
    if (!certified || sa == kInvalidId) return false;
    auto [it, fresh] = keeps.try_emplace(k);
    if (fresh) it->second = keep_of(a, b, sa, sb);
    return apart_by(it->second, uncertainty, s0, s1, extra);
  };
  auto moves = [&](const PairKey& k) { return index.count(std::get<0>(k)) > 0 || index.count(std::get<1>(k)) > 0; };
  // A check at s about the pairs `keys` (null: all). Here it examines those pairs only; a distributed
  // run's own check (MotionOptions::check) examines all, and the others are left out of its answer.
  // Except at a stretch's ends (`movers_only` false), both examine only the moving instances' pairs
  // (CollideOptions::involving): the first check of a stretch, grown the most, then reaches every
  // face a later one of the search can, so a lazy model meshes the same faces either way.
  std::vector<InstanceId> movers;
  if (index.size() < model.instances.size())
    for (const auto& [i, k] : index) movers.push_back(i);
  // `over`: the stretch the check stands for; its surface pairs that the turn keeps apart over all
  // of it (held_apart) are left out of it (CollideOptions::proved_apart), a distributed check's on
  // every rank alike: the search would clear them whatever the check said of them.
  auto check = [&](double s, double tolerance, const std::set<PairKey>* keys, bool movers_only = true,
                   const std::pair<double, double>* over = nullptr) {
    place(s);
    CollideOptions o = options;
    o.tolerance = tolerance;
    o.clearance = 0.0;
    if (movers_only) o.involving = movers;
    if (over && certified) {
      const double s0 = over->first, s1 = over->second;  // clang 14 cannot capture a structured binding
      o.proved_apart = [&keep_of, &apart_by, s0, s1](InstanceId a, InstanceId b, SurfaceId sa, SurfaceId sb, double eps) {
        return apart_by(keep_of(a, b, sa, sb), eps, s0, s1, 0.0);
      };
    }
    ++out.checks;
    if (motion.check) return contacts_of(motion.check(scene, o), certified, keys);
    detail::CheckRestriction only;
    if (keys)
      for (const auto& [a, b, sa, sb] : *keys) {
        auto& surfaces = only.pairs[{a, b}];
        if (sa != kInvalidId) surfaces.insert({sa, sb});
      }
    return contacts_of(detail::restricted_check(scene, o, keys ? &only : nullptr), certified, keys);
  };
  // What the static checks at T found, by s: the pairs examined there (all, or some), those of them
  // in contact, and those open. A pair's answer depends on that pair alone (restricted_check.h),
  // and an instance pair's on its surface pairs that may be in contact there, all of which the
  // stretch asking has (the others were proved apart, or settled with it, over a stretch holding
  // s): so a pair examined at s by one stretch is known there for every later one.
  struct AtS {
    bool all = false;
    std::set<PairKey> examined, contact, open;
  };
  std::map<double, AtS> at;
  auto merge = [](AtS& into, const Contacts& c) {
    into.contact.insert(c.contact.begin(), c.contact.end());
    into.open.insert(c.open.begin(), c.open.end());
  };
  if (motion.at_start) at[0.0].all = true, merge(at[0.0], contacts_of(*motion.at_start, certified, nullptr));
  if (motion.at_end) at[1.0].all = true, merge(at[1.0], contacts_of(*motion.at_end, certified, nullptr));
  // The contacts at s of the pairs `keys` (null: all), checking those not examined there yet (an
  // instance pair with all of its surface pairs the keys have, as a check of the keys would).
  auto contacts_at = [&](double s, const std::set<PairKey>* keys) -> const AtS& {
    AtS& known = at[s];
    if (known.all) return known;
    if (!keys) {
      merge(known, check(s, options.tolerance, nullptr, false));
      known.all = true;
      return known;
    }
    std::set<PairKey> missing;
    std::set<std::pair<InstanceId, InstanceId>> whole;
    for (const PairKey& k : *keys)
      if (!known.examined.count(k)) {
        missing.insert(k);
        if (std::get<2>(k) == kInvalidId) whole.insert({std::get<0>(k), std::get<1>(k)});
      }
    if (missing.empty()) return known;
    for (const PairKey& k : *keys)
      if (whole.count({std::get<0>(k), std::get<1>(k)})) missing.insert(k);
    merge(known, check(s, options.tolerance, &missing));
    known.examined.insert(missing.begin(), missing.end());
    return known;
  };
  std::map<PairKey, std::vector<MotionSpan>> spans;
  // Pairs of two instances that stay where they are keep their state over the stretch, the one at
  // its ends: in contact at both, one span proved at its ends; open but not so (undecided), one span
  // not proved either way (halving cannot tell more). The search is about the moving instances'
  // pairs: its checks examine theirs only (CollideOptions::involving).
  if (index.size() < model.instances.size()) {
    const AtS& start = contacts_at(0.0, nullptr);
    const AtS& finish = contacts_at(1.0, nullptr);
    std::set<PairKey> open = start.open;
    open.insert(finish.open.begin(), finish.open.end());
    for (const PairKey& k : open)
      if (!moves(k)) spans[k].push_back({0.0, 1.0, start.contact.count(k) > 0 && finish.contact.count(k) > 0});
  }
  // Depth first, the earlier half first: spans come out in ascending order. Each stretch carries
  // the pairs it still has to settle (at the start, `all`: those of a moving instance).
  struct Stretch {
    double s0, s1;
    std::set<PairKey> pairs;
    bool all;
  };
  std::vector<Stretch> stack{{0.0, 1.0, {}, true}};
  while (!stack.empty()) {
    Stretch st = std::move(stack.back());
    stack.pop_back();
    auto concerns = [&](const PairKey& k) { return st.all ? moves(k) : st.pairs.count(k) > 0; };
    const bool budget = out.checks + 3 <= motion.max_checks;
    std::set<PairKey> suspect;
    std::map<PairKey, double> margin;  // of each suspect: an instance key's, its suspect surface pairs' least
    Contacts grown;
    if (budget) {
      // Checked in the middle of the stretch: every pose of it is within half its travel of there.
      const double mid = 0.5 * (st.s0 + st.s1);
      auto half = [&](const auto& travel) { return std::max(travel(st.s0, mid), travel(mid, st.s1)); };
      // Grown by the largest travel of its pairs: a pair it leaves out is apart by more than T plus
      // its own travel.
      const std::pair<double, double> over{st.s0, st.s1};
      grown = check(mid, options.tolerance + half([&](double u0, double u1) { return travel_of(st.all ? nullptr : &st.pairs, u0, u1); }),
                    st.all ? nullptr : &st.pairs, true, &over);
      if (grown.complete && certified) {
        // What the grown check says of its pairs at T where its bounds settle it (an upper bound
        // within T: in contact; a lower bound beyond T: apart), known at mid without a check at T
        // there when a half asks. An instance pair: in contact with one of its surface pairs or a
        // containment (boxes that nest and surfaces that do not cross: not a matter of tolerance),
        // apart when all of its surface pairs are; otherwise left to a check at T.
        AtS& here = at[mid];
        const std::set<PairKey>& about = st.all ? grown.open : st.pairs;
        std::map<std::pair<InstanceId, InstanceId>, int> whole;  // 1: in contact, 0: apart, -1: not settled
        auto settle = [&](const PairKey& k, int state) {
          if (state < 0 || here.examined.count(k)) return;
          here.examined.insert(k);
          if (state == 1) here.contact.insert(k), here.open.insert(k);
        };
        for (const PairKey& k : about) {
          if (std::get<2>(k) == kInvalidId) continue;
          int state = 0;
          if (grown.open.count(k)) state = grown.upper.at(k) <= options.tolerance ? 1 : grown.margin.at(k) > options.tolerance ? 0 : -1;
          int& w = whole.try_emplace({std::get<0>(k), std::get<1>(k)}, 0).first->second;
          if (state == 1 || w == 1) w = 1;
          else if (state == -1) w = -1;
          settle(k, state);
        }
        for (const PairKey& k : about) {
          if (std::get<2>(k) != kInvalidId) continue;
          const auto w = whole.find({std::get<0>(k), std::get<1>(k)});
          settle(k, grown.containment.count(k) ? 1 : w == whole.end() ? 0 : w->second);
        }
      }
      if (grown.complete) {
        // Open at the grown tolerance, and not proved apart by its own travel (its distance in the
        // middle less what its two sides can travel from there stays above T where its lower bound
        // says so) nor by what the turn keeps (held_apart). An instance pair is suspect with one of
        // its surface pairs, or a containment.
        for (const PairKey& k : grown.open) {
          const InstanceId a = std::get<0>(k), b = std::get<1>(k);  // a lambda cannot capture a structured binding (C++17)
          if (std::get<2>(k) == kInvalidId || !concerns(k)) continue;
          const double travel = half([&](double u0, double u1) { return key_travel(k, u0, u1); });
          if (grown.margin.at(k) > options.tolerance + travel || held_apart(k, grown.uncertainty.at(k), st.s0, st.s1)) continue;
          suspect.insert(k);
          const PairKey whole{a, b, kInvalidId, kInvalidId};
          auto [it, fresh] = margin.try_emplace(whole, grown.margin.at(k));
          if (!fresh) it->second = std::min(it->second, grown.margin.at(k));
          margin[k] = grown.margin.at(k);
        }
        for (const PairKey& k : grown.open) {
          if (std::get<2>(k) != kInvalidId || !concerns(k)) continue;
          if (grown.containment.count(k)) margin[k] = -std::numeric_limits<double>::infinity();
          if (margin.count(k)) suspect.insert(k);
        }
      } else {
        out.complete = false;
      }
      if (grown.complete && suspect.empty()) continue;  // free over the whole stretch
    }
    if (!budget || out.complete == false) {
      // No proof: every pair it concerns keeps the stretch (all pairs: those seen in contact or open
      // anywhere so far, and the search is incomplete).
      out.complete = false;
      std::set<PairKey> keep = st.pairs;
      if (st.all)
        for (const auto& [s, c] : at)
          for (const PairKey& k : c.open)
            if (concerns(k)) keep.insert(k);
      for (const PairKey& k : keep) spans[k].push_back({st.s0, st.s1, false});
      continue;
    }
    std::set<PairKey> halve;
    // Only a pair that may touch in the middle can be in contact over the whole stretch: the checks
    // at its ends (at T) are run, once for the stretch, when such a pair is there.
    const AtS* ends[2] = {nullptr, nullptr};
    auto in_contact_at = [&](int end, const PairKey& k) {
      if (!ends[end]) ends[end] = &contacts_at(end == 0 ? st.s0 : st.s1, st.all ? nullptr : &st.pairs);
      return ends[end]->contact.count(k) > 0;
    };
    for (const PairKey& k : suspect) {
      if (!(margin.at(k) > options.tolerance) && in_contact_at(0, k) && in_contact_at(1, k))
        spans[k].push_back({st.s0, st.s1, true});
      else if (st.s1 - st.s0 <= motion.resolution) spans[k].push_back({st.s0, st.s1, false});
      else halve.insert(k);
    }
    if (halve.empty()) continue;
    // Conservative advancement around the middle: a pair proved apart there by more than T stays
    // apart while its two sides travel less than that, and a surface pair that the turn keeps apart
    // (held_apart) while it does; when every pair halved is, the halves leave out the part of the
    // stretch around the middle where all of them are (each half then has less travel, and a pair
    // approaching or leaving contact gets there in fewer checks).
    const double mid = 0.5 * (st.s0 + st.s1);
    // `*_screw`: that side's reach is what the turn keeps apart (not the distance's room), so a
    // contact the screw's shift makes or breaks lies just beyond it (probed below).
    struct Reach {
      double left = 0.0, right = 0.0;
      bool left_screw = false, right_screw = false;
    };
    // Half the resolution's shift to spare in what the turn keeps apart: a check at the end of such
    // a window is then not one of a distance within a hair of T, which a certified decision pays
    // dearly for.
    const double spare = 0.5 * motion.resolution;
    // The largest w in [0, most] for which holds(w), found by halving (what the turn keeps apart
    // shrinks as the stretch widens).
    auto longest = [](double most, auto&& holds) {
      if (holds(most)) return most;
      if (!holds(0.0)) return 0.0;
      double lo = 0.0, hi = most;
      for (int i = 0; i < 40; ++i) {
        const double m = 0.5 * (lo + hi);
        (holds(m) ? lo : hi) = m;
      }
      return lo;
    };
    auto reach_of = [&](const PairKey& k) {
      Reach r;
      if (const double room = margin.at(k) - options.tolerance; room > 0.0) {
        // The travel is affine in the width of the stretch: its rate and what it is over none.
        const double none = key_travel(k, mid, mid), rate = key_travel(k, 0.0, 1.0) - none;
        auto side = [&](double most, auto&& travel) {
          double free = rate > 0.0 ? std::min(most, (1.0 - 1e-6) * (room - none) / rate) : most;
          // Checked as the grown check clears a pair, halved where the rounding says otherwise.
          for (int tries = 0; free > 0.0 && !(travel(free) < room); ++tries) free = tries < 8 ? 0.5 * free : 0.0;
          return std::max(free, 0.0);
        };
        r.left = side(mid - st.s0, [&](double f) { return key_travel(k, mid - f, mid); });
        r.right = side(st.s1 - mid, [&](double f) { return key_travel(k, mid, mid + f); });
      }
      if (std::get<2>(k) != kInvalidId && grown.uncertainty.count(k)) {
        // The widest the turn keeps apart on either side.
        const double need = grown.uncertainty.at(k);
        const double left = longest(mid - st.s0, [&](double w) { return held_apart(k, need, mid - w, mid, spare); });
        const double right = longest(st.s1 - mid, [&](double w) { return held_apart(k, need, mid, mid + w, spare); });
        if (left > r.left) r.left = left, r.left_screw = true;
        if (right > r.right) r.right = right, r.right_screw = true;
      }
      return r;
    };
    // Each surface pair's reach; an instance pair's: the least of its suspect surface pairs', none
    // with a containment.
    std::map<PairKey, Reach> reaches;
    for (const auto& [k, m] : margin)
      if (std::get<2>(k) != kInvalidId) reaches.emplace(k, reach_of(k));
    auto least = [](Reach& into, const Reach& e) {
      if (e.left < into.left) into.left = e.left, into.left_screw = e.left_screw;
      if (e.right < into.right) into.right = e.right, into.right_screw = e.right_screw;
    };
    // The suspect surface pairs of an instance key's pair (its others were cleared over the stretch).
    auto surfaces_of = [&](const PairKey& k) {
      std::vector<PairKey> found;
      for (auto it = reaches.lower_bound({std::get<0>(k), std::get<1>(k), 0, 0});
           it != reaches.end() && std::get<0>(it->first) == std::get<0>(k) && std::get<1>(it->first) == std::get<1>(k); ++it)
        found.push_back(it->first);
      return found;
    };
    auto reach_at = [&](const PairKey& k) {
      if (std::get<2>(k) != kInvalidId) return reaches.at(k);
      if (grown.containment.count(k)) return Reach{};
      Reach r{mid - st.s0, st.s1 - mid};
      for (const PairKey& sk : surfaces_of(k)) least(r, reaches.at(sk));
      return r;
    };
    Reach r{mid - st.s0, st.s1 - mid};
    for (const PairKey& k : halve) least(r, reach_at(k));
    // What the turn keeps apart at a part's ends: a surface pair's longest start [a, p] and end
    // [q, b] held apart (p = a, q = b: none; p >= q: apart over the whole part). An instance pair
    // is also in contact where one part holds the other (containment), which needs no face to
    // touch: while all of its suspect surface pairs are apart (the others were cleared over the
    // stretch) that stays as it is, so only where such a stretch joins the middle of this one,
    // where the grown check saw no containment, is the instance pair kept apart by its surface
    // pairs: at the end of the part before the middle (`before_mid`), the start of the one after.
    auto surface_ends = [&](const PairKey& k, double a, double b) {
      const auto it = grown.uncertainty.find(k);
      if (it == grown.uncertainty.end()) return std::pair{a, b};
      auto apart = [&](double u0, double u1) { return held_apart(k, it->second, u0, u1, spare); };
      return std::pair{a + longest(b - a, [&](double w) { return apart(a, a + w); }),
                       b - longest(b - a, [&](double w) { return apart(b - w, b); })};
    };
    auto kept_ends = [&](const PairKey& k, double a, double b, bool before_mid) {
      if (std::get<2>(k) != kInvalidId) return surface_ends(k, a, b);
      const std::vector<PairKey> surfaces = surfaces_of(k);
      if (grown.containment.count(k) || surfaces.empty()) return std::pair{a, b};
      std::pair<double, double> hull = before_mid ? std::pair{a, a} : std::pair{b, b};
      for (const PairKey& sk : surfaces) {
        const auto [p, q] = surface_ends(sk, a, b);
        if (p >= q) continue;  // apart over the whole part
        if (before_mid) hull.second = std::max(hull.second, q);
        else hull.first = std::min(hull.first, p);
      }
      return hull;
    };
    // The parts of the stretch left to search, earliest first, each with the pairs it searches.
    // Each pair is searched only between the ends the turn keeps it apart beyond; and where it is
    // kept apart beyond a point, a contact the screw's shift makes or breaks there is likely just
    // inside it: a piece one resolution wide next to it is searched on its own (a check or two
    // settle it), as is what lies between such pieces (often in contact at both ends, settled by
    // one check), instead of halving down to them from the whole part. A surface pair whose instance
    // pair is halved too is searched where its instance pair is (the instance pair's state is its
    // surface pairs').
    const double probe = (1.0 - 1e-6) * motion.resolution;
    std::vector<Stretch> parts;
    auto add_part = [&](double a, double b, bool before_mid, bool screw_start, bool screw_end) {
      if (!(a < b)) return;
      std::vector<std::pair<PairKey, std::pair<double, double>>> where;  // each pair's [p, q]
      std::vector<std::pair<double, double>> windows;
      if (screw_start) windows.emplace_back(a, a + probe);
      if (screw_end) windows.emplace_back(b - probe, b);
      std::map<PairKey, std::pair<double, double>> kept;  // per key asked: an instance pair's is its surface pairs'
      for (const PairKey& k : halve) {
        const PairKey whole{std::get<0>(k), std::get<1>(k), kInvalidId, kInvalidId};
        const PairKey& by = halve.count(whole) ? whole : k;
        auto found = kept.find(by);
        if (found == kept.end()) found = kept.emplace(by, kept_ends(by, a, b, before_mid)).first;
        const auto [p, q] = found->second;
        if (p >= q) continue;  // kept apart at one end or the other: free over the part
        where.push_back({k, {p, q}});
        if (p > a) windows.emplace_back(p, p + probe);
        if (q < b) windows.emplace_back(q - probe, q);
      }
      // The windows, joined where they overlap or leave less than a resolution between them, and
      // the parts between them.
      std::sort(windows.begin(), windows.end());
      std::vector<std::pair<double, double>> joined;
      for (auto [u, v] : windows) {
        u = std::max(u, a), v = std::min(v, b);
        if (!joined.empty() && u <= joined.back().second + probe) joined.back().second = std::max(joined.back().second, v);
        else joined.emplace_back(u, v);
      }
      std::vector<std::pair<double, double>> pieces;
      double next = a;
      for (const auto& [u, v] : joined) {  // ascending, apart, within [a, b]
        if (u > next) pieces.emplace_back(next, u);
        if (v > u) pieces.emplace_back(u, v), next = v;
      }
      if (next < b) pieces.emplace_back(next, b);
      for (const auto& [u, v] : pieces) {
        std::set<PairKey> pairs;
        for (const auto& [k, pq] : where)
          if (std::max(pq.first, u) < std::min(pq.second, v)) pairs.insert(k);
        if (!pairs.empty()) parts.push_back({u, v, std::move(pairs), false});
      }
    };
    add_part(st.s0, mid - r.left, true, false, r.left > 0.0 && r.left_screw);
    add_part(mid + r.right, st.s1, false, r.right > 0.0 && r.right_screw, false);
    for (auto it = parts.rbegin(); it != parts.rend(); ++it) stack.push_back(std::move(*it));
  }
  std::map<std::pair<InstanceId, InstanceId>, PairMotion> by_pair;
  if (options.clearance > 0.0) {
    auto check_at = [&](double s, double grow) {
      place(s);
      CollideOptions o = options;
      o.clearance = options.clearance + grow;
      return motion.check ? motion.check(scene, o) : scene.check(o);
    };
    bool complete = true;
    const std::size_t left = motion.max_checks > out.checks ? motion.max_checks - out.checks : 1;
    std::size_t used = 0;
    for (auto& [k, c] : detail::closest_approach(check_at, travel_over, options.clearance, motion.resolution, left,
                                                 used, complete)) {
      if (spans.count({k.first, k.second, kInvalidId, kInvalidId})) continue;  // may touch: its spans say where
      PairMotion& p = by_pair[k];
      p.a = k.first, p.b = k.second;
      p.closest = c;
    }
    out.checks += used;
    out.complete = out.complete && complete;
  }
  place(1.0);
  for (auto& [k, v] : spans) {
    std::sort(v.begin(), v.end(), [](const MotionSpan& x, const MotionSpan& y) { return x.s0 < y.s0; });
    const auto [a, b, sa, sb] = k;
    PairMotion& p = by_pair[{a, b}];
    p.a = a, p.b = b;
    if (sa == kInvalidId && sb == kInvalidId) p.spans = std::move(v);
    else p.surfaces.push_back({sa, sb, std::move(v)});
  }
  for (auto& [k, p] : by_pair) out.pairs.push_back(std::move(p));
  return out;
}

}  // namespace cadclash
