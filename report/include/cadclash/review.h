// cadclash/review.h — the clash review of a report: stable clash ids, the diff against a baseline
// report, approvals, and grouping (docs/review.md; the report's `clashes` and `review`).
//
// A clash is one instance pair of a query with all its reported surface pairs. Everything here
// works on the report's structs (cadclash/report.h): a report read back from JSON reviews exactly as
// the query it was written from, so the CLI, the Python bindings and any later merge of partial
// reports share one definition.
//
// Contracts:
// - clash_id() depends only on the two instance paths and the two part names (never on STEP #ids,
//   array indices, coordinates, the thread count or the order the sides are given in).
// - Functions here never print and never throw; untrusted text (an approvals file) gives a
//   ReportError naming the JSON pointer of the problem.
// - Dates are ISO "YYYY-MM-DD" strings compared as text; `today` is always given by the caller
//   (the CLI: --today, else the UTC date), so a review is reproducible.
// Depends on cadclash::report only.
#pragma once

#include "cadclash/report.h"

#include <array>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace cadclash {

// The clash id of an instance pair: the first 12 hex digits (48 bits, lower case) of the 64-bit
// FNV-1a hash of "cadclash-clash-1" NUL path₁ NUL part₁ NUL path₂ NUL part₂, where side 1 is the
// side whose (path, part) is smaller in byte order. clash_id(a, pa, b, pb) == clash_id(b, pb, a, pa).
std::string clash_id(std::string_view instance_a, std::string_view part_a, std::string_view instance_b,
                     std::string_view part_b);

// The key of a surface pair within its clash, the sides in the clash's order: each side
// "f<face index>" followed by ":<name>" when the file named the face (STEP face names, OBJ groups)
// with anything but "#<digits>" (an exporter's entity id, which renumbering changes), or "part" for
// a containment; joined by " x " ("f12 x f3:TOP").
std::string surface_pair_key(const ReportSide& first, const ReportSide& second);

// Severity order of the classes for a clash's worst class: penetrating > containment > undecided >
// touching > clearance. Returns the more severe of the two.
ContactClass worse_class(ContactClass x, ContactClass y);

// True for the classes --fail-on-collision counts (all but clearance).
bool collision_class(ContactClass c);

// How clashes are grouped (ReportClash::group): "instance" (the clash's own "path x path"),
// "part" ("part x part", the part names in clash order), "subassembly" (the deepest assembly path
// holding both instances; "/" when they share none) or "space" ("cluster <k>": clashes whose boxes
// come within ReviewOptions::cluster_distance of each other, chained; k counts from 1 in clash order;
// a clash without a box is a cluster of its own).
inline constexpr std::array<std::string_view, 4> kGroupBy{"instance", "part", "subassembly", "space"};

// The clashes of `q`: one per instance pair, in the order of each pair's first surface pair; sides
// ordered as clash_id() orders them; status New; not approved; `group` per `group_by` ("space"
// without boxes: every clash its own cluster). `pair_boxes`, when not empty, holds one world box
// per pair of `q` (contact_boxes()); a clash's box is the union of its pairs' boxes.
// Preconditions: group_by is one of kGroupBy; pair_boxes is empty or has q.pairs.size() entries.
std::vector<ReportClash> clashes_of(const QueryReport& q, std::string_view group_by = "instance",
                                    std::span<const std::array<double, 6>> pair_boxes = {}, double cluster_distance = 0.0);

// Where each pair of `r` meets, in world coordinates at `poses` (one per instance of `model`): per
// axis, the overlap of the two surfaces' world boxes, or the gap between them when they do not
// overlap (a clearance pair). A whole-part side (containment) uses its part's surfaces' box.
// Preconditions: every id in `r` is valid for `model`; poses.size() == model.instances.size().
std::vector<std::array<double, 6>> contact_boxes(const Model& model, std::span<const Pose> poses, const Report& r);

