// A check of some instance pairs only and, of each, some of its surface pairs: what check_motion
// runs on the parts of a stretch it halves, where only a few pairs are still open. Each examined
// pair gets the result Scene::check gives it (a pair's decision depends on that pair alone); the
// others are not examined. Internal to cadclash::collide.
#pragma once

#include "scene_data.h"

namespace cadclash::detail {

// Scene::check(o) restricted to `only` (its instance pairs that the broad phase finds, and of each
// the surface pairs it names that the surface level finds; their containment as check() tests it),
// without the depth step: a contact it would prove penetrating is reported touching.
// `only` null: every pair, as check() (but the depth step).
Report restricted_check(Scene& scene, const CollideOptions& o, const CheckRestriction* only);

}  // namespace cadclash::detail
