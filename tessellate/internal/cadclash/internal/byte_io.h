// cadclash/internal/byte_io.h — plain little binary records (native-endian 64-bit integers, doubles
// by their bits, strings as a length and the bytes): a stored B-rep part (save_brep_source), what the
// isolated reader's child sends back (import's cad_transfer.h) and what an import cache entry holds
// (import_cache.h). Internal to cadclash, shared by tessellate and import (their CMakeLists add
// tessellate/internal to their private include path); not installed, not API. Changing a layout here
// changes the bytes of cache entries: bump the cache format version (import_cache.cpp) and the
// stored B-rep part's magic (brep_store.cpp).
#pragma once

#include "cadclash/model.h"

#include <bit>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

namespace cadclash::detail {

struct ByteWriter {
  std::string out;
  void u64(std::uint64_t v) { out.append(reinterpret_cast<const char*>(&v), sizeof v); }
  void i64(std::int64_t v) { u64(static_cast<std::uint64_t>(v)); }
  void f64(double v) { u64(std::bit_cast<std::uint64_t>(v)); }
  void str(std::string_view s) {
    u64(s.size());
    out += s;
  }
};

// Every read past the end (or of a length the rest cannot hold) clears `ok` and returns zero/empty.
struct ByteReader {
  std::string_view in;
  std::size_t at = 0;
  bool ok = true;
  std::uint64_t u64() {
    std::uint64_t v = 0;
    if (in.size() - at < sizeof v) {
      ok = false;
      return 0;
    }
    std::memcpy(&v, in.data() + at, sizeof v);
    at += sizeof v;
    return v;
  }
  std::int64_t i64() { return static_cast<std::int64_t>(u64()); }
  double f64() { return std::bit_cast<double>(u64()); }
  std::string str() {
    const std::uint64_t n = u64();
    if (!ok || in.size() - at < n) {
      ok = false;
      return {};
    }
    std::string s(in.substr(at, n));
    at += n;
    return s;
  }
  // A count of items of at least `item_bytes` bytes each; 0 (and !ok) when the rest cannot hold them.
  std::uint64_t count(std::size_t item_bytes) {
    const std::uint64_t n = u64();
    if (ok && n > (in.size() - at) / item_bytes) ok = false;
    return ok ? n : 0;
  }
  bool at_end() const { return ok && at == in.size(); }
};

// Diagnostics as the stored records hold them: a count, then per diagnostic its severity, file,
// line, STEP #id and message (at least 40 bytes each).
inline void write_diagnostics(ByteWriter& w, const std::vector<Diagnostic>& ds) {
  w.u64(ds.size());
  for (const Diagnostic& d : ds) {
    w.u64(static_cast<std::uint64_t>(d.severity));
    w.str(d.file);
    w.i64(d.line);
    w.i64(d.step_id);
    w.str(d.message);
  }
}
inline std::vector<Diagnostic> read_diagnostics(ByteReader& r) {
  std::vector<Diagnostic> ds(r.count(40));
  for (Diagnostic& d : ds) {
    d.severity = r.u64() == 0 ? Severity::Warning : Severity::Error;
    d.file = r.str();
    d.line = r.i64();
    d.step_id = r.i64();
    d.message = r.str();
  }
  return ds;
}

}  // namespace cadclash::detail
