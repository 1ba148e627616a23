// cadclash/testing/scenes.h — scenes of REAL CAD parts for truth tests (library cadclash::truth).
//
// Every scene is built from the sample files in data/external/ (scripts/setup.sh fetches them):
// as1-tu-203.stp (plate, L-brackets, bolts, nuts, rod), screw.step and linkrods.step. Poses are
// computed from the parts' exact geometry (BRepAdaptor_Surface planes and cylinders, face centroids,
// BRepExtrema for tangency); nothing is a hard-coded coordinate of a part.
//
// board_scene: the as1 plate is the board (identity pose). On its top face:
//   - nuts seated by one of their flat faces, coplanar with the top face (exact contact), at
//     stand-offs 0.005, 0.01, 0.02, 0.03 mm and sunk in by 0.001, 0.005, 0.01 mm, several turned
//     about the board normal by 17°, 29.5° or -33°;
//   - the linkrod (linkrods.step) seated on its two boss ends, sunk in by 0.005 mm, turned 29.5°;
//   - an L-bracket seated on its foot (exact contact) and one sunk in by 0.01 mm;
//   - a bolt lying on its side: its head cylinder (a B-spline surface) tangent to the top face;
//   - the screw (screw.step) lying on its side: its analytic cylinder tangent to the top face along
//     the shaft, its head beyond the board's edge;
//   - a bolt through one of the plate's holes (shaft coaxial with the hole, equal radius: a pin),
//     head seated on the top face, and a nut on its shaft seated against the plate's bottom face.
// Parts are spread over the board by a deterministic first-fit search so that no two of them (and
// no part and an unused hole) come within 1 mm: every designed relation is part–board only.
#pragma once

#include "cadclash/collide.h"

#include <string>
#include <vector>

namespace cadclash::truth {

// One placed instance and what the builder meant by it.
struct Placement {
  InstanceId instance = kInvalidId;
  std::string what;            // e.g. "nut face 4 on the board, stand-off 0.005 mm, turned 17 deg"
  InstanceId partner = kInvalidId;  // the instance the relation is with (the board, or the pin)
  double gap = 0.0;            // designed minimum distance to the partner (0 for contact and overlap)
  double overlap = 0.0;        // designed depth the part is sunk into the partner (0 when none)
};

struct BuiltScene {
  std::string name;
  Model model;
  std::vector<Placement> placements;     // board_scene and as1_moved only
  std::vector<Diagnostic> diagnostics;   // import problems; errors mean the scene is not usable
  bool ok() const;                       // a non-empty model and no error diagnostic
};

// `external_dir` is data/external. Parts are tessellated eagerly at `deflection` (mm).

// as1-tu-203.stp as read.
BuiltScene as1_scene(const std::string& external_dir, double deflection);

// A copy of `as1` (sharing its parts' exact geometry) where the instance `moved_path` is moved by
// `distance` mm away from `partner_path`, along the outward normal of the partner's planar face that
// is in exact contact with a planar face of the moved instance (found by exact distance). Positive:
// a gap opens there (and other contacts of the moved instance along that normal may close into
// overlaps). Sets placements[0] to the moved instance. Throws std::runtime_error when no such face
// pair exists.
BuiltScene as1_moved(const BuiltScene& as1, const std::string& moved_path, const std::string& partner_path,
                     double distance);

// Moves every instance by `distance` mm, each in its own direction fixed by its id (splitmix64 from
// seed 0x5EED0000 + id; the same in every run): exact contacts become small gaps and overlaps.
void jitter_instances(Model& model, double distance);

// The board scene described above.
BuiltScene board_scene(const std::string& external_dir, double deflection);

// Every instance pose premultiplied by `motion` (the whole scene moved rigidly).
void move_scene(Model& model, const Pose& motion);

// `copies` copies of `model`'s instances (sharing its parts) on a grid in the xy plane, so that
// copies stay `gap` mm apart; copy k's paths are "/copy<k>" + the original path, its instances
// [k·n, (k+1)·n) for n = model.instances.size(). Copy 0 is at the original place.
Model grid_copies(const Model& model, int copies, double gap);

}  // namespace cadclash::truth
