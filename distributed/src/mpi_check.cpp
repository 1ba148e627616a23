// check_distributed and replay_distributed: the plan on every rank, a part each, the parts gathered
// (MPI_Gatherv of their bytes) and merged on rank 0.
#include "cadclash/distributed.h"
#include "mpi_faults.h"

#include <sys/resource.h>
#include <time.h>

#include <algorithm>
#include <cassert>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <cstdio>
#include <cstring>
#include <new>

namespace cadclash {
namespace {

double process_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

std::uint64_t peak_memory_bytes() {
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  return static_cast<std::uint64_t>(ru.ru_maxrss) * 1024;  // Linux: KiB
}

// An MPI call that failed (the communicator returns errors): no report can be merged.
void check_mpi(int code, const char* what, MPI_Comm comm) {
  if (code == MPI_SUCCESS) return;
  char text[MPI_MAX_ERROR_STRING];
  int len = 0;
  MPI_Error_string(code, text, &len);
  int rank = -1;
  MPI_Comm_rank(comm, &rank);
  std::fprintf(stderr, "cadclash check: rank %d: %s failed: %.*s\n", rank, what, len, text);
  MPI_Abort(comm, 1);
}

// The rank's part checked, with the dying message armed while it runs.
PartialCheck run_part(Scene& scene, const Model& model, const CollideOptions& o, const CheckPlan& plan,
                      std::span<const std::uint32_t> part, int rank, int size, MPI_Comm comm) {
  detail::arm_fault_message(rank, size, model, plan, part);
  // A testing aid (the fault tests of tests/distributed): the named rank crashes as its part starts.
  if (const char* crash = std::getenv("CADCLASH_TEST_CRASH_RANK"); crash != nullptr && std::atoi(crash) == rank)
    std::raise(SIGSEGV);
  PartialCheck p;
  try {
    p = scene.check_part(o, plan, part);
  } catch (const std::bad_alloc&) {
    detail::print_fault_message("ran out of memory (std::bad_alloc)");
    MPI_Abort(comm, 1);
  }
  detail::disarm_fault_message();
  return p;
}

// The rank's run of the plan's pairs. The costs count the triangles of the surfaces a rank has
// tessellated, which differ between ranks: rank 0's split is broadcast (as run boundaries).
std::vector<std::uint32_t> my_part(const CheckPlan& plan, int rank, int size, MPI_Comm comm) {
  std::vector<unsigned> bounds(static_cast<std::size_t>(size) + 1, 0);
  if (rank == 0) {
    const std::vector<std::vector<std::uint32_t>> parts = split_by_cost(plan, size);
    for (int r = 0; r < size; ++r)
      bounds[static_cast<std::size_t>(r) + 1] =
          bounds[static_cast<std::size_t>(r)] + static_cast<unsigned>(parts[static_cast<std::size_t>(r)].size());
  }
  check_mpi(MPI_Bcast(bounds.data(), size + 1, MPI_UNSIGNED, 0, comm), "MPI_Bcast", comm);
  if (bounds.back() != plan.pairs.size()) {
    std::fprintf(stderr, "cadclash check: rank %d planned %zu instance pairs, rank 0 %u: the replicas differ\n", rank,
                 plan.pairs.size(), bounds.back());
    MPI_Abort(comm, 1);
  }
  std::vector<std::uint32_t> mine;
  for (unsigned k = bounds[static_cast<std::size_t>(rank)]; k < bounds[static_cast<std::size_t>(rank) + 1]; ++k)
    mine.push_back(k);
  return mine;
}

// Where each rank's part starts in a gather of `counts` bytes; ends the job when they pass what one
// MPI gather holds (int offsets). Returns the total.
std::size_t offsets_of(const std::vector<int>& counts, std::vector<int>& offsets, MPI_Comm comm) {
  long long total = 0;
  offsets.assign(counts.size(), 0);
  for (std::size_t r = 0; r < counts.size(); ++r) {
    offsets[r] = static_cast<int>(std::min<long long>(total, INT32_MAX));
    total += counts[r];
  }
  if (total > INT32_MAX) {
    std::fprintf(stderr, "cadclash check: the ranks' parts take %lld bytes, more than one MPI gather holds\n", total);
    MPI_Abort(comm, 1);
  }
  return static_cast<std::size_t>(total);
}

// Every rank's bytes on rank 0 (empty elsewhere).
std::vector<std::vector<std::uint8_t>> gather_bytes(const std::vector<std::uint8_t>& mine, int rank, int size,
                                                    MPI_Comm comm) {
  const auto n = static_cast<unsigned long long>(mine.size());
  if (n > static_cast<unsigned long long>(INT32_MAX)) {
    std::fprintf(stderr, "cadclash check: rank %d: its results take %llu bytes, more than one MPI message holds\n",
                 rank, n);
    MPI_Abort(comm, 1);
  }
  const int count = static_cast<int>(n);
  std::vector<int> counts(static_cast<std::size_t>(size)), offsets(static_cast<std::size_t>(size));
  check_mpi(MPI_Gather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, comm), "MPI_Gather", comm);
  std::vector<std::uint8_t> all;
  if (rank == 0) all.resize(offsets_of(counts, offsets, comm));
  check_mpi(MPI_Gatherv(mine.data(), count, MPI_BYTE, all.data(), counts.data(), offsets.data(), MPI_BYTE, 0, comm),
            "MPI_Gatherv", comm);
  std::vector<std::vector<std::uint8_t>> out;
  if (rank != 0) return out;
  for (int r = 0; r < size; ++r) {
    const auto at = all.begin() + offsets[static_cast<std::size_t>(r)];
    out.emplace_back(at, at + counts[static_cast<std::size_t>(r)]);
  }
  return out;
}

// Rank 0's new deflections to every rank, which notes them where it has no triangles.
void share_deflections(Scene& scene, Model& model, std::vector<std::pair<SurfaceId, double>>& d, MPI_Comm comm) {
  unsigned long long n = d.size();
  check_mpi(MPI_Bcast(&n, 1, MPI_UNSIGNED_LONG_LONG, 0, comm), "MPI_Bcast", comm);
  std::vector<unsigned> ids(n);
  std::vector<double> values(n);
  for (std::size_t i = 0; i < d.size(); ++i) {
    ids[i] = d[i].first;
    values[i] = d[i].second;
  }
  check_mpi(MPI_Bcast(ids.data(), static_cast<int>(n), MPI_UNSIGNED, 0, comm), "MPI_Bcast", comm);
  check_mpi(MPI_Bcast(values.data(), static_cast<int>(n), MPI_DOUBLE, 0, comm), "MPI_Bcast", comm);
  for (std::size_t i = 0; i < n; ++i) {
    Surface& s = model.surfaces[ids[i]];
    if (s.has_triangles) continue;  // tessellated here too: the same triangles
    s.deflection = values[i];
    scene.note_deflection(ids[i], values[i]);
  }
}

std::vector<RankStats> gather_stats(const RankStats& mine, int rank, int size, MPI_Comm comm) {
  constexpr int kFields = 11;
  const double v[kFields] = {static_cast<double>(mine.instance_pairs),    static_cast<double>(mine.cost),
                             static_cast<double>(mine.triangles),         mine.seconds,
                             mine.plan_seconds,                           static_cast<double>(mine.result_bytes),
                             static_cast<double>(mine.peak_memory_bytes), mine.cpu_seconds,
                             static_cast<double>(mine.held_triangles),    static_cast<double>(mine.meshed_triangles),
                             static_cast<double>(mine.model_triangles)};
  std::vector<double> all(rank == 0 ? kFields * static_cast<std::size_t>(size) : 0);
  check_mpi(MPI_Gather(v, kFields, MPI_DOUBLE, all.data(), kFields, MPI_DOUBLE, 0, comm), "MPI_Gather", comm);
  std::vector<RankStats> out;
  for (int r = 0; rank == 0 && r < size; ++r) {
    const double* x = all.data() + static_cast<std::ptrdiff_t>(kFields) * r;
    RankStats s;
    s.rank = r;
    s.instance_pairs = static_cast<std::uint64_t>(x[0]);
    s.cost = static_cast<std::uint64_t>(x[1]);
    s.triangles = static_cast<std::uint64_t>(x[2]);
    s.seconds = x[3];
    s.plan_seconds = x[4];
    s.result_bytes = static_cast<std::uint64_t>(x[5]);
    s.peak_memory_bytes = static_cast<std::uint64_t>(x[6]);
    s.cpu_seconds = x[7];
    s.held_triangles = static_cast<std::uint64_t>(x[8]);
    s.meshed_triangles = static_cast<std::uint64_t>(x[9]);
    s.model_triangles = static_cast<std::uint64_t>(x[10]);
    out.push_back(s);
  }
  return out;
}

}  // namespace

