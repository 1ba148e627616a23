// The progress line on stderr (tools/progress_line.h): shown on a terminal, never in a pipe or a
// file, never with --quiet, and never a change to what stdout says.
#include "cli_runner.h"

#include <gtest/gtest.h>

#include <pty.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <filesystem>
#include <string>
#include <vector>

namespace cadclash::testing {
namespace {

const std::string kData = std::string(CADCLASH_DATA_DIR) + "/";
const std::string kAs1 = kData + "external/as1-tu-203.stp";

struct PtyRun {
  int code = -1;
  std::string terminal;  // what the program wrote to its terminal (stderr; stdin too)
  std::string out;       // its stdout, sent to a file
};

// cadclash with stderr on a pseudo-terminal (80 columns) and stdout in a file.
PtyRun run_on_terminal(const std::vector<std::string>& args) {
  const std::string out_path = scratch_dir() + "/pty_out.txt";
  winsize size{};
  size.ws_row = 24;
  size.ws_col = 80;
  int master = -1;
  const pid_t pid = forkpty(&master, nullptr, nullptr, &size);
  if (pid == 0) {
    if (std::freopen(out_path.c_str(), "wb", stdout) == nullptr) _exit(126);
    std::vector<char*> argv{const_cast<char*>(CADCLASH_EXE)};
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    alarm(60);  // a hung run fails the test instead of the suite's timeout
    execv(CADCLASH_EXE, argv.data());
    _exit(127);
  }
  PtyRun r;
  if (pid < 0) return r;
  char buf[4096];
  for (;;) {
    const ssize_t n = read(master, buf, sizeof buf);
    if (n > 0) r.terminal.append(buf, static_cast<std::size_t>(n));
    else if (n < 0 && errno == EINTR) continue;
    else break;  // EIO: the child closed the terminal
  }
  int status = 0;
  waitpid(pid, &status, 0);
  close(master);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = slurp(out_path);
  return r;
}

bool as1_missing() { return !std::filesystem::exists(kAs1); }

TEST(ProgressCli, PipedStderrStaysClean) {
  if (as1_missing()) GTEST_SKIP() << kAs1 << " missing: run scripts/setup.sh";
  const CliRun r = run_cadclash("check '" + kAs1 + "' --tolerance 0.01 --no-timings");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err.find('\r'), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find('\033'), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("reading files"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("checking instance pairs"), std::string::npos) << r.err;
  EXPECT_EQ(r.out.find('\r'), std::string::npos);
  EXPECT_NE(r.out.find("376 reported pairs"), std::string::npos) << r.out;
  EXPECT_EQ(r.err, "");  // nothing at all: as1 reads cleanly
}

TEST(ProgressCli, PipedTrajectoryAndTessellateStayClean) {
  const CliRun path = run_cadclash("check '" + kData + "collide/box_a.obj' '" + kData + "collide/box_near.obj' --path '" +
                                   kData + "collide/path_ok.csv' --no-timings");
  ASSERT_EQ(path.code, 0) << path.err;
  EXPECT_EQ(path.err, "");
  EXPECT_NE(path.out.find("step 2:"), std::string::npos) << path.out;
  const std::string glb = scratch_dir() + "/piped.glb";
  const CliRun tess = run_cadclash("tessellate '" + kData + "cad/valid_two_solids.step' -o '" + glb + "'");
  ASSERT_EQ(tess.code, 0) << tess.err;
  EXPECT_EQ(tess.err.find('\r'), std::string::npos) << tess.err;
  EXPECT_EQ(tess.err.rfind("wrote ", 0), 0u) << tess.err;  // the result line, nothing before it
}

TEST(ProgressCli, CheckOnATerminalShowsProgressAndTheSameTable) {
  if (as1_missing()) GTEST_SKIP() << kAs1 << " missing: run scripts/setup.sh";
  const PtyRun r = run_on_terminal({"check", kAs1, "--eager", "--tolerance", "0.01", "--no-timings"});
  ASSERT_EQ(r.code, 0) << r.terminal;
  EXPECT_NE(r.terminal.find("\r\033[Kreading files 0/1"), std::string::npos) << r.terminal;
  EXPECT_NE(r.terminal.find("meshing parts"), std::string::npos) << r.terminal;
  EXPECT_NE(r.terminal.find("checking instance pairs"), std::string::npos) << r.terminal;
  EXPECT_NE(r.terminal.find("(surface level)"), std::string::npos) << r.terminal;
  // The line is cleared at the end: the last thing on the terminal is the clearing sequence.
  EXPECT_TRUE(r.terminal.ends_with("\r\033[K")) << r.terminal;
  // stdout is what a pipe gets, byte for byte.
  const CliRun piped = run_cadclash("check '" + kAs1 + "' --eager --tolerance 0.01 --no-timings");
  EXPECT_EQ(r.out, piped.out);
}

TEST(ProgressCli, QuietTerminalGetsNothing) {
  if (as1_missing()) GTEST_SKIP() << kAs1 << " missing: run scripts/setup.sh";
  const PtyRun r = run_on_terminal({"check", kAs1, "--tolerance", "0.01", "--no-timings", "--quiet"});
  ASSERT_EQ(r.code, 0) << r.terminal;
  EXPECT_EQ(r.terminal, "");
  EXPECT_NE(r.out.find("376 reported pairs"), std::string::npos) << r.out;
}

TEST(ProgressCli, TrajectoryOnATerminalShowsItsSteps) {
  const PtyRun r = run_on_terminal({"check", kData + "collide/box_a.obj", kData + "collide/box_near.obj", "--path",
                                    kData + "collide/path_ok.csv", "--no-timings"});
  ASSERT_EQ(r.code, 0) << r.terminal;
  EXPECT_NE(r.terminal.find("\r\033[Ktrajectory steps 0/3"), std::string::npos) << r.terminal;
  EXPECT_EQ(r.terminal.find("checking instance pairs"), std::string::npos) << r.terminal;  // steps, not their checks
  EXPECT_NE(r.out.find("step 2:"), std::string::npos) << r.out;
}

TEST(ProgressCli, TessellateOnATerminal) {
  const std::string glb = scratch_dir() + "/terminal.glb";
  const PtyRun r = run_on_terminal({"tessellate", kData + "cad/valid_two_solids.step", "-o", glb});
  ASSERT_EQ(r.code, 0) << r.terminal;
  EXPECT_NE(r.terminal.find("\r\033[Kreading files 0/1"), std::string::npos) << r.terminal;
  EXPECT_NE(r.terminal.find("\r\033[Kwriting " + glb), std::string::npos) << r.terminal;
  EXPECT_NE(r.terminal.find("\r\033[Kwrote " + glb), std::string::npos) << r.terminal;  // cleared first
  const PtyRun quiet = run_on_terminal({"tessellate", kData + "cad/valid_two_solids.step", "-o", glb, "--quiet"});
  ASSERT_EQ(quiet.code, 0) << quiet.terminal;
  EXPECT_EQ(quiet.terminal, "");
}

}  // namespace
}  // namespace cadclash::testing
