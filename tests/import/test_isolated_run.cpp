// The child-process runner behind the CAD readers (import/src/isolated_run.h): a child that dies is
// reported with its signal and the marks it reached, and leaves this process running.
#include "isolated_run.h"

#include <gtest/gtest.h>

#include <csignal>
#include <cstdlib>
#include <string>

#include <unistd.h>

namespace cadclash::detail {
namespace {

TEST(IsolatedRun, FinishedChildReportsItsMarks) {
  const std::string big(1 << 20, 'x');  // more than a pipe holds: the parent must read while the child writes
  const ChildRun run = run_in_child([&](const Mark& mark) {
    mark('P');
    mark('T');
    return big + '\0' + "end";
  });
  EXPECT_TRUE(run.isolated);
  EXPECT_FALSE(run.crashed) << run.how;
  EXPECT_EQ(run.marks, "PT");
  EXPECT_EQ(run.payload, big + '\0' + "end");
}

TEST(IsolatedRun, SegfaultIsContainedAndNamed) {
  const ChildRun run = run_in_child([](const Mark& mark) {
    mark('P');
    volatile int* null = nullptr;
    *null = 1;  // what OCCT's translators do with a missing parameter
    mark('T');
    return std::string("never");
  });
  EXPECT_TRUE(run.crashed);
  EXPECT_EQ(run.how.rfind("SIGSEGV", 0), 0u) << run.how;
  EXPECT_EQ(run.marks, "P");
  EXPECT_EQ(run.payload, "");
}

TEST(IsolatedRun, AbortAndNonZeroExitAreCrashes) {
  const ChildRun aborted = run_in_child([](const Mark&) -> std::string { std::abort(); });
  EXPECT_TRUE(aborted.crashed);
  EXPECT_EQ(aborted.how.rfind("SIGABRT", 0), 0u) << aborted.how;
  const ChildRun exited = run_in_child([](const Mark&) -> std::string { std::_Exit(3); });
  EXPECT_TRUE(exited.crashed);
  EXPECT_EQ(exited.how, "exit status 3");
}

// A child that never answers is killed at the time limit; its marks so far are kept.
TEST(IsolatedRun, HangingChildIsStoppedAtTheTimeLimit) {
  const ChildRun run = run_in_child(
      [](const Mark& mark) -> std::string {
        mark('P');
        mark_entity_begin(mark, 42);
        for (;;) pause();
      },
      0.5);
  EXPECT_TRUE(run.crashed);
  EXPECT_TRUE(run.timed_out);
  EXPECT_EQ(run.how, "the time limit");
  EXPECT_EQ(entity_in_progress(run.marks), 42);
  EXPECT_EQ(run.payload, "");
  // A limit that is not reached changes nothing, and a payload larger than a pipe still arrives.
  const std::string big(1 << 20, 'y');
  const ChildRun quick = run_in_child([&](const Mark& mark) {
    mark('P');
    return big;
  }, 60.0);
  EXPECT_FALSE(quick.crashed) << quick.how;
  EXPECT_FALSE(quick.timed_out);
  EXPECT_EQ(quick.marks, "P");
  EXPECT_EQ(quick.payload, big);
}

// A child whose status cannot be collected (the host reaps children itself) is judged by whether it
// wrote its final mark.
TEST(IsolatedRun, UnreapableChildIsJudgedByItsLastMark) {
  struct sigaction old {};
  struct sigaction ignore {};
  ignore.sa_handler = SIG_IGN;
  sigaction(SIGCHLD, &ignore, &old);
  const ChildRun fine = run_in_child([](const Mark& mark) {
    mark('P');
    return std::string("ok");
  });
  const ChildRun dead = run_in_child([](const Mark&) -> std::string { std::_Exit(0); });
  sigaction(SIGCHLD, &old, nullptr);
  EXPECT_FALSE(fine.crashed) << fine.how;
  EXPECT_EQ(fine.marks, "P");
  EXPECT_EQ(fine.payload, "ok");
  EXPECT_TRUE(dead.crashed);
}

TEST(IsolatedRun, ExceptionInChildIsNotACrash) {
  const ChildRun run = run_in_child([](const Mark&) -> std::string { throw std::bad_alloc(); });
  EXPECT_FALSE(run.crashed) << run.how;
}

TEST(IsolatedRun, EntityInProgressIsTheLastUnclosedMark) {
  std::string marks;
  const Mark mark = [&marks](char c) { marks += c; };
  EXPECT_EQ(entity_in_progress(marks), -1);
  mark('P');
  mark_entity_begin(mark, 17);
  mark_entity_end(mark);
  EXPECT_EQ(entity_in_progress(marks), -1);
  mark_entity_begin(mark, 1234567);
  EXPECT_EQ(entity_in_progress(marks), 1234567);
  EXPECT_EQ(marks, "P#17.#1234567");
}

}  // namespace
}  // namespace cadclash::detail
