// What a rank says when it dies while checking its part: prepared before the work (a signal handler
// may only write()), printed by the handler of a fatal signal or on std::bad_alloc. Internal.
#pragma once

#include "cadclash/collide.h"

#include <span>
#include <string>

namespace cadclash::detail {

// Arms the handlers (SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT, SIGTERM) with a message naming
// `rank` of `size` and its unfinished instance pairs (the first few by path, and how many).
void arm_fault_message(int rank, int size, const Model& model, const CheckPlan& plan,
                       std::span<const std::uint32_t> part);
// Restores the previous handlers.
void disarm_fault_message();
// Writes the armed message with `cause` ("ran out of memory (std::bad_alloc)") to stderr.
void print_fault_message(const char* cause);

}  // namespace cadclash::detail
