// fork + pipe + waitpid: a child that dies leaves this process untouched.
#include "isolated_run.h"

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <cstdint>
#include <cstring>
#include <mutex>
#include <shared_mutex>
#include <sstream>
#include <vector>

#include <fcntl.h>
#include <poll.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

namespace cadclash::detail {
namespace {

// Written last by a child whose work returned. Without it the child did not finish, whatever
// waitpid says (a host that ignores SIGCHLD has its children reaped before we can ask).
constexpr char kFinished = '\0';

std::string signal_text(int sig) {
  const char* name = sig == SIGSEGV ? "SIGSEGV" : sig == SIGBUS ? "SIGBUS" : sig == SIGFPE ? "SIGFPE"
                   : sig == SIGILL ? "SIGILL" : sig == SIGABRT ? "SIGABRT" : sig == SIGKILL ? "SIGKILL" : nullptr;
  const char* what = strsignal(sig);
  std::string out = name ? name : "signal " + std::to_string(sig);
  if (what != nullptr) out += std::string(" (") + what + ")";
  return out;
}

// The child dies of its signal without the handlers the parent installed (a sanitizer's or a
// fuzzer's would report the crash as the whole program's and write artifacts for it).
void default_crash_handlers() {
  for (const int sig : {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT}) std::signal(sig, SIG_DFL);
}

// The child's side of a run: `work` with marks and its payload down `out`, then the end.
[[noreturn]] void child_main(int out, const std::function<std::string(const Mark& mark)>& work) {
  default_crash_handlers();
  if (const int null = open("/dev/null", O_WRONLY); null >= 0) dup2(null, STDOUT_FILENO);
  std::string payload;
  try {
    payload = work([out](char c) { (void)!write(out, &c, 1); });
  } catch (...) {
    // An exception (bad_alloc, ...) is the parent's to meet again; it is not a crash.
  }
  // The end mark, the payload's size (8 bytes, little end first) and the payload: the parent stops
  // reading when it has them all, without waiting for this process to give back its memory, which
  // it does before its end of the pipe closes (a tenth of a second after a large file).
  std::string tail(1, kFinished);
  for (int b = 0; b < 8; ++b) tail += static_cast<char>((static_cast<std::uint64_t>(payload.size()) >> (8 * b)) & 0xff);
  tail += payload;
  for (std::size_t at = 0; at < tail.size();) {
    const ssize_t n = write(out, tail.data() + at, tail.size() - at);
    if (n > 0) at += static_cast<std::size_t>(n);
    else if (errno != EINTR) break;
  }
  _exit(0);  // no atexit handlers or static destructors: they belong to the parent
}

// Whether `bytes` (what a child wrote so far) hold its end mark, the payload's size and the whole
// payload.
bool whole(const std::string& bytes) {
  const std::size_t end = bytes.find(kFinished);
  if (end == std::string::npos || bytes.size() < end + 9) return false;
  std::uint64_t size = 0;
  for (int b = 0; b < 8; ++b) size |= static_cast<std::uint64_t>(static_cast<unsigned char>(bytes[end + 1 + b])) << (8 * b);
  return bytes.size() - end - 9 >= size;
}

// Finished children not yet reaped: each is reaped when it has ended, at the latest when the next
// child is started or finished (a zombie until then: no thread waits for it, so a caller that asked
// for one thread keeps one).
std::mutex& unreaped_mutex() {
  static std::mutex m;
  return m;
}
std::vector<pid_t>& unreaped() {
  static std::vector<pid_t> pids;
  return pids;
}
void reap_ended() {
  const std::lock_guard<std::mutex> lock(unreaped_mutex());
  std::erase_if(unreaped(), [](pid_t pid) {
    int status = 0;
    pid_t waited = -1;
    while ((waited = waitpid(pid, &status, WNOHANG)) < 0 && errno == EINTR) {
    }
    return waited != 0;  // ended and reaped, or not ours any more
  });
}
void reap_later(pid_t pid) {
  // A host that ignores SIGCHLD has its children reaped by the system: its pid could come back as
  // another of the host's children, which must not be reaped here.
  struct sigaction current {};
  if (sigaction(SIGCHLD, nullptr, &current) == 0 &&
      (current.sa_handler == SIG_IGN || (current.sa_flags & SA_NOCLDWAIT) != 0))
    return;
  const std::lock_guard<std::mutex> lock(unreaped_mutex());
  unreaped().push_back(pid);
}

// How a finished child's bytes and exit status read: the payload split off the marks, and what ended it.
void finish_run(ChildRun& run, pid_t pid) {
  reap_ended();
  const std::size_t end = run.marks.find(kFinished);
  const bool finished = !run.timed_out && whole(run.marks);
  if (end != std::string::npos) {
    run.payload = run.marks.size() >= end + 9 ? run.marks.substr(end + 9) : std::string();
    run.marks.resize(end);
  }
  int status = 0;
  pid_t waited = -1;
  // A child that sent all it had to say is done: its exit status is taken if it is there already,
  // else it is reaped later. Any other child is waited for, to say how it ended.
  while ((waited = waitpid(pid, &status, finished ? WNOHANG : 0)) < 0 && errno == EINTR) {
  }
  if (finished && waited == 0) {
    reap_later(pid);
    return;
  }
  if (run.timed_out) {
    run.crashed = true;
    run.how = "the time limit";
  } else if (waited == pid && WIFSIGNALED(status)) {
    run.crashed = true;
    run.how = signal_text(WTERMSIG(status));
  } else if (waited == pid && WIFEXITED(status) && WEXITSTATUS(status) != 0) {
    run.crashed = true;  // a sanitizer's report ends the child with exit status 1
    run.how = "exit status " + std::to_string(WEXITSTATUS(status));
  } else if (!finished) {
    run.crashed = true;
    run.how = "it ended before finishing";
  }
}

std::shared_mutex& fork_mutex() {
  static std::shared_mutex m;
  return m;
}

thread_local int cad_work_depth = 0;  // CadWork objects alive on this thread

// This thread's share of fork_mutex let go of while its child runs, taken back at the end. Not
// destroyed in the child, which ends with _exit.
class LetGo {
 public:
  LetGo() : held_(cad_work_depth > 0) {
    if (held_) fork_mutex().unlock_shared();
  }
  ~LetGo() {
    if (held_) fork_mutex().lock_shared();
  }
  LetGo(const LetGo&) = delete;
  LetGo& operator=(const LetGo&) = delete;

