// cadclash::report: write → read → write gives the same bytes, on hand-made reports (every optional
// field, non-finite numbers, a trajectory) and on real queries; enum and counter tables are complete.
#include "cadclash/import.h"
#include "cadclash/report.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <limits>
#include <set>
#include <string>

namespace cadclash {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

ReportSide surface_side(const std::string& instance, const std::string& surface, std::int64_t step_id) {
  ReportSide s;
  s.instance = instance;
  s.part = "part of " + instance;
  s.surface = surface;
  s.kind = step_id >= 0 ? SourceKind::StepFace : SourceKind::ObjGroup;
  s.face_index = 3;
  s.step_id = step_id;
  s.source_name = step_id >= 0 ? "" : "group \xc3\xa9";  // UTF-8 survives
  s.deflection = 0.0125;
  return s;
}

QueryReport sample_query() {
  QueryReport q;
  ReportPair touching;
  touching.a = surface_side("/a", "face0", 197);
  touching.b = surface_side("/b", "g1", -1);
  touching.contact = ContactClass::Touching;
  touching.decided_by = DecidedBy::Exact;
  touching.distance_lo = 0.0;
  touching.distance_hi = 1e-7;
  touching.intersecting = true;
  touching.exact_distance = 3.5e-8;
  touching.triangle_pairs = {{0, 1}, {2, 7}};
  ReportPair undecided = touching;
  undecided.contact = ContactClass::Undecided;
  undecided.decided_by = DecidedBy::Undecided;
  undecided.distance_hi = kInf;  // unbounded: null
  undecided.exact_distance = kInf;
  undecided.triangle_pairs.clear();
  ReportPair contained;
  contained.a = surface_side("/a", "", -1);
  contained.b = surface_side("/c", "", -1);
  contained.a.whole_part = contained.b.whole_part = true;
  contained.contact = ContactClass::Containment;
  contained.distance = kInf;
  contained.distance_lo = contained.distance_hi = kInf;
  q.pairs = {touching, undecided, contained};
  std::uint64_t k = 1;
  for (const CounterField& f : kCounterFields) q.counters.*f.member = k++;
  q.timings = CollideTimings{0.5, 0.25, 0.125, 1.0 / 3.0, 2.0, 0.0625, 0.03125, 0.75, 0.375, 1.5};
  q.stopped_by = "memory budget";
  q.unexamined_pairs = {{"/a", "/c"}};
  q.memory_charged_bytes = 123456789;
  q.model = SceneMemory{1200, 2400, 5600, 300, 100};
  return q;
}

CheckReport sample_report() {
  CheckReport r;
  r.files = {"x.stp", "y.obj"};
  r.settings.tolerance = 0.01;
  r.settings.preset = "fine";
  r.settings.mode = CollideMode::AllTrianglePairs;
  r.settings.parallel = ParallelVersion::V2;
  r.settings.schedule = Schedule::Static;
  r.settings.triangle_level = TriangleLevel::Bvh;
  r.settings.decision = DecisionMode::Exact;
  r.settings.select_a = {"/a"};
  r.settings.memory_budget_mb = 0.5;
  r.query = sample_query();
  r.diagnostics = {"x.stp: #12: error: broken face"};
  r.complete = false;
  return r;
}

// Reads `text`, expects success, and returns what the writer makes of it.
std::string rewrite(const std::string& text, const ReportWriteOptions& o = {}) {
  const ReportReadResult read = check_report_from_json(std::string_view(text));
  EXPECT_FALSE(read.error) << format_report_error(*read.error);
  return check_report_text(read.report, o);
}

TEST(ReportRoundTrip, HandMadeReportWithEveryOptionalField) {
  const std::string text = check_report_text(sample_report());
  for (const char* key : {"\"exact_distance\"", "\"triangle_pairs\"", "\"timings\"", "\"step_id\"", "\"source_name\"", "null"})
    EXPECT_NE(text.find(key), std::string::npos) << key;
  EXPECT_EQ(rewrite(text), text);
  const ReportReadResult read = check_report_from_json(std::string_view(text));
  ASSERT_TRUE(read.report.query);
  const QueryReport& q = *read.report.query;
  EXPECT_EQ(q.pairs[1].distance_hi, kInf);
  EXPECT_EQ(q.pairs[2].a.whole_part, true);
  EXPECT_EQ(q.counters.dismissed_pairs, 24u);
  EXPECT_EQ(read.report.settings.triangle_level, TriangleLevel::Bvh);
  EXPECT_EQ(q.model.hierarchies, 5600u);
  EXPECT_EQ(q.model.triangle_count, 100u);
  EXPECT_NE(text.find("\"total\": 9500"), std::string::npos);
  // Written before the model's size was reported: read as zeros.
  nlohmann::json old = nlohmann::json::parse(text);
  old.erase("model");
  const ReportReadResult read_old = check_report_from_parsed(old);
  ASSERT_FALSE(read_old.error);
  EXPECT_EQ(read_old.report.query->model.total(), 0u);
  // Written before the decision's step times: read as zeros, the stage times as written.
  nlohmann::json before_steps = nlohmann::json::parse(text);
  for (const char* f : {"decide_witness", "decide_depth", "decide_refine", "decide_hull", "decide_exact"})
    before_steps["timings"].erase(f);
  const ReportReadResult read_steps = check_report_from_parsed(before_steps);
  ASSERT_FALSE(read_steps.error);
  ASSERT_TRUE(read_steps.report.query->timings);
  EXPECT_EQ(read_steps.report.query->timings->decide_witness, 0.0);
  EXPECT_EQ(read_steps.report.query->timings->total, q.timings->total);
  // The stage times stay required.
  nlohmann::json no_total = nlohmann::json::parse(text);
  no_total["timings"].erase("total");
  EXPECT_TRUE(check_report_from_parsed(no_total).error);
  // Without timings: none written, and the rest unchanged.
  const std::string bare = check_report_text(sample_report(), {.timings = false});
  EXPECT_EQ(bare.find("\"timings\""), std::string::npos);
  EXPECT_EQ(rewrite(bare), bare);
}

TEST(ReportRoundTrip, TrajectoryReport) {
  CheckReport r = sample_report();
  r.query.reset();
  r.trajectory = "path.csv";
  r.steps = {{1, sample_query()}, {4, QueryReport{}}};
  r.steps_not_checked = 2;
  r.stopped_by = "time budget";
  const std::string text = check_report_text(r);
  EXPECT_NE(text.find("\"steps_not_checked\": 2"), std::string::npos);
  EXPECT_EQ(rewrite(text), text);
}

// A continuous path's report (--continuous): its timeline read back as written, spans and the
// surfaces' sides included; a timeline span without its `t1` is an error naming the path.
TEST(ReportRoundTrip, ContinuousPathTimeline) {
  const std::string dir = std::string(CADCLASH_DATA_DIR) + "/collide/";
  const std::vector<std::string> files = {dir + "box_a.obj", dir + "box_near.obj"};
  ImportResult in = import_files(files);
  ASSERT_EQ(in.model.instances.size(), 2u);
  Scene scene(in.model);
  const std::vector<TrajectoryRow> rows = {{0, in.model.instances[1].path, Pose::Identity(), 1},
                                           {1, in.model.instances[1].path, Pose(Eigen::Translation3d(-0.5, 0, 0)), 2}};
  CollideOptions o;
  o.tolerance = 0.01;
  std::vector<Diagnostic> ds;
  const PathResult path = replay_continuous(scene, in.model, rows, o, {}, ds, "path.csv");
  CheckReport r;
  r.files = {"box_a.obj", "box_near.obj"};
  r.settings = report_settings(o);
  r.trajectory = "path.csv";
  for (const StepResult& s : path.steps) r.steps.push_back({s.step, query_report(in.model, s.report)});
  r.timeline = timeline_report(in.model, path, 1e-3);
  ASSERT_EQ(r.timeline->pairs.size(), 1u);
  ASSERT_FALSE(r.timeline->pairs[0].surfaces.empty());
  const std::string text = check_report_text(r, {.timings = false});
  EXPECT_NE(text.find("\"timeline\""), std::string::npos);
  EXPECT_EQ(rewrite(text, {.timings = false}), text);
  const ReportReadResult read = check_report_from_json(std::string_view(text));
  ASSERT_TRUE(read.report.timeline);
  EXPECT_EQ(read.report.timeline->pairs[0].surfaces[0].a.surface, r.timeline->pairs[0].surfaces[0].a.surface);
  nlohmann::json bad = nlohmann::json::parse(text);
  bad["timeline"]["pairs"][0]["spans"][0].erase("t1");
  const ReportReadResult broken = check_report_from_parsed(bad);
  ASSERT_TRUE(broken.error);
  EXPECT_EQ(broken.error->path, "/timeline/pairs/0/spans/0/t1");
}

TEST(ReportRoundTrip, RealQueriesOnMeshesAndAs1) {
  const std::string dir = std::string(CADCLASH_DATA_DIR) + "/collide/";
  std::vector<std::vector<std::string>> inputs = {{dir + "box_a.obj", dir + "box_overlap.obj", dir + "box_near.obj"}};
  const std::string as1 = std::string(CADCLASH_DATA_DIR) + "/external/as1-tu-203.stp";
  if (std::filesystem::exists(as1)) inputs.push_back({as1});
  for (const auto& files : inputs) {
    ImportResult in = import_files(files);
    ASSERT_FALSE(in.model.instances.empty());
    CollideOptions o;
    o.clearance = 1.0;
    o.mode = CollideMode::AllTrianglePairs;
    Scene scene(in.model);
    CheckReport r;
    r.files = files;
    r.settings = report_settings(o);
    r.query = query_report(in.model, scene.check(o));
    ASSERT_FALSE(r.query->pairs.empty());
    const std::string text = check_report_text(r);
    EXPECT_EQ(rewrite(text), text) << files[0];
    const std::string bare = check_report_text(r, {.timings = false});
    EXPECT_EQ(rewrite(bare), bare) << files[0];
  }
}

TEST(ReportEnums, EveryValueHasOneNameThatParsesBack) {
  auto check = []<class Values>(const Values& values) {
    std::set<std::string> names;
    for (auto v : values) {
      using E = decltype(v);
      const std::string name = EnumNames<E>::name(v);
      EXPECT_TRUE(names.insert(name).second) << name;
      EXPECT_EQ(enum_from_name<E>(name), v) << name;
    }
    EXPECT_FALSE(enum_from_name<typename Values::value_type>("no such name"));
  };
  check(EnumNames<ContactClass>::values);
  check(EnumNames<DecidedBy>::values);
  check(EnumNames<DecisionMode>::values);
  check(EnumNames<SourceKind>::values);
  check(EnumNames<CollideMode>::values);
  check(EnumNames<ParallelVersion>::values);
  check(EnumNames<Schedule>::values);
  check(EnumNames<TriangleLevel>::values);
  // The last enumerator of each enum is listed (a new one added at the end must be named too).
  EXPECT_EQ(static_cast<std::size_t>(EnumNames<ContactClass>::values.back()), EnumNames<ContactClass>::values.size() - 1);
  EXPECT_EQ(static_cast<std::size_t>(EnumNames<DecidedBy>::values.back()), EnumNames<DecidedBy>::values.size() - 1);
  EXPECT_EQ(static_cast<std::size_t>(EnumNames<SourceKind>::values.back()), EnumNames<SourceKind>::values.size() - 1);
}

TEST(ReportFields, CounterAndTimingTablesCoverTheStructs) {
  // Every member is listed once: the tables' members are distinct and fill the struct.
  EXPECT_EQ(sizeof(CollideCounters), kCounterFields.size() * sizeof(std::uint64_t));
  EXPECT_EQ(sizeof(CollideTimings), kTimingFields.size() * sizeof(double));
  std::set<std::string> names;
  CollideCounters c;
  std::uint64_t k = 1;
  for (const CounterField& f : kCounterFields) {
    EXPECT_TRUE(names.insert(f.name).second) << f.name;
    c.*f.member = k++;
  }
  std::set<std::uint64_t> seen;
  for (const CounterField& f : kCounterFields) seen.insert(c.*f.member);
  EXPECT_EQ(seen.size(), kCounterFields.size());
}

TEST(ReportProvenance, RoundTripsEveryField) {
  Surface s;
  s.name = "face 3";
  s.deflection = 0.02;
  s.provenance.kind = SourceKind::Segment;
  s.provenance.step_id = 42;
  s.provenance.face_index = 3;
  s.provenance.source_name = "top";
  s.provenance.source_file = "x.stp";
  s.provenance.parent = 7;
  s.provenance.colour = std::array<float, 3>{0.25f, 0.5f, 1.0f};
  s.provenance.healed = true;
  s.aabb = Aabb(Vec3(0, 1, 2), Vec3(3, 4, 5));
  const nlohmann::json j = provenance_json(s);
  Surface back;
  EXPECT_FALSE(provenance_from_json(j, back));
  EXPECT_EQ(provenance_json(back), j);
  nlohmann::json bad = j;
  bad["kind"] = "hologram";
  const std::optional<ReportError> e = provenance_from_json(bad, back);
  ASSERT_TRUE(e);
  EXPECT_EQ(e->path, "/kind");
}

}  // namespace
}  // namespace cadclash
