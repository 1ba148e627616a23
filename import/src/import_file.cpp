// Dispatch by extension, and the multi-file scene.
#include "import_cache.h"
#include "isolated_run.h"
#include "readers.h"

#include <omp.h>

#include <algorithm>
#include <cassert>
#include <cctype>
#include <chrono>
#include <exception>
#include <filesystem>
#include <mutex>
#include <system_error>

#if defined(__SANITIZE_ADDRESS__)
#define CADCLASH_ASAN_RUNTIME 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define CADCLASH_ASAN_RUNTIME 1
#endif
#endif
#ifndef CADCLASH_ASAN_RUNTIME
#define CADCLASH_ASAN_RUNTIME 0
#endif

namespace cadclash {
namespace detail {

ImportResult failed_import(const std::string& path, std::string message) {
  ImportResult r;
  r.complete = false;
  r.diagnostics.push_back({Severity::Error, path, 0, -1, std::move(message)});
  return r;
}

}  // namespace detail

namespace {

std::string lower_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

}  // namespace

namespace {

// `text`, when given, is the file's bytes as the caller read them (a STEP reader scans them instead
// of reading the file again).
ImportResult read_any(const std::string& path, const ImportOptions& options, const std::string* text);

}  // namespace

const char* cache_use_name(CacheUse c) {
  switch (c) {
    case CacheUse::Off: return "off";
    case CacheUse::Hit: return "hit";
    case CacheUse::Miss: return "miss";
    case CacheUse::Rebuilt: return "rebuilt";
    case CacheUse::Placements: return "placements";
  }
  return "off";
}

namespace {

// One file, without its ReadFile progress; `options.tessellation.progress` gets its parts' meshing.
ImportResult import_one(const std::string& path, const ImportOptions& options) {
  assert(options.model_tolerance >= 0.0);
  assert(options.uncertainty != UncertaintyChoice::Value || options.uncertainty_value > 0.0);
  const auto start = std::chrono::steady_clock::now();
  const detail::CadWork occt_in_this_process;
  auto read = [&](const std::string* text) {
    const auto read_start = std::chrono::steady_clock::now();
    ImportResult r = read_any(path, options, text);
    for (Surface& s : r.model.surfaces) {
      const bool brep = r.model.parts[s.part].source != nullptr;
      if (options.uncertainty == UncertaintyChoice::Value) {
        if (brep && s.uncertainty > options.uncertainty_value) continue;  // its OCCT tolerance stands
        s.uncertainty = options.uncertainty_value;
        s.uncertainty_source = UncertaintySource::Given;
      } else if (options.model_tolerance > 0.0 && !brep) {
        s.uncertainty = options.model_tolerance;
        s.uncertainty_source = UncertaintySource::Given;
      }
    }
    if (r.files.empty()) {  // a mesh file, or a CAD file that could not be opened: reading is all
      r.files.emplace_back().path = path;
      r.files.back().timings.read = std::chrono::duration<double>(std::chrono::steady_clock::now() - read_start).count();
    }
    return r;
  };
  ImportResult r = options.cache_dir.empty() ? read(nullptr) : detail::cached_import(path, options, read);
  ImportTimings& t = r.files.front().timings;
  t.total = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  t.transfer = std::max(0.0, t.total - t.read - t.heal - t.tessellate);
  r.seconds = t.total;
  return r;
}

// The options a file is read with: the tessellation reports to `parts` (import ignores the caller's
// tessellation.progress: ImportOptions::progress gets every stage).
ImportOptions with_part_progress(const ImportOptions& options, ProgressCallback parts) {
  ImportOptions o = options;
  o.tessellation.progress = std::move(parts);
  return o;
}

}  // namespace

ImportResult import_file(const std::string& path, const ImportOptions& options) {
  if (!options.progress) return import_one(path, with_part_progress(options, nullptr));
  options.progress(Progress{ProgressStage::ReadFile, 0, 1, path});
  ImportResult r = import_one(path, with_part_progress(options, options.progress));
  options.progress(Progress{ProgressStage::ReadFile, 1, 1, path});
  return r;
}

namespace {

ImportResult read_any(const std::string& path, const ImportOptions& options, const std::string* text) {
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(status)) return detail::failed_import(path, "no such file");
  if (std::filesystem::is_directory(status)) return detail::failed_import(path, "is a directory, not a file");

