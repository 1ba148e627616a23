// `cadclash check` under mpirun: the MPI session, the split check and the per-rank lines
// (cadclash/distributed.h does the work). MpiCheck exists with CADCLASH_WITH_MPI only.
#pragma once

#include "cadclash/collide.h"

#include <cstdint>
#include <iostream>
#include <streambuf>
#include <memory>
#include <ostream>
#include <span>
#include <string>
#include <vector>

namespace cadclash::cli {

// This process's rank and the job's size as the launcher (mpirun) set them in the environment,
// read before MPI starts; size 1 and rank 0 when not launched by mpirun.
struct Launch {
  int rank = 0;
  int size = 1;
  bool by_mpirun = false;
};
Launch mpi_launch();

// Where a rank's output goes: rank 0 (or a single process) prints, the other ranks of an MPI job
// stay silent (they run the same code on their replica).
class SilentRank {
 public:
  explicit SilentRank(bool on) {
    if (!on) return;
    out_ = std::cout.rdbuf(&null_);
    err_ = std::cerr.rdbuf(&null_);
  }
  ~SilentRank() {
    if (out_ != nullptr) std::cout.rdbuf(out_);
    if (err_ != nullptr) std::cerr.rdbuf(err_);
  }
  SilentRank(const SilentRank&) = delete;
  SilentRank& operator=(const SilentRank&) = delete;

 private:
  struct : std::streambuf {
    int overflow(int c) override { return c; }
  } null_;
  std::streambuf* out_ = nullptr;
  std::streambuf* err_ = nullptr;
};

class MpiCheck;
class DistributedInputs;
#if CADCLASH_HAS_MPI
// One MPI session (MPI_Init_thread on construction, MPI_Finalize on destruction) and the distributed
// forms of the queries. Every rank calls every method in the same order (collectives).
class MpiCheck {
 public:
  MpiCheck();
  ~MpiCheck();
  MpiCheck(const MpiCheck&) = delete;
  MpiCheck& operator=(const MpiCheck&) = delete;

  int rank() const { return rank_; }
  int size() const { return size_; }

  // True when every rank imported the same model with the same diagnostics. Else, on rank 0, says on
  // stderr which rank read what (a file missing or different on its host).
  // `extra`: what else every rank read (the trajectory), in words.
  bool same_input_everywhere(const Model& model, const std::vector<Diagnostic>& diagnostics, const std::string& extra);
  // Part meshing (cadclash/distributed.h): `model` was imported without triangles (lazily) for a
  // check that asked for an eager import, and every rank now meshes (tessellate_parts) the parts it
  // owns and learns the other parts' facts; check() and replay() then mesh on each rank the parts its
  // share reaches. Collective. False on every rank when that cannot give the eager import's model (a
  // face that does not mesh, parts sharing edges): import eagerly then. `inputs` read the files
  // (DistributedInputs::read) and reads those of the parts a rank meshes that it has not read.
  bool mesh_parts_where_needed(Model& model, const SceneSelection& selection, const CollideOptions& options,
                               DistributedInputs& inputs);
  // Files read where needed (DistributedInputs::read gave `model`): before check() and replay() check
  // a rank's share, the files of the parts it reaches and has not read are read (a lazy check
  // tessellates their faces, a certified one asks them for exact distances).
  void read_where_needed(Model& model, DistributedInputs& inputs);
  // With part meshing: the checking scene (built after mesh_parts_where_needed) told the facts.
  void note_parts(Scene& scene);
  // With part meshing: every part not meshed here meshed now, the files not read here read first
  // (rank 0, before the HTML report).
  void mesh_every_part(Model& model);
  // Collective: how many of the `files` input files each rank read and in how many seconds, for
  // print_ranks.
  void note_files_read(std::size_t read_here, std::size_t files, double seconds);
  // Scene::check split over the ranks; the merged report on rank 0 (empty elsewhere).
  Report check(Scene& scene, Model& model, const CollideOptions& options);
  // check() whose pairs (ids, classes, distance bounds and uncertainties) and `complete` reach every
  // rank: the merged report on rank 0,
  // a report of those pairs alone elsewhere. Collective. For searches every rank must take alike
  // (check --continuous: MotionOptions::check).
  Report check_everywhere(Scene& scene, Model& model, const CollideOptions& options);
  // replay_trajectory split over the ranks; the steps on rank 0.
  std::vector<StepResult> replay(Scene& scene, Model& model, std::span<const TrajectoryRow> rows,
                                 const CollideOptions& options, std::vector<Diagnostic>& diagnostics,
                                 const std::string& file);
  // Rank 0: one line per rank (instance pairs, estimated cost, triangles, seconds, peak memory at the
  // end of its part, bytes sent, triangles its model holds and, with part meshing, the triangles it
  // meshed of the model's; the input files it read), rank 0's peak after merging and writing, and the load imbalance and merge
  // time, over the queries run so far.
  void print_ranks(std::ostream& os) const;
  // Rank 0's exit code, on every rank.
  int agree(int code);

 private:
  struct State;
  std::unique_ptr<State> state_;
  int rank_ = 0, size_ = 1;
};
#endif

}  // namespace cadclash::cli
