// One file's import without its exact faces, as bytes and back (import.h, import_description): a
// cache entry's contents (save_import) and the file's FileImport.
#include "cadclash/internal/byte_io.h"
#include "import_cache.h"

#include <cassert>

namespace cadclash {

std::string import_description(const ImportResult& one_file) {
  const std::optional<std::string> model = detail::save_import(one_file, false);
  assert(model && "a B-rep part without a BrepSource");
  detail::ByteWriter w;
  w.str(model ? *model : std::string());
  w.u64(one_file.files.size());
  for (const FileImport& f : one_file.files) {
    w.str(f.path);
    w.u64(static_cast<std::uint64_t>(f.cache));
    const ImportTimings& t = f.timings;
    for (const double x : {t.read, t.transfer, t.heal, t.tessellate, t.total}) w.f64(x);
  }
  w.f64(one_file.seconds);
  return std::move(w.out);
}

bool import_from_description(std::string_view bytes, ImportResult& out, std::string& why) {
  detail::ByteReader r{bytes};
  const std::string model = r.str();
  if (!r.ok || !detail::load_import(model, out, why, true)) {
    if (r.ok) why = "the description's model: " + why;
    else why = "the description is cut short";
    return false;
  }
  out.files.resize(r.count(8 * 7));
  for (FileImport& f : out.files) {
    f.path = r.str();
    const std::uint64_t cache = r.u64();
    f.cache = cache <= static_cast<std::uint64_t>(CacheUse::Placements) ? static_cast<CacheUse>(cache) : CacheUse::Off;
    ImportTimings& t = f.timings;
    for (double* x : {&t.read, &t.transfer, &t.heal, &t.tessellate, &t.total}) *x = r.f64();
  }
  out.seconds = r.f64();
  if (!r.at_end()) {
    why = "the description is cut short or has bytes left over";
    return false;
  }
  return true;
}

}  // namespace cadclash
