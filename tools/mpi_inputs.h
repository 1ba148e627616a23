// `cadclash check` under mpirun (part meshing or --lazy; not with --import-time-limit): each input
// file read by one rank (its reader), the others told what it holds without the exact faces, and a
// file read again on a rank only when that rank's share of the work reaches one of its parts, or
// on rank 0 when --volume measures a clash of its parts or --html shows them
// (cadclash/distributed.h, "Files read where they are needed"). Exists with CADCLASH_WITH_MPI only.
#pragma once

#include "cli_common.h"

#include "cadclash/distributed.h"

#include <cstddef>
#include <span>
#include <string>
#include <vector>

namespace cadclash::cli {

#if CADCLASH_HAS_MPI
class DistributedInputs {
 public:
  // Collective over `comm`: reads (as import_files with `in`, which asks for a lazy import) the files
  // this rank reads, shares their descriptions (import_description) and returns the scene
  // import_files gives, the same on every rank, in which the B-rep parts of files read elsewhere have
  // stand-in sources (default deflection only). Readers: assign_readers by rank 0's file sizes. One
  // file is read by every rank (OCCT reads a STEP whole, and every rank's share lies in it).
  ImportResult read(const InputOptions& in, MPI_Comm comm);

  // The files holding `parts` that were not read here are read now and their parts given their
  // exact faces (the surfaces already hold what the reader sent). False, after saying so on stderr,
  // when a file reads differently here than on its reader (a different file on this host).
  bool read_files_of(Model& model, std::span<const PartId> parts);
  // After an eager import on every rank (part meshing gave up): every file is read here.
  void read_everywhere() { read_.assign(read_.size(), 1); }

  // Per part of the scene, the reader of its file (PartMeshing::home).
  const std::vector<int>& part_readers() const { return part_reader_; }
  // Two B-rep parts of one file share an edge (on the rank that read it): part meshing cannot be
  // the eager import (brep_parts_share_edges).
  bool parts_share_edges() const { return share_edges_; }
  std::size_t files_read() const;
  std::size_t files() const { return read_.size(); }
  // Wall seconds this rank spent reading files (read and read_files_of).
  double read_seconds() const { return read_seconds_; }

 private:
  InputOptions in_;
  int rank_ = 0, size_ = 1;
  std::vector<int> reader_;          // per file
  std::vector<PartId> first_part_;   // per file, and the scene's part count at the end
  std::vector<int> part_reader_;     // per part
  std::vector<char> read_;           // per file: read here (its B-rep parts have their exact faces)
  std::vector<std::string> described_;  // per file not read here: its reader's description
  bool share_edges_ = false;
  double read_seconds_ = 0.0;
};
#endif

}  // namespace cadclash::cli