 private:
  bool held_;
};

}  // namespace

CadWork::CadWork() {
  if (cad_work_depth++ == 0) fork_mutex().lock_shared();
}

CadWork::~CadWork() {
  if (--cad_work_depth == 0) fork_mutex().unlock_shared();
}

ChildRun run_in_child(const std::function<std::string(const Mark& mark)>& work, double time_limit_seconds) {
  reap_ended();
  const LetGo let_go;
  ChildRun run;
  // Held from the pipe to the parent's closing of its write end: a child forked by another thread
  // meanwhile would inherit that end, and this pipe would not reach its end before that child did.
  std::unique_lock<std::shared_mutex> no_reader_inside(fork_mutex());
  int fds[2];
  if (pipe2(fds, O_CLOEXEC) != 0) {
    run.isolated = false;
    run.how = std::string("pipe: ") + std::strerror(errno);
    return run;
  }
  const pid_t pid = fork();
  if (pid < 0) {
    run.isolated = false;
    run.how = std::string("fork: ") + std::strerror(errno);
    close(fds[0]);
    close(fds[1]);
    return run;
  }
  if (pid == 0) {
    close(fds[0]);
    child_main(fds[1], work);
  }
  close(fds[1]);
  no_reader_inside.unlock();  // (the child keeps its copy locked: it never returns from here)
  const bool limited = time_limit_seconds > 0.0;
  const auto deadline = std::chrono::steady_clock::now() +
                        std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                            std::chrono::duration<double>(limited ? std::min(time_limit_seconds, 1e9) : 0.0));
  char buffer[1 << 16];
  while (!whole(run.marks)) {
    if (limited) {
      // A hanging child writes nothing: wait for its pipe no longer than the time left.
      const auto left = std::chrono::ceil<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
      if (left.count() <= 0) {
        run.timed_out = true;
        kill(pid, SIGKILL);
        break;
      }
      pollfd ready{fds[0], POLLIN, 0};
      const int polled = poll(&ready, 1, static_cast<int>(std::min<std::int64_t>(left.count(), 1 << 30)));
      if (polled == 0 || (polled < 0 && errno == EINTR)) continue;
    }
    const ssize_t n = read(fds[0], buffer, sizeof buffer);
    if (n > 0) {
      run.marks.append(buffer, static_cast<std::size_t>(n));
    } else if (n == 0 || errno != EINTR) {
      break;
    }
  }
  close(fds[0]);
  finish_run(run, pid);
  return run;
}

