// The clash review end to end (docs/review.md): as1, then as1 written again by OCCT (every STEP #id
// renumbered: every clash id kept), then with its PLATE moved (every status), one clash approved
// and a stale approval, `cadclash approve`, --fail-on-collision with approvals, and bad inputs.
#include "cli_runner.h"

#include <nlohmann/json.hpp>

#include <gtest/gtest.h>

#include <filesystem>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <tuple>

namespace cadclash::testing {
namespace {

const std::string kAs1 = std::string(CADCLASH_DATA_DIR) + "/external/as1-tu-203.stp";

std::string q(const std::string& path) { return "'" + path + "'"; }
std::string scratch(const std::string& name) { return scratch_dir() + "/" + name; }

nlohmann::json read_json(const std::string& path) { return nlohmann::json::parse(slurp(path)); }

// `step_rewrite IN OUT [NAME DX DY DZ]` (OCCT's XDE reader and writer).
void rewrite(const std::string& in, const std::string& out, const std::string& move = "") {
  const std::string cmd = std::string("'") + STEP_REWRITE_EXE + "' " + q(in) + " " + q(out) + " " + move + " >/dev/null 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
}

// A check that must run (exit 0, or 3 with --fail-on-collision); returns its JSON report.
nlohmann::json check(const std::string& args, const std::string& json) {
  const CliRun r = run_cadclash("check " + args + " --no-timings --json " + q(json));
  EXPECT_TRUE(r.code == 0 || r.code == 3) << r.code << "\n" << r.err;
  return read_json(json);
}

// What the test expects of a clash, computed here from the pairs alone (independently of
// cadclash/review.h): the surface pairs (faces in canonical order, class) and the max penetration.
using PairKey = std::tuple<int, int, std::string>;
struct Expected {
  std::set<PairKey> pairs;
  double max_penetration = 0.0;
};
std::map<std::pair<std::string, std::string>, Expected> instance_pairs(const nlohmann::json& report) {
  std::map<std::pair<std::string, std::string>, Expected> out;
  for (const nlohmann::json& p : report["pairs"]) {
    const auto side = [](const nlohmann::json& s) { return std::pair(s["instance"].get<std::string>(), s["part"].get<std::string>()); };
    const bool swap = side(p["a"]) > side(p["b"]);
    const nlohmann::json& x = swap ? p["b"] : p["a"];
    const nlohmann::json& y = swap ? p["a"] : p["b"];
    Expected& e = out[{x["instance"], y["instance"]}];
    e.pairs.insert({x.value("face_index", -1), y.value("face_index", -1), p["class"]});
    e.max_penetration = std::max(e.max_penetration, p["penetration"].get<double>());
  }
  return out;
}

std::map<std::pair<std::string, std::string>, const nlohmann::json*> clashes_by_pair(const nlohmann::json& report) {
  std::map<std::pair<std::string, std::string>, const nlohmann::json*> out;
  for (const nlohmann::json& c : report["clashes"]) out[{c["a"]["instance"], c["b"]["instance"]}] = &c;
  return out;
}

TEST(ReviewCli, RenumberedStepKeepsEveryClashId) {
  const nlohmann::json base = check(q(kAs1), scratch("base.json"));
  const std::string renumbered = scratch("as1_rewritten.stp");
  rewrite(kAs1, renumbered);
  const nlohmann::json again = check(q(renumbered) + " --baseline " + q(scratch("base.json")), scratch("again.json"));
  ASSERT_EQ(base["pairs"].size(), again["pairs"].size());
  // The rewrite renumbered the faces (else this test would prove nothing).
  std::set<std::int64_t> ids_before, ids_after;
  for (const nlohmann::json& p : base["pairs"]) ids_before.insert(p["a"].value("step_id", -1));
  for (const nlohmann::json& p : again["pairs"]) ids_after.insert(p["a"].value("step_id", -1));
  EXPECT_NE(ids_before, ids_after);
  std::set<std::string> before, after;
  for (const nlohmann::json& c : base["clashes"]) before.insert(c["id"]);
  for (const nlohmann::json& c : again["clashes"]) {
    after.insert(c["id"]);
    EXPECT_EQ(c["status"], "active") << c.dump();
  }
  EXPECT_EQ(before.size(), 32u);  // as1's instance pairs in contact
  EXPECT_EQ(before, after);
  EXPECT_EQ(again["review"]["summary"]["active"], 32);
  EXPECT_EQ(again["review"]["summary"]["new"], 0);
  EXPECT_EQ(again["review"]["summary"]["resolved"], 0);
  // The first run had no baseline: every clash new.
  EXPECT_EQ(base["review"]["summary"]["new"], 32);
  EXPECT_TRUE(base["review"]["baseline"].is_null());
}

TEST(ReviewCli, APartialRunCallsNothingResolvedThatItDidNotExamine) {
  const nlohmann::json full = check(q(kAs1), scratch("full.json"));
  const CliRun r = run_cadclash("check " + q(kAs1) + " --memory-budget 1 --no-timings --baseline " + q(scratch("full.json")) +
                                " --json " + q(scratch("partial.json")));
  ASSERT_EQ(r.code, 4) << r.err;  // the budget ran out: a partial report
  const nlohmann::json partial = read_json(scratch("partial.json"));
  ASSERT_FALSE(partial["unexamined_pairs"].empty());
  const nlohmann::json& s = partial["review"]["summary"];
  EXPECT_EQ(s["resolved"], 0);
  EXPECT_GT(s["unexamined"].get<int>(), 0);
  EXPECT_EQ(s["active"].get<int>() + s["unexamined"].get<int>(), static_cast<int>(full["clashes"].size()));
  std::set<std::pair<std::string, std::string>> unexamined;
  for (const nlohmann::json& u : partial["unexamined_pairs"]) {
    unexamined.emplace(u["a"], u["b"]);
    unexamined.emplace(u["b"], u["a"]);
  }
  for (const nlohmann::json& c : partial["clashes"])
    EXPECT_EQ(c["status"] == "unexamined", unexamined.count({c["a"]["instance"], c["b"]["instance"]}) == 1) << c["id"];
}

TEST(ReviewCli, TwoRunsEveryStatusApprovalsAndFailOnCollision) {
  const std::string base_json = scratch("base.json");
  const nlohmann::json base = check(q(kAs1), base_json);
  const std::string moved = scratch("as1_plate_moved.stp");
  rewrite(kAs1, moved, "PLATE 0 0 60");

  // Approve one clash that stays (a bolt in its nut) and one the move resolves (a nut on the plate).
  const auto pairs = clashes_by_pair(base);
  const std::string kept = pairs.at({"/as1/L-BRACKET-ASSEMBLY::1/NUT-BOLT-ASSEMBLY::1/BOLT",
                                     "/as1/L-BRACKET-ASSEMBLY::1/NUT-BOLT-ASSEMBLY::1/NUT::3"})->at("id");
  const std::string gone = pairs.at({"/as1/L-BRACKET-ASSEMBLY::1/NUT-BOLT-ASSEMBLY::1/NUT::3", "/as1/PLATE"})->at("id");
  const std::string approvals = scratch("approvals.json");
  std::filesystem::remove(approvals);
  CliRun a = run_cadclash("approve " + q(base_json) + " --id " + kept + " " + gone +
                          " --reason 'designed contact' --by tester --date 2026-01-05 -o " + q(approvals));
  ASSERT_EQ(a.code, 0) << a.err;
  EXPECT_EQ(a.out, "added 2 approvals to " + approvals + " (2 in all)\n");

  const std::string run2_json = scratch("run2.json");
  const CliRun run2 = run_cadclash("check " + q(moved) + " --no-timings --baseline " + q(base_json) + " --approvals " +
                                   q(approvals) + " --today 2026-06-01 --json " + q(run2_json));
  ASSERT_EQ(run2.code, 0) << run2.err;
  const nlohmann::json after = read_json(run2_json);

  // Every status, as this test computes it from the two reports' pairs.
  const auto then = instance_pairs(base), now = instance_pairs(after);
  const auto clashes = clashes_by_pair(after);
  std::map<std::string, int> count;
  for (const auto& [key, e] : now) {
    const nlohmann::json& c = *clashes.at(key);
    std::string expected = "new";
    if (then.count(key))
      expected = then.at(key).pairs == e.pairs && std::abs(then.at(key).max_penetration - e.max_penetration) <= 0.01
                     ? "active" : "changed";
    EXPECT_EQ(c["status"], expected) << key.first << " x " << key.second;
    ++count[expected];
  }
  for (const auto& [key, e] : then)
    if (!now.count(key)) {
      ASSERT_TRUE(clashes.count(key)) << "resolved clash not listed: " << key.first << " x " << key.second;
      EXPECT_EQ(clashes.at(key)->at("status"), "resolved");
      EXPECT_EQ(clashes.at(key)->at("surface_pairs").size(), e.pairs.size());  // its last data
      ++count["resolved"];
    }
  for (const char* s : {"new", "active", "changed", "resolved"}) {
    EXPECT_GT(count[s], 0) << s;  // the scenario exercises every status
    EXPECT_EQ(after["review"]["summary"][s], count[s]) << s;
  }
  EXPECT_TRUE(clashes.count({"/as1/PLATE", "/as1/ROD-ASSEMBLY/ROD"}));  // the plate now meets the rod

  // The kept clash is approved; the approval of the resolved one is stale.
  for (const nlohmann::json& c : after["clashes"]) EXPECT_EQ(c["approval"].is_null(), c["id"] != kept) << c["id"];
  EXPECT_EQ(after["review"]["approvals"][0]["state"], "used");
  EXPECT_EQ(after["review"]["approvals"][1]["state"], "stale");
  EXPECT_EQ(after["review"]["summary"]["approved"], 1);
  EXPECT_NE(run2.out.find("clash " + kept + "  active, approved (designed contact)"), std::string::npos) << run2.out;
  EXPECT_NE(run2.out.find("stale approval " + approvals + "#/approvals/1: id " + gone + " matches no clash"), std::string::npos);
  EXPECT_NE(run2.out.find("resolved " + gone), std::string::npos);

  // --fail-on-collision: 3 while unapproved contacts remain; 0 once every clash is approved; 3 again
  // when those approvals have expired.
  EXPECT_EQ(run_cadclash("check " + q(moved) + " --approvals " + q(approvals) + " --today 2026-06-01 --fail-on-collision").code, 3);
  const std::string all = scratch("approvals_all.json");
  std::filesystem::remove(all);
  a = run_cadclash("approve " + q(run2_json) + " --all --reason 'moved plate accepted' --by tester --date 2026-06-01 --expires 2026-06-30 -o " + q(all));
  ASSERT_EQ(a.code, 0) << a.err;
  const CliRun clean = run_cadclash("check " + q(moved) + " --approvals " + q(all) + " --today 2026-06-30 --fail-on-collision");
  EXPECT_EQ(clean.code, 0) << clean.out;
  EXPECT_EQ(run_cadclash("check " + q(moved) + " --approvals " + q(all) + " --today 2026-07-01 --fail-on-collision").code, 3);
}

TEST(ReviewCli, SpatialClustersAreDeterministic) {
  const nlohmann::json one = check(q(kAs1) + " --group-by space --cluster-distance 1 --threads 1", scratch("space1.json"));
  const CliRun two = run_cadclash("check " + q(kAs1) + " --group-by space --cluster-distance 1 --threads 2 --no-timings --json " +
                                  q(scratch("space2.json")));
  ASSERT_EQ(two.code, 0) << two.err;
  EXPECT_EQ(slurp(scratch("space1.json")), slurp(scratch("space2.json")));
  std::set<std::string> clusters;
  for (const nlohmann::json& c : one["clashes"]) {
    ASSERT_TRUE(c["box"].is_array()) << c.dump();
    for (int k = 0; k < 3; ++k) EXPECT_LE(c["box"][k].get<double>(), c["box"][k + 3].get<double>());
    clusters.insert(c["group"]);
  }
  EXPECT_GT(clusters.size(), 1u);  // as1's two brackets and the rod are more than 1 mm apart
  EXPECT_LT(clusters.size(), one["clashes"].size());
  EXPECT_EQ(one["review"]["cluster_distance"], 1.0);
  // Everything within a kilometre: one cluster.
  const nlohmann::json all = check(q(kAs1) + " --group-by space --cluster-distance 1e6", scratch("space3.json"));
  for (const nlohmann::json& c : all["clashes"]) EXPECT_EQ(c["group"], "cluster 1");
  // A bolt shares a cluster with its nut and with the bracket it holds.
  std::map<std::string, std::string> group;
  for (const nlohmann::json& c : one["clashes"]) group[c["a"]["instance"].get<std::string>() + " x " + c["b"]["instance"].get<std::string>()] = c["group"];
  EXPECT_EQ(group.at("/as1/L-BRACKET-ASSEMBLY::1/NUT-BOLT-ASSEMBLY::1/BOLT x /as1/L-BRACKET-ASSEMBLY::1/NUT-BOLT-ASSEMBLY::1/NUT::3"),
            group.at("/as1/L-BRACKET-ASSEMBLY::1/L-BRACKET x /as1/L-BRACKET-ASSEMBLY::1/NUT-BOLT-ASSEMBLY::1/BOLT"));
}

TEST(ReviewCli, VolumeOfPenetratingClashes) {
  // The plate pushed 0.05 mm up into the two brackets standing on it: each overlap is a slab 0.05 thick.
  const std::string pushed = scratch("as1_plate_up.stp");
  rewrite(kAs1, pushed, "PLATE 0 0 0.05");
  const nlohmann::json j = check(q(pushed) + " --volume --group-by space", scratch("volume.json"));
  int measured = 0;
  for (const nlohmann::json& c : j["clashes"]) {
    if (c["class"] != "penetrating") {
      EXPECT_TRUE(c["interference"].is_null()) << c.dump();
      continue;
    }
    const nlohmann::json& v = c["interference"];
    ASSERT_TRUE(v["measured"].get<bool>()) << v.dump();
    EXPECT_NEAR(v["depth"].get<double>(), 0.05, 1e-6) << c["id"];
    EXPECT_GT(v["volume"].get<double>(), 0.0);
    for (int k = 0; k < 3; ++k) {  // the centroid lies where the surfaces meet
      EXPECT_GE(v["centroid"][k].get<double>(), c["box"][k].get<double>() - 1e-6) << c["id"] << " axis " << k;
      EXPECT_LE(v["centroid"][k].get<double>(), c["box"][k + 3].get<double>() + 1e-6) << c["id"] << " axis " << k;
    }
    ++measured;
  }
  EXPECT_EQ(measured, 2);  // the two L-brackets
  // Mesh parts have no solid: the clash says so.
  const std::string d = std::string(CADCLASH_DATA_DIR) + "/collide/";
  const nlohmann::json mesh = check(q(d + "box_a.obj") + " " + q(d + "box_overlap.obj") + " --volume", scratch("mesh_volume.json"));
  ASSERT_EQ(mesh["clashes"].size(), 1u);
  EXPECT_FALSE(mesh["clashes"][0]["interference"]["measured"].get<bool>());
  EXPECT_EQ(mesh["clashes"][0]["interference"]["note"], "part box_a is not a B-rep part (a mesh): no solid to intersect");
}

std::string boxes() {
  const std::string d = std::string(CADCLASH_DATA_DIR) + "/collide/";
  return q(d + "box_a.obj") + " " + q(d + "box_overlap.obj") + " " + q(d + "box_touch.obj");
}

TEST(ReviewCli, BadInputsNameTheFileAndField) {
  const std::string bad = write_scratch_file(
      "bad_approvals.json", R"({"schema": "cadclash-approvals", "version": 1, "approvals": [{"id": "x", "reason": "r", "by": "b", "date": "2026-1-1"}]})");
  CliRun r = run_cadclash("check " + boxes() + " --approvals " + q(bad));
  EXPECT_EQ(r.code, 1);
  EXPECT_EQ(r.err, bad + ": error: /approvals/0/date: expected a date YYYY-MM-DD, got '2026-1-1'\n");
  EXPECT_EQ(r.out, "");  // refused before anything was imported or checked

  const std::string not_report = write_scratch_file("not_report.json", R"({"schema": "something else"})");
  r = run_cadclash("check " + boxes() + " --baseline " + q(not_report));
  EXPECT_EQ(r.code, 1);
  EXPECT_EQ(r.err, not_report + ": error: not a cadclash check report: /schema: expected \"cadclash-check-report\"\n");

  r = run_cadclash("check " + boxes() + " --baseline " + q(scratch("missing.json")));
  EXPECT_EQ(r.code, 1);
  EXPECT_EQ(r.err, scratch("missing.json") + ": error: cannot open the baseline report\n");

  r = run_cadclash("check " + boxes() + " --today 2026-02-30x");
  EXPECT_EQ(r.code, 2);

  const std::string path = std::string(CADCLASH_DATA_DIR) + "/collide/path_ok.csv";
  r = run_cadclash("check " + boxes() + " --path " + q(path) + " --baseline " + q(not_report));
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("a --path report has no clashes"), std::string::npos) << r.err;
}

// stdout of `cadclash ARGS` run on a pseudo-terminal (util-linux `script`), or nullopt without it.
std::optional<std::string> on_terminal(const std::string& args) {
  if (std::system("command -v script >/dev/null 2>&1") != 0) return std::nullopt;
  const std::string out = scratch("tty.txt");
  const std::string inner = std::string(CADCLASH_EXE) + " " + args;
  const std::string cmd = "script -qec \"" + inner + "\" /dev/null > '" + out + "' 2>&1 < /dev/null";
  if (std::system(cmd.c_str()) != 0) return std::nullopt;
  return slurp(out);
}

TEST(ReviewCli, TableCollapsesToClashesOnATerminalOnly) {
  const std::string piped = run_cadclash("check " + boxes() + " --no-timings").out;
  const std::optional<std::string> tty = on_terminal("check " + boxes() + " --no-timings");
  if (!tty) GTEST_SKIP() << "util-linux script is not available";
  const std::string row_header = "class       decided by";
  EXPECT_NE(piped.find(row_header), std::string::npos) << piped;  // piped: every surface pair listed
  EXPECT_EQ(tty->find(row_header), std::string::npos) << *tty;    // terminal: the clash headings only
  EXPECT_NE(tty->find("  clash "), std::string::npos) << *tty;
  const std::optional<std::string> expanded = on_terminal("check " + boxes() + " --no-timings --expand");
  ASSERT_TRUE(expanded);
  EXPECT_NE(expanded->find(row_header), std::string::npos) << *expanded;
}

TEST(ReviewCli, ApproveExtendsTheFileOnceAndRefusesUnknownIds) {
  const std::string report = scratch("boxes.json");
  const nlohmann::json j = check(boxes(), report);
  ASSERT_GE(j["clashes"].size(), 2u);
  const std::string first = j["clashes"][0]["id"];
  const std::string file = scratch("boxes_approvals.json");
  std::filesystem::remove(file);
  CliRun r = run_cadclash("approve " + q(report) + " --id " + first + " --reason r --by b --date 2026-01-01 -o " + q(file));
  ASSERT_EQ(r.code, 0) << r.err;
  r = run_cadclash("approve " + q(report) + " --all --reason r2 --by b --date 2026-01-02 -o " + q(file));
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json a = read_json(file);
  ASSERT_EQ(a["approvals"].size(), j["clashes"].size());  // the first id is not added twice
  EXPECT_EQ(a["approvals"][0]["reason"], "r");
  EXPECT_EQ(a["schema"], "cadclash-approvals");

  r = run_cadclash("approve " + q(report) + " --id 0123456789ab --reason r --by b -o " + q(file));
  EXPECT_EQ(r.code, 1);
  EXPECT_EQ(r.err, report + ": error: no clash with id 0123456789ab in the report; nothing written\n");
  EXPECT_EQ(read_json(file)["approvals"].size(), j["clashes"].size());

  // A rule from the command line: touching contacts between any two boxes.
  r = run_cadclash("approve --a '**' --b '/*/box_touch' --class touching --reason rule --by b --date 2026-01-03 -o " + q(file));
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json rule = read_json(file)["approvals"].back();
  EXPECT_EQ(rule["b"], "/*/box_touch");
  EXPECT_EQ(rule["classes"], nlohmann::json::array({"touching"}));
  EXPECT_EQ(run_cadclash("approve " + q(report) + " --reason r --by b -o " + q(file)).code, 2);  // neither --all nor --id
}

}  // namespace
}  // namespace cadclash::testing