  const std::string ext = lower_extension(path);
  if (ext == ".stp" || ext == ".step") return detail::read_step(path, options, text);
  if (ext == ".igs" || ext == ".iges") return detail::read_iges(path, options);
  if (ext == ".brep" || ext == ".rle") return detail::read_brep(path, options);
  if (ext == ".obj") return detail::read_obj(path, options);
  if (ext == ".off") return detail::read_off(path, options);
  if (ext == ".glb" && detail::is_cadclash_glb(path)) return detail::read_cadclash_glb(path, options);
  return detail::read_assimp_mesh(path, options);
}

}  // namespace

std::vector<ImportResult> import_each_file(std::span<const std::string> paths, const ImportOptions& options) {
  std::vector<ImportResult> each(paths.size());
  if (paths.size() == 1) {
    each.front() = import_file(paths.front(), options);
    return each;
  }
  std::vector<std::exception_ptr> failed(paths.size());
  int threads = options.parallel_files > 0 ? options.parallel_files : omp_get_max_threads();
#if CADCLASH_ASAN_RUNTIME
  // clang-14's AddressSanitizer runtime does not make its own locks safe across fork: a child forked
  // while another thread of this process is inside the runtime (starting a thread, allocating) can
  // inherit a held lock and hang (seen once in the sanitizer pass: an isolated STEP reader that never
  // finished while a mesh file was read beside it). Sanitizer builds read files one after another;
  // Release builds (glibc's fork-safe allocator) read them in parallel.
  threads = 1;
#endif
  // Progress from the threads reading files, one call at a time: each file as it starts and ends
  // (ReadFile, done = files finished), its parts as they are meshed (TessellatePart).
  std::mutex progress_lock;
  std::size_t finished = 0;
  auto file_progress = [&](const std::string& path, bool ended) {
    if (!options.progress) return;
    const std::lock_guard<std::mutex> hold(progress_lock);
    finished += ended ? 1 : 0;
    options.progress(Progress{ProgressStage::ReadFile, finished, paths.size(), path});
  };
  ProgressCallback part_progress;
  if (options.progress)
    part_progress = [&](const Progress& p) {
      const std::lock_guard<std::mutex> hold(progress_lock);
      options.progress(p);
    };
  const ImportOptions file_options = with_part_progress(options, part_progress);
  // One file per thread at a time; OpenMP regions inside a file's import then run on that thread.
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads) if (threads > 1)
  for (std::ptrdiff_t k = 0; k < static_cast<std::ptrdiff_t>(paths.size()); ++k) {
    const auto i = static_cast<std::size_t>(k);
    try {
      file_progress(paths[i], false);
      each[i] = import_one(paths[i], file_options);
      file_progress(paths[i], true);
    } catch (...) {
      failed[i] = std::current_exception();  // bad_alloc and the like: thrown again below
    }
  }
  for (const std::exception_ptr& e : failed)
    if (e) std::rethrow_exception(e);
  return each;
}

ImportResult merge_file_imports(std::span<const std::string> paths, std::vector<ImportResult> each) {
  assert(each.size() == paths.size());
  if (paths.size() == 1) return std::move(each.front());
  ImportResult all;
  for (std::size_t i = 0; i < paths.size(); ++i) {
    ImportResult& one = each[i];
    std::string prefix = "/";  // built in two steps: GCC 12 warns falsely (-Wrestrict) on "/" + string
    prefix += std::filesystem::path(paths[i]).filename().string();
    append_model(all.model, std::move(one.model), prefix);
    all.diagnostics.insert(all.diagnostics.end(), one.diagnostics.begin(), one.diagnostics.end());
    all.complete = all.complete && one.complete;
    all.files.insert(all.files.end(), one.files.begin(), one.files.end());
    all.seconds = std::max(all.seconds, one.seconds);
  }
  return all;
}

ImportResult import_files(std::span<const std::string> paths, const ImportOptions& options) {
  if (paths.size() == 1) return import_file(paths.front(), options);
  const auto start = std::chrono::steady_clock::now();
  ImportResult all = merge_file_imports(paths, import_each_file(paths, options));
  all.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return all;
}

}  // namespace cadclash