void add_stats(RankStats& into, const RankStats& s) {
  into.instance_pairs += s.instance_pairs;
  into.cost += s.cost;
  into.triangles = s.triangles;  // what it holds now
  into.seconds += s.seconds;
  into.cpu_seconds += s.cpu_seconds;
  into.plan_seconds += s.plan_seconds;
  into.result_bytes += s.result_bytes;
  into.peak_memory_bytes = std::max(into.peak_memory_bytes, s.peak_memory_bytes);
  into.held_triangles = s.held_triangles;
  into.meshed_triangles = s.meshed_triangles;
  into.model_triangles = s.model_triangles;
}

std::vector<std::string> allgather_bytes(const std::string& mine, MPI_Comm comm) {
  MPI_Comm_set_errhandler(comm, MPI_ERRORS_RETURN);
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  if (mine.size() > static_cast<std::size_t>(INT32_MAX)) {
    std::fprintf(stderr, "cadclash check: rank %d: %zu bytes to share, more than one MPI message holds\n", rank,
                 mine.size());
    MPI_Abort(comm, 1);
  }
  const int count = static_cast<int>(mine.size());
  std::vector<int> counts(static_cast<std::size_t>(size)), offsets(static_cast<std::size_t>(size));
  check_mpi(MPI_Allgather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, comm), "MPI_Allgather", comm);
  std::string all(offsets_of(counts, offsets, comm), '\0');
  check_mpi(MPI_Allgatherv(mine.data(), count, MPI_CHAR, all.data(), counts.data(), offsets.data(), MPI_CHAR, comm),
            "MPI_Allgatherv", comm);
  std::vector<std::string> out;
  for (int r = 0; r < size; ++r)
    out.push_back(all.substr(static_cast<std::size_t>(offsets[static_cast<std::size_t>(r)]),
                             static_cast<std::size_t>(counts[static_cast<std::size_t>(r)])));
  return out;
}

