// The bad-input catalogue of issue 7: every row of data/bad/CATALOGUE.tsv is run through
// `cadclash info` (and `info --json`) and must end with the listed exit code and message, without a
// crash, a hang or a lost surface count.
#include <gtest/gtest.h>
#include "cli_runner.h"
#include <nlohmann/json.hpp>

#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <sys/wait.h>
#include <unistd.h>
#include <vector>

namespace {

struct Row {
  std::string file, stderr_part, description;
  int exit_code = -1;
  int kept = -1;
  int line = 0;  // in CATALOGUE.tsv
};

std::vector<Row> load_catalogue() {
  const std::string path = std::string(CADCLASH_DATA_DIR) + "/bad/CATALOGUE.tsv";
  std::ifstream in(path);
  std::vector<Row> rows;
  std::string text;
  bool header = true;
  for (int line = 1; std::getline(in, text); ++line) {
    if (text.empty() || text[0] == '#') continue;
    if (header) {  // the column names
      header = false;
      continue;
    }
    std::vector<std::string> cols;
    std::stringstream ss(text);
    for (std::string col; std::getline(ss, col, '\t');) cols.push_back(col);
    if (cols.size() != 5) {
      ADD_FAILURE() << path << ":" << line << ": expected 5 tab-separated columns, found " << cols.size();
      continue;
    }
    Row r;
    r.file = cols[0];
    r.exit_code = std::stoi(cols[1]);
    r.stderr_part = cols[2];
    r.kept = std::stoi(cols[3]);
    r.description = cols[4];
    r.line = line;
    rows.push_back(r);
  }
  return rows;
}

using cadclash::testing::CliRun;
using cadclash::testing::slurp;
CliRun cadclash(const std::string& args) { return cadclash::testing::run_cadclash(args); }

// The path a row names; '@' rows are made here. Empty if the row cannot run in this environment.
std::string prepare(const Row& row, std::string& skip_reason) {
  const std::string dir = cadclash::testing::scratch_dir();
  if (row.file == "@directory.obj") {
    const std::string p = dir + "/directory.obj";
    std::filesystem::create_directories(p);
    return p;
  }
  if (row.file == "@unreadable.obj") {
    if (::geteuid() == 0) {
      skip_reason = "running as root, which can read a mode-000 file";
      return "";
    }
    const std::string p = dir + "/unreadable.obj";
    std::filesystem::remove(p);
    std::filesystem::copy_file(std::string(CADCLASH_DATA_DIR) + "/bad/truncated.obj", p);
    std::filesystem::permissions(p, std::filesystem::perms::none);
    return p;
  }
  return std::string(CADCLASH_DATA_DIR) + "/bad/" + row.file;
}

int kept_surfaces(const std::string& json_text) {
  const nlohmann::json j = nlohmann::json::parse(json_text);
  int n = 0;
  if (j.contains("parts"))
    for (const auto& p : j.at("parts")) n += static_cast<int>(p.at("surfaces").size());
  return n;
}

class BadCatalogue : public ::testing::TestWithParam<Row> {};

TEST(BadCatalogueManifest, HasAtLeastThirtyCasesAndEveryFileExists) {
  const std::vector<Row> rows = load_catalogue();
  EXPECT_GE(rows.size(), 30u);
  for (const Row& r : rows) {
    EXPECT_TRUE(r.exit_code == 0 || r.exit_code == 1 || r.exit_code == 2) << "CATALOGUE.tsv:" << r.line;
    if (r.file[0] != '@') {
      EXPECT_TRUE(std::filesystem::is_regular_file(std::string(CADCLASH_DATA_DIR) + "/bad/" + r.file))
          << "CATALOGUE.tsv:" << r.line << ": " << r.file;
    }
  }
}

TEST_P(BadCatalogue, ExitCodeMessageAndKeptSurfaces) {
  const Row& row = GetParam();
  SCOPED_TRACE("CATALOGUE.tsv:" + std::to_string(row.line) + ": " + row.file + " (" + row.description + ")");
  std::string skip_reason;
  const std::string path = prepare(row, skip_reason);
  if (path.empty()) GTEST_SKIP() << row.file << " skipped: " << skip_reason;

  const CliRun text = cadclash("info '" + path + "'");
  ASSERT_NE(text.code, 124) << "timed out after 60 s (a hang)";
  ASSERT_EQ(text.signal, 0) << "crashed with signal " << text.signal << "\n" << text.err;
  EXPECT_TRUE(text.code == 0 || text.code == 1 || text.code == 2) << "exit code " << text.code;
  EXPECT_EQ(text.code, row.exit_code) << text.err;
  if (row.stderr_part == "-") {
    EXPECT_EQ(text.err, "");
  } else {
    EXPECT_NE(text.err.find(row.stderr_part), std::string::npos) << "stderr:\n" << text.err;
  }

  const CliRun json = cadclash("info --json '" + path + "'");
  ASSERT_NE(json.code, 124) << "info --json timed out after 60 s (a hang)";
  ASSERT_EQ(json.signal, 0) << "info --json crashed with signal " << json.signal << "\n" << json.err;
  EXPECT_EQ(json.code, row.exit_code) << json.err;
  int kept = -1;
  EXPECT_NO_THROW(kept = kept_surfaces(json.out)) << json.out.substr(0, 400);
  EXPECT_EQ(kept, row.kept);
}

std::string row_name(const ::testing::TestParamInfo<Row>& info) {
  std::string name;
  for (const char c : info.param.file) name += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
  return std::to_string(info.index) + "_" + name;
}

INSTANTIATE_TEST_SUITE_P(Rows, BadCatalogue, ::testing::ValuesIn(load_catalogue()), row_name);

}  // namespace
