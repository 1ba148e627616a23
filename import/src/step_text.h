// Checks and corrections of a STEP file's text, made before OCCT parses it: OCCT reads some damage
// without a word (a context without a length unit) or is led by it into a crash (a reference to an
// entity the file does not define). Internal to cadclash::import.
#pragma once

#include "cadclash/collide.h"

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace cadclash::detail {

// One error per FILE_SCHEMA name of the header that is not an AP203/AP214/AP242 schema, on the
// header line that names it: OCCT reads such a file as AP214 anyway.
std::vector<Diagnostic> unknown_schemas(const std::string& text, const std::string& path);

// A truncated file cut back to its last complete entity and closed properly, with the line of the
// cut; nullopt when the file is not truncated (it ends with END-ISO-10303-21).
std::optional<std::pair<std::string, std::int64_t>> close_truncated(const std::string& source);

// References to entities the file does not define, replaced by '$' (unset) in a copy of the text.
// OCCT may bind such a reference to an unrelated entity instead of leaving it null: a cut-up file
// whose ORIENTED_EDGE named a vanished edge got itself as its edge and OCCT's own load check
// (RWStepShape_RWEdgeLoop::Check) recursed until the stack overflowed (fuzz_step). Unset, the
// parameter is reported by OCCT as missing and the entity is left out as for any bad parameter.
// Returns nullopt when every reference resolves.
struct UnsetReferences {
  std::string text;
  std::vector<Diagnostic> diagnostics;
};
std::optional<UnsetReferences> unset_undefined_references(const std::string& text, const std::string& path);

// Representation contexts without a usable length unit, as diagnostics naming the context's #id.
// OCCT knows the complex context entity only with its GLOBAL_UNIT_ASSIGNED_CONTEXT, so without one it
// drops the entity and reports only that the representations using it have an "illegal type"
// parameter (an error); with a unit list that holds no LENGTH_UNIT it says nothing and reads the
// lengths as millimetres (a warning).
std::vector<Diagnostic> unit_context_problems(const std::string& text, const std::string& path);

}  // namespace cadclash::detail
