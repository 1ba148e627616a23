#include "brep_face_cache.h"

#include <atomic>
#include <cassert>
#include <memory>
#include <optional>
#include <unordered_map>

namespace cadclash::detail {
namespace {

struct Entry {
  std::weak_ptr<const char> alive;  // the source's (BrepSource::Impl::alive)
  std::optional<BRepAdaptor_Surface> surface;
  const FaceLocator* locator = nullptr;
};

// An adaptor holds its face's shape, and with it the face's triangulation: a thread keeps at most
// this many, and lets go of those of sources that are gone every kSweep new entries (a model
// unloaded by an application that goes on checking others is not kept alive by the threads that
// checked it). A check meets a few hundred faces per thread.
constexpr std::size_t kMaxEntries = 1024;
constexpr std::size_t kSweep = 64;

Entry& entry(const BrepSource::Impl& source, std::uint32_t local_index) {
  thread_local std::unordered_map<std::uint64_t, std::unique_ptr<Entry>> cache;
  thread_local std::size_t added = 0;
  assert(source.id < (std::uint64_t{1} << 32));
  const std::uint64_t key = (source.id << 32) | local_index;
  auto it = cache.find(key);
  if (it != cache.end()) return *it->second;
  if (++added % kSweep == 0) std::erase_if(cache, [](const auto& kv) { return kv.second->alive.expired(); });
  if (cache.size() >= kMaxEntries) cache.clear();
  auto e = std::make_unique<Entry>();
  e->alive = source.alive;
  return *cache.emplace(key, std::move(e)).first->second;
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
