#include "matching/sequence.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <exception>
#include <limits>
#include <stdexcept>
#include <thread>

#include "OpenABLE/base/threading.h"
#include "matching/distances.h"
#include "matching/large_matrix.h"

namespace openable {
void CheckTraversalStarts(const std::vector<int>& starts, int n, const char* what) {
  int prev = -1;
  for (const int v : starts) {
    if (v <= prev || v < 0 || (prev < 0 && v != 0) || (n > 0 && v >= n))
      throw std::logic_error(std::string(what) + ": " + std::to_string(v) +
                             " is not valid; expected first frames increasing from 0 and below "
                             "the " +
                             std::to_string(n) + " frames");
    prev = v;
  }
}

namespace {

// first[x] = first frame of the traversal holding x; last[x] = its last frame.
struct Traversals {
  std::vector<int> first, last;
};

Traversals Bounds(const std::vector<int>& starts, int n, const char* what) {
  CheckTraversalStarts(starts, n, (std::string("SequenceDistances: ") + what + " starts").c_str());
  std::vector<int> s = starts.empty() ? std::vector<int>{0} : starts;
  Traversals t;
  t.first.resize(static_cast<size_t>(n));
  t.last.resize(static_cast<size_t>(n));
  for (size_t k = 0; k < s.size(); ++k) {
    const int begin = std::min(s[k], n);
    const int end = k + 1 < s.size() ? std::min(s[k + 1], n) : n;
    for (int x = begin; x < end; ++x) {
      t.first[static_cast<size_t>(x)] = begin;
      t.last[static_cast<size_t>(x)] = end - 1;
    }
  }
  return t;
}

// A barrier for a handful of threads that meet once per row (thousands of times per run):
// spinning costs far less than a condition variable at that rate. Written by hand: std::barrier
// is C++20.
class SpinBarrier {
 public:
  explicit SpinBarrier(int threads) : threads_(threads) {}
  void Wait() {
    const int generation = generation_.load(std::memory_order_acquire);
    if (arrived_.fetch_add(1, std::memory_order_acq_rel) + 1 == threads_) {
      arrived_.store(0, std::memory_order_relaxed);
      generation_.store(generation + 1, std::memory_order_release);
      return;
    }
    for (int spins = 0; generation_.load(std::memory_order_acquire) == generation; ++spins)
      if (spins > 1000) std::this_thread::yield();
  }

