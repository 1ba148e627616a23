// Poses recomputed from a STEP file's numbers. An assembly whose file changed only in the points
// and directions of its occurrences' placements (each NEXT_ASSEMBLY_USAGE_OCCURRENCE placed by an
// ITEM_DEFINED_TRANSFORMATION between two AXIS2_PLACEMENT_3D) is the model read before with other
// poses: the import cache (import_cache.h) keeps, per file, what the transfer made of the placements
// and computes the new poses with OCCT's own steps (StepToGeom's axis placement, gp_Trsf,
// TopLoc_Location), after checking that they give every pose of the file they were taken from bit
// for bit. Internal to cadclash::import.
#pragma once

#include "cad_xcaf.h"

#include "cadclash/internal/byte_io.h"

#include <TDocStd_Document.hxx>
#include <Transfer_TransientProcess.hxx>
#include <XCAFDoc_DataMapOfShapeLabel.hxx>

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

namespace cadclash::detail {

// An AXIS2_PLACEMENT_3D by its #id and those of its point and directions (-1: not given).
struct AxisIds {
  std::int64_t id = -1, location = -1, axis = -1, ref = -1;
};

// One XCAF component (an occurrence) placed by an item-defined transformation: OCCT's STEP reader
// moves the occurrence's shape by the transformation from `origin` to `target` (after its own swap
// of axes given in the wrong order), or by its inverse when the relationship runs against the
// occurrence (`inverted`).
struct ComponentPlacement {
  std::string label;  // the component's label entry in the XCAF document ("0:1:1:2:3")
  AxisIds origin, target;
  bool inverted = false;
};

// Every occurrence of the transferred file with its component and placement; nullopt when one is
// placed otherwise (a Cartesian transformation operator, no transformation, several shape
// relationships), its component cannot be found, or two share a component.
// `shapes`: the reader's shapes and their labels (STEPCAFControl_Reader::GetShapeLabelMap).
// Precondition: `process` transferred the products into `doc`.
std::optional<std::vector<ComponentPlacement>> component_placements(const Handle(TDocStd_Document)& doc,
                                                                    const Handle(Transfer_TransientProcess)& process,
                                                                    const XCAFDoc_DataMapOfShapeLabel& shapes,
                                                                    const EntityLabelFn& label);

void write_component_placements(ByteWriter& w, const std::optional<std::vector<ComponentPlacement>>& c);
// False when the bytes are not whole.
bool read_component_placements(ByteReader& r, std::optional<std::vector<ComponentPlacement>>& c);

// A file's placements: its components and, per instance of the file (in the model's order), the
// components from the root down to it (indices into `components`).
struct Placements {
  std::vector<ComponentPlacement> components;
  std::vector<std::vector<std::uint32_t>> chains;
  // The locations as the XCAF document's binary format reads them back (the isolated reader's child
  // places its instances so: walk_xcaf_document), not as the reader made them.
  bool stored = true;

  std::vector<std::int64_t> value_ids() const;  // the points and directions of every axis, ascending
  std::vector<std::int64_t> axis_ids() const;   // the axes, ascending
};

// The recipe of a file whose walk gave `chains` (per instance, the component label entries from
// the root down; walk_xcaf_document); nullopt when a component has no placement in `placed`.
std::optional<Placements> file_placements(const std::vector<ComponentPlacement>& placed,
                                          const std::vector<std::vector<std::string>>& chains);

std::string save_placements(const Placements& p);
bool load_placements(std::string_view bytes, Placements& p);

using PlacementValues = std::unordered_map<std::int64_t, std::array<double, 3>>;

// Each instance's pose from `values` (every value_ids() entry), as the STEP reader and the assembly
// walk would make it; nullopt when a pose has a scale or lies outside the supported range (which
// the walk warns about or drops) or a value is missing.
std::optional<std::vector<Pose>> placement_poses(const Placements& p, const PlacementValues& values);

// The statements `ids` of a STEP file's text (each a CARTESIAN_POINT or DIRECTION of a name and
// three numbers): their numbers, and a SHA-256 (hex) of the text with the numbers of `free` (a
// subset of `ids`) left out. nullopt when the text cannot be scanned (for_each_statement) or one of
// `ids` is missing or not such a statement.
struct PlacementText {
  std::string skeleton;
  PlacementValues values;
};
std::optional<PlacementText> placement_text(std::string_view text, std::span<const std::int64_t> ids,
                                            std::span<const std::int64_t> free);

// placement_text, in the same one pass finding `free`: those of `ids` that place occurrences and
// nothing else (referenced only by the axes `axes`, each referenced only by
// ITEM_DEFINED_TRANSFORMATIONs and shape representations, whose transfer skips an axis an
// item-defined transformation uses), ascending. Precondition: axes not empty.
struct FreePlacementText {
  std::vector<std::int64_t> free;
  PlacementText text;
};
std::optional<FreePlacementText> free_placement_text(std::string_view text, std::span<const std::int64_t> ids,
                                                     std::span<const std::int64_t> axes);

}  // namespace cadclash::detail
