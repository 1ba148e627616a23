#include "import_stages.h"

#include <filesystem>
#include <iomanip>
#include <sstream>

namespace cadclash::cli {

ReportImport import_report(const ImportResult& imported) {
  ReportImport out;
  out.seconds = imported.seconds;
  for (const FileImport& f : imported.files) {
    const ImportTimings& t = f.timings;
    ReportFileImport& r = out.files.emplace_back();
    r.file = f.path;
    r.cache = cache_use_name(f.cache);
    r.read = t.read;
    r.transfer = t.transfer;
    r.heal = t.heal;
    r.tessellate = t.tessellate;
    r.total = t.total;
    r.processes = f.transfer_workers;
    r.pieces = f.pieces;
    r.pieces_cached = f.pieces_cached;
    r.parts_cached = f.parts_cached;
    if (const PieceCosts& c = f.piece_costs; !c.bytes.empty())
      r.piece_costs = ReportPieceCosts{c.split, c.main_parse, c.workers, {c.bytes.begin(), c.bytes.end()},
                                       {c.weights.begin(), c.weights.end()}, c.seconds};
    r.part_heal_seconds = f.part_heal_seconds;
  }
  return out;
}

void print_import_stages(const ImportResult& imported, const CheckReport& report, std::ostream& os) {
  auto ms = [](double seconds) {
    std::ostringstream s;
    s << std::fixed << std::setprecision(seconds < 0.01 ? 2 : seconds < 1.0 ? 1 : 0) << seconds * 1e3;
    return s.str();
  };
  double query = 0.0;
  if (report.query && report.query->timings) query = report.query->timings->total;
  for (const StepReport& s : report.steps)
    if (s.query.timings) query += s.query.timings->total;
  ImportTimings sum;
  os << "\nimport: " << imported.files.size() << (imported.files.size() == 1 ? " file" : " files") << " in "
     << ms(imported.seconds) << " ms\n";
  os << "  " << std::left << std::setw(28) << "file" << std::setw(9) << "cache" << std::right << std::setw(10) << "read"
     << std::setw(10) << "transfer" << std::setw(10) << "heal" << std::setw(12) << "tessellate" << std::setw(10)
     << "total" << "  (ms)\n";
  for (const FileImport& f : imported.files) {
    const ImportTimings& t = f.timings;
    os << "  " << std::left << std::setw(28) << std::filesystem::path(f.path).filename().string() << std::setw(9)
       << cache_use_name(f.cache) << std::right << std::setw(10) << ms(t.read) << std::setw(10) << ms(t.transfer)
       << std::setw(10) << ms(t.heal) << std::setw(12) << ms(t.tessellate) << std::setw(10) << ms(t.total) << '\n';
    sum.read += t.read;
    sum.transfer += t.transfer;
    sum.heal += t.heal;
    sum.tessellate += t.tessellate;
  }
  os << "stages: read " << ms(sum.read) << " ms, transfer " << ms(sum.transfer) << " ms, heal " << ms(sum.heal)
     << " ms, tessellate " << ms(sum.tessellate) << " ms, query " << ms(query) << " ms\n";
}

}  // namespace cadclash::cli
