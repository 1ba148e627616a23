// Runs OCCT's file translators in a forked child before trusting them in this process.
// OCCT's STEP/IGES translators dereference parameters of malformed entities without checking
// (StepToGeom::MakeLine on a LINE whose point was cut off), so a bad file can end the process with
// SIGSEGV instead of a check-list message. A crash in a child becomes an error naming the file; a
// child that finished sends back what it made (cad_transfer.h). Internal to cadclash::import.
#pragma once

#include "cadclash/import.h"

#include <chrono>
#include <cstdint>
#include <optional>
#include <functional>
#include <string>
#include <vector>

#include <poll.h>

namespace cadclash::detail {

// How a child run ended.
struct ChildRun {
  bool isolated = true;   // false when no child could be started (the work was not run at all)
  bool crashed = false;   // the child ended by a signal or a non-zero exit, or was stopped
  bool timed_out = false; // stopped at the time limit (crashed is true too)
  std::string how;        // "SIGSEGV (segmentation fault)", "exit status 1", or why no child started
  std::string marks;      // the progress marks the child reported, in order (see `work` below)
  std::string payload;    // what `work` returned, when the child finished
};

using Mark = std::function<void(char)>;

// Calls `work(mark)` in a forked child and waits for it. `work` calls `mark(c)` as it passes each
// stage, so a crash can be placed (marks are any char but '\0'); what it returns comes back as
// `payload`.
// Preconditions:
// - `work` uses no OpenMP (a forked child has only the calling thread; the runtime's pool is the
//   parent's copy), and joins the threads it starts before it forks (Children);
// - `work` writes nothing to stdout (the child's stdout is /dev/null).
// Several threads may each run a child at once (import_files reads files in parallel); the fork
// itself waits until no other thread holds a CadWork. A child still running after
// `time_limit_seconds` (> 0; 0 = none) is killed, and the run is `timed_out`.
ChildRun run_in_child(const std::function<std::string(const Mark& mark)>& work, double time_limit_seconds = 0.0);

// Calls `work(k, mark)` for k = 0 ... n - 1, each in a forked child, all at once; wait() waits for
// them all and gives one ChildRun per k, as run_in_child's. The caller may work meanwhile (a child
// that has finished waits to hand over its payload). For a process with one thread (an isolated
// reader's child spreading its work over processes): it takes no lock. Each child dies with the
// calling process (PR_SET_PDEATHSIG), so a reader stopped at its time limit leaves none behind; one
// not waited for is killed by the destructor.
// Preconditions: as run_in_child's, and the calling process has one thread.
class Children {
 public:
  Children(std::size_t n, const std::function<std::string(std::size_t k, const Mark& mark)>& work);
  ~Children();
  Children(const Children&) = delete;
  Children& operator=(const Children&) = delete;
  std::vector<ChildRun> wait();  // once

 private:
  std::vector<ChildRun> runs_;
  std::vector<int> pids_;
  std::vector<struct pollfd> pipes_;
  std::vector<std::size_t> owner_;  // the run each of pipes_ reads
};

// Children(n, work).wait().
std::vector<ChildRun> run_in_children(std::size_t n, const std::function<std::string(std::size_t k, const Mark& mark)>& work);

// Held by a thread while it reads a file in this process (import_file holds one throughout).
// Forking while another thread is inside OCCT (or any library that locks) could give the child a
// lock that nobody releases, since a child has only the forking thread: run_in_child forks only
// while no thread holds a CadWork, letting go of its own thread's one for as long as its child runs.
// Nests within one thread.
class CadWork {
 public:
  CadWork();
  ~CadWork();
  CadWork(const CadWork&) = delete;
  CadWork& operator=(const CadWork&) = delete;
};

// The time an import's isolated readers have left (ImportOptions::reader_time_limit_seconds), over
// every child of one file.
class ReaderClock {
 public:
  explicit ReaderClock(double limit_seconds);
  // Seconds left for the next child, > 0; 0 when there is no limit.
  double left() const;
  // The error for a reader stopped at the limit: "the isolated reader did not finish within the time
  // limit of 2 s while <stage>[, at this entity]; stopped, nothing more is read from the file".
  std::string stopped_message(const std::string& stage, std::int64_t entity) const;

 private:
  double limit_;
  std::chrono::steady_clock::time_point start_;
};

// The warning for a time limit that cannot be applied (no isolation), or nothing.
std::optional<Diagnostic> unapplied_time_limit(const std::string& path, const ImportOptions& options);

// Marks that name the entity a child is working on: "#<id>" before it, "." after it. A child that
// crashes inside the entity leaves an unclosed "#<id>", so the next child can skip that entity.
void mark_entity_begin(const Mark& mark, std::int64_t id);
void mark_entity_end(const Mark& mark);

// The entity whose "#<id>" mark is the last one and unclosed; -1 when there is none.
std::int64_t entity_in_progress(const std::string& marks);

}  // namespace cadclash::detail
