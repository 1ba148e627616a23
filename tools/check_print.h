// What `cadclash check` prints on stdout about a query: the pairs under their clash headings, the
// summary of classes, counters and times, and the partial-report lines.
#pragma once

#include "check_review.h"

#include "cadclash/collide.h"

#include <ostream>
#include <string>

namespace cadclash::cli {

// "#123" for STEP faces, the group name for mesh groups, else the face index.
std::string source_label(const Surface& s);

struct ClassCounts {
  std::size_t c[5] = {0, 0, 0, 0, 0};  // by ContactClass
  void add(const Report& r) {
    for (const SurfacePairResult& p : r.pairs) ++c[static_cast<int>(p.contact)];
  }
  // An undecided pair may be a contact: an audit fails safe.
  bool collision() const { return c[0] + c[1] + c[3] + c[4] > 0; }
};

// Four significant digits; "-" for infinities and NaN.
std::string fmt(double v);

// The pairs under one heading per instance pair (its clash's id, status and worst class); with
// `collapse`, the headings alone.
void print_table(const Model& m, const Report& r, const ClashReview& review, bool collapse, std::ostream& os);

// Counts by class and by deciding step, the query's counters and (with `timings`) its times.
void print_summary(const Report& r, bool timings, std::ostream& os);

// Report::stopped_by of a query refused for a value outside the supported range (model.h).
inline const std::string kOutOfRange = "out of range";

// What stopped a query, for "stopped by ...".
std::string stopped_text(const std::string& stopped_by);

// A loud line (and the first few pairs not examined) when a budget ran out or the query was refused.
void print_partial(const Model& m, const Report& r, std::ostream& os);

}  // namespace cadclash::cli
