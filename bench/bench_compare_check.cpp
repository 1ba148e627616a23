// Reads bench_compare's compare.json and fails unless it is complete (every workload has its
// rows, every row ran and carries its numbers) and every method held to exact agreement found the
// same surface pairs as cadclash, every copy of the instanced scene reported copy 0's pairs with the
// same contact classes, and the trajectory CSVs beside it parse with parse_trajectory.
// Timings are only checked to be present, never judged.
//   bench_compare_check compare.json      exit 0 ok, 1 a check failed (each failure printed), 77 no file
#include "cadclash/collide.h"

#include <nlohmann/json.hpp>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: bench_compare_check compare.json\n");
    return 2;
  }
  std::ifstream in(argv[1]);
  if (!in) {
    std::fprintf(stderr, "%s: not found (bench_compare skipped?)\n", argv[1]);
    return 77;
  }
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(in);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: %s\n", argv[1], e.what());
    return 1;
  }
  int failures = 0;
  auto fail = [&](const std::string& where, const std::string& what) {
    std::fprintf(stderr, "%s: %s\n", where.c_str(), what.c_str());
    ++failures;
  };
  if (!j.contains("workloads") || j["workloads"].size() < 4) fail("compare.json", "fewer than 4 workloads");
  for (const auto& w : j.value("workloads", nlohmann::json::array())) {
    const std::string wn = w.value("name", "?");
    for (const char* key : {"instances", "instance_triangles", "steps", "methods"})
      if (!w.contains(key)) fail(wn, std::string("missing ") + key);
    std::size_t cadclash_rows = 0, peer_rows = 0;
    for (const auto& m : w.value("methods", nlohmann::json::array())) {
      const std::string where = wn + " / " + m.value("name", "?");
      if (!m.value("error", std::string()).empty()) {
        fail(where, "not run: " + m.value("error", std::string()));
        continue;
      }
      (m.value("kind", "") == "cadclash" ? cadclash_rows : peer_rows)++;
      if (m["times_seconds"].empty() || !(m.value("median_seconds", 0.0) > 0.0)) fail(where, "no timing");
      if (!m.contains("surface_pairs") || !m.contains("ratio_to_default")) fail(where, "missing counts");
      const std::string name = m.value("name", "");
      // Held to exact agreement: every cadclash variant except the float-only one, and CGAL (exact
      // predicates on the same doubles). FCL's float triangle test and OCCT's overlap test may
      // differ on touching faces; their counts are reported, not judged.
      const bool exact = (m.value("kind", "") == "cadclash" && name.find("float filter only") == std::string::npos) ||
                         name.rfind("CGAL", 0) == 0;
      if (!m["agreement"].is_null()) {
        for (const char* key : {"both", "only_reference", "only_method", "agree"})
          if (!m["agreement"].contains(key)) fail(where, std::string("agreement lacks ") + key);
        if (exact && !m["agreement"].value("agree", false))
          fail(where, "surface pairs differ from cadclash: " + m["agreement"].dump());
      }
    }
    if (cadclash_rows < 8 || peer_rows < 5) fail(wn, "rows missing");
    // Copies of one assembly differ only by their placement: the certified verdicts must not.
    if (w.contains("copies")) {
      const auto& c = w["copies"];
      if (c.value("copies", 0u) < 2 || c.value("same_pairs_and_classes", 0u) != c.value("copies", 0u))
        fail(wn, "copies report other pairs or classes than copy 0: " + c.dump());
    } else if (wn.rfind("instanced scene", 0) == 0) {
      fail(wn, "missing copies");
    }
  }
  // The paths written for `cadclash check --path`: they must read back whole, one pose per moving
  // instance per step, with as many steps as the workload replayed.
  for (const auto& w : j.value("workloads", nlohmann::json::array())) {
    const std::string wn = w.value("name", "");
    for (const char* path : {"unscrew", "withdraw"}) {
      if (wn.find(std::string("\"") + path + "\"") == std::string::npos) continue;
      const std::string csv = (std::filesystem::path(argv[1]).parent_path() / (std::string(path) + ".csv")).string();
      std::ifstream f(csv);
      if (!f) {
        fail(csv, "missing");
        continue;
      }
      std::stringstream text;
      text << f.rdbuf();
      std::vector<cadclash::Diagnostic> diagnostics;
      const auto rows = cadclash::parse_trajectory(text.str(), csv, diagnostics);
      for (const auto& d : diagnostics) fail(csv, cadclash::format_diagnostic(d));
      std::set<std::int64_t> steps;
      for (const auto& r : rows) steps.insert(r.step);
      if (steps.size() != w.value("steps", std::size_t{0}) ||
          rows.size() != steps.size() * w.value("moving_instances", std::size_t{0}))
        fail(csv, "rows do not match the workload's steps and moving instances");
    }
  }
  if (failures == 0) std::printf("%s: complete, exact methods agree\n", argv[1]);
  return failures ? 1 : 0;
}
