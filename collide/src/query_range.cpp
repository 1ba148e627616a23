// The supported range (model.h): a query whose lengths could overflow the float steps is refused
// with errors rather than answered.
#include "scene_stages.h"

#include <cmath>
#include <cstdio>

namespace cadclash::detail {
namespace {

constexpr std::size_t kListed = 16;

std::string length_text(double x) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6g", x);
  return buf;
}

const std::string kRange = "outside the supported range (magnitude <= 2^128, about 3.4e38 mm)";

}  // namespace

namespace {

// Why instance `i` is outside the supported range; empty when it is not.
std::string instance_outside(const SceneData& s, InstanceId i) {
  const Instance& inst = s.model.instances[i];
  if (!(s.part_length[inst.part] <= kMaxLength))
    return "its part '" + s.model.parts[inst.part].name + "' has a coordinate, deflection or uncertainty " + kRange;
  const Pose& pose = s.poses[i];
  const Vec3 t = pose.translation();
  for (int k = 0; k < 3; ++k)
    if (!in_supported_range(t[k])) return "its pose translates by " + length_text(t[k]) + " mm, " + kRange;
  // A rotation's entries are at most 1; anything else is no rigid pose.
  const auto r = pose.linear();
  for (int k = 0; k < 9; ++k)
    if (!(std::abs(r(k % 3, k / 3)) <= 1.0 + 0x1p-20))
      return "its pose's rotation has an entry " + length_text(r(k % 3, k / 3)) + " (not a rotation)";
  return {};
}

}  // namespace

std::vector<Diagnostic> range_errors(SceneData& s, const CollideOptions& o) {
  // Parts never change and poses only where moved: only the instances moved since the last query
  // (all of them before the first) are looked at again, so a path step costs what it moves.
  for (InstanceId i : s.dirty_list) {
    if (instance_outside(s, i).empty()) s.outside_range.erase(i);
    else s.outside_range.insert(i);
  }
  std::vector<Diagnostic> out;
  auto error = [&out](std::string file, std::string message) {
    Diagnostic d;
    d.file = std::move(file);
    d.message = std::move(message);
    out.push_back(std::move(d));
  };
  if (!in_supported_range(o.tolerance)) error("", "tolerance " + length_text(o.tolerance) + " mm is " + kRange);
  if (!in_supported_range(o.clearance)) error("", "clearance " + length_text(o.clearance) + " mm is " + kRange);
  std::size_t more = 0;
  for (InstanceId i : s.outside_range) {
    if (!s.in_a[i] && !s.in_b[i]) continue;
    if (out.size() >= kListed) {
      ++more;
      continue;
    }
    const Instance& inst = s.model.instances[i];
    error(s.model.parts[inst.part].source_file, "instance '" + inst.path + "' not checked: " + instance_outside(s, i));
  }
  if (more > 0) error("", std::to_string(more) + " more instances outside the supported range not listed");
  if (!out.empty()) error("", "the query was refused: nothing was checked");
  return out;
}

void refuse(Report& r, std::vector<Diagnostic> errors) {
  r.pairs.clear();
  r.diagnostics = std::move(errors);
  r.complete = false;
  r.stopped_by = "out of range";
}

}  // namespace cadclash::detail
