#include "cmd_check_mpi.h"
#include "mpi_inputs.h"

#include "cadclash/distributed.h"
#include "cadclash/tessellate.h"

#include <sys/resource.h>

#include <algorithm>
#include <bit>
#include <cstdlib>
#include <functional>
#include <iomanip>
#include <iostream>
#include <optional>
#include <sstream>

namespace cadclash::cli {
namespace {

int env_int(const char* name, int fallback) {
  const char* v = std::getenv(name);
  if (v == nullptr || *v == '\0') return fallback;
  char* end = nullptr;
  const long x = std::strtol(v, &end, 10);
  return (end != nullptr && *end == '\0' && x >= 0 && x < (1L << 30)) ? static_cast<int>(x) : fallback;
}

}  // namespace

Launch mpi_launch() {
  Launch l;
  for (const auto& [rank_var, size_var] : {std::pair{"OMPI_COMM_WORLD_RANK", "OMPI_COMM_WORLD_SIZE"},
                                           std::pair{"PMI_RANK", "PMI_SIZE"}}) {
    const int size = env_int(size_var, -1);
    if (size < 1) continue;
    l.by_mpirun = true;
    l.size = size;
    l.rank = env_int(rank_var, 0);
    break;
  }
  return l;
}

#if CADCLASH_HAS_MPI
struct MpiCheck::State {
  std::vector<RankStats> ranks;  // rank 0: summed over the queries
  double merge_seconds = 0.0;
  // One history for every check() of the scene (--repeat): what an earlier query tessellated or
  // built is not counted again, as in one process.
  std::optional<MergeHistory> history;
  std::optional<PartMeshing> parts;  // part meshing, when mesh_parts_where_needed set it up
  PartReader read;                   // files read where needed, when read_where_needed set it up
  std::vector<double> files_read;    // rank 0: per rank, the input files it read and the seconds it took
  std::size_t files = 0;
  PartMeshing* part_meshing() { return parts ? &*parts : nullptr; }
  void add(const std::vector<RankStats>& r, double merge) {
    merge_seconds += merge;
    if (ranks.empty()) {
      ranks = r;
      return;
    }
    for (std::size_t i = 0; i < r.size(); ++i) add_stats(ranks[i], r[i]);
  }
};

MpiCheck::MpiCheck() : state_(std::make_unique<State>()) {
  int provided = 0;
  // OpenMP threads inside a rank never call MPI: the main thread does every call.
  MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
  MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
}

MpiCheck::~MpiCheck() { MPI_Finalize(); }

bool MpiCheck::same_input_everywhere(const Model& model, const std::vector<Diagnostic>& diagnostics,
                                     const std::string& extra) {
  std::ostringstream what;
  what << model.instances.size() << " instances, " << model.parts.size() << " parts, " << model.surfaces.size()
       << " surfaces, " << diagnostics.size() << " import diagnostics, " << extra;
  std::string text = what.str();
  for (const Diagnostic& d : diagnostics) text += '\n' + format_diagnostic(d);
  const unsigned long long mine = std::hash<std::string>{}(text);
  std::vector<unsigned long long> all(static_cast<std::size_t>(size_));
  MPI_Allgather(&mine, 1, MPI_UNSIGNED_LONG_LONG, all.data(), 1, MPI_UNSIGNED_LONG_LONG, MPI_COMM_WORLD);
  bool same = true;
  for (int r = 1; r < size_; ++r) {
    if (all[static_cast<std::size_t>(r)] == all[0]) continue;
    same = false;
    if (rank_ == 0)
      std::cerr << "cadclash check: rank " << r << " read the input differently from rank 0 (rank 0: " << what.str()
                << "): are the files the same on every host?\n";
  }
  return same;
}

bool MpiCheck::mesh_parts_where_needed(Model& model, const SceneSelection& selection, const CollideOptions& options,
                                       DistributedInputs& inputs) {
  PartMeshing pm;
  pm.home = inputs.part_readers();
  pm.mesher.mesh = [&model, &inputs](std::span<const PartId> parts) {
    if (!inputs.read_files_of(model, parts)) return false;
    std::vector<Diagnostic> errors;
    bool complete = true;
    tessellate_parts(model, parts, errors, complete);
    return errors.empty() && complete;
  };
  pm.mesher.release = [&model](std::span<const PartId> parts) { release_part_triangles(model, parts); };
  bool ok = false;
  {
    Scene boxes(model, selection);
    ok = share_part_facts(boxes, model, options, inputs.parts_share_edges(), pm, MPI_COMM_WORLD);
  }
  if (ok) state_->parts = std::move(pm);
  return ok;
}

void MpiCheck::read_where_needed(Model& model, DistributedInputs& inputs) {
  state_->read = [&model, &inputs](std::span<const PartId> parts) { return inputs.read_files_of(model, parts); };
}

void MpiCheck::note_parts(Scene& scene) {
  if (state_->parts) note_surface_facts(scene, *state_->parts);
}

void MpiCheck::mesh_every_part(Model& model) {
  if (!state_->parts) return;
  std::vector<PartId> all(model.parts.size());
  for (PartId p = 0; p < all.size(); ++p) all[p] = p;
  state_->parts->mesher.mesh(all);  // a failure would have shown in mesh_parts_where_needed
}

void MpiCheck::note_files_read(std::size_t read_here, std::size_t files, double seconds) {
  const double mine[2] = {static_cast<double>(read_here), seconds};
  state_->files_read.assign(2 * static_cast<std::size_t>(size_), 0.0);
  state_->files = files;
  MPI_Gather(mine, 2, MPI_DOUBLE, state_->files_read.data(), 2, MPI_DOUBLE, 0, MPI_COMM_WORLD);
}

Report MpiCheck::check(Scene& scene, Model& model, const CollideOptions& options) {
  if (!state_->history) state_->history.emplace(model.surfaces.size(), scene.memory());
  DistributedCheck c =
      check_distributed(scene, model, options, *state_->history, MPI_COMM_WORLD, state_->part_meshing(), state_->read);
  state_->add(c.ranks, c.merge_seconds);
  return std::move(c.report);
}

Report MpiCheck::check_everywhere(Scene& scene, Model& model, const CollideOptions& options) {
  Report r = check(scene, model, options);
  // Nine numbers per pair (instances, surfaces, class, the bits of the distance bounds and of the
  // surfaces' uncertainties: check_motion's margins are the bounds less the uncertainties) and
  // `complete` last, broadcast from rank 0.
  constexpr std::size_t kPer = 9;
  std::vector<std::uint64_t> packed;
  if (rank_ == 0) {
    for (const SurfacePairResult& p : r.pairs)
      packed.insert(packed.end(), {p.instance_a, p.instance_b, p.surface_a, p.surface_b,
                                   static_cast<std::uint64_t>(p.contact), std::bit_cast<std::uint64_t>(p.distance_lo),
                                   std::bit_cast<std::uint64_t>(p.distance_hi), std::bit_cast<std::uint64_t>(p.uncertainty_a),
                                   std::bit_cast<std::uint64_t>(p.uncertainty_b)});
    packed.push_back(r.complete ? 1 : 0);
  }
  unsigned long long n = packed.size();
  MPI_Bcast(&n, 1, MPI_UNSIGNED_LONG_LONG, 0, MPI_COMM_WORLD);
  packed.resize(n);
  MPI_Bcast(packed.data(), static_cast<int>(n), MPI_UINT64_T, 0, MPI_COMM_WORLD);
  if (rank_ == 0) return r;
  Report thin;
  for (std::size_t k = 0; k + kPer <= packed.size(); k += kPer) {
    SurfacePairResult p;
    p.instance_a = static_cast<InstanceId>(packed[k]);
    p.instance_b = static_cast<InstanceId>(packed[k + 1]);
    p.surface_a = static_cast<SurfaceId>(packed[k + 2]);
    p.surface_b = static_cast<SurfaceId>(packed[k + 3]);
    p.contact = static_cast<ContactClass>(packed[k + 4]);
    p.distance_lo = std::bit_cast<double>(packed[k + 5]);
    p.distance_hi = std::bit_cast<double>(packed[k + 6]);
    p.uncertainty_a = std::bit_cast<double>(packed[k + 7]);
    p.uncertainty_b = std::bit_cast<double>(packed[k + 8]);
    thin.pairs.push_back(p);
  }
  thin.complete = !packed.empty() && packed.back() == 1;
  return thin;
}

std::vector<StepResult> MpiCheck::replay(Scene& scene, Model& model, std::span<const TrajectoryRow> rows,
                                         const CollideOptions& options, std::vector<Diagnostic>& diagnostics,
                                         const std::string& file) {
  DistributedReplay r =
      replay_distributed(scene, model, rows, options, diagnostics, file, MPI_COMM_WORLD, state_->part_meshing(),
                         state_->read);
  state_->add(r.ranks, r.merge_seconds);
  return std::move(r.steps);
}

void MpiCheck::print_ranks(std::ostream& os) const {
  const std::vector<RankStats>& ranks = state_->ranks;
  if (ranks.empty()) return;
  double slowest = 0.0, sum = 0.0;
  for (const RankStats& s : ranks) {
    os << "rank " << s.rank << " of " << size_ << ": " << s.instance_pairs << " instance pairs (estimated cost "
       << s.cost << "), " << s.triangles << " triangles, " << std::fixed << std::setprecision(3) << s.seconds
       << " s (CPU " << s.cpu_seconds << " s; plan " << s.plan_seconds << " s), peak memory " << std::setprecision(1)
       << static_cast<double>(s.peak_memory_bytes) / (1024.0 * 1024.0) << " MiB, results "
       << static_cast<double>(s.result_bytes) / 1024.0 << " KiB; model triangles held " << s.held_triangles;
    if (state_->parts)
      os << ", meshed here " << s.meshed_triangles << " of the model's " << s.model_triangles;
    if (const auto at = 2 * static_cast<std::size_t>(s.rank); state_->files > 0 && at < state_->files_read.size())
      os << "; files read here " << static_cast<std::size_t>(state_->files_read[at]) << " of " << state_->files
         << " (" << std::fixed << std::setprecision(3) << state_->files_read[at + 1] << " s)";
    os << '\n' << std::defaultfloat;
    slowest = std::max(slowest, s.seconds);
    sum += s.seconds;
  }
  const double mean = sum / static_cast<double>(ranks.size());
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);  // Linux: KiB
  os << "rank 0 after merging and writing the report: peak memory " << std::fixed << std::setprecision(1)
     << static_cast<double>(ru.ru_maxrss) / 1024.0 << " MiB\n"
     << std::defaultfloat;
  os << "load imbalance: slowest rank " << std::fixed << std::setprecision(3) << slowest << " s, mean " << mean
     << " s (" << std::setprecision(2) << (mean > 0.0 ? slowest / mean : 1.0) << "x); merge on rank 0 "
     << std::setprecision(3) << state_->merge_seconds << " s\n"
     << std::defaultfloat;
}

int MpiCheck::agree(int code) {
  MPI_Bcast(&code, 1, MPI_INT, 0, MPI_COMM_WORLD);
  return code;
}
#endif

}  // namespace cadclash::cli
