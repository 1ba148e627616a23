// cadclash/glb_layout.h — the glTF 2.0 binary container as cadclash writes and reads it.
//
// cadclash::export writes this layout (export_model, cadclash/export.h) and cadclash::import reads it
// back exactly (import_file on a .glb). It lives here, beside the provenance JSON the primitives'
// extras hold (cadclash/report.h), so that the writer and the reader share one definition without
// either module depending on the other. Constants only; nothing to link.
//
// Layout of a cadclash .glb (asset.generator kCadclashGenerator):
// - the JSON chunk starts with {"asset":...}, so a reader recognises the file from its first bytes,
//   even when it was cut short;
// - one glTF mesh per part that has surfaces, one primitive (TRIANGLES) per surface, POSITION as
//   float32 part-local coordinates (what any viewer shows) and indices as uint32;
// - primitive extras.cadclash: the surface's name and provenance, and "positions_f64", the index of
//   a bufferView holding the same positions as float64, so our reader gets them back exactly;
// - one node per instance: name = instance path, mesh = its part's mesh, matrix = its pose
//   (column-major), extras.cadclash.part = part id; the scene lists every node;
// - root extras.cadclash: format version (kCadclashGlbFormat) and the part table (name, source
//   file, mesh or -1).
#pragma once

#include <cstdint>

namespace cadclash {

// The GLB container (glTF 2.0 spec): file magic and chunk types, little-endian.
inline constexpr std::uint32_t kGlbMagic = 0x46546C67;      // "glTF"
inline constexpr std::uint32_t kGlbChunkJson = 0x4E4F534A;  // "JSON"
inline constexpr std::uint32_t kGlbChunkBin = 0x004E4942;   // "BIN\0"
// Bumped whenever the layout above changes in a way an older reader would misread.
inline constexpr int kCadclashGlbFormat = 1;
// asset.generator; a reader takes a .glb whose generator starts with "cadclash" for one of ours.
inline constexpr const char* kCadclashGenerator = "cadclash 0.1.0";

}  // namespace cadclash
