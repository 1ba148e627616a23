// cadclash/trajectory.h — paths of poses replayed on a prepared Scene: a CSV of steps parsed into
// rows, each step's rows applied, and the scene checked after each (collide.h includes it).
//
// Part of cadclash::collide; the conventions are model.h's.
#pragma once

#include "cadclash/collide.h"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace cadclash {

// One row of a trajectory: instance `path` gets the absolute world pose at step `step`.
struct TrajectoryRow {
  std::int64_t step = 0;
  std::string path;
  Pose pose = Pose::Identity();
  std::int64_t line = 0;  // 1-based line in the CSV
};

// Parses CSV text "step,instance_path,tx,ty,tz,qw,qx,qy,qz" (optional header line starting with
// "step"; blank lines and lines starting with '#' skipped). Bad rows become diagnostics naming
// `file` and the line and are skipped; quaternions are normalised (a zero quaternion is an error);
// a translation outside the supported range (model.h) is an error.
std::vector<TrajectoryRow> parse_trajectory(const std::string& text, const std::string& file,
                                            std::vector<Diagnostic>& diagnostics);

// Applies the rows of the step that starts at rows[k] (the rows that follow with the same step
// number) to `scene`; a row naming an unknown instance becomes a warning naming `file` and its line
// and is skipped. Returns the index of the first row after the step. Precondition: k < rows.size().
std::size_t apply_trajectory_step(Scene& scene, std::span<const TrajectoryRow> rows, std::size_t k,
                                  std::vector<Diagnostic>& diagnostics, const std::string& file);

// The warning a replay gives when its time budget ran out before the step that starts at rows[k]:
// how many steps from there on were not checked, at that row's line of `file`.
// Precondition: k < rows.size().
Diagnostic steps_not_checked(std::span<const TrajectoryRow> rows, std::size_t k, const std::string& file);

// ---------------------------------------------------------------------------------------------
// Motion between steps
// ---------------------------------------------------------------------------------------------
// Between two consecutive poses a and b of an instance, its motion for s in [0, 1] is the screw of
// the displacement M = b a^-1 (Chasles: every rigid displacement is a turn about a line and a shift
// along it): at s the part is turned by s times M's angle about M's axis and shifted by s times M's
// shift along it, so its rotation is slerp(q_a, q_b, s) (along the shorter arc, q and -q being one
// rotation, at constant angular speed) and each point moves along a helix about that axis. A point's
// path depends on the two placements of the part only, not on where its own frame (a CAD model's
// origin, often far off the part) or the world's has its origin: a nut turned about its bolt between
// two steps stays on the bolt, parts moved by one displacement move together. Without a turn it is
// the straight shift t_a -> t_b. (FCL's CCDM_SCREW is the same motion; its CCDM_LINEAR, a
// translation blended linearly with the slerp, depends on the part's origin.)

// The pose at fraction s of the motion from a to b (s = 0: a's rotation and translation, s = 1:
// b's, each up to its quaternion's rounding). Preconditions: a and b are rigid (orthonormal linear
// parts); 0 <= s <= 1.
Pose interpolate_pose(const Pose& a, const Pose& b, double s);

// The angle (radians, in [0, pi]) the motion from a to b turns through.
double motion_angle(const Pose& a, const Pose& b);

// An upper bound on how far any point of `box` (part-local) moves while s runs over [s0, s1] of
// the motion from a to b: (s1 - s0) times the largest speed of a box corner along its helix,
// hypot(angle * its distance from the screw's axis, the shift along it) (for a pure shift,
// |t_b - t_a|; for a turn about the part's origin, angle * |p|). Computed with its rounding: it also covers
// the rounding of the poses interpolate_pose computes (a few units in the last place of |p| + |t|),
// so a point of the box placed by interpolate_pose(a, b, s) for s in [s0, s1] lies within it of the
// same point placed by interpolate_pose(a, b, s0). Preconditions: 0 <= s0 <= s1 <= 1; box not empty.
double travel_bound(const Pose& a, const Pose& b, const Aabb& box, double s0, double s1);

// An upper bound on how much the distance between a point of `box_a` (a part-local box of a part
// moving from pose a0 to a1) and a point of `box_b` (another's, from b0 to b1) changes while s runs
// over [s0, s1] of both motions: how fast b's points move relative to a's, from the difference of
// the two screws' velocity fields over b's reach. Parts moved by one displacement (a sub-assembly
// pulled out or turned as a whole) get their poses' rounding only, where each travel_bound is the
// whole motion's. Computed with its rounding, as travel_bound. Preconditions: 0 <= s0 <= s1 <= 1;
// boxes not empty.
double relative_travel_bound(const Pose& a0, const Pose& a1, const Aabb& box_a, const Pose& b0, const Pose& b1,
                             const Aabb& box_b, double s0, double s1);

