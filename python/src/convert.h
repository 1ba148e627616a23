// Conversions between cadclash's C++ values and plain Python / NumPy values.
#pragma once

#include "state.h"

#include "cadclash/report.h"

#include <pybind11/numpy.h>

#include <span>

namespace cadclash::py {

// A new 4x4 float64 array (row-major) holding the pose's homogeneous matrix.
pyb::array_t<double> pose_to_array(const Pose& pose);

// A rigid pose from a 4x4 array-like. Raises ValueError unless it is 4x4, finite, its last row is
// (0, 0, 0, 1) and its upper-left 3x3 is a rotation (orthonormal within 1e-6, determinant +1).
Pose pose_from_matrix(const pyb::handle& matrix);

// A pose from a translation (tx, ty, tz) and a quaternion (qw, qx, qy, qz), normalised like a
// trajectory row. Raises ValueError for non-finite values or a zero quaternion.
Pose pose_from_translation_quaternion(const pyb::handle& translation, const pyb::handle& quaternion);

// (severity "error"|"warning", file, line, step_id, message, formatted) per diagnostic.
pyb::list diagnostics_to_list(std::span<const Diagnostic> ds);

// (pairs, counters, timings, diagnostics, complete, stopped_by, unexamined_pairs [(a, b)],
//  memory_charged, record) with each pair as
// (instance_a, instance_b, surface_a|-1, surface_b|-1, class, intersecting, distance, penetration,
//  exact_distance|None, triangle_pairs (k x 2 uint32 array), decided_by, distance_lo, distance_hi,
//  contact_within|None),
// and `record` the same query as the JSON report holds it (query_report(model, report), made under
// the model's lock: surface deflections change when a running query tessellates).
// Builds Python objects: needs the GIL.
pyb::tuple report_to_tuple(const Report& report, QueryReport record);

// {name: value} of the counters / timings (kCounterFields, kTimingFields).
pyb::dict counters_to_dict(const CollideCounters& c);
pyb::dict timings_to_dict(const CollideTimings& t);
// {triangles, vertices, hierarchies, instances, triangle_count}: bytes per component of SceneMemory.
pyb::dict model_memory_to_dict(const SceneMemory& m);

// contact_within_name(w), None for ContactWithin::Unknown.
pyb::object within_or_none(ContactWithin w);

// A k x 2 uint32 array (a copy) of triangle index pairs.
pyb::array_t<std::uint32_t> triangle_pairs_array(const std::vector<std::array<std::uint32_t, 2>>& pairs);

}  // namespace cadclash::py
