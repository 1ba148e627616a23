// Stage 3: lazy tessellation of exactly the surviving surfaces, then their BVHs (built once per
// surface). Under a memory budget in rounds of a fixed number of surfaces in order of first need,
// checking the budget between rounds, so a small budget does not tessellate the whole scene first.
#include "scene_stages.h"
#include "team_loop.h"

#include <algorithm>

namespace cadclash::detail {
namespace {

// Surfaces tessellated per round under a memory budget: a constant, so the rounds, and so what the
// budget keeps, do not depend on the thread count.
constexpr std::size_t kBudgetRound = 64;
// Fewer work items than this run on the calling thread: waking a team costs more than they do.
constexpr std::ptrdiff_t kMinParallel = 4;

// Triangles for the surfaces of one round that have none yet; charged to their first pair.
void tessellate_round(SceneData& s, QueryState& q, std::span<const SurfaceId> wave) {
  Model& model = s.model;
  std::vector<SurfaceId> missing;
  std::vector<double> before;
  for (SurfaceId sid : wave)
    if (!model.surfaces[sid].has_triangles) {
      missing.push_back(sid);
      before.push_back(model.surfaces[sid].deflection);
    }
  if (missing.empty()) return;
  const std::uint64_t revision = model.revision;
  std::vector<Diagnostic> ds = require_triangles(model, missing, 0.0, q.threads, q.deadline, &q.failed);
  s.surfaces_changed(revision, missing);
  q.report.diagnostics.insert(q.report.diagnostics.end(), ds.begin(), ds.end());
  q.asked.insert(q.asked.end(), missing.begin(), missing.end());
  for (std::size_t i = 0; i < missing.size(); ++i) {
    const Surface& surf = model.surfaces[missing[i]];
    if (!surf.has_triangles) continue;
    q.tessellated.push_back(missing[i]);
    q.old_deflection.push_back(before[i]);
    q.charge[s.first_need[missing[i]]] += mesh_bytes(surf.mesh);
  }
}

void build_round(SceneData& s, QueryState& q, std::span<const SurfaceId> wave) {
  for (SurfaceId sid : build_trees(s, wave, q.threads, q.deadline)) {
    q.built.push_back(sid);
    q.charge[s.first_need[sid]] += bvh_heap_bytes(s.bvh[sid]);
  }
}

}  // namespace

std::vector<SurfaceId> build_trees(SceneData& s, std::span<const SurfaceId> wave, int threads, const Deadline& deadline) {
  std::vector<SurfaceId> to_build;
  for (SurfaceId sid : wave)
    if (!s.bvh_ready[sid] && s.model.surfaces[sid].has_triangles) to_build.push_back(sid);
  std::vector<char> done(to_build.size(), 0);
  const auto nbuild = static_cast<std::ptrdiff_t>(to_build.size());
  dynamic_loop(nbuild, threads, nbuild >= kMinParallel, [&](std::ptrdiff_t k) {
    if (deadline.expired()) return;
    const SurfaceId sid = to_build[static_cast<std::size_t>(k)];
    s.bvh[sid] = build_surface_bvh(s.model.surfaces[sid].mesh);
    done[static_cast<std::size_t>(k)] = 1;
  });
  std::vector<SurfaceId> built;
  for (std::size_t k = 0; k < to_build.size(); ++k) {
    if (!done[k]) continue;
    s.bvh_ready[to_build[k]] = 1;
    s.hold(to_build[k], +1);
    built.push_back(to_build[k]);
  }
  return built;
}

void tessellation_stage(SceneData& s, QueryState& q) {
  const std::size_t round = q.o.memory_budget_bytes > 0 ? kBudgetRound : std::max<std::size_t>(q.needed.size(), 1);
  for (std::size_t r = 0; r < q.needed.size(); r += round) {
    if (s.first_need[q.needed[r]] >= q.cutoff || q.deadline.expired()) break;
    const std::span<const SurfaceId> wave(q.needed.data() + r, std::min(round, q.needed.size() - r));
    tessellate_round(s, q, wave);
    build_round(s, q, wave);
    q.apply_memory_budget();
  }
}

}  // namespace cadclash::detail
