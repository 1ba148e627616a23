// What `cadclash check` was asked (its command line) and the steps of it that run in more than one
// file: the check itself (cmd_check.cpp) and a run as one rank of an MPI job (check_rank.cpp).
#pragma once

#include "check_review.h"
#include "cli_common.h"

#include "cadclash/collide.h"

#include <optional>
#include <string>
#include <vector>

namespace cadclash::cli {

// Exit code of --fail-on-collision when a penetrating or touching pair (or containment) was found.
constexpr int kExitCollision = 3;
// Exit code when --time-budget or --memory-budget ran out: the report was written, marked partial.
constexpr int kExitBudget = 4;

struct CheckOptions {
  InputOptions in;
  double tolerance = 0.0;
  double clearance = 0.0;
  int threads = 0;
  int repeat = 1;
  double time_budget = 0.0;       // seconds; 0 = none
  double memory_budget_mb = 0.0;  // MiB; 0 = none
  std::string path_csv;
  bool continuous = false;          // --continuous: the motion between the steps too
  double time_resolution = 1e-3;    // fraction of the stretch between two steps
  std::size_t motion_checks = 4096;  // static checks at most per stretch
  bool all_triangles = false;
  std::string json;
  std::string html;
  bool no_timings = false;
  bool fail_on_collision = false;  // approved clashes (--approvals) never count
  bool brute_force = false;
  bool no_containment = false;
  bool exact = false;
  bool fast = false;
  std::string parallel = "v1";
  std::string schedule = "guided";
  std::string triangle_level = "auto";
  std::vector<std::string> select_a, select_b, exclude_under;
  ReviewCliOptions review;
};

// The query's options from the command line.
CollideOptions collide_options(const CheckOptions& o);

// The --path trajectory's rows; std::nullopt, after saying why on stderr, when the file cannot be
// read or has errors.
std::optional<std::vector<TrajectoryRow>> read_trajectory(const std::string& csv);

// The instances --select-a/-b name and the sub-assemblies --exclude-under leaves out; std::nullopt,
// after saying so on stderr, when a --select matches no instance.
std::optional<SceneSelection> scene_selection(const Model& m, const CheckOptions& o);

class MpiCheck;
class DistributedInputs;

// The check of what was imported, printed and written: in this process, or split over the ranks of
// `mpi` when given (then `inputs`, with files read where needed, reads the files a rank needs and
// has not read). Returns the exit code.
int check_imported(const CheckOptions& o, ImportResult& imported, const std::vector<TrajectoryRow>& rows,
                   const ReviewInputs& review, MpiCheck* mpi, DistributedInputs* inputs = nullptr);

#if CADCLASH_HAS_MPI
// `cadclash check` as one rank of an MPI job (check_rank.cpp). Returns the exit code all ranks agree on.
int run_check_mpi(const CheckOptions& o, const ReviewInputs& review);
#endif

}  // namespace cadclash::cli
