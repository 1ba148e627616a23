#include "compare_workload.h"

#include "cadclash/geometry.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <omp.h>

namespace cadclash::bench {
namespace {

InstanceId find_path(const Model& model, const std::string& path) {
  for (InstanceId i = 0; i < model.instances.size(); ++i)
    if (model.instances[i].path == path) return i;
  return kInvalidId;
}

// Area-weighted centroid and covariance of the triangles of some instances, in world coordinates:
// the principal axes of a tessellated surface do not depend on how densely each face was meshed.
struct Moments {
  Vec3 centroid = Vec3::Zero();
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  double area = 0.0;
};

Moments surface_moments(const Model& model, const std::vector<InstanceId>& instances) {
  Moments m;
  Vec3 sum = Vec3::Zero();
  Eigen::Matrix3d outer = Eigen::Matrix3d::Zero();
  for (InstanceId i : instances) {
    const Instance& in = model.instances[i];
    const Part& part = model.parts[in.part];
    for (SurfaceId s = part.first_surface; s < part.first_surface + part.surface_count; ++s) {
      const TriangleMesh& mesh = model.surfaces[s].mesh;
      for (const auto& t : mesh.triangles) {
        const Vec3 a = in.pose * mesh.vertices[t[0]], b = in.pose * mesh.vertices[t[1]], c = in.pose * mesh.vertices[t[2]];
        const double w = 0.5 * (b - a).cross(c - a).norm();
        const Vec3 g = (a + b + c) / 3.0;
        sum += w * g;
        outer += w * g * g.transpose();
        m.area += w;
      }
    }
  }
  if (m.area > 0.0) {
    m.centroid = sum / m.area;
    m.covariance = outer / m.area - m.centroid * m.centroid.transpose();
  }
  return m;
}

// Unit eigenvector of the largest (largest == true) or smallest eigenvalue.
Vec3 principal_axis(const Eigen::Matrix3d& covariance, bool largest) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance);  // eigenvalues ascending
  return solver.eigenvectors().col(largest ? 2 : 0).normalized();
}

// Smallest and largest projection of the world vertices of `instances` on `axis`.
std::pair<double, double> extent_along(const Model& model, const std::vector<InstanceId>& instances, const Vec3& axis) {
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (InstanceId i : instances) {
    const Instance& in = model.instances[i];
    const Part& part = model.parts[in.part];
    for (SurfaceId s = part.first_surface; s < part.first_surface + part.surface_count; ++s)
      for (const Vec3& v : model.surfaces[s].mesh.vertices) {
        const double p = axis.dot(in.pose * v);
        lo = std::min(lo, p);
        hi = std::max(hi, p);
      }
  }
  return {lo, hi};
}

}  // namespace

PoseState::PoseState(const Model& model) {
  poses.reserve(model.instances.size());
  for (const Instance& in : model.instances) poses.push_back(in.pose);
}

void PoseState::apply(const std::vector<PoseUpdate>& updates) {
  for (const PoseUpdate& u : updates) poses[u.instance] = u.pose;
}

std::vector<Aabb> part_triangle_boxes(const Model& model) {
  std::vector<Aabb> boxes(model.parts.size());
  for (PartId p = 0; p < model.parts.size(); ++p) {
    const Part& part = model.parts[p];
    for (SurfaceId s = part.first_surface; s < part.first_surface + part.surface_count; ++s)
      for (const Vec3& v : model.surfaces[s].mesh.vertices) boxes[p].extend(v);
  }
  return boxes;
}

