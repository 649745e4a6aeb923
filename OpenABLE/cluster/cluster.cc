#include "OpenABLE/cluster/cluster.h"

#include <cstdlib>
#include <cstring>
#include <string>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/module_loader.h"
#include "OpenABLE/io/module_api.h"

namespace openable {
namespace {

// The rank and size a launcher gives its processes: Open MPI's mpirun, or a PMI launcher
// (MPICH's Hydra, Slurm's srun). -1 when absent or not a number.
int EnvironmentNumber(const char* const* names) {
  for (const char* const* n = names; *n != nullptr; ++n) {
    const char* v = std::getenv(*n);
    if (v == nullptr || *v == '\0') continue;
    char* end = nullptr;
    const long x = std::strtol(v, &end, 10);
    if (*end == '\0' && x >= 0 && x < (1L << 30)) return static_cast<int>(x);
  }
  return -1;
}

template <typename F>
F Symbol(const char* name) {
  return reinterpret_cast<F>(ModuleSymbol("mpi", name));
}

}  // namespace

Cluster& Cluster::Get() {
  static Cluster cluster;
  return cluster;
}

Cluster::Cluster() {
  static const char* const kRank[] = {"OMPI_COMM_WORLD_RANK", "PMIX_RANK", "PMI_RANK", nullptr};
  static const char* const kSize[] = {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", nullptr};
  const int rank = EnvironmentNumber(kRank), size = EnvironmentNumber(kSize);
  if (size > 1 && rank >= 0 && rank < size) launch_rank_ = rank, launch_size_ = size;
}

std::string Cluster::Name(int rank) const {
  return "process " + std::to_string(rank) + " of " + std::to_string(size_);
}

void Cluster::Connect() {
  if (launch_size_ < 2 || connected_) return;
  OpenableMpiInit init = nullptr;
  try {
    init = Symbol<OpenableMpiInit>("openable_mpi_init");
  } catch (const InputError&) {
    throw InputError("mpirun started " + std::to_string(launch_size_) +
                     " processes, but this build of OpenABLE has no MPI (its module "
                     "libopenable_mpi.so cannot be loaded); expected one process, or "
                     "OpenABLE built with Open MPI installed (libopenmpi-dev, "
                     "docs/distributed.md)");
  }
  init(&rank_, &size_);
  connected_ = true;
}

void Cluster::Disconnect() {
  if (!connected_) return;
  Symbol<OpenableMpiFinalize>("openable_mpi_finalize")();
  connected_ = false;
  rank_ = 0, size_ = 1;
}

void Cluster::Abort(int code) {
  if (connected_) Symbol<OpenableMpiAbort>("openable_mpi_abort")(code);
  std::_Exit(code);
}

void Cluster::Agree(const std::function<void()>& step) {
  if (!Distributed()) {  // one process: its errors as they are
    step();
    return;
  }
  // Each process's outcome: a kind byte (0 fine, 1 InputError, 2 other) and its message.
  std::vector<char> mine(1, 0);
  try {
    step();
  } catch (const ClusterFailure& e) {
    mine[0] = e.InputErrorCause() ? 1 : 2;
    const std::string m = e.what();
    mine.insert(mine.end(), m.begin(), m.end());
  } catch (const InputError& e) {
    mine[0] = 1;
    const std::string m = e.what();
    mine.insert(mine.end(), m.begin(), m.end());
  } catch (const std::exception& e) {
    mine[0] = 2;
    const std::string m = e.what();
    mine.insert(mine.end(), m.begin(), m.end());
  }
  std::vector<std::int64_t> sizes;
  const std::vector<char> all = AllGather(mine, &sizes);
  std::int64_t off = 0;
  for (int r = 0; r < size_; ++r) {
    const std::int64_t n = sizes[static_cast<size_t>(r)];
    if (n > 0 && all[static_cast<size_t>(off)] != 0)
      throw ClusterFailure(
          std::string(all.begin() + off + 1, all.begin() + off + n) + " (" + Name(r) + ")",
          all[static_cast<size_t>(off)] == 1);
    off += n;
  }
}

std::pair<int, int> Cluster::Share(int n, int rank) const {
  const std::int64_t k = size_;
  return {static_cast<int>(n * static_cast<std::int64_t>(rank) / k),
          static_cast<int>(n * static_cast<std::int64_t>(rank + 1) / k)};
}

std::vector<char> Cluster::Gather(const std::vector<char>& mine, int root,
                                  std::vector<std::int64_t>* sizes) {
  std::vector<std::int64_t> counts;
  std::vector<char> all;
  if (!Distributed()) {
    all = mine;
    counts = {static_cast<std::int64_t>(mine.size())};
  } else {
    Symbol<OpenableMpiGather>("openable_mpi_gather")(mine, root, all, counts);
  }
  if (sizes != nullptr) *sizes = counts;
  return all;
}

std::vector<char> Cluster::AllGather(const std::vector<char>& mine,
                                     std::vector<std::int64_t>* sizes) {
  return Gather(mine, -1, sizes);
}

std::vector<char> Cluster::GatherToFirst(const std::vector<char>& mine,
                                         std::vector<std::int64_t>* sizes) {
  return Gather(mine, 0, sizes);
}

void Cluster::GatherInto(const char* mine, std::int64_t bytes, char* into, std::int64_t capacity) {
  bool ok = true;
  if (!Distributed()) {
    ok = bytes == capacity;
    if (ok && bytes > 0) std::memcpy(into, mine, static_cast<size_t>(bytes));
  } else {
    ok = Symbol<OpenableMpiGatherInto>("openable_mpi_gather_into")(mine, bytes, into, capacity);
  }
  if (!ok) throw std::logic_error("Cluster::GatherInto: the shares do not add up");
}

double Cluster::Max(double value) {
  if (!Distributed()) return value;
  return Symbol<OpenableMpiMax>("openable_mpi_max")(value);
}

}  // namespace openable
