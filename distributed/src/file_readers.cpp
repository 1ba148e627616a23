// Which rank reads which input file (distributed.h, "Files read where they are needed").
#include "cadclash/distributed.h"

#include <algorithm>
#include <cassert>

namespace cadclash {

std::vector<int> assign_readers(std::span<const std::uint64_t> file_bytes, int ranks) {
  assert(ranks >= 1);
  // A file of 0 bytes (empty, or not there on rank 0) still costs its reader a look.
  auto weight = [](std::uint64_t b) { return static_cast<long double>(std::max<std::uint64_t>(b, 1)); };
  long double total = 0.0L;
  for (const std::uint64_t b : file_bytes) total += weight(b);
  std::vector<int> reader(file_bytes.size(), 0);
  long double before = 0.0L;
  for (std::size_t f = 0; f < file_bytes.size(); ++f) {
    const long double middle = before + 0.5L * weight(file_bytes[f]);
    reader[f] = std::min(ranks - 1, static_cast<int>(middle * ranks / total));
    before += weight(file_bytes[f]);
  }
  return reader;
}

}  // namespace cadclash
