// Approvals: the file's reader and writer, glob matching, and applying approvals to clashes.
#include "cadclash/review.h"

#include <algorithm>
#include <cassert>
#include <vector>

namespace cadclash {

bool iso_date(std::string_view d) {
  if (d.size() != 10 || d[4] != '-' || d[7] != '-') return false;
  for (std::size_t k : {0, 1, 2, 3, 5, 6, 8, 9})
    if (d[k] < '0' || d[k] > '9') return false;
  const int month = (d[5] - '0') * 10 + (d[6] - '0');
  const int day = (d[8] - '0') * 10 + (d[9] - '0');
  return month >= 1 && month <= 12 && day >= 1 && day <= 31;
}

bool glob_match(std::string_view pattern, std::string_view text) {
  // can[i][j]: pattern[i..] matches text[j..]; filled from the ends (no backtracking blow-up).
  const std::size_t np = pattern.size(), nt = text.size();
  std::vector<std::vector<char>> can(np + 1, std::vector<char>(nt + 1, 0));
  can[np][nt] = 1;
  for (std::size_t i = np; i-- > 0;) {
    const bool star2 = pattern[i] == '*' && i + 1 < np && pattern[i + 1] == '*';
    for (std::size_t j = nt + 1; j-- > 0;) {
      char& m = can[i][j];
      if (star2) {
        // "**": skip it, or eat any one character and stay.
        m = can[i + 2][j] || (j < nt && can[i][j + 1]);
      } else if (pattern[i] == '*') {
        m = can[i + 1][j] || (j < nt && text[j] != '/' && can[i][j + 1]);
      } else if (pattern[i] == '?') {
        m = j < nt && text[j] != '/' && can[i + 1][j + 1];
      } else {
        m = j < nt && text[j] == pattern[i] && can[i + 1][j + 1];
      }
    }
  }
  return can[0][0] != 0;
}

bool approval_matches(const Approval& a, const ReportClash& c) {
  if (!a.classes.empty() && std::find(a.classes.begin(), a.classes.end(), c.worst) == a.classes.end()) return false;
  if (!a.id.empty()) return a.id == c.id;
  auto side = [](const std::string& path_glob, const std::string& part_glob, const std::string& path, const std::string& part) {
    return (path_glob.empty() || glob_match(path_glob, path)) && (part_glob.empty() || glob_match(part_glob, part));
  };
  return (side(a.a, a.part_a, c.instance_a, c.part_a) && side(a.b, a.part_b, c.instance_b, c.part_b)) ||
         (side(a.a, a.part_a, c.instance_b, c.part_b) && side(a.b, a.part_b, c.instance_a, c.part_a));
}

std::vector<ApprovalUse> apply_approvals(std::vector<ReportClash>& clashes, const std::vector<Approval>& approvals,
                                         const std::string& file, const std::string& today) {
  assert(iso_date(today));
  std::vector<ApprovalUse> uses;
  for (std::size_t k = 0; k < approvals.size(); ++k) {
    ApprovalUse u;
    u.approval = approvals[k];
    u.source = file + "#/approvals/" + std::to_string(k);
    u.expired = !approvals[k].expires.empty() && approvals[k].expires < today;
    uses.push_back(std::move(u));
  }
  for (ReportClash& c : clashes) {
    c.approval = -1;
    if (!current_clash(c)) continue;
    for (std::size_t k = 0; k < uses.size(); ++k)
      if (!uses[k].expired && approval_matches(uses[k].approval, c)) {
        c.approval = static_cast<std::int64_t>(k);
        ++uses[k].matched;
        break;
      }
  }
  return uses;
}

ApprovalsReadResult approvals_from_json(std::string_view text) {
  ApprovalsReadResult out;
  const nlohmann::json j = nlohmann::json::parse(text.begin(), text.end(), nullptr, /*allow_exceptions=*/false);
  auto fail = [&](std::string path, std::string message) {
    out.error = ReportError{std::move(path), std::move(message)};
    return out;
  };
  if (j.is_discarded()) return fail("", "not valid JSON");
  if (!j.is_object()) return fail("", "expected an object");
  if (!j.contains("schema") || j["schema"] != kApprovalsSchema)
    return fail("/schema", "expected \"" + std::string(kApprovalsSchema) + "\"");
  if (!j.contains("version") || j["version"] != kApprovalsVersion)
    return fail("/version", "expected " + std::to_string(kApprovalsVersion));
  if (!j.contains("approvals") || !j["approvals"].is_array()) return fail("/approvals", "expected an array");
  for (std::size_t k = 0; k < j["approvals"].size(); ++k) {
    Approval a;
    if (std::optional<ReportError> e = approval_from_json(j["approvals"][k], "/approvals/" + std::to_string(k), a)) {
      out.error = std::move(e);
      return out;
    }
    out.approvals.push_back(std::move(a));
  }
  return out;
}

std::string approvals_text(const std::vector<Approval>& approvals) {
  nlohmann::json list = nlohmann::json::array();
  for (const Approval& a : approvals) list.push_back(approval_json(a));
  return report_text({{"schema", kApprovalsSchema}, {"version", kApprovalsVersion}, {"approvals", std::move(list)}});
}

}  // namespace cadclash
