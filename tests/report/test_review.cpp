// cadclash/review.h: clash ids, grouping, the baseline diff, approvals (matching, expiry, the file),
// and the report's `clashes` / `review` written, read back and refused when inconsistent.
#include "cadclash/review.h"

#include <gtest/gtest.h>

#include <limits>
#include <string>

namespace cadclash {
namespace {

ReportPair pair(const std::string& ia, int fa, const std::string& ib, int fb, ContactClass c, double pen = 0.0) {
  ReportPair p;
  p.a.instance = ia;
  p.a.part = "part of " + ia;
  p.a.surface = "face" + std::to_string(fa);
  p.a.kind = SourceKind::StepFace;
  p.a.face_index = fa;
  p.a.step_id = 100 + fa;
  p.b = p.a;
  p.b.instance = ib;
  p.b.part = "part of " + ib;
  p.b.surface = "face" + std::to_string(fb);
  p.b.face_index = fb;
  p.b.step_id = 200 + fb;
  p.contact = c;
  p.intersecting = c == ContactClass::Penetrating;
  p.penetration = pen;
  p.distance = c == ContactClass::Clearance ? 0.5 : 0.0;
  p.distance_hi = p.distance;
  return p;
}

QueryReport query(std::vector<ReportPair> pairs) {
  QueryReport q;
  q.pairs = std::move(pairs);
  return q;
}

TEST(ClashId, IsAFixedHashOfPathsAndPartsInEitherOrder) {
  // Pinned: FNV-1a 64 of "cadclash-clash-1\0/as1/PLATE\0plate\0/as1/ROD-ASSEMBLY/ROD\0rod" is 091e3d921a6fee9b.
  EXPECT_EQ(clash_id("/as1/PLATE", "plate", "/as1/ROD-ASSEMBLY/ROD", "rod"), "091e3d921a6f");
  EXPECT_EQ(clash_id("/as1/ROD-ASSEMBLY/ROD", "rod", "/as1/PLATE", "plate"), "091e3d921a6f");
}

TEST(ClashId, DependsOnEveryPathAndPart) {
  const std::string base = clash_id("/a", "p", "/b", "q");
  EXPECT_EQ(base.size(), 12u);
  EXPECT_NE(base, clash_id("/a", "p", "/b", "r"));
  EXPECT_NE(base, clash_id("/a", "x", "/b", "q"));
  EXPECT_NE(base, clash_id("/a2", "p", "/b", "q"));
  EXPECT_NE(base, clash_id("/a", "p/b", "", "q"));  // the NUL separators keep fields apart
}

TEST(Glob, StarStopsAtSlashDoubleStarDoesNot) {
  EXPECT_TRUE(glob_match("/as1/*", "/as1/PLATE"));
  EXPECT_FALSE(glob_match("/as1/*", "/as1/ROD-ASSEMBLY/ROD"));
  EXPECT_TRUE(glob_match("/as1/**", "/as1/ROD-ASSEMBLY/ROD"));
  EXPECT_TRUE(glob_match("**/BOLT", "/as1/L-BRACKET-ASSEMBLY::1/NUT-BOLT-ASSEMBLY::2/BOLT"));
  EXPECT_TRUE(glob_match("/as1/**/NUT::?", "/as1/L/NUT-BOLT-ASSEMBLY::2/NUT::3"));
  EXPECT_FALSE(glob_match("/as1/**/NUT::?", "/as1/L/NUT-BOLT-ASSEMBLY::2/NUT::34"));
  EXPECT_TRUE(glob_match("*bolt*", "hex bolt m6"));
  EXPECT_FALSE(glob_match("bolt", "bolts"));
  EXPECT_TRUE(glob_match("", ""));
  EXPECT_FALSE(glob_match("?", "/"));
}

TEST(Clashes, GroupSurfacePairsUnderTheirInstancePairInCanonicalOrder) {
  // /b x /a is listed with /a first: the clash and its keys follow the canonical side order.
  const QueryReport q = query({pair("/b", 1, "/a", 2, ContactClass::Touching),
                               pair("/b", 3, "/a", 4, ContactClass::Penetrating, 0.25),
                               pair("/a", 5, "/c", 6, ContactClass::Clearance)});
  const std::vector<ReportClash> c = clashes_of(q);
  ASSERT_EQ(c.size(), 2u);
  EXPECT_EQ(c[0].instance_a, "/a");
  EXPECT_EQ(c[0].instance_b, "/b");
  EXPECT_EQ(c[0].id, clash_id("/b", "part of /b", "/a", "part of /a"));
  EXPECT_EQ(c[0].worst, ContactClass::Penetrating);
  EXPECT_DOUBLE_EQ(c[0].max_penetration, 0.25);
  ASSERT_EQ(c[0].surface_pairs.size(), 2u);
  EXPECT_EQ(c[0].surface_pairs[0].key, "f2 x f1");
  EXPECT_EQ(c[0].surface_pairs[1].pair, 1);
  EXPECT_EQ(c[1].worst, ContactClass::Clearance);
  EXPECT_DOUBLE_EQ(c[1].min_distance, 0.5);
  EXPECT_EQ(c[0].group, "/a x /b");
  EXPECT_EQ(clashes_of(q, "part")[0].group, "part of /a x part of /b");
}

TEST(Clashes, KeysUseFaceNamesAndNeverStepIds) {
  ReportPair p = pair("/a", 1, "/b", 2, ContactClass::Touching);
  ReportPair renumbered = p;
  renumbered.a.step_id = 9001;
  renumbered.b.step_id = 9002;
  EXPECT_EQ(clashes_of(query({p}))[0].surface_pairs[0].key, clashes_of(query({renumbered}))[0].surface_pairs[0].key);
  p.a.source_name = "TOP";
  p.b.source_name = "#202";  // an exporter's entity id as the face's name: renumbered on re-export
  EXPECT_EQ(clashes_of(query({p}))[0].surface_pairs[0].key, "f1:TOP x f2");
  p.b.source_name = "#20x";
  EXPECT_EQ(clashes_of(query({p}))[0].surface_pairs[0].key, "f1:TOP x f2:#20x");
}

TEST(Clashes, SubassemblyGroupIsTheDeepestCommonAssembly) {
  const QueryReport q = query({pair("/as1/L::1/NB::2/BOLT", 1, "/as1/L::1/NB::2/NUT", 2, ContactClass::Touching),
                               pair("/as1/PLATE", 1, "/as1/L::1/BRACKET", 2, ContactClass::Touching),
                               pair("/x/A", 1, "/y/B", 2, ContactClass::Touching)});
  const std::vector<ReportClash> c = clashes_of(q, "subassembly");
  EXPECT_EQ(c[0].group, "/as1/L::1/NB::2");
  EXPECT_EQ(c[1].group, "/as1");
  EXPECT_EQ(c[2].group, "/");
}

TEST(Space, ClustersChainWithinTheDistanceAndNumberInClashOrder) {
  std::vector<ReportClash> c(5);
  c[0].box = std::array<double, 6>{0, 0, 0, 1, 1, 1};
  c[1].box = std::array<double, 6>{10, 0, 0, 11, 1, 1};   // far from everything
  c[2].box = std::array<double, 6>{1.5, 0, 0, 2.5, 1, 1};  // 0.5 from c[0]
  c[4].box = std::array<double, 6>{3, 0.5, 0, 4, 1, 1};    // 0.5 from c[2] only: chained to c[0]
  cluster_clashes(c, 0.6);
  EXPECT_EQ(c[0].group, "cluster 1");
  EXPECT_EQ(c[1].group, "cluster 2");
  EXPECT_EQ(c[2].group, "cluster 1");
  EXPECT_EQ(c[3].group, "cluster 3");  // no box: alone
  EXPECT_EQ(c[4].group, "cluster 1");
  cluster_clashes(c, 0.4);
  EXPECT_EQ(c[2].group, "cluster 3");
  EXPECT_EQ(c[4].group, "cluster 5");
  // Off in y and z too: the distance is box to box in 3D, not along x alone.
  c[2].box = std::array<double, 6>{1.5, 3, 0, 2.5, 4, 1};
  cluster_clashes(c, 0.6);
  EXPECT_EQ(c[2].group, "cluster 3");
}

TEST(Space, ClashBoxIsTheUnionOfItsPairs) {
  const QueryReport q = query({pair("/a", 1, "/b", 1, ContactClass::Touching), pair("/a", 2, "/b", 2, ContactClass::Touching),
                               pair("/a", 3, "/c", 1, ContactClass::Touching)});
  const std::vector<std::array<double, 6>> boxes{{0, 0, 0, 1, 1, 1}, {-1, 2, 0, 0, 3, 0}, {50, 50, 50, 51, 51, 51}};
  const std::vector<ReportClash> c = clashes_of(q, "space", boxes, 1.0);
  ASSERT_EQ(c.size(), 2u);
  EXPECT_EQ(*c[0].box, (std::array<double, 6>{-1, 0, 0, 1, 3, 1}));
  EXPECT_EQ(c[0].group, "cluster 1");
  EXPECT_EQ(c[1].group, "cluster 2");
  EXPECT_FALSE(clashes_of(q)[0].box);
}

TEST(Baseline, EveryStatus) {
  const QueryReport before = query({pair("/a", 1, "/b", 1, ContactClass::Touching),      // stays: active
                                    pair("/a", 2, "/c", 1, ContactClass::Touching),      // turns penetrating
                                    pair("/a", 3, "/d", 1, ContactClass::Penetrating, 0.1),  // deeper
                                    pair("/a", 4, "/e", 1, ContactClass::Touching),      // another face too
                                    pair("/a", 5, "/f", 1, ContactClass::Touching)});    // gone
  const QueryReport after = query({pair("/a", 1, "/b", 1, ContactClass::Touching),
                                   pair("/a", 2, "/c", 1, ContactClass::Penetrating, 0.2),
                                   pair("/a", 3, "/d", 1, ContactClass::Penetrating, 0.3),
                                   pair("/a", 4, "/e", 1, ContactClass::Touching),
                                   pair("/a", 4, "/e", 2, ContactClass::Touching),
                                   pair("/a", 6, "/g", 1, ContactClass::Touching)});  // new
  const ClashReview r = review_query(after, &before, {}, {});
  ASSERT_EQ(r.clashes.size(), 6u);
  const ClashStatus expected[] = {ClashStatus::Active,  ClashStatus::Changed, ClashStatus::Changed,
                                  ClashStatus::Changed, ClashStatus::New,     ClashStatus::Resolved};
  for (std::size_t k = 0; k < 6; ++k) EXPECT_EQ(r.clashes[k].status, expected[k]) << k;
  EXPECT_EQ(r.clashes[5].instance_b, "/f");
  EXPECT_EQ(r.clashes[5].surface_pairs[0].pair, -1);  // last data only
  // A partial run that did not examine /a x /f does not call its clash resolved.
  QueryReport partial = after;
  partial.unexamined_pairs = {{"/f", "/a"}};
  const ClashReview p = review_query(partial, &before, {}, {});
  EXPECT_EQ(p.clashes[5].status, ClashStatus::Unexamined);
  EXPECT_FALSE(current_clash(p.clashes[5]));
  EXPECT_EQ(check_report_json([&] {
              CheckReport doc;
              doc.query = partial;
              doc.review = p;
              return doc;
            }())["review"]["summary"]["unexamined"], 1);
  // A depth move within --depth-change keeps the clash active.
  ReviewOptions loose;
  loose.depth_change = 0.5;
  EXPECT_EQ(review_query(after, &before, {}, loose).clashes[2].status, ClashStatus::Active);
}

TEST(Approvals, IdsRulesClassesExpiryAndStale) {
  const QueryReport q = query({pair("/as1/sub/bolt", 1, "/as1/sub/nut", 1, ContactClass::Touching),
                               pair("/as1/plate", 1, "/as1/sub/bolt", 2, ContactClass::Penetrating, 0.5),
                               pair("/as1/plate", 1, "/as1/rod", 2, ContactClass::Touching)});
  const std::vector<ReportClash> c = clashes_of(q);
  Approval by_id;
  by_id.id = c[2].id;
  Approval expired = by_id;
  expired.expires = "2026-05-31";
  Approval sub;  // everything inside /as1/sub, touching only
  sub.a = "/as1/sub/**";
  sub.b = "/as1/sub/**";
  sub.classes = {ContactClass::Touching};
  Approval touching_plate;  // plate against bolts, touching only: the penetrating clash stays
  touching_plate.part_a = "part of /as1/plate";
  touching_plate.b = "**/bolt";
  touching_plate.classes = {ContactClass::Touching};
  Approval nothing;
  nothing.id = "000000000000";
  ReviewOptions o;
  o.approvals_file = "ok.json";
  o.today = "2026-06-01";
  const ClashReview r = review_query(q, nullptr, {expired, sub, touching_plate, by_id, nothing}, o);
  EXPECT_EQ(r.clashes[0].approval, 1);
  EXPECT_EQ(r.clashes[1].approval, -1);
  EXPECT_EQ(r.clashes[2].approval, 3);
  EXPECT_TRUE(r.approvals[0].expired);
  EXPECT_EQ(r.approvals[2].matched, 0u);  // stale: its class does not match
  EXPECT_EQ(r.approvals[4].matched, 0u);
  EXPECT_EQ(r.approvals[4].source, "ok.json#/approvals/4");
  EXPECT_TRUE(unapproved_collision(r));
  // The day it expires it still applies.
  o.today = "2026-05-31";
  EXPECT_EQ(review_query(q, nullptr, {expired}, o).clashes[2].approval, 0);
  // Approving the penetrating clash too leaves no collision.
  Approval all;
  all.a = "**";
  EXPECT_FALSE(unapproved_collision(review_query(q, nullptr, {all}, o)));
}

TEST(ApprovalsFile, RoundTripsAndNamesTheBadField) {
  Approval a;
  a.id = "0123456789ab";
  a.reason = "press fit";
  a.by = "ana";
  a.date = "2026-01-02";
  Approval rule;
  rule.a = "/as1/**";
  rule.part_b = "bolt*";
  rule.classes = {ContactClass::Touching, ContactClass::Clearance};
  rule.reason = "fasteners";
  rule.by = "bo";
  rule.date = "2026-01-03";
  rule.expires = "2026-12-31";
  const std::string text = approvals_text({a, rule});
  const ApprovalsReadResult back = approvals_from_json(text);
  ASSERT_FALSE(back.error) << format_report_error(*back.error);
  EXPECT_EQ(approvals_text(back.approvals), text);

  auto error_of = [](const std::string& t) {
    const ApprovalsReadResult r = approvals_from_json(t);
    return r.error ? format_report_error(*r.error) : std::string("no error");
  };
  const std::string head = R"({"schema": "cadclash-approvals", "version": 1, "approvals": [)";
  EXPECT_EQ(error_of(head + R"({"id": "x", "reason": "", "by": "", "date": "2026-13-01"}]})"),
            "/approvals/0/date: expected a date YYYY-MM-DD, got '2026-13-01'");
  EXPECT_EQ(error_of(head + R"({"reason": "", "by": "", "date": "2026-01-01"}]})"),
            "/approvals/0: names neither a clash `id` nor globs `a`/`b`/`part_a`/`part_b`");
  EXPECT_EQ(error_of(head + R"({"id": "x", "a": "*", "reason": "", "by": "", "date": "2026-01-01"}]})"),
            "/approvals/0: names both a clash id and instance/part globs; give one");
  EXPECT_EQ(error_of(head + R"({"id": "x", "classes": ["hot"], "reason": "", "by": "", "date": "2026-01-01"}]})"),
            "/approvals/0/classes/0: unknown contact class 'hot' (one of penetrating, touching, clearance, containment, undecided)");
  EXPECT_EQ(error_of(head + R"({"id": "x", "by": "", "date": "2026-01-01"}]})"), "/approvals/0/reason: is missing");
  EXPECT_EQ(error_of(R"({"schema": "cadclash-check-report", "version": 1, "approvals": []})"),
            "/schema: expected \"cadclash-approvals\"");
  EXPECT_EQ(error_of("[1,"), "not valid JSON");
}

CheckReport reviewed_report() {
  CheckReport r;
  r.files = {"as1.stp"};
  const QueryReport before = query({pair("/a", 1, "/b", 1, ContactClass::Touching), pair("/a", 5, "/f", 1, ContactClass::Touching)});
  r.query = query({pair("/a", 1, "/b", 1, ContactClass::Touching), pair("/a", 2, "/c", 1, ContactClass::Penetrating, 0.2)});
  Approval a;
  a.a = "/a";
  a.classes = {ContactClass::Touching};
  a.reason = "designed";
  a.by = "ana";
  a.date = "2026-01-01";
  Approval stale = a;
  stale.id = "ffffffffffff";
  stale.a.clear();
  stale.expires = "2027-01-01";
  ReviewOptions o;
  o.baseline_file = "before.json";
  o.approvals_file = "approvals.json";
  o.today = "2026-06-01";
  o.group_by = "part";
  r.review = review_query(*r.query, &before, {a, stale}, o);
  return r;
}

TEST(ReportReview, RoundTripsByteForByte) {
  const std::string text = check_report_text(reviewed_report());
  const ReportReadResult read = check_report_from_json(text);
  ASSERT_FALSE(read.error) << format_report_error(*read.error);
  ASSERT_TRUE(read.report.review);
  EXPECT_EQ(read.report.review->clashes.size(), 3u);
  EXPECT_EQ(check_report_text(read.report), text);
  const nlohmann::json j = nlohmann::json::parse(text);
  EXPECT_EQ(j["review"]["summary"]["resolved"], 1);
  EXPECT_EQ(j["review"]["summary"]["approved"], 1);
  EXPECT_EQ(j["review"]["summary"]["stale_approvals"], 1);
  EXPECT_EQ(j["review"]["approvals"][1]["state"], "stale");
  EXPECT_TRUE(j["clashes"][2]["surface_pairs"][0]["pair"].is_null());
}

TEST(ReportReview, InconsistentReviewIsRefusedWithItsPointer) {
  nlohmann::json j = check_report_json(reviewed_report());
  auto error_of = [](const nlohmann::json& doc) {
    const ReportReadResult r = check_report_from_parsed(doc);
    return r.error ? format_report_error(*r.error) : std::string("no error");
  };
  nlohmann::json bad = j;
  bad["clashes"][0]["surface_pairs"][0]["pair"] = 7;
  EXPECT_EQ(error_of(bad), "/clashes/0/surface_pairs/0/pair: names no entry of /pairs");
  bad = j;
  bad["clashes"][1]["status"] = "fixed";
  EXPECT_EQ(error_of(bad), "/clashes/1/status: unknown clash status 'fixed' (one of new, active, changed, resolved, unexamined)");
  bad = j;
  bad["review"]["summary"]["new"] = 5;
  EXPECT_EQ(error_of(bad), "/review: does not match the clashes and approvals");
  bad = j;
  bad["clashes"][0]["approval"] = 9;
  EXPECT_EQ(error_of(bad), "/clashes/0/approval: names no entry of /review/approvals");
  bad = j;
  bad["review"]["approvals"][1]["state"] = "used";
  EXPECT_EQ(error_of(bad), "/review/approvals/1/state: does not match `matched` and the expiry");
}

}  // namespace
}  // namespace cadclash
