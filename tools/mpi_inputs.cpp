#include "mpi_inputs.h"

#include "cadclash/tessellate.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <system_error>

namespace cadclash::cli {

#if CADCLASH_HAS_MPI
namespace {

// A testing aid (tests/distributed/test_mpi_cli.cpp): with CADCLASH_TEST_SHOW_READS=1 every rank
// says on stderr which file it reads and why (ranks other than 0 are silent otherwise).
void show_read(int rank, int size, const std::string& path, const char* why) {
  static const bool on = [] {
    const char* v = std::getenv("CADCLASH_TEST_SHOW_READS");
    return v != nullptr && std::strcmp(v, "1") == 0;
  }();
  if (on) std::fprintf(stderr, "cadclash check: rank %d of %d reads '%s' (%s)\n", rank, size, path.c_str(), why);
}

void put_u64(std::string& out, std::uint64_t v) { out.append(reinterpret_cast<const char*>(&v), sizeof v); }

// A u64 at `at` of `in`, `at` moved past it; false when `in` is too short.
bool get_u64(const std::string& in, std::size_t& at, std::uint64_t& v) {
  if (in.size() - at < sizeof v) return false;
  std::memcpy(&v, in.data() + at, sizeof v);
  at += sizeof v;
  return true;
}

[[noreturn]] void garbled(int rank, const std::string& what, MPI_Comm comm) {
  std::fprintf(stderr, "cadclash check: rank %d: %s\n", rank, what.c_str());
  MPI_Abort(comm, 1);
  std::abort();
}

}  // namespace

ImportResult DistributedInputs::read(const InputOptions& in, MPI_Comm comm) {
  const auto start = std::chrono::steady_clock::now();
  in_ = in;
  MPI_Comm_rank(comm, &rank_);
  MPI_Comm_size(comm, &size_);
  const std::size_t n = in.files.size();
  read_.assign(n, 0);
  described_.assign(n, {});
  if (n == 1) {  // every rank's share lies in it: read everywhere at once, as one process would
    reader_ = {rank_};
    read_[0] = 1;
    show_read(rank_, size_, in.files[0], "the only file");
    ImportResult one = import_files(in.files, import_options(in));
    read_seconds_ += one.seconds;
    share_edges_ = brep_parts_share_edges(one.model);
    first_part_ = {0, static_cast<PartId>(one.model.parts.size())};
    part_reader_.clear();  // parts no pair reaches: spread by surfaces (mesh_owners)
    return one;
  }

  // Rank 0's sizes decide for every rank: a host that sees other sizes must not choose other readers.
  std::string sizes;
  if (rank_ == 0)
    for (const std::string& path : in.files) {
      std::error_code ec;
      const std::uintmax_t bytes = std::filesystem::file_size(path, ec);
      put_u64(sizes, ec ? 0 : static_cast<std::uint64_t>(bytes));
    }
  sizes = allgather_bytes(sizes, comm).front();
  std::vector<std::uint64_t> file_bytes(n, 0);
  std::size_t at = 0;
  for (std::uint64_t& b : file_bytes)
    if (!get_u64(sizes, at, b)) garbled(rank_, "rank 0's file sizes are cut short", comm);
  reader_ = assign_readers(file_bytes, size_);

  std::vector<std::string> paths;
  std::vector<std::size_t> mine;
  for (std::size_t f = 0; f < n; ++f)
    if (reader_[f] == rank_) {
      mine.push_back(f);
      paths.push_back(in.files[f]);
      show_read(rank_, size_, in.files[f], "its reader");
    }
  std::vector<ImportResult> each(n);
  std::string shared;  // per file read here: its index, its description's length, the description
  int edges = 0;
  if (!paths.empty()) {
    const auto read_start = std::chrono::steady_clock::now();
    std::vector<ImportResult> got = import_each_file(paths, import_options(in));
    read_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - read_start).count();
    for (std::size_t k = 0; k < mine.size(); ++k) {
      const std::string d = import_description(got[k]);
      put_u64(shared, mine[k]);
      put_u64(shared, d.size());
      shared += d;
      edges = edges || brep_parts_share_edges(got[k].model) ? 1 : 0;
      each[mine[k]] = std::move(got[k]);
      read_[mine[k]] = 1;
    }
  }
  MPI_Allreduce(MPI_IN_PLACE, &edges, 1, MPI_INT, MPI_MAX, comm);
  share_edges_ = edges != 0;
  const std::vector<std::string> all = allgather_bytes(shared, comm);
  for (int r = 0; r < size_; ++r) {
    const std::string& from = all[static_cast<std::size_t>(r)];
    for (std::size_t at_r = 0; at_r < from.size();) {
      std::uint64_t f = 0, len = 0;
      if (!get_u64(from, at_r, f) || !get_u64(from, at_r, len) || f >= n || from.size() - at_r < len)
        garbled(rank_, "the descriptions of rank " + std::to_string(r) + " are cut short", comm);
      if (r != rank_) described_[f] = from.substr(at_r, len);
      at_r += len;
    }
  }
  first_part_.assign(n + 1, 0);
  for (std::size_t f = 0; f < n; ++f) {
    if (!read_[f]) {
      std::string why;
      if (!import_from_description(described_[f], each[f], why))
        garbled(rank_, "the description of " + in.files[f] + " from rank " + std::to_string(reader_[f]) +
                           " is unreadable: " + why,
                comm);
    }
    first_part_[f + 1] = first_part_[f] + static_cast<PartId>(each[f].model.parts.size());
  }
  part_reader_.clear();
  for (std::size_t f = 0; f < n; ++f) part_reader_.resize(first_part_[f + 1], reader_[f]);
  ImportResult scene = merge_file_imports(in.files, std::move(each));
  scene.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return scene;
}

