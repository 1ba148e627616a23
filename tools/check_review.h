// The clash review of `cadclash check` (--baseline, --approvals, --group-by): loading its inputs,
// printing it, and the `cadclash approve` subcommand. The review itself is library code (cadclash/review.h).
#pragma once

#include "cadclash/review.h"

#include <CLI/CLI.hpp>

#include <optional>
#include <ostream>
#include <string>
#include <vector>

namespace cadclash::cli {

struct ReviewCliOptions {
  std::string baseline;   // an earlier `check --json` report
  std::string approvals;  // an approvals file (docs/review.md)
  std::string today;      // YYYY-MM-DD; "" = today's UTC date
  std::string group_by = "instance";
  double cluster_distance = 10.0;  // mm, with --group-by space
  double depth_change = 0.01;  // mm
  bool expand = false;         // list every surface pair under its clash even on a terminal
  bool volume = false;         // measure the interference of penetrating and containment clashes
};

// Adds --baseline, --approvals, --today, --group-by, --depth-change and --expand to `cmd`.
void add_review_options(CLI::App& cmd, ReviewCliOptions& o);

// What the review reads before the check: the baseline's query and the approvals.
struct ReviewInputs {
  std::optional<QueryReport> baseline;
  std::vector<Approval> approvals;
  ReviewOptions options;
};

// Reads the baseline and the approvals; std::nullopt, after saying why on stderr (file and JSON
// pointer), when one cannot be read or is not valid. `trajectory`: the check replays a --path, which
// has no clashes: any review option is then refused.
std::optional<ReviewInputs> load_review_inputs(const ReviewCliOptions& o, bool trajectory);

// The whole file at `path`; nullopt when it cannot be opened.
std::optional<std::string> read_text_file(const std::string& path);

// Today's date in UTC, YYYY-MM-DD.
std::string utc_today();

// With --volume: the Boolean common of each current penetrating or containment clash's two solids
// (cadclash/interference.h) into its `interference`.
void measure_clashes(const Model& m, ClashReview& r);
// The parts whose solids measure_clashes(m, r) intersects: ascending, each once.
std::vector<PartId> parts_to_measure(const Model& m, const ClashReview& r);

// For each pair index of the query, its clash in `r` (nullptr for none).
std::vector<const ReportClash*> clash_of_pairs(const ClashReview& r, std::size_t pairs);

// "id status class ..." of a clash, the table's heading line for it.
std::string clash_heading(const ClashReview& r, const ReportClash& c);

// The clash counts per status, the resolved clashes, and every stale or expired approval.
void print_review(const ClashReview& r, std::ostream& os);

// The one line a person reads first, the last of `cadclash check`'s output: "verdict: 32 clashes
// (32 new): 0 penetrating, 32 touching; 0 undecided", the current clashes by their worst class
// (containment and clearance named when there are any, approved ones counted apart), "PARTIAL" when
// not every pair was examined.
std::string verdict_line(const ClashReview& r, bool complete);

// True when the table shows only one line per clash: stdout is a terminal and --expand was not given.
bool collapse_clashes(const ReviewCliOptions& o);

void register_approve(CLI::App& app);

}  // namespace cadclash::cli