std::vector<std::array<InstanceId, 2>> overlapping_instance_pairs(const Model& model,
                                                                   const std::vector<Aabb>& part_boxes,
                                                                   const std::vector<Pose>& poses,
                                                                   const std::vector<char>& moving,
                                                                   std::uint32_t instance_limit) {
  const std::uint32_t n = instance_limit > 0 ? std::min<std::uint32_t>(instance_limit, static_cast<std::uint32_t>(model.instances.size()))
                                             : static_cast<std::uint32_t>(model.instances.size());
  std::vector<Aabb> world(n);
  std::vector<InstanceId> order;
  for (InstanceId i = 0; i < n; ++i) {
    world[i] = placed_box(part_boxes[model.instances[i].part], poses[i]);
    if (world[i].isEmpty()) continue;
    // Rounding of the mapped corners must not separate boxes that touch exactly.
    const double pad = 1e-9 * (1.0 + std::max(world[i].min().cwiseAbs().maxCoeff(), world[i].max().cwiseAbs().maxCoeff()));
    world[i].min().array() -= pad;
    world[i].max().array() += pad;
    order.push_back(i);
  }
  std::sort(order.begin(), order.end(), [&](InstanceId a, InstanceId b) {
    return world[a].min().x() < world[b].min().x() || (world[a].min().x() == world[b].min().x() && a < b);
  });
  std::vector<std::array<InstanceId, 2>> pairs;
  for (std::size_t k = 0; k < order.size(); ++k) {
    const Aabb& a = world[order[k]];
    for (std::size_t l = k + 1; l < order.size() && world[order[l]].min().x() <= a.max().x(); ++l) {
      const InstanceId i = order[k], j = order[l];
      if (!moving.empty() && !moving[i] && !moving[j]) continue;
      if (!a.intersects(world[j])) continue;
      pairs.push_back({std::min(i, j), std::max(i, j)});
    }
  }
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

void for_each_step_pair(const Workload& w, const Subset& subset,
                        const std::function<void(std::uint32_t, InstanceId, InstanceId, const Pose&, const Pose&)>& f) {
  const Model& model = *w.model;
  const std::vector<Aabb> boxes = part_triangle_boxes(model);
  std::vector<char> moving;
  if (!w.moving.empty()) {
    moving.assign(model.instances.size(), 0);
    for (InstanceId i : w.moving) moving[i] = 1;
  }
  PoseState state(model);
  for (std::uint32_t k = 0; k < w.steps.size(); ++k) {
    state.apply(w.steps[k]);
    if (!subset.has_step(k)) continue;
    for (const auto& [a, b] : overlapping_instance_pairs(model, boxes, state.poses, moving, subset.instances))
      f(k, a, b, state.poses[a], state.poses[b]);
  }
}

bool unscrew_path(const Model& model, const std::string& nut_path, const std::string& bolt_path, int steps,
                  double turns, GeneratedPath& out, std::string& error) {
  const InstanceId nut = find_path(model, nut_path), bolt = find_path(model, bolt_path);
  if (nut == kInvalidId || bolt == kInvalidId) {
    error = "no instance " + (nut == kInvalidId ? nut_path : bolt_path);
    return false;
  }
  const Moments mb = surface_moments(model, {bolt}), mn = surface_moments(model, {nut});
  Vec3 axis = principal_axis(mb.covariance, true);
  if (axis.dot(mn.centroid - mb.centroid) < 0.0) axis = -axis;  // from the bolt's head towards the nut
  // The axis passes through the bolt's centroid; the nut turns about that line.
  const Vec3 c = mb.centroid;
  const double bolt_end = extent_along(model, {bolt}, axis).second;
  const double nut_start = extent_along(model, {nut}, axis).first;
  const double travel = bolt_end - nut_start + 0.5;
  out = {};
  out.name = "unscrew";
  out.moving = {nut};
  char buf[256];
  std::snprintf(buf, sizeof buf, "%s turned %.0f times about and moved %.2f mm along the axis of %s, %d steps",
                nut_path.c_str(), turns, travel, bolt_path.c_str(), steps);
  out.description = buf;
  const Pose start = model.instances[nut].pose;
  for (int k = 0; k <= steps; ++k) {
    const double f = static_cast<double>(k) / steps;
    Pose m = Pose::Identity();
    m.translate(c + axis * (travel * f));
    m.rotate(Eigen::AngleAxisd(2.0 * std::numbers::pi * turns * f, axis));
    m.translate(-c);
    out.steps.push_back({PoseUpdate{nut, m * start}});
  }
  return true;
}

bool withdraw_path(const Model& model, const std::string& subassembly, const std::string& plate_path, int steps,
                   GeneratedPath& out, std::string& error) {
  const InstanceId plate = find_path(model, plate_path);
  if (plate == kInvalidId) {
    error = "no instance " + plate_path;
    return false;
  }
  std::vector<InstanceId> group;
  for (InstanceId i = 0; i < model.instances.size(); ++i)
    if (model.instances[i].path.rfind(subassembly + "/", 0) == 0) group.push_back(i);
  if (group.empty()) {
    error = "no instance under " + subassembly;
    return false;
  }
  const Moments mp = surface_moments(model, {plate}), mg = surface_moments(model, group);
  Vec3 normal = principal_axis(mp.covariance, false);
  if (normal.dot(mg.centroid - mp.centroid) < 0.0) normal = -normal;
  const double travel = extent_along(model, {plate}, normal).second - extent_along(model, group, normal).first + 0.5;
  out = {};
  out.name = "withdraw";
  out.moving = group;
  char buf[256];
  std::snprintf(buf, sizeof buf, "%s (%zu instances) moved %.2f mm off %s along its normal, %d steps",
                subassembly.c_str(), group.size(), travel, plate_path.c_str(), steps);
  out.description = buf;
  for (int k = 0; k <= steps; ++k) {
    const Pose m(Eigen::Translation3d(normal * (travel * static_cast<double>(k) / steps)));
    std::vector<PoseUpdate> step;
    for (InstanceId i : group) step.push_back({i, m * model.instances[i].pose});
    out.steps.push_back(std::move(step));
  }
  return true;
}

bool write_path_csv(const Model& model, const GeneratedPath& path, const std::string& file) {
  std::FILE* f = std::fopen(file.c_str(), "w");
  if (!f) return false;
  std::fprintf(f, "# %s\nstep,instance_path,tx,ty,tz,qw,qx,qy,qz\n", path.description.c_str());
  for (std::size_t k = 0; k < path.steps.size(); ++k)
    for (const PoseUpdate& u : path.steps[k]) {
      const Vec3 t = u.pose.translation();
      const Eigen::Quaterniond q(u.pose.rotation());
      std::fprintf(f, "%zu,%s,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n", k, model.instances[u.instance].path.c_str(),
                   t.x(), t.y(), t.z(), q.w(), q.x(), q.y(), q.z());
    }
  return std::fclose(f) == 0;
}

Model instanced_grid(const Model& base, std::uint32_t copies) {
  const std::vector<Aabb> boxes = part_triangle_boxes(base);
  Aabb world;
  for (const Instance& in : base.instances) world.extend(placed_box(boxes[in.part], in.pose));
  const Vec3 size = world.sizes();
  const double gap = 0.1 * size.norm();
  const auto cols = static_cast<std::uint32_t>(std::ceil(std::sqrt(static_cast<double>(copies))));
  Model out;
  out.parts = base.parts;
  out.surfaces = base.surfaces;
  out.instances.reserve(base.instances.size() * copies);
  for (std::uint32_t k = 0; k < copies; ++k) {
    const Pose shift(Eigen::Translation3d((size.x() + gap) * (k % cols), (size.y() + gap) * (k / cols), 0.0));
    for (const Instance& in : base.instances)
      out.instances.push_back({"/copy" + std::to_string(k) + in.path, in.part, shift * in.pose});
  }
  return out;
}

Model distinct_grid(const Model& base, std::uint32_t copies) {
  const Model grid = instanced_grid(base, copies);
  Model out;
  // append_model gives each copy its own parts and surfaces (ids shifted) and the "/copyK" paths.
  for (std::uint32_t k = 0; k < copies; ++k) append_model(out, base, "/copy" + std::to_string(k));
  for (std::size_t i = 0; i < out.instances.size(); ++i) out.instances[i].pose = grid.instances[i].pose;
  return out;
}

std::size_t instance_triangle_count(const Model& model) {
  std::vector<std::size_t> per_part(model.parts.size(), 0);
  for (const Surface& s : model.surfaces)
    if (s.part < per_part.size()) per_part[s.part] += s.mesh.triangles.size();
  std::size_t n = 0;
  for (const Instance& in : model.instances) n += per_part[in.part];
  return n;
}

double core_round_trip_ns(int trips) {
  // On the OpenMP team's own two threads: a fresh thread would share a core with the team's worker
  // while that still spins after a parallel region, and measure the time slice, not the cache.
  alignas(64) std::atomic<long> turn{0};
  double ns = 0.0;
#pragma omp parallel num_threads(2)
  {
    if (omp_get_num_threads() == 2) {
      if (omp_get_thread_num() == 1) {
        for (long i = 0; i < trips; ++i) {
          while (turn.load(std::memory_order_acquire) != 2 * i + 1) {
          }
          turn.store(2 * i + 2, std::memory_order_release);
        }
      } else {
        const auto t0 = std::chrono::steady_clock::now();
        for (long i = 0; i < trips; ++i) {
          turn.store(2 * i + 1, std::memory_order_release);
          while (turn.load(std::memory_order_acquire) != 2 * i + 2) {
          }
        }
        ns = std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - t0).count() / trips;
      }
    }
  }
  return ns;
}

namespace {

// A dependent chain of xorshift steps: no memory traffic, so only the CPU's availability shows.
double compute_seconds() {
  const auto t0 = std::chrono::steady_clock::now();
  std::uint64_t x = 88172645463325252ULL;
  for (long i = 0; i < 12000000; ++i) {
    x ^= x << 13;
    x ^= x >> 7;
    x ^= x << 17;
  }
  volatile std::uint64_t sink = x;
  (void)sink;
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

double second_cpu_share() {
  std::vector<double> shares;
  for (int round = 0; round < 3; ++round) {
    const double one = compute_seconds();
    double both[2] = {0.0, 0.0};
#pragma omp parallel num_threads(2)
    both[omp_get_thread_num() & 1] = compute_seconds();
    shares.push_back(one / std::max(both[0], both[1]));
  }
  std::sort(shares.begin(), shares.end());
  return shares[1];
}

}  // namespace cadclash::bench