bool DistributedInputs::read_files_of(Model& model, std::span<const PartId> parts) {
  std::vector<std::size_t> files;
  for (PartId p : parts) {
    const auto f = static_cast<std::size_t>(std::upper_bound(first_part_.begin(), first_part_.end(), p) -
                                            first_part_.begin()) - 1;
    if (f < read_.size() && !read_[f] && std::find(files.begin(), files.end(), f) == files.end()) files.push_back(f);
  }
  if (files.empty()) return true;
  std::sort(files.begin(), files.end());
  std::vector<std::string> paths;
  for (std::size_t f : files) {
    paths.push_back(in_.files[f]);
    show_read(rank_, size_, in_.files[f], "its share reaches it");
  }
  const auto start = std::chrono::steady_clock::now();
  std::vector<ImportResult> got = import_each_file(paths, import_options(in_));
  read_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  bool same = true;
  for (std::size_t k = 0; k < files.size(); ++k) {
    const std::size_t f = files[k];
    ImportResult& r = got[k];
    // What the reader sent, but for what may differ between two reads of the same bytes: the cache's
    // use, warnings and timings.
    ImportResult sent;
    std::string why;
    if (!import_from_description(described_[f], sent, why)) return false;
    r.diagnostics = sent.diagnostics;
    r.files = sent.files;
    r.seconds = sent.seconds;
    if (import_description(r) != described_[f]) {
      std::fprintf(stderr,
                   "cadclash check: rank %d read %s differently from rank %d, its reader: are the files the same "
                   "on every host?\n",
                   rank_, in_.files[f].c_str(), reader_[f]);
      same = false;
      continue;
    }
    for (PartId p = 0; p < r.model.parts.size(); ++p) model.parts[first_part_[f] + p].source = r.model.parts[p].source;
    read_[f] = 1;
    described_[f] = std::string();
  }
  return same;
}

std::size_t DistributedInputs::files_read() const {
  return static_cast<std::size_t>(std::count(read_.begin(), read_.end(), char{1}));
}
#endif

}  // namespace cadclash::cli
