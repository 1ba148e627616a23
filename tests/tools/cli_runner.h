// Runs the built `cadclash` binary (CADCLASH_EXE) for the CLI tests: stdout and stderr go to files
// in this process's scratch folder, so the program never sees a terminal and parallel tests never
// share a file.
#pragma once

#include "../test_temp.h"

#include <cstdlib>
#include <fstream>
#include <iterator>
#include <string>
#include <sys/wait.h>

namespace cadclash::testing {

struct CliRun {
  int code = -1;   // exit code, or -1 if ended by a signal
  int signal = 0;  // the signal, if any (timeout's 124 is an exit code: the run hung)
  std::string out, err;
};

inline std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// `timeout 60 cadclash <args>`; `args` is pasted into a shell command line, so quote paths.
inline CliRun run_cadclash(const std::string& args) {
  const std::string dir = scratch_dir();
  const std::string out = dir + "/cli_out.txt", err = dir + "/cli_err.txt";
  const std::string command = std::string("timeout 60 '") + CADCLASH_EXE + "' " + args + " >'" + out + "' 2>'" + err +
                              "' </dev/null";
  const int status = std::system(command.c_str());
  CliRun r;
  if (WIFEXITED(status)) {
    r.code = WEXITSTATUS(status);
    if (r.code > 128) {  // the shell's way of saying the child died of a signal
      r.signal = r.code - 128;
      r.code = -1;
    }
  } else if (WIFSIGNALED(status)) {
    r.signal = WTERMSIG(status);
  }
  r.out = slurp(out);
  r.err = slurp(err);
  return r;
}

}  // namespace cadclash::testing
