// Module libopenable_mpi.so (see module_loader.h and module_api.h): the few MPI calls a run
// spread over processes needs (OpenABLE/cluster/cluster.h). A module, so that a single-process run
// does not load Open MPI (and its dozens of libraries) at start-up.
//
// MPI counts are ints: buffers of any size go in pieces of at most kPiece bytes, point to point
// to the root and then broadcast piece by piece, rather than through MPI_Gatherv and a derived
// type (simpler to get right for sizes that differ per process and exceed 2^31 in all).
#include <mpi.h>

#include <algorithm>
#include <cstdint>
#include <vector>

#include "OpenABLE/io/module_api.h"

namespace {

constexpr std::int64_t kPiece = std::int64_t{1} << 30;

void SendAll(const char* data, std::int64_t bytes, int to) {
  for (std::int64_t off = 0; off < bytes; off += kPiece)
    MPI_Send(data + off, static_cast<int>(std::min(kPiece, bytes - off)), MPI_BYTE, to, 1,
             MPI_COMM_WORLD);
}

void ReceiveAll(char* data, std::int64_t bytes, int from) {
  for (std::int64_t off = 0; off < bytes; off += kPiece)
    MPI_Recv(data + off, static_cast<int>(std::min(kPiece, bytes - off)), MPI_BYTE, from, 1,
             MPI_COMM_WORLD, MPI_STATUS_IGNORE);
}

}  // namespace

extern "C" void openable_mpi_init(int* rank, int* size) {
  int provided = 0;
  MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
  MPI_Comm_rank(MPI_COMM_WORLD, rank);
  MPI_Comm_size(MPI_COMM_WORLD, size);
}

extern "C" void openable_mpi_finalize() {
  int done = 0;
  MPI_Finalized(&done);
  if (!done) MPI_Finalize();
}

extern "C" void openable_mpi_abort(int code) { MPI_Abort(MPI_COMM_WORLD, code); }

extern "C" void openable_mpi_gather(const std::vector<char>& mine, int root, std::vector<char>& all,
                                    std::vector<std::int64_t>& sizes) {
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  const int at = root < 0 ? 0 : root;
  const std::int64_t bytes = static_cast<std::int64_t>(mine.size());
  sizes.assign(static_cast<size_t>(size), 0);
  MPI_Allgather(&bytes, 1, MPI_INT64_T, sizes.data(), 1, MPI_INT64_T, MPI_COMM_WORLD);
  std::int64_t total = 0;
  for (const std::int64_t s : sizes) total += s;
  all.clear();
  if (rank == at) {
    all.resize(static_cast<size_t>(total));
    std::int64_t off = 0;
    for (int r = 0; r < size; ++r) {
      if (r == rank)
        std::copy(mine.begin(), mine.end(), all.begin() + off);
      else
        ReceiveAll(all.data() + off, sizes[static_cast<size_t>(r)], r);
      off += sizes[static_cast<size_t>(r)];
    }
  } else {
    SendAll(mine.data(), bytes, at);
  }
  if (root >= 0) return;
  all.resize(static_cast<size_t>(total));
  for (std::int64_t off = 0; off < total; off += kPiece)
    MPI_Bcast(all.data() + off, static_cast<int>(std::min(kPiece, total - off)), MPI_BYTE, at,
              MPI_COMM_WORLD);
}

extern "C" bool openable_mpi_gather_into(const char* mine, std::int64_t bytes, char* into,
                                         std::int64_t capacity) {
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  std::vector<std::int64_t> sizes(static_cast<size_t>(size), 0);
  MPI_Allgather(&bytes, 1, MPI_INT64_T, sizes.data(), 1, MPI_INT64_T, MPI_COMM_WORLD);
  std::int64_t total = 0;
  for (const std::int64_t s : sizes) total += s;
  // Every process sees the same counts, so all agree to skip the transfer when they do not
  // add up to what process 0 holds.
  std::int64_t expected = rank == 0 ? capacity : 0;
  MPI_Bcast(&expected, 1, MPI_INT64_T, 0, MPI_COMM_WORLD);
  if (total != expected) return false;
  if (rank != 0) {
    SendAll(mine, bytes, 0);
    return true;
  }
  std::int64_t off = 0;
  for (int r = 0; r < size; ++r) {
    if (r == 0)
      std::copy(mine, mine + bytes, into);
    else
      ReceiveAll(into + off, sizes[static_cast<size_t>(r)], r);
    off += sizes[static_cast<size_t>(r)];
  }
  return true;
}

extern "C" double openable_mpi_max(double value) {
  double out = value;
  MPI_Allreduce(&value, &out, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  return out;
}
