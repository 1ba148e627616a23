// Clashes from a query's pairs: stable ids, surface-pair keys, groups, and the diff against a baseline.
#include "cadclash/review.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <set>
#include <utility>

namespace cadclash {
namespace {

// FNV-1a, 64 bit: tiny, fixed by its published constants, the same on every machine.
struct Fnv1a {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  void add(std::string_view s) {
    for (unsigned char c : s) {
      h ^= c;
      h *= 0x100000001b3ULL;
    }
  }
  void nul() { add(std::string_view("\0", 1)); }
};

// True when side (ia, pa) comes after (ib, pb): the clash then lists b first.
bool swapped(std::string_view ia, std::string_view pa, std::string_view ib, std::string_view pb) {
  return std::pair(ia, pa) > std::pair(ib, pb);
}

int severity(ContactClass c) {
  switch (c) {
    case ContactClass::Penetrating: return 4;
    case ContactClass::Containment: return 3;
    case ContactClass::Undecided: return 2;
    case ContactClass::Touching: return 1;
    case ContactClass::Clearance: break;
  }
  return 0;
}

// "#<digits>": what some exporters write as every face's name (as1's faces are named after their
// own entity ids), which renumbering changes. Not a name to key on.
bool entity_id_name(const std::string& name) {
  return name.size() > 1 && name[0] == '#' &&
         std::all_of(name.begin() + 1, name.end(), [](char c) { return c >= '0' && c <= '9'; });
}

std::string face_label(const ReportSide& s) {
  if (s.whole_part) return "part";
  std::string out = "f";
  out += std::to_string(s.face_index);
  if (!s.source_name.empty() && !entity_id_name(s.source_name)) {
    out += ':';
    out += s.source_name;
  }
  return out;
}

// The path of the deepest assembly holding both instances: their common leading segments.
std::string common_assembly(const std::string& x, const std::string& y) {
  std::size_t end = 0;  // length of the common prefix that ends at a '/'
  for (std::size_t k = 0; k < x.size() && k < y.size() && x[k] == y[k]; ++k)
    if (x[k] == '/') end = k;
  return end == 0 ? std::string("/") : x.substr(0, end);
}

std::string group_of(const ReportClash& c, std::string_view group_by) {
  if (group_by == "part") return c.part_a + " x " + c.part_b;
  if (group_by == "subassembly") return common_assembly(c.instance_a, c.instance_b);
  return c.instance_a + " x " + c.instance_b;
}

}  // namespace

std::string clash_id(std::string_view instance_a, std::string_view part_a, std::string_view instance_b,
                     std::string_view part_b) {
  if (swapped(instance_a, part_a, instance_b, part_b)) {
    std::swap(instance_a, instance_b);
    std::swap(part_a, part_b);
  }
  Fnv1a f;
  f.add("cadclash-clash-1");
  for (std::string_view s : {instance_a, part_a, instance_b, part_b}) {
    f.nul();
    f.add(s);
  }
  static constexpr char kHex[] = "0123456789abcdef";
  std::string out(12, '0');
  for (int k = 0; k < 12; ++k) out[k] = kHex[(f.h >> (60 - 4 * k)) & 15];
  return out;
}

std::string surface_pair_key(const ReportSide& first, const ReportSide& second) {
  return face_label(first) + " x " + face_label(second);
}

ContactClass worse_class(ContactClass x, ContactClass y) { return severity(y) > severity(x) ? y : x; }

bool collision_class(ContactClass c) { return c != ContactClass::Clearance; }

std::vector<ReportClash> clashes_of(const QueryReport& q, std::string_view group_by,
                                    std::span<const std::array<double, 6>> pair_boxes, double cluster_distance) {
  assert(std::find(kGroupBy.begin(), kGroupBy.end(), group_by) != kGroupBy.end());
  assert(pair_boxes.empty() || pair_boxes.size() == q.pairs.size());
  std::vector<ReportClash> out;
  std::map<std::pair<std::string, std::string>, std::size_t> index;  // (instance a, instance b) as reported
  for (std::size_t k = 0; k < q.pairs.size(); ++k) {
    const ReportPair& p = q.pairs[k];
    const bool swap = swapped(p.a.instance, p.a.part, p.b.instance, p.b.part);
    const ReportSide& first = swap ? p.b : p.a;
    const ReportSide& second = swap ? p.a : p.b;
    auto [it, inserted] = index.try_emplace({first.instance, second.instance}, out.size());
    if (inserted) {
      ReportClash c;
      c.id = clash_id(first.instance, first.part, second.instance, second.part);
      c.instance_a = first.instance;
      c.part_a = first.part;
      c.instance_b = second.instance;
      c.part_b = second.part;
      c.worst = p.contact;
      c.max_penetration = 0.0;
      c.min_distance = std::numeric_limits<double>::infinity();
      out.push_back(std::move(c));
    }
    ReportClash& c = out[it->second];
    c.worst = worse_class(c.worst, p.contact);
    c.max_penetration = std::max(c.max_penetration, p.penetration);
    c.min_distance = std::min(c.min_distance, p.distance);
    c.surface_pairs.push_back({surface_pair_key(first, second), static_cast<std::int64_t>(k), p.contact, p.penetration, p.distance});
    if (!pair_boxes.empty()) {
      const std::array<double, 6>& b = pair_boxes[k];
      if (!c.box) c.box = b;
      for (int a = 0; a < 3; ++a) {
        (*c.box)[a] = std::min((*c.box)[a], b[a]);
        (*c.box)[a + 3] = std::max((*c.box)[a + 3], b[a + 3]);
      }
    }
  }
  if (group_by == "space") {
    cluster_clashes(out, cluster_distance);
  } else {
    for (ReportClash& c : out) c.group = group_of(c, group_by);
  }
  return out;
}

bool current_clash(const ReportClash& c) {
  return c.status == ClashStatus::New || c.status == ClashStatus::Active || c.status == ClashStatus::Changed;
}

void diff_clashes(std::vector<ReportClash>& current, const std::vector<ReportClash>& baseline, double depth_change,
                  std::span<const std::array<std::string, 2>> unexamined) {
  std::set<std::pair<std::string, std::string>> not_examined;
  for (const auto& [a, b] : unexamined) {
    not_examined.emplace(a, b);
    not_examined.emplace(b, a);
  }
  std::map<std::string, const ReportClash*> before;
  for (const ReportClash& b : baseline) before.emplace(b.id, &b);
  std::map<std::string, bool> seen;
  for (ReportClash& c : current) {
    seen[c.id] = true;
    const auto it = before.find(c.id);
    if (it == before.end()) {
      c.status = ClashStatus::New;
      continue;
    }
    const ReportClash& b = *it->second;
    std::map<std::string, ContactClass> now, then;
    for (const ClashSurfacePair& s : c.surface_pairs) now[s.key] = s.contact;
    for (const ClashSurfacePair& s : b.surface_pairs) then[s.key] = s.contact;
    const bool changed = c.worst != b.worst || now != then ||
                         std::abs(c.max_penetration - b.max_penetration) > depth_change;
    c.status = changed ? ClashStatus::Changed : ClashStatus::Active;
  }
  for (const ReportClash& b : baseline) {
    if (seen.count(b.id)) continue;
    ReportClash r = b;
    r.status = not_examined.count({b.instance_a, b.instance_b}) ? ClashStatus::Unexamined : ClashStatus::Resolved;
    r.approval = -1;
    for (ClashSurfacePair& s : r.surface_pairs) s.pair = -1;
    current.push_back(std::move(r));
  }
}

ClashReview review_query(const QueryReport& current, const QueryReport* baseline, const std::vector<Approval>& approvals,
                         const ReviewOptions& o) {
  ClashReview r;
  r.baseline = o.baseline_file;
  r.approvals_file = o.approvals_file;
  r.group_by = o.group_by;
  const bool space = o.group_by == "space";
  r.cluster_distance = space ? o.cluster_distance : 0.0;
  r.clashes = clashes_of(current, o.group_by, o.pair_boxes, o.cluster_distance);
  if (baseline) {
    // Grouped by instance pair for the resolved ones: the baseline's clusters mean nothing now.
    std::vector<ReportClash> before = clashes_of(*baseline, space ? "instance" : o.group_by);
    if (space)
      for (ReportClash& c : before) c.group = "resolved";
    diff_clashes(r.clashes, before, o.depth_change, current.unexamined_pairs);
  }
  if (!o.approvals_file.empty() || !approvals.empty()) {
    r.today = o.today;
    r.approvals = apply_approvals(r.clashes, approvals, o.approvals_file, o.today);
  }
  return r;
}

bool unapproved_collision(const ClashReview& r) {
  for (const ReportClash& c : r.clashes)
    if (current_clash(c) && c.approval < 0 && collision_class(c.worst)) return true;
  return false;
}

}  // namespace cadclash
