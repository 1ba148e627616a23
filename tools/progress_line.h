// The status line of long work on stderr: one line rewritten in place (\r), with the stage, how far
// it is, its rate and time left, and what it is working on; cleared before anything else is printed.
#pragma once

#include "cadclash/collide.h"

#include <chrono>
#include <cstddef>
#include <ostream>
#include <string>

namespace cadclash::cli {

// Whether a command shows the line: stderr is a terminal, the command was not started by mpirun (a
// rank's stderr is Open MPI's forwarding pseudo-terminal whatever mpirun's own is: an MPI job shows
// none, and its output stays byte-identical to a single process's) and --quiet was not given.
bool show_progress(bool quiet);

// One phase's line (an import, a check). Calls to the callback must not overlap (the library's
// contract, collide.h); the line is cleared when a run of a stage ends, by clear() and on destruction.
class ProgressLine {
 public:
  explicit ProgressLine(bool shown, std::ostream& os);
  ~ProgressLine();
  ProgressLine(const ProgressLine&) = delete;
  ProgressLine& operator=(const ProgressLine&) = delete;

  // What the library's options take; empty when the line is not shown (the library then does no
  // progress work at all).
  ProgressCallback callback();
  // A line of the command's own ("writing OUT.glb"), until the next update or clear().
  void status(const std::string& text);
  void clear();

 private:
  using Clock = std::chrono::steady_clock;
  void update(const Progress& p);
  void draw(std::string text);

  bool shown_;
  std::ostream& os_;
  bool drawn_ = false;
  Clock::time_point last_draw_{};
  // The run being timed: restarted when a stage starts (done 0) or changes.
  ProgressStage stage_ = ProgressStage::ReadFile;
  std::size_t total_ = 0;
  Clock::time_point run_start_{};
};

// "reading files 2/5 40%, 0.8/s, 0:04 left: bolt.stp" (rate and time left once a run has gone on
// for half a second). Exposed for the tests.
std::string progress_text(const Progress& p, double seconds);

}  // namespace cadclash::cli