// One stretch of motion checked continuously: the instances `moving` go from poses `from` to `to`
// (interpolate_pose; the others stay where the scene has them), and every instance pair the scene
// checks is proved out of contact over the whole stretch or listed with the parts of it where it
// may be in contact. Contact is a static check's (penetrating, touching or containment, certified
// on the exact faces within T = tolerance + the faces' uncertainties); no time between two checks
// is called free unless proved.
//
// How: a stretch [s0, s1] is free for a pair when the certified check in its middle with the
// tolerance grown by the two largest travel_bounds of the moving instances over its halves proves
// the pair apart by more than T plus the pair's own travel (travel_bound of each side, or
// relative_travel_bound when both move; for a surface pair of which one side moves, that face's own
// travel: a face near the axis of a turn moves less than the part's far end), or, for a surface
// pair of a moving part and one that
// stays, when what the part's screw keeps proves them apart by more than T over the whole stretch
// (a point's coordinate along the screw's axis shifts by s times the shift, its distance from the
// axis stays: a nut's face rising off a plate, its bore turning about the bolt's exact cylinder;
// from the faces' boxes (each box's least and largest distance from the axis) and their exact
// cylinders, cones and tori about the axis; certified checks only; such pairs are left out of the
// stretch's check, CollideOptions::proved_apart, so that it neither meshes nor decides them). Pairs
// it cannot clear are halved, down to `resolution`; when every pair halved is proved apart in the
// middle, the part around it where their travel stays below that margin, or where the screw keeps
// them apart, is left out of both halves (conservative advancement). Each half is searched, for
// each pair, only between the ends the screw keeps that pair apart beyond, and where a part ends
// at such a point a piece one resolution wide beside it is searched on its own: a contact the
// screw's shift makes or breaks (a nut leaving its seat, a face passing a plane) lies there, and
// is bracketed by a check or two instead of halving down to it. An instance pair is kept apart by
// its surface pairs only where that joins the middle, where the check saw no containment (a part
// held inside another touches none of its faces). A part of the stretch
// where the pair is proved in contact at both ends is not halved further (in between it is not
// proved either way). Contact that begins and ends between two steps, a part passing through a thin
// plate, is found: such a stretch is never cleared. A pair of two instances that stay keeps the
// state it has at the stretch's ends (one span, proved in contact at its ends or not); the search is
// about the moving instances' pairs.
// With options.clearance > 0 the pairs that come within the clearance somewhere also get their
// closest approach (PairMotion::closest): a branch and bound over the stretch, each part of it
// bounded below by the check at its start (with the clearance grown by the travel) less the
// travel, pruned where that cannot beat the smallest upper bound found, halved down to
// `resolution` elsewhere.
struct MotionOptions {
  double resolution = 1e-3;      // width of the spans a contact may begin or end in, as a fraction of the stretch (> 0)
  std::size_t max_checks = 4096;  // static checks at most; past it the open spans are listed as they are
  // How each static check runs; empty: Scene::check. A distributed run (cadclash check under mpirun)
  // passes its own: it must return, on every process, reports with the same pairs (ids, classes,
  // distance bounds and uncertainties) and the same `complete`, so that every process takes the same
  // stretches.
  std::function<Report(Scene&, const CollideOptions&)> check;
  // The static checks a caller has made already at the stretch's ends (the moving instances at
  // `from`, and at `to`; the others where the scene has them), with options.tolerance and no
  // clearance (options as check_motion's; their time budget may differ): used instead of checking
  // there again. Null: checked here. replay_continuous passes its steps' checks.
  const Report* at_start = nullptr;
  const Report* at_end = nullptr;
};
struct MotionSpan {
  double s0 = 0.0, s1 = 0.0;
  // Proved in contact at s0 and at s1 (between: not proved either way); otherwise s1 - s0 <=
  // resolution and a contact may begin, end or hold there (or the search stopped: MotionResult), or
  // the pair's two instances do not move and it is undecided at the stretch's ends: the whole stretch.
  bool contact_at_ends = false;
};
struct SurfaceMotion {
  SurfaceId a = kInvalidId, b = kInvalidId;  // a surface of instance a's part, one of b's
  std::vector<MotionSpan> spans;             // ascending, disjoint
};
// How close a pair comes over a stretch (with options.clearance > 0): the minimum distance of its
// exact faces lies in [lo, hi] and is reached within [s0, s1] (certified: hi is a static check's
// upper bound at a point of the stretch, lo a lower bound over all of it; s0 and s1 bound every
// place where the distance can be below hi). lo is 0 when the pair may touch.
struct ClosestApproach {
  double lo = 0.0, hi = 0.0;
  double s0 = 0.0, s1 = 0.0;
};
struct PairMotion {
  InstanceId a = kInvalidId, b = kInvalidId;  // a < b
  // The instance pair's: where any of its surface pairs (or containment) may be in contact.
  std::vector<MotionSpan> spans;              // ascending, disjoint
  // Each surface pair's own (by (a, b)): where that pair may be in contact, the same guarantees.
  std::vector<SurfaceMotion> surfaces;
  // With options.clearance > 0: how close the pair comes, when it comes within the clearance
  // somewhere and may touch nowhere (it is then listed with no spans; a pair with spans has none).
  std::optional<ClosestApproach> closest;
};
struct MotionResult {
  std::vector<PairMotion> pairs;  // by (a, b); a pair not listed is out of contact over the whole stretch
  std::size_t checks = 0;         // static checks run
  bool complete = true;           // false: max_checks ran out, the spans of the unfinished parts are listed whole
};

