// `cadclash check` as one rank of an MPI job: the files read where the ranks need them, parts meshed
// where needed, the check split over the ranks (cmd_check_mpi.h, mpi_inputs.h).
#include "check_options.h"

#if CADCLASH_HAS_MPI
#include "cmd_check_mpi.h"
#include "mpi_inputs.h"

#include <iostream>
#include <sstream>
#include <streambuf>

namespace cadclash::cli {
namespace {

// Part meshing (cmd_check_mpi.h) on what the ranks read without triangles, printing `messages` (what
// the import said); when part meshing cannot give the eager import's model, every rank imports
// eagerly. False (rank 0 says why) when the ranks' eager imports differ.
bool mesh_parts_or_import(const CheckOptions& o, ImportResult& imported, const std::string& messages,
                          const std::string& extra, DistributedInputs& inputs, MpiCheck& mpi) {
  std::optional<SceneSelection> sel;
  {
    std::ostringstream quiet;  // check_imported says why a selection fails
    std::streambuf* err = std::cerr.rdbuf(quiet.rdbuf());
    sel = scene_selection(imported.model, o);
    std::cerr.rdbuf(err);
  }
  if (sel && mpi.mesh_parts_where_needed(imported.model, *sel, collide_options(o), inputs)) {
    std::cerr << messages;
    return true;
  }
  imported = import_inputs(o.in);
  inputs.read_everywhere();
  return mpi.same_input_everywhere(imported.model, imported.diagnostics, extra);
}

}  // namespace

// `cadclash check` as one rank of an MPI job. MPI starts before the files are read, although the
// isolated CAD reader forks a child per file (import/src/isolated_run.cpp): part meshing reads files
// after the plan, which needs MPI, and the import's descriptions are exchanged over it. Forking
// after MPI_Init is safe with the transports Open MPI 4.1 uses on a node and between nodes without
// RDMA (vader shared memory, tcp, self): the child never calls MPI, touches none of Open MPI's
// memory or sockets and leaves with _exit, and Open MPI arms its fork warning (mpi_warn_on_fork,
// opal_warn_fork) only in the openib BTL, whose registered (pinned) memory a forked child's
// copy-on-write pages can corrupt (Open MPI FAQ, "OpenFabrics: fork"; in 4.1.4 only
// mca_btl_openib.so calls opal_warn_fork). vader copies between processes by address (CMA,
// process_vm_readv), which copy-on-write does not disturb. On InfiniBand (openib, or UCX) it is as
// safe as the verbs stack's fork support (ibv_fork_init; Linux 5.12+ copies pinned pages at fork);
// --no-isolation reads without forking there.
int run_check_mpi(const CheckOptions& o, const ReviewInputs& review) {
  // Files are read where needed unless --import-time-limit may cut a read short: what a read
  // finishes within the limit depends on the machine's speed and load (import_cache.cpp does not
  // even cache such a result), so a rank reading a file again for its share could get another
  // scene than the file's reader described. Without the limit, an eager check meshes whole parts
  // where needed (part meshing; under the limit it could not: the limit covers the import's
  // meshing, not meshing after it) and --lazy tessellates face by face in the check.
  const bool where_needed = o.in.import_time_limit <= 0.0;
  const bool by_parts = where_needed && !o.in.lazy;
  MpiCheck mpi;
  DistributedInputs inputs;
  // What the import says on stderr waits, under part meshing, until part meshing is known to stand.
  std::ostringstream import_messages;
  ImportResult imported;
  if (where_needed) {
    InputOptions lazy = o.in;
    lazy.lazy = true;
    std::streambuf* err = by_parts ? std::cerr.rdbuf(import_messages.rdbuf()) : nullptr;
    imported = finish_inputs(lazy, inputs.read(lazy, MPI_COMM_WORLD));
    if (by_parts) std::cerr.rdbuf(err);
  } else {
    imported = import_inputs(o.in);
  }
  std::optional<std::vector<TrajectoryRow>> rows = std::vector<TrajectoryRow>{};
  if (!o.path_csv.empty()) rows = read_trajectory(o.path_csv);
  // Every rank must hold the same input before any further collective, or the ranks would wait for
  // each other.
  const std::string trajectory = rows ? std::to_string(rows->size()) + " trajectory rows" : "unreadable trajectory";
  if (!mpi.same_input_everywhere(imported.model, imported.diagnostics, trajectory)) {
    std::cerr << import_messages.str();
    return kExitInputError;
  }
  if (by_parts && !mesh_parts_or_import(o, imported, import_messages.str(), trajectory, inputs, mpi))
    return kExitInputError;
  const int code = rows ? check_imported(o, imported, *rows, review, &mpi, where_needed ? &inputs : nullptr)
                        : kExitInputError;
  mpi.note_files_read(where_needed ? inputs.files_read() : o.in.files.size(), o.in.files.size(),
                      where_needed ? inputs.read_seconds() : imported.seconds);
  if (mpi.rank() == 0 && !o.in.quiet) mpi.print_ranks(std::cerr);
  return mpi.agree(code);
}

}  // namespace cadclash::cli
#endif
