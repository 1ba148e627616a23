// A scratch folder private to this test process. CTest runs tests in parallel, each in its own
// process, and gtest's TempDir() is shared by all of them, so fixed file names there would race.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

namespace cadclash::testing {

inline std::string scratch_dir() {
  static const std::string dir = [] {
    const std::filesystem::path p =
        std::filesystem::path(::testing::TempDir()) / ("cadclash-test-" + std::to_string(::getpid()));
    std::filesystem::create_directories(p);
    return p.string();
  }();
  return dir;
}

// Writes `text` to `name` in the scratch folder and returns the file's path.
inline std::string write_scratch_file(const std::string& name, const std::string& text) {
  const std::string path = (std::filesystem::path(scratch_dir()) / name).string();
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

}  // namespace cadclash::testing
