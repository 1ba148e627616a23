// The child-process runner behind the CAD readers (import/src/isolated_run.h): a child that dies is
// reported with its signal and the marks it reached, and leaves this process running.
#include "isolated_run.h"

#include <gtest/gtest.h>

#include <csignal>
#include <cstdlib>
#include <string>

namespace cadclash::detail {
namespace {

TEST(IsolatedRun, FinishedChildReportsItsMarks) {
  const ChildRun run = run_in_child([](const std::function<void(char)>& mark) {
    mark('P');
    mark('T');
  });
  EXPECT_TRUE(run.isolated);
  EXPECT_FALSE(run.crashed) << run.how;
  EXPECT_EQ(run.marks, "PT");
}

TEST(IsolatedRun, SegfaultIsContainedAndNamed) {
  const ChildRun run = run_in_child([](const std::function<void(char)>& mark) {
    mark('P');
    volatile int* null = nullptr;
    *null = 1;  // what OCCT's translators do with a missing parameter
    mark('T');
  });
  EXPECT_TRUE(run.crashed);
  EXPECT_EQ(run.how.rfind("SIGSEGV", 0), 0u) << run.how;
  EXPECT_EQ(run.marks, "P");
}

TEST(IsolatedRun, AbortAndNonZeroExitAreCrashes) {
  const ChildRun aborted = run_in_child([](const std::function<void(char)>&) { std::abort(); });
  EXPECT_TRUE(aborted.crashed);
  EXPECT_EQ(aborted.how.rfind("SIGABRT", 0), 0u) << aborted.how;
  const ChildRun exited = run_in_child([](const std::function<void(char)>&) { std::_Exit(3); });
  EXPECT_TRUE(exited.crashed);
  EXPECT_EQ(exited.how, "exit status 3");
}

// A child whose status cannot be collected (the host reaps children itself) is judged by whether it
// wrote its final mark.
TEST(IsolatedRun, UnreapableChildIsJudgedByItsLastMark) {
  struct sigaction old {};
  struct sigaction ignore {};
  ignore.sa_handler = SIG_IGN;
  sigaction(SIGCHLD, &ignore, &old);
  const ChildRun fine = run_in_child([](const std::function<void(char)>& mark) { mark('P'); });
  const ChildRun dead = run_in_child([](const std::function<void(char)>&) { std::_Exit(0); });
  sigaction(SIGCHLD, &old, nullptr);
  EXPECT_FALSE(fine.crashed) << fine.how;
  EXPECT_EQ(fine.marks, "P");
  EXPECT_TRUE(dead.crashed);
}

TEST(IsolatedRun, ExceptionInChildIsNotACrash) {
  const ChildRun run = run_in_child([](const std::function<void(char)>&) { throw std::bad_alloc(); });
  EXPECT_FALSE(run.crashed) << run.how;
}

}  // namespace
}  // namespace cadclash::detail
