// What the import tests compare imports by: the whole result as bytes (the B-rep faces by their
// count) and a byte comparison that says where two differ. Shared by test_import_cache.cpp and
// test_import_parallel.cpp (one test program).
#pragma once

#include "cadclash/import.h"
#include "cadclash/report.h"
#include "import_cache.h"

#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <optional>
#include <vector>
#include <sstream>
#include <string>

namespace cadclash::testing_import {

inline std::string read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

inline void write_bytes(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
}

inline std::vector<std::string> messages(const ImportResult& r) {
  std::vector<std::string> out;
  for (const Diagnostic& d : r.diagnostics) out.push_back(format_diagnostic(d));
  return out;
}

// Every field of the result but the B-rep parts' exact faces, which stand in as their number: what the
// faces answer is compared through the reports of checks that query them (OCCT's binary format of a
// face read back can differ from the face it wrote in bookkeeping flags such as TShape::Orientable).
inline std::string everything(const ImportResult& r) {
  ImportResult plain;
  plain.diagnostics = r.diagnostics;
  plain.complete = r.complete;
  plain.model = r.model;
  for (Part& part : plain.model.parts) {
    if (const auto* brep = dynamic_cast<const BrepSource*>(part.source.get())) part.name += "/faces " + std::to_string(brep->face_count());
    part.source.reset();
  }
  const std::optional<std::string> bytes = detail::save_import(plain);
  EXPECT_TRUE(bytes.has_value());
  return bytes.value_or("");
}

// The report of a certified check of the whole model, without timings: what `cadclash check` writes.
inline std::string check_text(ImportResult r) {  // a copy: a scene tessellates lazy surfaces of its model
  Scene scene(r.model, SceneSelection{});
  CollideOptions options;
  options.tolerance = 1e-4;
  options.threads = 1;
  CheckReport report;
  report.query = query_report(r.model, scene.check(options));
  for (const Diagnostic& d : r.diagnostics) report.diagnostics.push_back(format_diagnostic(d));
  return check_report_text(report, {.timings = false});
}

// Equal bytes; on a difference, its offset and the sizes (not the bytes: they are binary).
inline ::testing::AssertionResult same_bytes(const std::string& a, const std::string& b) {
  if (a == b) return ::testing::AssertionSuccess();
  std::size_t at = 0;
  while (at < a.size() && at < b.size() && a[at] == b[at]) ++at;
  auto around = [at](const std::string& s) {
    std::ostringstream o;
    for (std::size_t k = at >= 24 ? at - 24 : 0; k < s.size() && k < at + 24; ++k) o << (k == at ? "[" : "") << int(static_cast<unsigned char>(s[k])) << (k == at ? "]" : "") << ' ';
    return o.str();
  };
  return ::testing::AssertionFailure() << "sizes " << a.size() << " and " << b.size() << ", first difference at byte " << at
                                       << ":\n  " << around(a) << "\n  " << around(b);
}

}  // namespace cadclash::testing_import
