// Which rank reads which input file (distributed.h, "Files read where they are needed").
#include "cadclash/distributed.h"

#include <algorithm>
#include <cassert>
#include <numeric>

namespace cadclash {

std::vector<int> assign_readers(std::span<const std::uint64_t> file_bytes, int ranks) {
  assert(ranks >= 1);
  std::vector<std::size_t> order(file_bytes.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return file_bytes[a] > file_bytes[b]; });
  std::vector<std::uint64_t> load(static_cast<std::size_t>(ranks), 0);
  std::vector<int> reader(file_bytes.size(), 0);
  for (std::size_t f : order) {
    const auto least = std::min_element(load.begin(), load.end());
    reader[f] = static_cast<int>(least - load.begin());
    // A file of 0 bytes (empty, or not there on rank 0) still costs a reader a look.
    *least += std::max<std::uint64_t>(file_bytes[f], 1);
  }
  return reader;
}

}  // namespace cadclash