Children::Children(std::size_t n, const std::function<std::string(std::size_t k, const Mark& mark)>& work)
    : runs_(n), pids_(n, -1) {
  const pid_t self = getpid();
  for (std::size_t k = 0; k < n; ++k) {
    int fds[2];
    if (pipe2(fds, O_CLOEXEC) != 0) {
      runs_[k].isolated = false;
      runs_[k].how = std::string("pipe: ") + std::strerror(errno);
      continue;
    }
    pids_[k] = fork();
    if (pids_[k] < 0) {
      runs_[k].isolated = false;
      runs_[k].how = std::string("fork: ") + std::strerror(errno);
      close(fds[0]);
      close(fds[1]);
      continue;
    }
    if (pids_[k] == 0) {
      // A child outlives nothing: when the process that forked it ends (an isolated reader stopped
      // at its time limit), so does it.
      prctl(PR_SET_PDEATHSIG, SIGKILL);
      if (getppid() != self) _exit(1);
      for (const pollfd& p : pipes_) close(p.fd);
      close(fds[0]);
      child_main(fds[1], [&work, k](const Mark& mark) { return work(k, mark); });
    }
    close(fds[1]);
    pipes_.push_back({fds[0], POLLIN, 0});
    owner_.push_back(k);
  }
}

std::vector<ChildRun> Children::wait() {
  char buffer[1 << 16];
  while (!pipes_.empty()) {
    if (poll(pipes_.data(), pipes_.size(), -1) < 0 && errno != EINTR) break;
    for (std::size_t i = pipes_.size(); i-- > 0;) {
      if (pipes_[i].revents == 0) continue;
      const ssize_t got = read(pipes_[i].fd, buffer, sizeof buffer);
      if (got > 0) runs_[owner_[i]].marks.append(buffer, static_cast<std::size_t>(got));
      if ((got > 0 && whole(runs_[owner_[i]].marks)) || got == 0 || (got < 0 && errno != EINTR)) {
        close(pipes_[i].fd);
        pipes_.erase(pipes_.begin() + static_cast<std::ptrdiff_t>(i));
        owner_.erase(owner_.begin() + static_cast<std::ptrdiff_t>(i));
      }
    }
  }
  for (std::size_t k = 0; k < pids_.size(); ++k)
    if (pids_[k] > 0) finish_run(runs_[k], pids_[k]);
  pids_.clear();
  return std::move(runs_);
}

Children::~Children() {
  for (const pollfd& p : pipes_) close(p.fd);
  for (const pid_t pid : pids_) {
    if (pid <= 0) continue;
    kill(pid, SIGKILL);
    int status = 0;
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
  }
}

std::vector<ChildRun> run_in_children(std::size_t n, const std::function<std::string(std::size_t k, const Mark& mark)>& work) {
  return Children(n, work).wait();
}

void mark_entity_begin(const Mark& mark, std::int64_t id) {
  mark('#');
  for (const char c : std::to_string(id)) mark(c);
}

void mark_entity_end(const Mark& mark) { mark('.'); }

std::int64_t entity_in_progress(const std::string& marks) {
  const std::size_t hash = marks.rfind('#');
  if (hash == std::string::npos || marks.find('.', hash) != std::string::npos) return -1;
  std::int64_t id = 0;
  std::size_t i = hash + 1;
  for (; i < marks.size() && marks[i] >= '0' && marks[i] <= '9' && id < (std::int64_t{1} << 50); ++i) id = id * 10 + (marks[i] - '0');
  return i > hash + 1 ? id : -1;
}

ReaderClock::ReaderClock(double limit_seconds) : limit_(limit_seconds), start_(std::chrono::steady_clock::now()) {}

double ReaderClock::left() const {
  if (!(limit_ > 0.0)) return 0.0;
  const std::chrono::duration<double> used = std::chrono::steady_clock::now() - start_;
  return std::max(limit_ - used.count(), 1e-3);  // spent: the next child is stopped at once
}

std::string ReaderClock::stopped_message(const std::string& stage, std::int64_t entity) const {
  std::ostringstream out;
  out << "the isolated reader did not finish within the time limit of " << limit_ << " s while " << stage
      << (entity >= 0 ? ", at this entity" : "") << "; stopped, nothing more is read from the file";
  return out.str();
}

std::optional<Diagnostic> unapplied_time_limit(const std::string& path, const ImportOptions& options) {
  if (!(options.reader_time_limit_seconds > 0.0) || options.isolate_cad_readers) return std::nullopt;
  return Diagnostic{Severity::Warning, path, 0, -1,
                    "the reader time limit needs the isolated reader, which is off; not applied"};
}

}  // namespace cadclash::detail
