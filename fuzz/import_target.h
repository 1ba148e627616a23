// The body shared by the reader fuzzers: the input bytes become a file, import_file reads it, and
// the result is checked against the contract of cadclash/import.h.
#pragma once

#include <cstddef>
#include <cstdint>

namespace cadclash::fuzz {

// Writes `data` to a scratch file of this process ending in `extension` (".obj"), imports it and
// aborts when the result breaks a promise of import.h that the sanitizers cannot see:
// - every triangle index is in range and every vertex is finite;
// - an empty model comes with an error diagnostic;
// - every diagnostic names the file, and its message is valid UTF-8 (the JSON report needs it);
// - no exception escapes import_file.
void import_bytes(const std::uint8_t* data, std::size_t size, const char* extension);

}  // namespace cadclash::fuzz