 private:
  const int threads_;
  std::atomic<int> arrived_{0};
  std::atomic<int> generation_{0};
};

// One row i of the running sums over columns [c0, c1): `row` holds D(i, j) and receives S(i, j);
// `keep` receives D(i, j) (row i of the ring); `old` is row i - L of D, read only where the
// diagonal holds L earlier terms; `prev` and `cur` are the raw (unscaled, double) sums of rows
// i - 1 and i; `ti` the steps back within the traversal of i and steps(j) those within the
// traversal of column j. Shared by the sweep and SequenceRowSums, so both give the same floats.
template <typename Steps>
inline void SumRow(float* row, float* keep, const float* old, const double* prev, double* cur,
                   int c0, int c1, int ti, int L, bool reverse, SequencePartial partial,
                   Steps steps) {
  for (int j = c0; j < c1; ++j) {
    const float dij = row[j];
    keep[j] = dij;
    // Steps the run can go back from (i, j) without leaving either traversal.
    const int t = std::min(ti, steps(j));
    double w = dij;
    if (t > 0) {
      w += prev[reverse ? j + 1 : j - 1];
      if (t >= L) w -= old[reverse ? j + L : j - L];
    }
    cur[j] = w;
    row[j] = ScaleSequenceSum(w, SequenceTerms(L, t), L, partial);
  }
}

// One direction, in place. step = +1: diagonals (predecessor (i-1, j-1)); -1: anti-diagonals
// (predecessor (i-1, j+1)).
void Sweep(cv::Mat1f& d, int L, const Traversals& rows, const Traversals& cols, bool reverse,
           int threads, SequencePartial partial) {
  const int n = d.rows, m = d.cols;
  // ring[r % R] holds row r of D once row r has been overwritten by S. Row i - L is read only
  // when L < n, so R = min(L, n) + 1 slots suffice (and i - L sits in slot (i + 1) % R).
  const int R = std::min(L, n) + 1;
  std::vector<float> ring(static_cast<size_t>(R) * m);
  std::vector<double> prev(static_cast<size_t>(m)), cur(static_cast<size_t>(m));
  threads = std::max(1, std::min(threads, m / 256 + 1));
  SpinBarrier barrier(threads);
  // A stop asked by the host's interrupt check (Ctrl-C in Python, threading.h), run by the
  // thread of the first columns between rows at most every 50 ms: a sweep over a large matrix
  // takes seconds, and every thread must leave at the same row, or the others would wait at
  // the barrier for ever. The flag is set before the first barrier of a row and read between
  // the two, so all threads see it at the same row.
  std::atomic<bool> stop{false};
  std::exception_ptr stopped;
  auto last_check = std::chrono::steady_clock::now();
  // Columns are split evenly between the threads, which meet at the barrier once per row.
  auto work = [&](int c0, int c1) {
    for (int i = 0; i < n; ++i) {
      float* row = d.ptr<float>(i);
      float* keep = &ring[static_cast<size_t>(i % R) * m];
      const float* old = &ring[static_cast<size_t>((i + 1) % R) * m];  // row i - L
      const int ti = i - rows.first[static_cast<size_t>(i)];  // steps back within i's traversal
      SumRow(row, keep, old, prev.data(), cur.data(), c0, c1, ti, L, reverse, partial, [&](int j) {
        return reverse ? cols.last[static_cast<size_t>(j)] - j
                       : j - cols.first[static_cast<size_t>(j)];
      });
      if (c0 == 0) {
        const auto now = std::chrono::steady_clock::now();
        if (now - last_check >= std::chrono::milliseconds(50)) {
          last_check = now;
          try {
            CheckForInterrupt();
          } catch (...) {
            stopped = std::current_exception();
            stop.store(true, std::memory_order_relaxed);
          }
        }
      }
      barrier.Wait();  // every column of row i done before anyone reads it as row i - 1
      // Read between the two barriers: the flag can only change before the first one.
      const bool leave = stop.load(std::memory_order_relaxed);
      if (c0 == 0) std::swap(prev, cur);
      barrier.Wait();
      if (leave) return;
    }
  };
  RunOnThreads(threads, [&](int t) {
    work(static_cast<int>(static_cast<long>(m) * t / threads),
         static_cast<int>(static_cast<long>(m) * (t + 1) / threads));
  });
  if (stopped) std::rethrow_exception(stopped);
}

// FillAheadCells on known traversals.
void FillAhead(cv::Mat1f& s, int L, const Traversals& rows, const Traversals& cols, bool reverse) {
  if (L <= 1) return;
  const int n = s.rows, m = s.cols;
  // Columns that can go fewer than L - 1 steps back: the first L - 1 of each traversal along
  // diagonals, the last L - 1 along anti-diagonals.
  std::vector<int> edge;
  for (int j = 0; j < m; ++j) {
    const int tj =
        reverse ? cols.last[static_cast<size_t>(j)] - j : j - cols.first[static_cast<size_t>(j)];
    if (tj < L - 1) edge.push_back(j);
  }
  const float inf = std::numeric_limits<float>::infinity();
  for (int i = 0; i < n; ++i) {
    const int ti = i - rows.first[static_cast<size_t>(i)];
    const int fi = rows.last[static_cast<size_t>(i)] - i;
    auto fill = [&](int j) {
      const int first = cols.first[static_cast<size_t>(j)];
      const int last = cols.last[static_cast<size_t>(j)];
      const int t = std::min(ti, reverse ? last - j : j - first);
      if (t >= L - 1) return;
      const int f = std::min(fi, reverse ? j - first : last - j);
      const int shift = AheadShift(L, t, f);
      s(i, j) = shift < 0 ? inf : s(i + shift, reverse ? j - shift : j + shift);
    };
    if (ti < L - 1) {
      for (int j = 0; j < m; ++j) fill(j);
    } else {
      for (const int j : edge) fill(j);
    }
  }
}

}  // namespace

void FillAheadCells(cv::Mat1f& s, int sequence_length, const std::vector<int>& row_starts,
                    const std::vector<int>& col_starts, bool reverse) {
  if (sequence_length < 1) throw std::logic_error("FillAheadCells: sequence length < 1");
  FillAhead(s, sequence_length, Bounds(row_starts, s.rows, "row"),
            Bounds(col_starts, s.cols, "column"), reverse);
}

void SequenceDistancesInPlace(cv::Mat1f& d, int sequence_length, const std::vector<int>& row_starts,
                              const std::vector<int>& col_starts, SequenceDirection direction,
                              int threads, SequencePartial partial) {
  if (sequence_length < 1) throw std::logic_error("SequenceDistances: sequence length < 1");
  const Traversals rows = Bounds(row_starts, d.rows, "row");
  const Traversals cols = Bounds(col_starts, d.cols, "column");
  if (sequence_length == 1 || d.empty()) return;
  threads = EffectiveThreads(threads);
  const bool ahead = partial == SequencePartial::kAhead;
  if (direction == SequenceDirection::kBoth) {
    cv::Mat1f reverse = LargeMatrix(d.rows, d.cols);
    d.copyTo(reverse);
    Sweep(d, sequence_length, rows, cols, false, threads, partial);
    Sweep(reverse, sequence_length, rows, cols, true, threads, partial);
    if (ahead) {
      FillAhead(d, sequence_length, rows, cols, false);
      FillAhead(reverse, sequence_length, rows, cols, true);
    }
    cv::min(cv::InputArray(d), cv::InputArray(reverse), cv::OutputArray(d));
    return;
  }
  const bool reverse = direction == SequenceDirection::kReverse;
  Sweep(d, sequence_length, rows, cols, reverse, threads, partial);
  if (ahead) FillAhead(d, sequence_length, rows, cols, reverse);
}

cv::Mat1f SequenceDistances(const cv::Mat1f& d, int sequence_length,
                            const std::vector<int>& row_starts, const std::vector<int>& col_starts,
                            SequenceDirection direction, int threads, SequencePartial partial) {
  cv::Mat1f out = LargeMatrix(d.rows, d.cols);
  d.copyTo(out);
  SequenceDistancesInPlace(out, sequence_length, row_starts, col_starts, direction, threads,
                           partial);
  return out;
}

float SequenceCellDistance(const cv::Mat& queries, int q, const cv::Mat& references, int j,
                           int sequence_length, bool reverse, double* largest_term,
                           SequencePartial partial) {
  int steps_back = std::min(q, reverse ? references.rows - 1 - j : j);
  if (partial == SequencePartial::kAhead && steps_back < sequence_length - 1) {
    const int steps_forward = std::min(queries.rows - 1 - q, reverse ? j : references.rows - 1 - j);
    const int shift = AheadShift(sequence_length, steps_back, steps_forward);
    if (shift < 0) return std::numeric_limits<float>::infinity();
    q += shift;
    j += reverse ? -shift : shift;
    steps_back += shift;
  }
  const int terms = SequenceTerms(sequence_length, steps_back);
  double sum = 0;
  for (int k = 0; k < terms; ++k) {
    const double d = RowDistance(queries, q - k, references, reverse ? j + k : j - k);
    if (largest_term != nullptr && d > *largest_term) *largest_term = d;
    sum += d;
  }
  return ScaleSequenceSum(sum, terms, sequence_length, partial);
}

SequenceRowSums::SequenceRowSums(int sequence_length, SequencePartial partial)
    : length_(sequence_length), partial_(partial) {
  if (sequence_length < 1) throw std::logic_error("SequenceRowSums: sequence length < 1");
  if (partial == SequencePartial::kAhead)
    throw std::logic_error("SequenceRowSums: kAhead reads query frames not given yet");
  ring_.resize(static_cast<size_t>(sequence_length) + 1);
}

void SequenceRowSums::Restart() { rows_ = 0; }

void SequenceRowSums::Push(float* d, int columns, const std::vector<int>& col_starts) {
  const bool grows = columns == columns_ || columns == columns_ + 1;
  // New traversals only begin at new columns.
  bool extends = col_starts.size() >= starts_.size() &&
                 std::equal(starts_.begin(), starts_.end(), col_starts.begin());
  for (size_t k = starts_.size(); extends && k < col_starts.size(); ++k)
    extends = col_starts[k] >= columns_;
  if (rows_ > 0 && (!grows || !extends))
    throw std::logic_error("SequenceRowSums::Push: " + std::to_string(columns) + " columns after " +
                           std::to_string(columns_) +
                           ", or other traversals; expected as many "
                           "columns or one more, and the same traversals (Restart first)");
  CheckTraversalStarts(col_starts, columns + 1, "SequenceRowSums: column starts");
  if (rows_ == 0) columns_ = 0;
  starts_ = col_starts;
  if (length_ == 1) {  // S = D, as the sweep leaves it
    columns_ = columns;
    ++rows_;
    return;
  }
  first_.resize(static_cast<size_t>(columns));
  for (int j = columns_; j < columns; ++j) {
    int f = 0;
    for (const int s : starts_)
      if (s <= j) f = s;
    first_[static_cast<size_t>(j)] = f;
  }
  const int L = length_, R = L + 1, i = rows_;
  std::vector<float>& keep = ring_[static_cast<size_t>(i % R)];
  const std::vector<float>& old = ring_[static_cast<size_t>((i + 1) % R)];
  keep.resize(static_cast<size_t>(columns));
  cur_.resize(static_cast<size_t>(columns));
  SumRow(d, keep.data(), old.data(), prev_.data(), cur_.data(), 0, columns, i, L, false, partial_,
         [&](int j) { return j - first_[static_cast<size_t>(j)]; });
  std::swap(prev_, cur_);
  columns_ = columns;
  ++rows_;
}

}  // namespace openable
