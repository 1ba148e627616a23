// `cadclash check` run as a process: exit codes, the table, the JSON report and its determinism.
#include <nlohmann/json.hpp>

#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <sys/wait.h>

namespace {

struct Proc {
  int code = -1;
  std::string out;  // stdout and stderr together
};

Proc run(const std::string& args) {
  const std::string cmd = std::string(CADCLASH_EXE) + " " + args + " 2>&1";
  Proc r;
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return r;
  std::array<char, 4096> buf;
  std::size_t n;
  while ((n = fread(buf.data(), 1, buf.size(), p)) > 0) r.out.append(buf.data(), n);
  const int status = pclose(p);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

std::string data(const std::string& name) { return std::string(CADCLASH_DATA_DIR) + "/collide/" + name; }

std::string boxes() {
  return data("box_a.obj") + " " + data("box_overlap.obj") + " " + data("box_touch.obj") + " " + data("box_near.obj");
}

std::string read(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

std::string tmp(const std::string& name) { return std::string(CADCLASH_BINARY_DIR) + "/check_cli_" + name; }

TEST(CheckCli, TableAndJsonReport) {
  const std::string json = tmp("report.json");
  const Proc r = run("check " + boxes() + " --clearance 0.6 --json " + json);
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("/box_a.obj/box_a (box_a)  x  /box_overlap.obj/box_overlap (box_overlap)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("penetrating"), std::string::npos);
  EXPECT_NE(r.out.find("18 penetrating, 41 touching, 89 clearance, 0 containment"), std::string::npos) << r.out;
  const nlohmann::json j = nlohmann::json::parse(read(json));
  EXPECT_EQ(j["schema"], "cadclash-check-report");
  EXPECT_EQ(j["version"], 2);
  EXPECT_EQ(j["summary"]["penetrating"], 18);
  EXPECT_EQ(j["summary"]["touching"], 41);
  EXPECT_EQ(j["settings"]["clearance"], 0.6);
  EXPECT_TRUE(j.contains("timings"));
  EXPECT_GT(j["counters"]["triangle_tests"].get<int>(), 0);
  // Face-to-face contact of box_a's x+ with box_touch's x-, with provenance.
  bool found = false;
  for (const auto& p : j["pairs"])
    if (p["a"]["instance"] == "/box_a.obj/box_a" && p["b"]["instance"] == "/box_touch.obj/box_touch" &&
        p["a"]["surface"] == "x+" && p["b"]["surface"] == "x-") {
      found = true;
      EXPECT_EQ(p["class"], "touching");
      EXPECT_EQ(p["distance"], 0.0);
      EXPECT_EQ(p["a"]["kind"], "obj-group");
      // Mesh triangles are the surfaces: the contact is proved on them alone.
      EXPECT_EQ(p["decided_by"], "mesh-exact");
      EXPECT_EQ(p["distance_interval"][0], 0.0);
      EXPECT_LE(p["distance_interval"][1].get<double>(), 1e-12);
    }
  EXPECT_TRUE(found);
  EXPECT_EQ(j["settings"]["decision"], "certified");
  EXPECT_EQ(j["summary"]["undecided"], 0);
  EXPECT_EQ(j["summary"]["decided_by"]["mesh-exact"].get<int>() + j["summary"]["decided_by"]["mesh"].get<int>(),
            j["pairs"].size());
}

// The last line of a check is its verdict: the clashes by worst class; the help shows an example.
TEST(CheckCli, EndsWithTheVerdictAndHelpShowsAnExample) {
  Proc r = run("check " + boxes() + " --clearance 0.6");
  ASSERT_EQ(r.code, 0) << r.out;
  std::string out = r.out;
  while (!out.empty() && out.back() == '\n') out.pop_back();
  const std::string last = out.substr(out.rfind('\n') + 1);
  // The four boxes pairwise (the JSON review's clashes by class).
  EXPECT_EQ(last, "verdict: 6 clashes (6 new): 3 penetrating, 2 touching, 1 clearance; 0 undecided") << r.out;
  r = run("check " + data("box_a.obj") + " " + data("box_near.obj"));
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("verdict: no clashes"), std::string::npos) << r.out;
  for (const char* help : {"--help", "check --help"}) {
    r = run(help);
    EXPECT_EQ(r.code, 0);
    EXPECT_NE(r.out.find("Example: cadclash check assembly.step --json report.json"), std::string::npos) << help;
  }
}

// --fast and --exact exclude each other; the modes are recorded; on meshes all three agree.
TEST(CheckCli, DecisionModes) {
  EXPECT_EQ(run("check " + boxes() + " --fast --exact").code, 2);
  nlohmann::json summary, within;
  for (const char* mode : {"--fast", "--exact", ""}) {
    const std::string json = tmp(std::string("mode") + mode + ".json");
    const Proc r = run("check " + boxes() + " " + mode + " --clearance 0.6 --no-timings --json " + json);
    ASSERT_EQ(r.code, 0) << r.out;
    const nlohmann::json j = nlohmann::json::parse(read(json));
    EXPECT_EQ(j["settings"]["decision"], *mode == 0 ? "certified" : std::string(mode + 2));
    nlohmann::json counts = j["summary"];
    counts.erase("decided_by");
    // Whether the tolerance alone holds a contact: the fast mode uses no ε and never says.
    const nlohmann::json w = counts["contact_within"];
    counts.erase("contact_within");
    if (*mode != 0 && std::string(mode) == "--fast") {
      EXPECT_EQ(w["tolerance"], 0);
      EXPECT_EQ(w["model uncertainty"], 0);
    } else if (within.is_null()) {
      within = w;
      EXPECT_GT(w["tolerance"].get<int>(), 0);  // the penetrating pairs at least
    } else {
      EXPECT_EQ(w, within) << mode;
    }
    if (summary.is_null()) summary = counts;
    else EXPECT_EQ(counts, summary) << mode;
  }
}

// box_near is 0.5 mm from box_a: apart by default; a mesh model tolerance of 0.3 mm on each side
// makes them touch (0.5 <= 0 + 0.3 + 0.3).
TEST(CheckCli, ModelToleranceWidensTouching) {
  const std::string pair = data("box_a.obj") + " " + data("box_near.obj");
  EXPECT_EQ(run("check " + pair + " --fail-on-collision").code, 0);
  EXPECT_EQ(run("check " + pair + " --model-tolerance 0.2 --fail-on-collision").code, 0);
  const Proc r = run("check " + pair + " --model-tolerance 0.3 --fail-on-collision");
  EXPECT_EQ(r.code, 3) << r.out;
  EXPECT_NE(r.out.find("touching    mesh-exact"), std::string::npos) << r.out;
}

// --uncertainty MM gives every surface that ε, and each side of a pair says where its ε came from
// (JSON, table); a contact only that ε holds says so. Bad values are usage errors.
TEST(CheckCli, UncertaintySwitchAndItsSource) {
  const std::string pair = data("box_a.obj") + " " + data("box_near.obj");
  for (const char* bad : {"0", "-1", "nan", "inf", "1e39", "occ", "declared", "0.1mm", ""})
    EXPECT_EQ(run("check " + pair + " --uncertainty '" + bad + "'").code, 2) << bad;
  const std::string json = tmp("uncertainty.json");
  Proc r = run("check " + pair + " --uncertainty 0.3 --no-timings --json " + json);
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("only within the model uncertainty (eps 0.3 given + 0.3 given)"), std::string::npos) << r.out;
  nlohmann::json j = nlohmann::json::parse(read(json));
  ASSERT_FALSE(j["pairs"].empty());
  for (const auto& p : j["pairs"]) {
    EXPECT_EQ(p["class"], "touching");
    EXPECT_EQ(p["contact_within"], "model uncertainty");
    for (const char* side : {"a", "b"}) {
      EXPECT_EQ(p[side]["uncertainty"], 0.3);
      EXPECT_EQ(p[side]["uncertainty_source"], "given");
    }
  }
  // By default a mesh's ε comes from its coordinates.
  r = run("check " + boxes() + " --no-timings --json " + json);
  ASSERT_EQ(r.code, 0) << r.out;
  j = nlohmann::json::parse(read(json));
  ASSERT_FALSE(j["pairs"].empty());
  for (const auto& p : j["pairs"])
    for (const char* side : {"a", "b"}) EXPECT_EQ(p[side]["uncertainty_source"], "coordinates");
}

// Where the certified decision spent its time, per step, in the JSON timings and the table; none in
// --fast, which decides nothing beyond the triangles.
TEST(CheckCliAs1, DecisionStepTimes) {
  const std::string step = std::string(CADCLASH_DATA_DIR) + "/external/as1-tu-203.stp";
  const char* steps[] = {"decide_witness", "decide_depth", "decide_refine", "decide_hull", "decide_exact"};
  const std::string json = tmp("steps.json");
  Proc r = run("check " + step + " --json " + json);
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("decision steps (ms, summed over threads): witnesses "), std::string::npos) << r.out;
  nlohmann::json t = nlohmann::json::parse(read(json))["timings"];
  for (const char* f : steps) EXPECT_GE(t[f].get<double>(), 0.0) << f;
  EXPECT_GT(t["decide_witness"].get<double>(), 0.0);  // as1's contacts are proved by witnesses
  r = run("check " + step + " --fast --json " + json);
  ASSERT_EQ(r.code, 0) << r.out;
  t = nlohmann::json::parse(read(json))["timings"];
  for (const char* f : steps) EXPECT_EQ(t[f].get<double>(), 0.0) << f;
}

TEST(CheckCli, ReportIsByteIdenticalForAnyThreadCount) {
  for (const std::string variant : {"--parallel v1", "--parallel v2 --all-triangles", "--schedule static"}) {
    std::string first;
    for (int threads : {1, 2, 4}) {
      const std::string json = tmp("threads" + std::to_string(threads) + ".json");
      const Proc r = run("check " + boxes() + " --clearance 0.4 --no-timings " + variant + " --threads " +
                        std::to_string(threads) + " --json " + json);
      ASSERT_EQ(r.code, 0) << r.out;
      const std::string text = read(json);
      EXPECT_EQ(text.find("timings"), std::string::npos);
      if (threads == 1) first = text;
      else EXPECT_EQ(text, first) << variant << " threads " << threads;
    }
  }
}

TEST(CheckCli, BruteForceGivesTheSamePairs) {
  const Proc a = run("check " + boxes() + " --tolerance 0.01 --clearance 0.3 --all-triangles --json " + tmp("oaabb.json"));
  const Proc b = run("check " + boxes() + " --tolerance 0.01 --clearance 0.3 --all-triangles --brute-force --json " +
                    tmp("brute.json"));
  ASSERT_EQ(a.code, 0) << a.out;
  ASSERT_EQ(b.code, 0) << b.out;
  const nlohmann::json ja = nlohmann::json::parse(read(tmp("oaabb.json")));
  const nlohmann::json jb = nlohmann::json::parse(read(tmp("brute.json")));
  EXPECT_EQ(ja["pairs"], jb["pairs"]);
  EXPECT_EQ(ja["summary"], jb["summary"]);
  EXPECT_LT(ja["counters"]["triangle_tests"].get<int>(), jb["counters"]["triangle_tests"].get<int>());
}

TEST(CheckCli, ExitCodes) {
  EXPECT_EQ(run("check " + boxes() + " --fail-on-collision").code, 3);
  EXPECT_EQ(run("check " + data("box_a.obj") + " " + data("box_near.obj") + " --fail-on-collision").code, 0);
  EXPECT_EQ(run("check " + data("box_a.obj") + " --no-such-option").code, 2);
  EXPECT_EQ(run("check " + data("box_a.obj") + " --tolerance -1").code, 2);
  const Proc missing = run("check " + data("no_such_file.obj"));  // an input error, not a usage error
  EXPECT_EQ(missing.code, 1);
  EXPECT_NE(missing.out.find("no_such_file.obj: error: no such file"), std::string::npos) << missing.out;
  EXPECT_EQ(run("check").code, 2);
  const Proc bad_select = run("check " + boxes() + " --select-a /nothing");
  EXPECT_EQ(bad_select.code, 1) << bad_select.out;
}

TEST(CheckCli, TrajectoryReplay) {
  const std::string json = tmp("path.json");
  const Proc r = run("check " + data("box_a.obj") + " " + data("box_near.obj") + " --path " + data("path_ok.csv") +
                    " --no-timings --json " + json);
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("step 0: 0 penetrating, 0 touching"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("step 1: 0 penetrating, 21 touching"), std::string::npos) << r.out;
  const nlohmann::json j = nlohmann::json::parse(read(json));
  ASSERT_EQ(j["steps"].size(), 3u);
  EXPECT_EQ(j["steps"][0]["summary"]["pairs"], 0);
  EXPECT_GT(j["steps"][2]["summary"]["penetrating"].get<int>(), 0);
}

// --continuous: the motion between the steps too. From step 0 to 1 the near box closes a 0.5 mm gap
// to box_a, so it comes within the 0.01 tolerance at t = 0.98 (0.5 - 0.5 t <= 0.01): the timeline's
// first span is at most 1/1000 of the stretch wide and brackets it; from there the pair stays in
// contact to the last step (proved at both ends). The JSON is the same for 1 and 2 threads. Steps
// that go back are an error naming the line; --continuous without --path a usage error.
TEST(CheckCli, ContinuousTrajectoryHasATimeline) {
  std::string first;
  for (const char* threads : {"1", "2"}) {
    const std::string json = tmp(std::string("continuous_") + threads + ".json");
    const Proc r = run("check " + data("box_a.obj") + " " + data("box_near.obj") + " --path " + data("path_ok.csv") +
                       " --continuous --tolerance 0.01 --threads " + threads + " --no-timings --json " + json);
    ASSERT_EQ(r.code, 0) << r.out;
    EXPECT_NE(r.out.find("between the steps"), std::string::npos) << r.out;
    const std::string text = read(json);
    if (first.empty()) first = text;
    EXPECT_EQ(text, first) << "the report must not depend on the thread count";
    const nlohmann::json j = nlohmann::json::parse(text);
    ASSERT_EQ(j["steps"].size(), 3u);
    const nlohmann::json& t = j["timeline"];
    EXPECT_EQ(t["complete"], true);
    ASSERT_EQ(t["pairs"].size(), 1u);
    const nlohmann::json& spans = t["pairs"][0]["spans"];
    ASSERT_GE(spans.size(), 2u);
    const double t0 = spans[0]["t0"], t1 = spans[0]["t1"];
    EXPECT_LE(t0, 0.98);
    EXPECT_GE(t1, 0.98);
    EXPECT_LE(t1 - t0, 1e-3 + 1e-12);
    EXPECT_EQ(spans.back()["t1"], 2.0);
    EXPECT_EQ(spans.back()["contact_at_ends"], true);
    EXPECT_FALSE(t["pairs"][0]["surfaces"].empty());
    EXPECT_FALSE(t["pairs"][0].contains("closest"));  // no --clearance
  }
  // With --clearance, a path that passes 0.3 mm from box_a at step 1 and never touches: the pair is
  // listed with no spans and its closest approach, 0.3 within [lo, hi], reached near t = 1.
  const std::string pass_json = tmp("continuous_pass.json");
  const Proc pass = run("check " + data("box_a.obj") + " " + data("box_near.obj") + " --path " + data("path_pass.csv") +
                        " --continuous --tolerance 0.01 --clearance 0.6 --no-timings --json " + pass_json);
  ASSERT_EQ(pass.code, 0) << pass.out;
  const nlohmann::json pp = nlohmann::json::parse(read(pass_json))["timeline"]["pairs"];
  ASSERT_EQ(pp.size(), 1u);
  EXPECT_TRUE(pp[0]["spans"].empty());
  const nlohmann::json& c = pp[0]["closest"];
  EXPECT_LE(c["lo"].get<double>(), 0.3);
  EXPECT_GE(c["hi"].get<double>(), 0.3 - 1e-9);
  EXPECT_LE(c["hi"].get<double>() - c["lo"].get<double>(), 0.01);
  EXPECT_LE(c["t0"].get<double>(), 1.0);
  EXPECT_GE(c["t1"].get<double>(), 1.0);
  const std::string back = tmp("path_back.csv");
  std::ofstream(back) << "step,instance_path,tx,ty,tz,qw,qx,qy,qz\n0,/box_near.obj/box_near,0,0,0,1,0,0,0\n"
                         "2,/box_near.obj/box_near,-0.5,0,0,1,0,0,0\n1,/box_near.obj/box_near,0,0,0,1,0,0,0\n";
  const Proc bad = run("check " + data("box_a.obj") + " " + data("box_near.obj") + " --path " + back + " --continuous");
  EXPECT_EQ(bad.code, 1) << bad.out;
  EXPECT_NE(bad.out.find("path_back.csv:4: error: step 1 does not follow step 2"), std::string::npos) << bad.out;
  EXPECT_EQ(run("check " + data("box_a.obj") + " --continuous").code, 2);
}

TEST(CheckCli, BadTrajectoryNamesTheLines) {
  const Proc r = run("check " + data("box_a.obj") + " " + data("box_near.obj") + " --path " + data("path_bad.csv"));
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.out.find("path_bad.csv:3: error:"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("path_bad.csv:4: error: quaternion"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("path_bad.csv:5: error: expected 9 fields"), std::string::npos) << r.out;
}

}  // namespace

namespace {

// The real sample assembly: the OAABB answer equals brute force, and every fastener contact is found.
TEST(CheckCliAs1, EqualsBruteForceAndFindsEveryFastenerContact) {
  const std::string step = std::string(CADCLASH_DATA_DIR) + "/external/as1-tu-203.stp";
  if (!std::ifstream(step)) GTEST_SKIP() << "run scripts/setup.sh for " << step;
  const std::string common = "check " + step + " --tolerance 0.01 --all-triangles --no-timings --json ";
  const Proc fast = run(common + tmp("as1_oaabb.json"));
  const Proc slow = run(common + tmp("as1_brute.json") + " --brute-force");
  ASSERT_EQ(fast.code, 0) << fast.out;
  ASSERT_EQ(slow.code, 0) << slow.out;
  const nlohmann::json a = nlohmann::json::parse(read(tmp("as1_oaabb.json")));
  const nlohmann::json b = nlohmann::json::parse(read(tmp("as1_brute.json")));
  EXPECT_EQ(a["pairs"], b["pairs"]);
  EXPECT_LT(a["counters"]["triangle_tests"].get<double>() * 20, b["counters"]["triangle_tests"].get<double>());

  // Instance pairs in contact, keyed by the last two path components of each side.
  std::set<std::string> contacts;
  auto tail = [](const std::string& path) {
    const auto last = path.rfind('/');
    const auto prev = path.rfind('/', last - 1);
    return path.substr(prev + 1);
  };
  for (const auto& p : a["pairs"]) {
    EXPECT_EQ(p["class"], "touching") << p.dump();  // nothing in as1 really penetrates
    contacts.insert(tail(p["a"]["instance"]) + " | " + tail(p["b"]["instance"]));
  }
  for (int k = 1; k <= 3; ++k) {
    const std::string bolt = "NUT-BOLT-ASSEMBLY::" + std::to_string(k) + "/BOLT";
    EXPECT_TRUE(contacts.count(bolt + " | NUT-BOLT-ASSEMBLY::" + std::to_string(k) + "/NUT::3")) << bolt;
    EXPECT_TRUE(contacts.count(bolt + " | L-BRACKET-ASSEMBLY::1/L-BRACKET") ||
                contacts.count(bolt + " | L-BRACKET-ASSEMBLY::2/L-BRACKET")) << bolt;
  }
  EXPECT_TRUE(contacts.count("ROD-ASSEMBLY/NUT::1 | ROD-ASSEMBLY/ROD"));
  EXPECT_TRUE(contacts.count("ROD-ASSEMBLY/NUT::2 | ROD-ASSEMBLY/ROD"));
  EXPECT_TRUE(contacts.count("ROD-ASSEMBLY/ROD | L-BRACKET-ASSEMBLY::1/L-BRACKET"));
  std::size_t bolt_plate = 0;
  for (const std::string& c : contacts) bolt_plate += (c.find("/BOLT") != std::string::npos && c.find("PLATE") != std::string::npos);
  EXPECT_EQ(bolt_plate, 6u);  // every bolt passes through the plate
  std::size_t nut_plate = 0;
  for (const std::string& c : contacts) nut_plate += (c.find("NUT::3") != std::string::npos && c.find("PLATE") != std::string::npos);
  EXPECT_EQ(nut_plate, 6u);  // and its nut sits on it
  EXPECT_TRUE(contacts.count("ROD-ASSEMBLY/ROD | L-BRACKET-ASSEMBLY::2/L-BRACKET"));
}

// --exact asks the B-rep for every non-penetrating pair, including touching pairs whose triangles
// cross (the rod's facets cut the bracket holes' facets): in as1 every reported contact is exact.
TEST(CheckCliAs1, ExactVerificationMeasuresEveryContactOnTheBrep) {
  const std::string step = std::string(CADCLASH_DATA_DIR) + "/external/as1-tu-203.stp";
  if (!std::ifstream(step)) GTEST_SKIP() << "run scripts/setup.sh for " << step;
  const Proc r = run("check " + step + " --exact --select-a /as1/ROD-ASSEMBLY/ROD --no-timings --json " +
                     tmp("as1_exact.json"));
  ASSERT_EQ(r.code, 0) << r.out;
  const nlohmann::json j = nlohmann::json::parse(read(tmp("as1_exact.json")));
  std::size_t crossing = 0;
  ASSERT_GE(j["pairs"].size(), 4u);
  for (const auto& p : j["pairs"]) {
    ASSERT_TRUE(p.contains("exact_distance")) << p.dump();
    EXPECT_LE(p["exact_distance"].get<double>(), 1e-6) << p.dump();
    crossing += p["intersecting"].get<bool>();
  }
  EXPECT_GT(crossing, 0u);  // some verified pairs had crossing triangles
}

}  // namespace

namespace {

// Budgets: a partial report that says so (table, JSON, exit code 4); under a memory budget the same
// for any thread count; a budget that is not exhausted changes nothing.
TEST(CheckCliBudget, MemoryBudgetPartialReportIsMarkedAndThreadIndependent) {
  const Proc full = run("check " + boxes() + " --clearance 0.4 --all-triangles --no-timings --json " + tmp("budget_full.json"));
  ASSERT_EQ(full.code, 0) << full.out;
  const nlohmann::json jf = nlohmann::json::parse(read(tmp("budget_full.json")));
  EXPECT_TRUE(jf["stopped_by"].is_null());
  EXPECT_TRUE(jf["unexamined_pairs"].empty());
  EXPECT_EQ(jf["complete"], true);
  const double charged = jf["memory_charged_bytes"].get<double>();
  ASSERT_GT(charged, 0.0);

  // A budget that keeps some instance pairs but not all: the first pair also pays for the BVHs.
  std::string budget;
  double budget_bytes = 0.0;
  for (const double fraction : {0.5, 0.65, 0.8, 0.9}) {
    std::ostringstream mb;
    mb.precision(17);
    mb << charged * fraction / (1024.0 * 1024.0);
    const Proc probe = run("check " + boxes() + " --clearance 0.4 --all-triangles --no-timings --memory-budget " +
                           mb.str() + " --json " + tmp("budget_probe.json"));
    const nlohmann::json jp = nlohmann::json::parse(read(tmp("budget_probe.json")));
    if (probe.code == 4 && !jp["pairs"].empty()) {
      budget = mb.str();
      budget_bytes = charged * fraction;
      break;
    }
  }
  ASSERT_FALSE(budget.empty()) << "no budget between half and 90% of the total keeps a non-empty prefix";
  std::string first;
  for (int threads : {1, 2, 4}) {
    const std::string json = tmp("budget_mem" + std::to_string(threads) + ".json");
    const Proc r = run("check " + boxes() + " --clearance 0.4 --all-triangles --no-timings --memory-budget " + budget +
                      " --threads " + std::to_string(threads) + " --json " + json);
    ASSERT_EQ(r.code, 4) << r.out;
    EXPECT_NE(r.out.find("PARTIAL REPORT: stopped by the memory budget"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("not examined: /"), std::string::npos) << r.out;
    const std::string text = read(json);
    const nlohmann::json j = nlohmann::json::parse(text);
    EXPECT_EQ(j["stopped_by"], "memory budget");
    EXPECT_EQ(j["complete"], false);
    EXPECT_FALSE(j["unexamined_pairs"].empty());
    EXPECT_LT(j["unexamined_pairs"].size(), j["counters"]["instance_pairs"].get<std::size_t>());
    EXPECT_FALSE(j["pairs"].empty());
    EXPECT_LE(j["memory_charged_bytes"].get<double>(), budget_bytes);
    for (const auto& p : j["pairs"]) {  // every reported pair is in the full report, unchanged
      bool found = false;
      for (const auto& q : jf["pairs"]) found = found || q == p;
      EXPECT_TRUE(found) << p.dump();
    }
    if (threads == 1) first = text;
    else EXPECT_EQ(text, first) << "threads " << threads;
  }
}

TEST(CheckCliBudget, ExpiredTimeBudgetAndGenerousBudgets) {
  const std::string json = tmp("budget_time.json");
  const Proc r = run("check " + boxes() + " --time-budget 1e-9 --json " + json);
  ASSERT_EQ(r.code, 4) << r.out;
  EXPECT_NE(r.out.find("PARTIAL REPORT: stopped by the time budget"), std::string::npos) << r.out;
  const nlohmann::json j = nlohmann::json::parse(read(json));
  EXPECT_EQ(j["stopped_by"], "time budget");
  EXPECT_EQ(j["complete"], false);
  EXPECT_FALSE(j["unexamined_pairs"].empty());

  const Proc none = run("check " + boxes() + " --clearance 0.4 --no-timings --json " + tmp("budget_none.json"));
  const Proc generous = run("check " + boxes() + " --clearance 0.4 --no-timings --time-budget 1000 --memory-budget 1000 --json " +
                           tmp("budget_generous.json"));
  ASSERT_EQ(none.code, 0) << none.out;
  ASSERT_EQ(generous.code, 0) << generous.out;
  EXPECT_EQ(generous.out.find("PARTIAL"), std::string::npos);
  const nlohmann::json a = nlohmann::json::parse(read(tmp("budget_none.json")));
  const nlohmann::json b = nlohmann::json::parse(read(tmp("budget_generous.json")));
  for (const char* key : {"pairs", "summary", "counters", "stopped_by", "unexamined_pairs", "complete"})
    EXPECT_EQ(a[key], b[key]) << key;

  EXPECT_EQ(run("check " + boxes() + " --time-budget -1").code, 2);
  EXPECT_EQ(run("check " + boxes() + " --memory-budget x").code, 2);
  // --fail-on-collision wins when the partial report already holds a collision; else 4.
  EXPECT_EQ(run("check " + boxes() + " --memory-budget 0.000001 --fail-on-collision").code, 4);
}

TEST(CheckCliBudget, TimeBudgetCoversTheWholeTrajectory) {
  const std::string json = tmp("budget_path.json");
  const Proc r = run("check " + data("box_a.obj") + " " + data("box_near.obj") + " --path " + data("path_ok.csv") +
                    " --time-budget 1e-9 --no-timings --json " + json);
  ASSERT_EQ(r.code, 4) << r.out;
  EXPECT_NE(r.out.find("were not checked"), std::string::npos) << r.out;
  const nlohmann::json j = nlohmann::json::parse(read(json));
  EXPECT_EQ(j["stopped_by"], "time budget");
  EXPECT_EQ(j["complete"], false);
  EXPECT_GE(j["steps_not_checked"].get<int>(), 2);
  EXPECT_LE(j["steps"].size(), 1u);
}

}  // namespace

// A preset is one choice of deflections, made once: `--preset P` reports exactly what the explicit
// `--deflection d --angular a` of that preset reports, with and without --lazy (a lazy face is meshed
// at its part's load deflection, not at --deflection's default), and the settings show the
// deflections in effect. Before, `--preset fine --lazy` meshed the lazy faces at 0.1 mm.
TEST(CheckCliAs1, PresetsEqualTheirExplicitDeflectionsWithAndWithoutLazy) {
  const std::string step = std::string(CADCLASH_DATA_DIR) + "/external/as1-tu-203.stp";
  if (!std::ifstream(step)) GTEST_SKIP() << "run scripts/setup.sh for " << step;
  struct Preset {
    const char* name;
    const char* deflection;
    const char* angular;
    double value;
  };
  for (const Preset& p : {Preset{"coarse", "1", "0.8", 1.0}, Preset{"normal", "0.1", "0.5", 0.1},
                          Preset{"fine", "0.01", "0.25", 0.01}})
    for (const char* lazy : {"", " --lazy"}) {
      const std::string what = std::string(p.name) + lazy;
      const std::string a = tmp(std::string("preset_") + p.name + (*lazy ? "_lazy" : "") + ".json");
      const std::string b = tmp(std::string("explicit_") + p.name + (*lazy ? "_lazy" : "") + ".json");
      const Proc ra = run("check " + step + " --preset " + p.name + lazy + " --no-timings --json " + a);
      const Proc rb = run("check " + step + " --deflection " + p.deflection + " --angular " + p.angular + lazy +
                          " --no-timings --json " + b);
      ASSERT_EQ(ra.code, 0) << what << ra.out;
      ASSERT_EQ(rb.code, 0) << what << rb.out;
      const nlohmann::json ja = nlohmann::json::parse(read(a)), jb = nlohmann::json::parse(read(b));
      EXPECT_EQ(ja["pairs"], jb["pairs"]) << what;
      EXPECT_EQ(ja["summary"], jb["summary"]) << what;
      EXPECT_EQ(ja["settings"]["preset"], p.name) << what;
      EXPECT_TRUE(jb["settings"]["preset"].is_null()) << what;
      for (const nlohmann::json* j : {&ja, &jb}) {
        EXPECT_EQ((*j)["settings"]["deflection"].get<double>(), p.value) << what;
        EXPECT_EQ((*j)["settings"]["angular_deflection"].get<double>(), std::stod(p.angular)) << what;
      }
      // Every reported face was meshed at the preset's deflection (achieved at most that, as measured).
      ASSERT_FALSE(ja["pairs"].empty()) << what;
      for (const auto& pair : ja["pairs"])
        for (const char* side : {"a", "b"})
          EXPECT_LE(pair[side]["deflection"].get<double>(), p.value) << what << ' ' << pair.dump();
    }
}
