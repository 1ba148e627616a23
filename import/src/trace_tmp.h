#pragma once
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <unistd.h>
inline void ttrace(const char* what) {
  static const bool on = std::getenv("CADCLASH_TRACE") != nullptr;
  if (!on) return;
  const double t = std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
  std::fprintf(stderr, "TRACE %d %.3f %s\n", (int)getpid(), t, what);
}