bool share_part_facts(Scene& boxes_scene, Model& model, const CollideOptions& options, bool share_edges,
                      PartMeshing& pm, MPI_Comm comm) {
  assert(pm.mesher.mesh && pm.mesher.release);
  MPI_Comm_set_errhandler(comm, MPI_ERRORS_RETURN);
  if (share_edges) return false;
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  const CheckPlan plan = boxes_scene.plan(options);  // boxes only, the same on every replica
  const std::vector<int> owners = mesh_owners(model, plan, size, pm.home);
  std::vector<std::vector<PartId>> owned(static_cast<std::size_t>(size));
  for (PartId p = 0; p < owners.size(); ++p) owned[static_cast<std::size_t>(owners[p])].push_back(p);
  const std::vector<PartId>& mine = owned[static_cast<std::size_t>(rank)];
  pm.held.assign(model.parts.size(), 0);
  pm.facts_only.assign(model.parts.size(), 0);
  pm.facts.assign(model.surfaces.size(), SurfaceFacts{});
  pm.model_triangles = 0;
  const std::uint64_t before = held_triangles(model);  // mesh files' triangles come with the import
  int failed = (mine.empty() || pm.mesher.mesh(mine)) ? 0 : 1;
  for (PartId p : mine) pm.held[p] = pm.facts_only[p] = 1;
  pm.meshed_triangles += held_triangles(model) - before;
  check_mpi(MPI_Allreduce(MPI_IN_PLACE, &failed, 1, MPI_INT, MPI_MAX, comm), "MPI_Allreduce", comm);
  if (failed) return false;

  // Every rank's facts, as doubles: box min, box max, deflection, triangles, has_triangles.
  constexpr int kPer = 9;
  std::vector<double> mine_v;
  for (const SurfaceFacts& f : surface_facts(model, mine)) {
    const double v[kPer] = {f.box.min().x(), f.box.min().y(), f.box.min().z(), f.box.max().x(),
                            f.box.max().y(), f.box.max().z(), f.deflection,    static_cast<double>(f.triangles),
                            f.has_triangles ? 1.0 : 0.0};
    mine_v.insert(mine_v.end(), v, v + kPer);
  }
  // Doubles as their bytes: the ranks run one build on one kind of host.
  const std::vector<std::string> all = allgather_bytes(
      std::string(reinterpret_cast<const char*>(mine_v.data()), mine_v.size() * sizeof(double)), comm);
  for (int r = 0; r < size; ++r) {
    const std::string& bytes = all[static_cast<std::size_t>(r)];
    std::vector<double> x(bytes.size() / sizeof(double));
    std::memcpy(x.data(), bytes.data(), x.size() * sizeof(double));
    std::vector<SurfaceFacts> facts;
    for (std::size_t i = 0; i + kPer <= x.size(); i += kPer) {
      SurfaceFacts f;
      f.box = Aabb(Vec3(x[i], x[i + 1], x[i + 2]), Vec3(x[i + 3], x[i + 4], x[i + 5]));
      f.deflection = x[i + 6];
      f.triangles = static_cast<std::uint64_t>(x[i + 7]);
      f.has_triangles = x[i + 8] != 0.0;
      facts.push_back(f);
    }
    apply_surface_facts(model, owned[static_cast<std::size_t>(r)], facts, pm);
  }
  return true;
}

