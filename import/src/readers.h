// Per-format readers behind import_file(). Internal to cadclash::import.
#pragma once

#include "cadclash/import.h"

namespace cadclash::detail {

ImportResult read_obj(const std::string& path, const ImportOptions& options);
ImportResult read_off(const std::string& path, const ImportOptions& options);
ImportResult read_assimp_mesh(const std::string& path, const ImportOptions& options);  // stl, ply, gltf, glb, ...
ImportResult read_cadclash_glb(const std::string& path, const ImportOptions& options);  // our own .glb, exact round trip
// `text`, when given, is the file's bytes as the caller read them: scanned and cut instead of the
// file read again (OCCT still opens the file itself when it parses it whole).
ImportResult read_step(const std::string& path, const ImportOptions& options, const std::string* text = nullptr);
// Fault injection for the tests of the isolated reader: the STEP reader raises SIGSEGV when it
// transfers face entity #face_id on its own (loose faces); -1 turns it off.
void set_step_crash_injection_for_testing(std::int64_t face_id);
// The same, but the reader hangs there (until the time limit kills it). Only with isolation.
void set_step_hang_injection_for_testing(std::int64_t face_id);
ImportResult read_iges(const std::string& path, const ImportOptions& options);
ImportResult read_brep(const std::string& path, const ImportOptions& options);

// Returns true if `path` is a .glb that cadclash wrote (asset.generator starts with "cadclash").
bool is_cadclash_glb(const std::string& path);

// An ImportResult holding only an error about `path`.
ImportResult failed_import(const std::string& path, std::string message);

}  // namespace cadclash::detail