// Checks one stretch continuously (see above) and leaves the moving instances at `to`. At s = 0 and
// s = 1 the moving instances are checked at `from` and `to` themselves. Uses the
// scene's selection and `options` (its tolerance and decision; its budgets apply to each static check,
// and a partial check clears nothing). Preconditions: moving, from and to have one entry per
// moving instance; the poses are rigid; resolution > 0.
MotionResult check_motion(Scene& scene, const Model& model, std::span<const InstanceId> moving,
                          std::span<const Pose> from, std::span<const Pose> to, const CollideOptions& options,
                          const MotionOptions& motion = {});

struct StepResult {
  std::int64_t step = 0;
  Report report;
};

// Replays rows on `scene`: rows with equal consecutive step numbers are applied together, then the
// scene is checked. Rows naming unknown instances become diagnostics (warning) and are skipped.
// Budgets: options.time_budget_seconds covers the whole replay. When it runs out, the step being
// checked returns a partial report (Report::complete false), the later steps are not checked (not
// in the result) and a warning naming `file` and the first unchecked step's line says how many were
// left. options.memory_budget_bytes applies to each step's check() on its own.
std::vector<StepResult> replay_trajectory(Scene& scene, std::span<const TrajectoryRow> rows,
                                          const CollideOptions& options,
                                          std::vector<Diagnostic>& diagnostics, const std::string& file = {});

// A whole path checked continuously: each step checked as replay_trajectory does, and the motion
// between consecutive steps by check_motion (the instances a step's rows move, from where the
// scene had them). Times are the path's: between steps k and k + 1 the motion's fraction s is at
// time step_k + s (step_{k+1} - step_k); `motion.resolution` is a fraction of that stretch. The
// first step places the instances (no motion before it).
struct PathResult {
  std::vector<StepResult> steps;  // the check at each step, as replay_trajectory
  // Every instance pair that may be in contact at some time between the first and last step checked,
  // with its spans and its surface pairs' in path time; consecutive spans proved in contact at both
  // ends are joined (also across steps). A pair not listed is out of contact over the whole path.
  std::vector<PairMotion> pairs;
  std::size_t checks = 0;  // static checks run for the motion (the steps' own not counted)
  bool complete = true;    // false: a stretch ran out of max_checks, or the time budget stopped the path
};
// Budgets as replay_trajectory: options.time_budget_seconds covers the whole path (each stretch and
// step gets what the earlier ones left); when it runs out, the later steps and the motion to them are
// not checked and a warning says from which step. Rows naming unknown instances: warnings, skipped.
// Step numbers must ascend: a step not after the one before is an error naming its line, and the
// path is checked up to there.
// Precondition: motion.resolution > 0.
PathResult replay_continuous(Scene& scene, const Model& model, std::span<const TrajectoryRow> rows,
                             const CollideOptions& options, const MotionOptions& motion,
                             std::vector<Diagnostic>& diagnostics, const std::string& file = {});

}  // namespace cadclash