// Gives clashes whose boxes come within `distance` (mm, box to box) of each other one group,
// "cluster <k>", chaining (single linkage); k counts from 1 in clash order. Sorts on the boxes'
// lower x and sweeps, so well-separated scenes cost about n log n.
void cluster_clashes(std::vector<ReportClash>& clashes, double distance);

// Sets each clash's status against `baseline` (clashes_of() the baseline report's query): New when
// its id is not there; Changed when its worst class, the set of its surface-pair keys or one of
// their classes differs, or its max_penetration moved by more than `depth_change` mm; else Active.
// Appends every baseline clash whose id is gone with its last data (`pair` -1): status Unexamined
// when its instance pair is in `unexamined` (a partial run did not look at it), else Resolved.
void diff_clashes(std::vector<ReportClash>& current, const std::vector<ReportClash>& baseline, double depth_change,
                  std::span<const std::array<std::string, 2>> unexamined = {});

// True for the clashes of this run's pairs (new, active, changed); false for resolved and unexamined.
bool current_clash(const ReportClash& c);

// Glob over instance paths and part names: `*` any run of characters except '/', `**` any run
// including '/', `?` one character except '/'; anything else matches itself.
bool glob_match(std::string_view pattern, std::string_view text);

// Whether `a` (an id, or a rule of globs applied to the sides in either order) covers `c`, and its
// `classes` (when given) hold c's worst class. Expiry is not looked at here.
bool approval_matches(const Approval& a, const ReportClash& c);

// Applies `approvals` (in file order; `file` names them in ApprovalUse::source) to the current
// clashes (current_clash): each gets the first unexpired approval that matches it. An approval whose `expires` is
// before `today` is expired and applies to nothing. Returns what became of every approval.
// Precondition: `today` is YYYY-MM-DD (iso_date).
std::vector<ApprovalUse> apply_approvals(std::vector<ReportClash>& clashes, const std::vector<Approval>& approvals,
                                         const std::string& file, const std::string& today);

// True when `d` is YYYY-MM-DD (month 01-12, day 01-31).
bool iso_date(std::string_view d);

// ---------------------------------------------------------------------------------------------
// The whole review, and what it means for --fail-on-collision
// ---------------------------------------------------------------------------------------------

struct ReviewOptions {
  std::string group_by = "instance";  // one of kGroupBy
  double cluster_distance = 10.0;     // mm, with group_by "space"
  double depth_change = 0.01;         // mm: a smaller move of max_penetration keeps a clash active
  std::vector<std::array<double, 6>> pair_boxes;  // contact_boxes() of the current query; empty: unknown
  std::string baseline_file;          // recorded in the review; "" = none
  std::string approvals_file;         // recorded in the review and in ApprovalUse::source
  std::string today;                  // YYYY-MM-DD; needed (and recorded) only with approvals
};

// clashes_of(current), diffed against `baseline` when given, approvals applied.
// Preconditions: o.group_by is in kGroupBy; o.today is a date when approvals are given.
ClashReview review_query(const QueryReport& current, const QueryReport* baseline, const std::vector<Approval>& approvals,
                         const ReviewOptions& o);

// True when a current clash (current_clash) that is not approved has a collision class.
bool unapproved_collision(const ClashReview& r);

// ---------------------------------------------------------------------------------------------
// The approvals file (docs/review.md): {"schema": "cadclash-approvals", "version": 1, "approvals": [...]}
// ---------------------------------------------------------------------------------------------

inline constexpr std::string_view kApprovalsSchema = "cadclash-approvals";
inline constexpr int kApprovalsVersion = 1;

struct ApprovalsReadResult {
  std::vector<Approval> approvals;   // meaningful only when !error
  std::optional<ReportError> error;  // the first problem, with its JSON pointer
};
// Parses an approvals file's text. Never throws.
ApprovalsReadResult approvals_from_json(std::string_view text);
// The file's text: 2-space indent, one trailing newline; approvals_from_json() reads it back equal.
std::string approvals_text(const std::vector<Approval>& approvals);

}  // namespace cadclash
