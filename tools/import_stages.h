// Where reading the input files went: the per-stage times `cadclash check` prints and writes
// (report key `import_timings`), left out with --no-timings.
#pragma once

#include "cadclash/import.h"
#include "cadclash/report.h"

#include <ostream>

namespace cadclash::cli {

// The import's timings and cache use as the report holds them.
ReportImport import_report(const ImportResult& imported);

// One line per file (cache use, read, transfer, heal, tessellate, total in ms) and one line with the
// stages summed over the files and the query's time (`report`'s query, or its steps summed).
void print_import_stages(const ImportResult& imported, const CheckReport& report, std::ostream& os);

}  // namespace cadclash::cli
