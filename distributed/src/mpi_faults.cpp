#include "mpi_faults.h"

#include <csignal>
#include <cstring>
#include <unistd.h>

namespace cadclash::detail {
namespace {

constexpr int kSignals[] = {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT, SIGTERM};
constexpr std::size_t kShownPairs = 8;

// Filled before the work starts; read by the handler (no allocation there).
std::string g_head;  // "cadclash: rank 1 of 4 "
std::string g_tail;  // " before finishing its 12 instance pairs: ...\n"
struct sigaction g_old[sizeof(kSignals) / sizeof(kSignals[0])];
bool g_armed = false;

void write_all(const char* s, std::size_t n) {
  while (n > 0) {
    const ssize_t w = ::write(STDERR_FILENO, s, n);
    if (w <= 0) return;
    s += w;
    n -= static_cast<std::size_t>(w);
  }
}

const char* signal_cause(int sig) {
  switch (sig) {
    case SIGSEGV: return "crashed (signal SIGSEGV, invalid memory access)";
    case SIGBUS: return "crashed (signal SIGBUS)";
    case SIGFPE: return "crashed (signal SIGFPE)";
    case SIGILL: return "crashed (signal SIGILL)";
    case SIGABRT: return "aborted (signal SIGABRT: an uncaught exception such as std::bad_alloc, or a failed check)";
    case SIGTERM: return "was terminated (signal SIGTERM, e.g. by mpirun after another rank failed)";
    default: return "stopped by a signal";
  }
}

extern "C" void on_fatal_signal(int sig) {
  const char* cause = signal_cause(sig);
  write_all(g_head.data(), g_head.size());
  write_all(cause, std::strlen(cause));
  write_all(g_tail.data(), g_tail.size());
  std::signal(sig, SIG_DFL);  // SA_RESETHAND did so already; kept for clarity of intent
  std::raise(sig);
}

}  // namespace

void arm_fault_message(int rank, int size, const Model& model, const CheckPlan& plan,
                       std::span<const std::uint32_t> part) {
  g_head = "cadclash check: rank " + std::to_string(rank) + " of " + std::to_string(size) + " ";
  std::uint64_t cost = 0;
  for (std::uint32_t k : part) cost += plan.pairs[k].cost;
  g_tail = " before finishing its " + std::to_string(part.size()) + " instance pairs (estimated cost " +
           std::to_string(cost) + "); none of them is in any report";
  for (std::size_t i = 0; i < part.size() && i < kShownPairs; ++i) {
    const PlannedPair& p = plan.pairs[part[i]];
    g_tail += (i == 0 ? ": " : ", ") + model.instances[p.a].path + " x " + model.instances[p.b].path;
  }
  if (part.size() > kShownPairs) g_tail += ", ... and " + std::to_string(part.size() - kShownPairs) + " more";
  g_tail += "\n";
  struct sigaction sa {};
  sa.sa_handler = on_fatal_signal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESETHAND;
  for (std::size_t i = 0; i < std::size(kSignals); ++i) sigaction(kSignals[i], &sa, &g_old[i]);
  g_armed = true;
}

void disarm_fault_message() {
  if (!g_armed) return;
  for (std::size_t i = 0; i < std::size(kSignals); ++i) sigaction(kSignals[i], &g_old[i], nullptr);
  g_armed = false;
}

void print_fault_message(const char* cause) {
  write_all(g_head.data(), g_head.size());
  write_all(cause, std::strlen(cause));
  write_all(g_tail.data(), g_tail.size());
}

}  // namespace cadclash::detail