DistributedCheck check_distributed(Scene& scene, Model& model, const CollideOptions& o, MergeHistory& history,
                                   MPI_Comm comm, PartMeshing* parts, const PartReader& read) {
  assert(o.memory_budget_bytes == 0);
  MPI_Comm_set_errhandler(comm, MPI_ERRORS_RETURN);
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  const auto t_plan = std::chrono::steady_clock::now();
  const CheckPlan plan = scene.plan(o);  // the same pairs on every replica
  const double plan_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_plan).count();
  const std::vector<std::uint32_t> mine = my_part(plan, rank, size, comm);
  const auto t0 = std::chrono::steady_clock::now();
  const double cpu0 = process_cpu_seconds();
  if (read && !read(parts_of_pairs(model, plan, mine))) {
    std::fprintf(stderr, "cadclash check: rank %d: the files its instance pairs reach could not be read\n", rank);
    MPI_Abort(comm, 1);
  }
  if (parts != nullptr && !share_parts(model, plan, mine, *parts)) {
    // share_part_facts meshed every part once without a failure: the same meshing cannot fail now.
    std::fprintf(stderr, "cadclash check: rank %d: a part that meshed on its owner failed to mesh here\n", rank);
    MPI_Abort(comm, 1);
  }
  const PartialCheck part = run_part(scene, model, o, plan, mine, rank, size, comm);
  RankStats stats;
  stats.rank = rank;
  stats.instance_pairs = mine.size();
  for (std::uint32_t k : mine) stats.cost += plan.pairs[k].cost;
  stats.triangles = part.report.model_memory.triangle_count;
  stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  stats.cpu_seconds = process_cpu_seconds() - cpu0;
  stats.plan_seconds = plan_seconds;
  const std::vector<std::uint8_t> my_bytes = partial_check_bytes(part);
  stats.result_bytes = my_bytes.size();
  stats.peak_memory_bytes = peak_memory_bytes();
  stats.held_triangles = held_triangles(model);
  if (parts != nullptr) {
    stats.meshed_triangles = parts->meshed_triangles;
    stats.model_triangles = parts->model_triangles;
  }

  const std::vector<std::vector<std::uint8_t>> bytes = gather_bytes(my_bytes, rank, size, comm);
  DistributedCheck out;
  out.ranks = gather_stats(stats, rank, size, comm);
  std::vector<std::pair<SurfaceId, double>> deflections;
  if (rank == 0) {
    const auto t_merge = std::chrono::steady_clock::now();
    std::vector<PartialCheck> all;
    for (int r = 0; r < size; ++r) {
      std::string error;
      std::optional<PartialCheck> p = partial_check_from_bytes(bytes[static_cast<std::size_t>(r)], error);
      if (!p) {
        std::fprintf(stderr, "cadclash check: the results of rank %d are unreadable: %s\n", r, error.c_str());
        MPI_Abort(comm, 1);
      }
      all.push_back(std::move(*p));
    }
    MergedCheck merged = merge_parts(plan, all, model, history);
    out.report = std::move(merged.report);
    deflections = std::move(merged.new_deflections);
    out.merge_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_merge).count();
  }
  share_deflections(scene, model, deflections, comm);
  return out;
}

DistributedReplay replay_distributed(Scene& scene, Model& model, std::span<const TrajectoryRow> rows,
                                     const CollideOptions& options, std::vector<Diagnostic>& diagnostics,
                                     const std::string& file, MPI_Comm comm, PartMeshing* parts,
                                     const PartReader& read) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  DistributedReplay out;
  MergeHistory history(model.surfaces.size(), scene.memory());
  // The time budget covers the whole replay, as in replay_trajectory; rank 0 decides for every rank.
  const auto start = std::chrono::steady_clock::now();
  bool last_cut_by_time = false;
  std::size_t k = 0;
  while (k < rows.size()) {
    const std::int64_t step = rows[k].step;
    CollideOptions step_options = options;
    if (options.time_budget_seconds > 0.0) {
      double left = options.time_budget_seconds -
                    std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      int stop = (left <= 0.0 || last_cut_by_time) ? 1 : 0;
      check_mpi(MPI_Bcast(&stop, 1, MPI_INT, 0, comm), "MPI_Bcast", comm);
      check_mpi(MPI_Bcast(&left, 1, MPI_DOUBLE, 0, comm), "MPI_Bcast", comm);
      if (stop) {
        diagnostics.push_back(steps_not_checked(rows, k, file));
        break;
      }
      step_options.time_budget_seconds = left;
    }
    k = apply_trajectory_step(scene, rows, k, diagnostics, file);
    DistributedCheck c = check_distributed(scene, model, step_options, history, comm, parts, read);
    if (rank == 0) {
      last_cut_by_time = !c.report.complete && c.report.stopped_by.find("time") != std::string::npos;
      out.merge_seconds += c.merge_seconds;
      if (out.ranks.empty()) out.ranks = c.ranks;
      else
        for (std::size_t r = 0; r < c.ranks.size(); ++r) add_stats(out.ranks[r], c.ranks[r]);
      out.steps.push_back({step, std::move(c.report)});
    }
  }
  return out;
}

}  // namespace cadclash
