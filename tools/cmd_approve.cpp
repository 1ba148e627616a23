// cadclash approve: approvals for the clashes of a report, written into (or added to) an approvals file.
#include "check_review.h"
#include "cli_common.h"

#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <set>

namespace cadclash::cli {
namespace {

struct ApproveOptions {
  std::string report;
  bool all = false;
  std::vector<std::string> ids;
  std::string rule_a, rule_b, part_a, part_b;  // a rule instead of ids
  std::vector<std::string> classes;
  std::string reason, by, date, expires;
  std::string output;
};

// The report's current clashes: its review's when written, else grouped from its pairs.
std::optional<std::vector<ReportClash>> report_clashes(const std::string& path) {
  const std::optional<std::string> text = read_text_file(path);
  if (!text) {
    std::cerr << path << ": error: cannot open the report\n";
    return std::nullopt;
  }
  ReportReadResult read = check_report_from_json(*text);
  if (read.error) {
    std::cerr << path << ": error: not a cadclash check report: " << format_report_error(*read.error) << '\n';
    return std::nullopt;
  }
  if (!read.report.query) {
    std::cerr << path << ": error: a --path report has no clashes to approve\n";
    return std::nullopt;
  }
  std::vector<ReportClash> out;
  for (ReportClash& c : read.report.review ? read.report.review->clashes : clashes_of(*read.report.query))
    if (current_clash(c)) out.push_back(std::move(c));
  return out;
}

// The approvals already in `path` (none when it does not exist yet).
std::optional<std::vector<Approval>> existing_approvals(const std::string& path) {
  if (!std::filesystem::exists(path)) return std::vector<Approval>{};
  const std::optional<std::string> text = read_text_file(path);
  if (!text) {
    std::cerr << path << ": error: cannot open the approvals file\n";
    return std::nullopt;
  }
  ApprovalsReadResult read = approvals_from_json(*text);
  if (read.error) {
    std::cerr << path << ": error: " << format_report_error(*read.error) << '\n';
    return std::nullopt;
  }
  return std::move(read.approvals);
}

int run_approve(const ApproveOptions& o) {
  const bool rule = !o.rule_a.empty() || !o.rule_b.empty() || !o.part_a.empty() || !o.part_b.empty();
  if (static_cast<int>(o.all) + static_cast<int>(!o.ids.empty()) + static_cast<int>(rule) != 1) {
    std::cerr << "cadclash approve: give exactly one of --all, --id ID..., or a rule (--a/--b/--part-a/--part-b)\n";
    return kExitUsage;
  }
  if (!rule && o.report.empty()) {
    std::cerr << "cadclash approve: --all and --id need the report the clashes are in\n";
    return kExitUsage;
  }
  std::optional<std::vector<Approval>> approvals = existing_approvals(o.output);
  if (!approvals) return kExitInputError;
  Approval base;
  base.reason = o.reason;
  base.by = o.by;
  base.date = o.date.empty() ? utc_today() : o.date;
  base.expires = o.expires;
  for (const std::string& c : o.classes) base.classes.push_back(*enum_from_name<ContactClass>(c));
  std::size_t added = 0;
  if (rule) {
    Approval a = base;
    a.a = o.rule_a == "**" ? "" : o.rule_a;
    a.b = o.rule_b == "**" ? "" : o.rule_b;
    a.part_a = o.part_a;
    a.part_b = o.part_b;
    approvals->push_back(std::move(a));
    added = 1;
  } else {
    const std::optional<std::vector<ReportClash>> clashes = report_clashes(o.report);
    if (!clashes) return kExitInputError;
    std::set<std::string> known, present;
    for (const ReportClash& c : *clashes) present.insert(c.id);
    for (const Approval& a : *approvals)
      if (!a.id.empty()) known.insert(a.id);
    std::vector<std::string> ids = o.ids;
    if (o.all)
      for (const ReportClash& c : *clashes) ids.push_back(c.id);
    for (const std::string& id : ids) {
      if (!present.count(id)) {
        std::cerr << o.report << ": error: no clash with id " << id << " in the report; nothing written\n";
        return kExitInputError;
      }
      if (!known.insert(id).second) continue;  // approved by id already (the first entry stays)
      Approval a = base;
      a.id = id;
      approvals->push_back(std::move(a));
      ++added;
    }
  }
  std::ofstream f(o.output, std::ios::binary);
  f << approvals_text(*approvals);
  if (!f) {
    std::cerr << o.output << ": error: cannot write the approvals file\n";
    return kExitInputError;
  }
  std::cout << "added " << added << " approval" << (added == 1 ? "" : "s") << " to " << o.output << " ("
            << approvals->size() << " in all)\n";
  return kExitOk;
}

}  // namespace

void register_approve(CLI::App& app) {
  auto o = std::make_shared<ApproveOptions>();
  CLI::App* cmd = app.add_subcommand("approve", "Approve clashes of a report: create or extend an approvals file");
  cmd->footer("Exit codes: 0 written; 1 a file could not be read or written, or an --id is not in the report; 2 usage error.\n"
              "The approvals file format and the rules' glob syntax: docs/review.md.");
  cmd->add_option("report", o->report, "A `cadclash check --json` report (not needed for a rule)");
  cmd->add_flag("--all", o->all, "Approve every current clash of the report (not resolved or unexamined ones)");
  cmd->add_option("--id", o->ids, "Approve these clash ids");
  cmd->add_option("--a", o->rule_a, "A rule instead: instance path glob of one side (default **)");
  cmd->add_option("--b", o->rule_b, "... and of the other side (default **)");
  cmd->add_option("--part-a", o->part_a, "Part name glob of the --a side");
  cmd->add_option("--part-b", o->part_b, "Part name glob of the --b side");
  std::vector<std::string> classes;
  for (ContactClass c : EnumNames<ContactClass>::values) classes.emplace_back(contact_class_name(c));
  cmd->add_option("--class", o->classes, "Approve only clashes whose worst class is one of these (e.g. touching)")
      ->check(CLI::IsMember(classes));
  cmd->add_option("--reason", o->reason, "Why the contact is intended")->required();
  cmd->add_option("--by", o->by, "Who approves")->required();
  auto date = [](const std::string& d) { return iso_date(d) ? std::string() : "expected a date YYYY-MM-DD"; };
  cmd->add_option("--date", o->date, "Date of the approval, YYYY-MM-DD (default: today, UTC)")->check(date);
  cmd->add_option("--expires", o->expires, "Last day the approval applies, YYYY-MM-DD")->check(date);
  cmd->add_option("-o,--output", o->output, "The approvals file to create or extend")->required();
  cmd->callback([o] {
    const int code = run_approve(*o);
    if (code != kExitOk) throw CLI::RuntimeError(code);
  });
}

}  // namespace cadclash::cli
