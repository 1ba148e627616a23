// The glTF 2.0 binary container as cadclash writes and reads it. Internal.
//
// Layout of a cadclash .glb (asset.generator "cadclash <version>"):
// - one glTF mesh per part that has surfaces, one primitive (TRIANGLES) per surface, POSITION as
//   float32 part-local coordinates (what any viewer shows) and indices as uint32;
// - primitive extras.cadclash: the surface's name and provenance, and "positions_f64", the index of
//   a bufferView holding the same positions as float64, so our reader gets them back exactly;
// - one node per instance: name = instance path, mesh = its part's mesh, matrix = its pose
//   (column-major), extras.cadclash.part = part id; the scene lists every node;
// - root extras.cadclash: format version and the part table (name, source file, mesh or -1).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace cadclash::detail {

inline constexpr std::uint32_t kGlbMagic = 0x46546C67;      // "glTF"
inline constexpr std::uint32_t kGlbChunkJson = 0x4E4F534A;  // "JSON"
inline constexpr std::uint32_t kGlbChunkBin = 0x004E4942;   // "BIN\0"
inline constexpr int kCadclashGlbFormat = 1;
inline constexpr const char* kCadclashGenerator = "cadclash 0.1.0";

// The two chunks of a GLB file, as views into its bytes.
struct GlbChunks {
  std::string_view json;
  std::string_view bin;  // empty when the file has no BIN chunk
};

// Splits a GLB file into its chunks, checking the header and every length. Returns false with a
// one-sentence `error` when the bytes are not a well-formed GLB.
bool split_glb(std::string_view bytes, GlbChunks& chunks, std::string& error);

}  // namespace cadclash::detail
