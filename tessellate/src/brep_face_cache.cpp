#include "brep_face_cache.h"

#include <atomic>
#include <cassert>
#include <memory>
#include <optional>
#include <unordered_map>

namespace cadclash::detail {
namespace {

struct Entry {
  std::optional<BRepAdaptor_Surface> surface;
  const FaceLocator* locator = nullptr;
};

// Bounds what a thread keeps (each entry holds its face's geometry alive): past this many faces the
// cache starts again. A check meets a few hundred faces at most per thread.
constexpr std::size_t kMaxEntries = 4096;

Entry& entry(const BrepSource::Impl& source, std::uint32_t local_index) {
  thread_local std::unordered_map<std::uint64_t, std::unique_ptr<Entry>> cache;
  assert(source.id < (std::uint64_t{1} << 32));
  const std::uint64_t key = (source.id << 32) | local_index;
  auto it = cache.find(key);
  if (it != cache.end()) return *it->second;
  if (cache.size() >= kMaxEntries) cache.clear();
  return *cache.emplace(key, std::make_unique<Entry>()).first->second;
}

}  // namespace

std::uint64_t next_source_id() {
  static std::atomic<std::uint64_t> next{0};
  return next.fetch_add(1, std::memory_order_relaxed);
}

const BRepAdaptor_Surface& face_surface(const BrepSource::Impl& source, std::uint32_t local_index) {
  assert(local_index < source.faces.size());
  Entry& e = entry(source, local_index);
  if (!e.surface) e.surface.emplace(source.faces[local_index], Standard_False);
  return *e.surface;
}

const FaceLocator& face_locator(const BrepSource::Impl& source, std::uint32_t local_index) {
  assert(local_index < source.faces.size());
  Entry& e = entry(source, local_index);
  if (e.locator == nullptr) e.locator = &source.locator(local_index);
  return *e.locator;
}

}  // namespace cadclash::detail
