// cadclash check's review options: the baseline and approvals read, and the review printed.
#include "check_review.h"
#include "check_print.h"
#include "cmd_check_mpi.h"

#include "cli_common.h"

#include "cadclash/interference.h"

#include <algorithm>
#include <ctime>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <sstream>
#include <unistd.h>

namespace cadclash::cli {
namespace {

std::map<std::string, InstanceId> instances_by_path(const Model& m) {
  std::map<std::string, InstanceId> out;
  for (InstanceId i = 0; i < m.instances.size(); ++i) out.emplace(m.instances[i].path, i);
  return out;
}

// Whether --volume measures the clash: a current one whose solids overlap.
bool measured(const ReportClash& c) {
  return current_clash(c) && (c.worst == ContactClass::Penetrating || c.worst == ContactClass::Containment);
}

}  // namespace

std::optional<std::string> read_text_file(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) return std::nullopt;
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

void add_review_options(CLI::App& cmd, ReviewCliOptions& o) {
  cmd.add_option("--baseline", o.baseline,
                 "An earlier --json report: each clash is new, active, changed or resolved against it (docs/review.md)");
  cmd.add_option("--approvals", o.approvals,
                 "Approvals file (JSON, docs/review.md): approved clashes are listed, never fail --fail-on-collision");
  cmd.add_option("--today", o.today, "The date approvals expire against, YYYY-MM-DD (default: today, UTC)")
      ->check([](const std::string& d) { return iso_date(d) ? std::string() : "expected a date YYYY-MM-DD"; });
  std::vector<std::string> groups(kGroupBy.begin(), kGroupBy.end());
  cmd.add_option("--group-by", o.group_by,
                 "Group clashes by instance pair, part pair, common sub-assembly, or place (space: clusters of "
                 "clashes within --cluster-distance)")
      ->check(CLI::IsMember(groups));
  cmd.add_option("--cluster-distance", o.cluster_distance,
                 "With --group-by space: clashes whose contact boxes come this close (mm) share a cluster")
      ->check(CLI::NonNegativeNumber);
  cmd.add_option("--depth-change", o.depth_change,
                 "A clash whose max penetration moved by more than this (mm) since the baseline is changed")
      ->check(CLI::NonNegativeNumber);
  cmd.add_flag("--expand", o.expand, "List every surface pair under its clash, also on a terminal");
  cmd.add_flag("--volume", o.volume,
               "Interference volume, depth and centroid of each penetrating or containment clash (Boolean common "
               "of the two B-rep solids; docs/review.md)");
}

std::string utc_today() {
  const std::time_t now = std::time(nullptr);
  std::tm t{};
  gmtime_r(&now, &t);
  char buf[16];
  std::strftime(buf, sizeof buf, "%Y-%m-%d", &t);
  return buf;
}

std::optional<ReviewInputs> load_review_inputs(const ReviewCliOptions& o, bool trajectory) {
  if (trajectory && (!o.baseline.empty() || !o.approvals.empty() || o.volume || o.group_by != "instance")) {
    std::cerr << "cadclash check: --baseline, --approvals, --group-by and --volume review one query; a --path report "
                 "has no clashes\n";
    return std::nullopt;
  }
  ReviewInputs in;
  in.options.group_by = o.group_by;
  in.options.depth_change = o.depth_change;
  in.options.cluster_distance = o.cluster_distance;
  in.options.baseline_file = o.baseline;
  in.options.approvals_file = o.approvals;
  if (!o.baseline.empty()) {
    const std::optional<std::string> text = read_text_file(o.baseline);
    if (!text) {
      std::cerr << o.baseline << ": error: cannot open the baseline report\n";
      return std::nullopt;
    }
    ReportReadResult read = check_report_from_json(*text);
    if (read.error) {
      std::cerr << o.baseline << ": error: not a cadclash check report: " << format_report_error(*read.error) << '\n';
      return std::nullopt;
    }
    if (!read.report.query) {
      std::cerr << o.baseline << ": error: a --path report cannot be a baseline (it has steps, not one query)\n";
      return std::nullopt;
    }
    in.baseline = std::move(*read.report.query);
  }
  if (!o.approvals.empty()) {
    const std::optional<std::string> text = read_text_file(o.approvals);
    if (!text) {
      std::cerr << o.approvals << ": error: cannot open the approvals file\n";
      return std::nullopt;
    }
    ApprovalsReadResult read = approvals_from_json(*text);
    if (read.error) {
      std::cerr << o.approvals << ": error: " << format_report_error(*read.error) << '\n';
      return std::nullopt;
    }
    in.approvals = std::move(read.approvals);
    in.options.today = o.today.empty() ? utc_today() : o.today;
  }
  return in;
}

void measure_clashes(const Model& m, ClashReview& r) {
  const std::map<std::string, InstanceId> by_path = instances_by_path(m);
  for (ReportClash& c : r.clashes) {
    if (!measured(c)) continue;
    const InterferenceResult v = measure_interference(m, by_path.at(c.instance_a), by_path.at(c.instance_b));
    c.interference = ClashInterference{v.measured, v.note, v.volume, v.depth, {v.centroid.x(), v.centroid.y(), v.centroid.z()}};
  }
}

std::vector<PartId> parts_to_measure(const Model& m, const ClashReview& r) {
  const std::map<std::string, InstanceId> by_path = instances_by_path(m);
  std::vector<PartId> out;
  for (const ReportClash& c : r.clashes)
    if (measured(c))
      for (const std::string* path : {&c.instance_a, &c.instance_b}) out.push_back(m.instances[by_path.at(*path)].part);
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

std::vector<const ReportClash*> clash_of_pairs(const ClashReview& r, std::size_t pairs) {
  std::vector<const ReportClash*> out(pairs, nullptr);
  for (const ReportClash& c : r.clashes)
    for (const ClashSurfacePair& s : c.surface_pairs)
      if (s.pair >= 0 && static_cast<std::size_t>(s.pair) < pairs) out[s.pair] = &c;
  return out;
}

std::string clash_heading(const ClashReview& r, const ReportClash& c) {
  std::ostringstream s;
  s << "clash " << c.id << "  " << clash_status_name(c.status);
  if (c.approval >= 0) s << ", approved (" << r.approvals[c.approval].approval.reason << ")";
  s << "  " << contact_class_name(c.worst);
  if (c.max_penetration > 0) s << ", max penetration " << fmt(c.max_penetration);
  s << ", " << c.surface_pairs.size() << " surface pair" << (c.surface_pairs.size() == 1 ? "" : "s");
  if (c.interference && c.interference->measured)
    s << ", interference " << fmt(c.interference->volume) << " mm3, depth " << fmt(c.interference->depth) << " mm";
  else if (c.interference)
    s << ", no volume: " << c.interference->note;
  if (r.group_by != "instance") s << "  [group " << c.group << "]";
  return s.str();
}

std::string verdict_line(const ClashReview& r, bool complete) {
  std::size_t by_status[5] = {0, 0, 0, 0, 0}, by_class[5] = {0, 0, 0, 0, 0}, approved = 0, current = 0;
  for (const ReportClash& c : r.clashes) {
    if (!current_clash(c)) continue;
    ++current;
    ++by_status[static_cast<int>(c.status)];
    if (c.approval >= 0) ++approved;
    else ++by_class[static_cast<int>(c.worst)];
  }
  std::ostringstream s;
  s << "verdict: " << (complete ? "" : "PARTIAL: ");
  if (current == 0) {
    s << "no clashes";
    return s.str();
  }
  s << current << " clash" << (current == 1 ? "" : "es") << " (";
  const char* sep = "";
  for (const ClashStatus st : {ClashStatus::New, ClashStatus::Active, ClashStatus::Changed})
    if (by_status[static_cast<int>(st)] > 0) {
      s << sep << by_status[static_cast<int>(st)] << " " << clash_status_name(st);
      sep = ", ";
    }
  if (approved > 0) s << sep << approved << " approved";
  s << "): " << by_class[static_cast<int>(ContactClass::Penetrating)] << " penetrating, "
    << by_class[static_cast<int>(ContactClass::Touching)] << " touching";
  for (const ContactClass c : {ContactClass::Containment, ContactClass::Clearance})
    if (by_class[static_cast<int>(c)] > 0) s << ", " << by_class[static_cast<int>(c)] << " " << contact_class_name(c);
  s << "; " << by_class[static_cast<int>(ContactClass::Undecided)] << " undecided";
  return s.str();
}

void print_review(const ClashReview& r, std::ostream& os) {
  std::size_t n[5] = {0, 0, 0, 0, 0}, approved = 0;
  for (const ReportClash& c : r.clashes) {
    ++n[static_cast<int>(c.status)];
    approved += c.approval >= 0;
  }
  os << "\nclashes: " << n[0] + n[1] + n[2] << " (new " << n[0] << ", active " << n[1] << ", changed " << n[2]
     << "; approved " << approved << ")";
  if (!r.baseline.empty()) os << ", resolved since the baseline: " << n[3];
  if (n[4] > 0) os << ", not examined by this partial run: " << n[4];
  os << '\n';
  for (const ReportClash& c : r.clashes)
    if (!current_clash(c))
      os << "  " << clash_status_name(c.status) << " " << c.id << "  " << c.instance_a << "  x  " << c.instance_b << "  (was " << contact_class_name(c.worst)
         << ", " << c.surface_pairs.size() << " surface pairs)\n";
  for (const ApprovalUse& u : r.approvals) {
    if (!u.expired && u.matched > 0) continue;
    const Approval& a = u.approval;
    os << "  " << (u.expired ? "expired" : "stale") << " approval " << u.source << ": ";
    if (!a.id.empty()) {
      os << "id " << a.id;
    } else {
      os << (a.a.empty() ? "**" : a.a) << (a.part_a.empty() ? "" : " (part " + a.part_a + ")") << " x "
         << (a.b.empty() ? "**" : a.b) << (a.part_b.empty() ? "" : " (part " + a.part_b + ")");
    }
    if (u.expired) os << " (expired " << a.expires << ")";
    else os << " matches no clash";
    os << '\n';
  }
}

// Under mpirun a rank's stdout is the pseudo-terminal Open MPI forwards output through, whatever
// mpirun's own stdout is: isatty says nothing there, so an MPI job lists every pair, as a pipe does
// (and its table stays byte-identical to a single process's).
bool collapse_clashes(const ReviewCliOptions& o) {
  return !o.expand && !mpi_launch().by_mpirun && isatty(STDOUT_FILENO) == 1;
}

}  // namespace cadclash::cli
