// A run spread over several processes: `mpirun -np K Test_OpenABLE Config.txt` runs the same
// program and configuration K times and Open MPI connects them. Each process describes its share
// of the frames, the rows are gathered on every process, each computes its share of the query
// rows, and process 0 gathers the result and writes the outputs a single process writes. A step
// that can fail on one process only goes through Agree, so every process throws the same error;
// only process 0 speaks. Without mpirun MPI is never loaded (module libopenable_mpi.so,
// module_api.h). docs/distributed.md.
#pragma once

#include <cstdint>
#include <cstring>
#include <functional>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace openable {

// The error every process throws when a step failed on one of them (an InputError's message
// keeps its meaning: exit status 1).
class ClusterFailure : public std::runtime_error {
 public:
  ClusterFailure(const std::string& message, bool input_error)
      : std::runtime_error(message), input_error_(input_error) {}
  bool InputErrorCause() const { return input_error_; }

 private:
  bool input_error_;
};

class Cluster {
 public:
  // The processes of this run. The rank and count that mpirun (Open MPI, or a PMI launcher)
  // gives in the environment are read first; MPI itself is initialised by Connect(). Until
  // then (and in a library that never connects) the run is one process.
  static Cluster& Get();

  // As the launcher says (0 of 1 without one).
  int LaunchRank() const { return launch_rank_; }
  int LaunchSize() const { return launch_size_; }
  // As MPI says, once connected (0 of 1 otherwise).
  int Rank() const { return rank_; }
  int Size() const { return size_; }
  bool Distributed() const { return size_ > 1; }
  // "process 2 of 3"
  std::string Name(int rank) const;

  // Initialises MPI when the launcher started several processes. Throws InputError when the
  // build has no MPI (the module is missing).
  void Connect();
  // MPI_Finalize, when connected. Called once at the end of the program.
  void Disconnect();
  // Marks the end of the collective part of the run: a failure after it concerns this process
  // only (process 0 writing the outputs).
  void Release() { released_ = true; }
  // True while a failure on one process could leave the others waiting in a collective call.
  bool Collective() const { return Distributed() && connected_ && !released_; }
  // Ends every process at once (MPI_Abort): for a failure outside Agree while Collective().
  [[noreturn]] void Abort(int code);

  // Runs `step` on every process; when it threw on any of them, throws ClusterFailure on every
  // process with the message of the lowest failing process, followed by the process's name.
  // Collective. In one process, runs `step` and lets its exceptions through unchanged.
  void Agree(const std::function<void()>& step);

  // [first, last) of the share of `n` items of process `rank` (contiguous, in rank order, sizes
  // differing by at most one).
  std::pair<int, int> Share(int n, int rank) const;
  std::pair<int, int> Share(int n) const { return Share(n, rank_); }

  // The bytes of every process in rank order, on every process (AllGather) or on process 0
  // only (GatherToFirst: empty elsewhere); `sizes` receives each process's count. Collective.
  std::vector<char> AllGather(const std::vector<char>& mine,
                              std::vector<std::int64_t>* sizes = nullptr);
  std::vector<char> GatherToFirst(const std::vector<char>& mine,
                                  std::vector<std::int64_t>* sizes = nullptr);
  // The `bytes` at `mine` of every process, in rank order, into the `capacity` bytes at `into`
  // on process 0 (nullptr elsewhere), without an intermediate copy. Throws std::logic_error
  // on every process when the counts do not add up to `capacity`. Collective.
  void GatherInto(const char* mine, std::int64_t bytes, char* into, std::int64_t capacity);
  // The largest `value` of every process. Collective.
  double Max(double value);

 private:
  Cluster();
  // AllGather (root -1) and GatherToFirst (root 0).
  std::vector<char> Gather(const std::vector<char>& mine, int root,
                           std::vector<std::int64_t>* sizes);
  int launch_rank_ = 0, launch_size_ = 1;
  int rank_ = 0, size_ = 1;
  bool connected_ = false, released_ = false;
};

// Trivially copyable values to and from the byte buffers of Cluster.
template <typename T>
void AppendBytes(std::vector<char>& out, const T* data, std::size_t count) {
  static_assert(std::is_trivially_copyable<T>::value, "bytes of a trivially copyable type");
  const std::size_t at = out.size();
  out.resize(at + count * sizeof(T));
  if (count > 0) std::memcpy(out.data() + at, data, count * sizeof(T));
}

template <typename T>
std::vector<T> FromBytes(const char* data, std::int64_t bytes) {
  static_assert(std::is_trivially_copyable<T>::value, "bytes of a trivially copyable type");
  std::vector<T> out(static_cast<std::size_t>(bytes) / sizeof(T));
  if (!out.empty()) std::memcpy(out.data(), data, out.size() * sizeof(T));
  return out;
}

}  // namespace openable
