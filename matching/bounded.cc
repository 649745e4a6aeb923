#include "matching/bounded.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <limits>
#include <mutex>
#include <opencv2/core/hal/intrin.hpp>
#include <stdexcept>

#include "OpenABLE/base/option_checks.h"
#include "OpenABLE/base/threading.h"
#include "matching/distances.h"
#include "matching/large_matrix.h"

namespace openable {

void KeepRules::Check() const {
  CheckIntRange("Best_matches", best, 0, 100000);
  CheckIntAtLeast("Band_width", band, -1);
  CheckIntAtLeast("Exclusion", exclusion, 1);
}

MatchBlock BlockOf(const std::vector<int>& starts, int n) {
  MatchBlock b;
  if (starts.size() <= 1) {
    b.query_count = b.reference_count = n;
    return b;
  }
  if (starts.size() != 2) throw std::logic_error("BlockOf: one or two traversals");
  b.one_traversal = false;
  b.reference_first = 0;
  b.reference_count = starts[1];
  b.query_first = starts[1];
  b.query_count = n - starts[1];
  return b;
}

namespace {

// The kept matches of one query row (KeepRow), from slices of its columns given in increasing
// order (the whole row at once, or the tiles of TiledMatches). A max-heap keeps the k smallest
// cells by (distance, column), a set that does not depend on how the row is cut; ties go to the
// smaller column. For the ratio score it keeps the 2 window + 2 smallest: a kept match's best
// rival (the smallest cell more than window columns away) is among them, since at most
// 2 window + 1 cells lie within its window.
class SlicedKeep {
 public:
  SlicedKeep(int q, int references, const KeepRules& rules)
      : q_(q),
        limit_(rules.one_traversal ? std::min(references, q - rules.exclusion + 1) : references),
        kept_(KeptCells(rules)),
        rules_(&rules) {}

  // Cells kept per query: KeepRules::best, more for the ratio score.
  static int KeptCells(const KeepRules& rules) {
    return rules.score.kind == MatchScore::kRatio ? std::max(rules.best, 2 * rules.score.window + 2)
                                                  : rules.best;
  }

  // Columns [c0, c1) of the row, s[0] being column c0.
  void Add(const float* s, int c0, int c1) {
    const int end = std::min(c1, limit_);
    int j = c0;
    for (; kept_ > 0 && j < end && static_cast<int>(heap_.size()) < kept_; ++j)
      if (std::isfinite(s[j - c0])) Push(s[j - c0], j);
    if (kept_ > 0 && j < end) {
      // The heap is full: a cell enters when it is below the worst kept (a tie loses, being at
      // a larger column than every kept one). Most cells do not, so blocks of 16 cells are
      // first tested together, with OpenCV's universal intrinsics (SSE2 at the x86-64
      // baseline, NEON on ARM): the compiler leaves this test scalar when written as a loop.
      // NaN is never below; visit() decides exactly for the cells of a block that has one.
      float worst = heap_.front().first;
      const auto visit = [&](int c) {
        const float v = s[c - c0];
        if (v < worst && std::isfinite(v)) {
          std::pop_heap(heap_.begin(), heap_.end());
          heap_.back() = {v, c};
          std::push_heap(heap_.begin(), heap_.end());
          worst = heap_.front().first;
        }
      };
      for (; j + 16 <= end; j += 16) {
        const float* b = s + (j - c0);
        const cv::v_float32x4 w = cv::v_setall_f32(worst);
        const cv::v_float32x4 below = (cv::v_load(b) < w) | (cv::v_load(b + 4) < w) |
                                      (cv::v_load(b + 8) < w) | (cv::v_load(b + 12) < w);
        if (cv::v_check_any(below))
          for (int u = 0; u < 16; ++u) visit(j + u);
      }
      for (; j < end; ++j) visit(j);
    }
    if (rules_->band >= 0) {
      const int j0 = std::max(c0, q_ - rules_->band);
      const int j1 = std::min(c1, q_ + rules_->band + 1);
      for (int c = j0; c < j1; ++c)
        if (std::isfinite(s[c - c0])) band_.push_back({s[c - c0], c});
    }
  }

  // The row's matches, in KeepRow's order: ranks 1 .. k, then the band's other cells.
  void Finish(std::vector<Match>& out) {
    std::sort_heap(heap_.begin(), heap_.end());  // (distance, column) increasing
    const int ranked = std::min(rules_->best, static_cast<int>(heap_.size()));
    std::vector<std::pair<float, int>> candidates;
    const auto score = [&](float v, int j) {
      if (rules_->score.kind == MatchScore::kDistance) return v;
      // Among the kept cells and the match itself (in its own window: never its rival).
      candidates.assign(heap_.begin(), heap_.end());
      candidates.push_back({v, j});
      return ScoreOfCandidate(candidates, candidates.size() - 1, rules_->score);
    };
    for (int r = 0; r < ranked; ++r)
      out.push_back(
          {q_, heap_[r].second, heap_[r].first, r + 1, score(heap_[r].first, heap_[r].second)});
    for (const std::pair<float, int>& cell : band_) {
      // (Not a structured binding: C++17 does not let a lambda capture one; clang refuses.)
      const int j = cell.second;
      const bool is_ranked = std::any_of(heap_.begin(), heap_.begin() + ranked,
                                         [&](const auto& e) { return e.second == j; });
      if (!is_ranked) out.push_back({q_, j, cell.first, 0, score(cell.first, j)});
    }
  }

 private:
  void Push(float v, int j) {
    heap_.push_back({v, j});
    std::push_heap(heap_.begin(), heap_.end());
  }

  int q_, limit_, kept_;
  const KeepRules* rules_;
  std::vector<std::pair<float, int>> heap_;  // max-heap of (distance, column)
  std::vector<std::pair<float, int>> band_;  // (distance, column), columns increasing
};

}  // namespace

void KeepRow(const float* s, int references, int q, const KeepRules& rules,
             std::vector<Match>& out) {
  SlicedKeep keep(q, references, rules);
  keep.Add(s, 0, references);
  keep.Finish(out);
}

std::vector<Match> MatchesFromMatrix(const cv::Mat1f& normalized, const MatchBlock& block,
                                     const KeepRules& rules) {
  std::vector<Match> out;
  for (int q = 0; q < block.query_count; ++q)
    KeepRow(normalized.ptr<float>(block.query_first + q) + block.reference_first,
            block.reference_count, q, rules, out);
  return out;
}

namespace {

// The bulk of SequenceRow: the operations of its general case, in the same order (so every sum
// is the same double), on columns whose sums have all L terms. Compiled for AVX-512 and AVX2
// too and chosen at load time (GCC's target_clones), since the double arithmetic is a third
// of a bounded run at the SSE2 baseline.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
__attribute__((target_clones("avx512f", "avx2", "default")))
#endif
float SequenceBulk(const float* __restrict row, const float* __restrict old,
                   const double* __restrict prev, double* __restrict cur, float* __restrict out,
                   int n) {
  // The largest sum, compared as the integers of its bits (the sums are finite and >= 0, which
  // the bits order as the values): GCC vectorises an integer maximum, not a float one without
  // -ffinite-math-only.
  std::int32_t largest = 0;
  for (int j = 0; j < n; ++j) {
    const double w = static_cast<double>(row[j]) + prev[j] - static_cast<double>(old[j]);
    cur[j] = w;
    out[j] = static_cast<float>(w);
    std::int32_t bits = 0;
    std::memcpy(&bits, &out[j], sizeof bits);
    largest = bits > largest ? bits : largest;
  }
  float value = 0.0f;
  std::memcpy(&value, &largest, sizeof value);
  return value;
}

// The same in float, for distances that are small integers (Hamming, L1) whose sums stay below
// 2^24 (SumsAreExactInFloat): every partial sum is then exact in float as in double, so the
// sums are the same, with half the memory traffic of the running sums (the rows of 100k
// references do not stay in cache, and this loop is bound by memory).
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
__attribute__((target_clones("avx512f", "avx2", "default")))
#endif
float SequenceBulk(const float* __restrict row, const float* __restrict old,
                   const float* __restrict prev, float* __restrict cur, float* __restrict out,
                   int n) {
  std::int32_t largest = 0;  // as above
  for (int j = 0; j < n; ++j) {
    const float w = row[j] + prev[j] - old[j];
    cur[j] = w;
    out[j] = w;
    std::int32_t bits = 0;
    std::memcpy(&bits, &w, sizeof bits);
    largest = bits > largest ? bits : largest;
  }
  float value = 0.0f;
  std::memcpy(&value, &largest, sizeof value);
  return value;
}

// Whether the running sums of L distances of `metric` between rows of `width` bytes are
// integers below 2^24, exact in float: the largest distance (8 bits a byte for Hamming, 255 a
// byte for L1) times L.
bool SumsAreExactInFloat(Metric metric, int width, int L) {
  if (metric == Metric::kL2) return false;
  const double largest = (metric == Metric::kHamming ? 8.0 : 255.0) * width;
  return largest * L < 16777216.0;
}

// One row of the running sequence sum of one direction (the recurrence of
// SequenceDistancesInPlace, matching/sequence.cc, for one traversal of columns): w(i, j) =
// D(i, j) + w(i - 1, j -+ 1) - D(i - L, j -+ L), in double (or in float where that is exact:
// Acc), finished by ScaleSequenceSum. `steps` is how far row i can go back (i minus the first
// row of the rows summed), `prev` the sums of row i - 1, `old` row i - L of D (read only when
// steps >= L). Returns the largest finite value written to `out` (0 when none).
//
// Going forward, the row may be a slice of columns: the m cells start at column `first` of
// the traversal, and prev[-1] and old[-L .. -1] hold the cells of the columns before it (read
// where a sum reaches back there), so that a slice gives the same floats as the whole row.
template <typename Acc>
float SequenceRow(const float* row, const float* old, const Acc* prev, Acc* cur, float* out, int m,
                  int steps, int L, bool reverse, SequencePartial partial, int first = 0) {
  float largest = 0.0f;
  // Columns whose sums reach back a full L - 1 steps along the columns too: [L, m) going
  // forward, [0, m - L) in reverse; the other L columns go through the general case.
  const int bulk0 = reverse ? 0 : std::clamp(L - first, 0, m);
  const int bulk1 = reverse ? std::max(0, m - L) : m;
  auto general = [&](int j) {
    double w = row[j];
    const int t = std::min(steps, reverse ? m - 1 - j : first + j);
    if (t > 0) {
      w += prev[reverse ? j + 1 : j - 1];
      if (t >= L) w -= old[reverse ? j + L : j - L];
    }
    cur[j] = static_cast<Acc>(w);
    out[j] = ScaleSequenceSum(w, SequenceTerms(L, t), L, partial);
    if (std::isfinite(out[j])) largest = std::max(largest, out[j]);
  };
  if (steps < L) {
    for (int j = 0; j < m; ++j) general(j);
    return largest;
  }
  for (int j = 0; j < bulk0; ++j) general(j);
  largest = std::max(largest, SequenceBulk(row + bulk0, old + bulk0 + (reverse ? L : -L),
                                           prev + bulk0 + (reverse ? 1 : -1), cur + bulk0,
                                           out + bulk0, bulk1 - bulk0));
  for (int j = bulk1; j < m; ++j) general(j);
  return largest;
}

// The largest finite value of s[0, n), or `seen` when larger; `seen` >= 0. Compared as the
// integers of their bits, which order non-negative floats as their values and put +inf and
// NaN (0x7f800000 and above) and negative values (sign bit) outside [0, 0x7f800000): a
// reduction the compiler vectorises, where a float maximum with the NaN test stays scalar (the
// scalar loop took most of a 100k x 100k bounded run).
float LargestFinite(const float* s, int n, float seen) {
  std::int32_t best = 0;
  std::memcpy(&best, &seen, sizeof best);
  for (int j = 0; j < n; ++j) {
    std::int32_t bits = 0;
    std::memcpy(&bits, &s[j], sizeof bits);
    bits = bits >= 0 && bits < 0x7f800000 ? bits : 0;
    best = bits > best ? bits : best;
  }
  float out = 0.0f;
  std::memcpy(&out, &best, sizeof out);
  return out;
}

// The fused pipeline: each thread takes ranges of query rows in turn and, for every row,
// computes its distances, the running sequence sums over a ring of the last L + 1 rows, the
// row's largest value and its kept matches, in one pass with no barrier between threads. A
// range starts L - 1 rows early so that its first row has a full sequence behind it, exactly as
// when the block is computed from its first row.
//
// Each finished row i of query sums (m cells, unnormalised) goes to sink(range, i, sums) on the
// thread of its range. Returns the largest finite sum of the rows computed: taken from the
// running sums as they are written where a row's cells are its sums (one direction), from
// the finished rows otherwise (L = 1, both directions: the smaller of two sums).
using RowSink = std::function<void(int range, int row, const float* sums)>;

// The queries computed (rows [begin, end) of the block) in ranges of range_rows rows, taken in
// turn by `threads` threads: several ranges per thread for balance, large enough that the
// L - 1 rows computed twice (once as history) cost little.
struct RangePlan {
  int begin = 0, end = 0, threads = 1, range_rows = 1, ranges = 0;
};

RangePlan PlanRanges(const MatchBlock& block, const BoundedOptions& options) {
  RangePlan p;
  p.begin = std::clamp(options.query_begin, 0, block.query_count);
  p.end = options.query_end < 0 ? block.query_count
                                : std::clamp(options.query_end, p.begin, block.query_count);
  const int queries = p.end - p.begin;
  p.threads = EffectiveThreads(options.threads);
  p.range_rows =
      options.range_rows > 0 ? options.range_rows : std::clamp(queries / (8 * p.threads), 64, 1024);
  p.ranges = queries <= 0 ? 0 : (queries + p.range_rows - 1) / p.range_rows;
  return p;
}

float SequenceRows(const cv::Mat& descriptors, const MatchBlock& block,
                   const BoundedOptions& options, const std::function<void(int)>& ranges_known,
                   const RowSink& sink, const std::function<void(int, int)>& progress) {
  const int L = options.sequence_length;
  if (L < 1) throw std::logic_error("BoundedMatches: sequence length < 1");
  const int m = block.reference_count;
  const RangePlan plan = PlanRanges(block, options);
  const int q_begin = plan.begin, q_end = plan.end, queries = q_end - q_begin;
  const cv::Mat references = descriptors.rowRange(block.reference_first, block.reference_first + m);
  const Metric metric = options.metric.value_or(MetricOfType(descriptors.type()));
  std::unique_ptr<HammingReferences> packed;
  if (metric == Metric::kHamming) packed = std::make_unique<HammingReferences>(references);
  const int threads = plan.threads, range_rows = plan.range_rows, ranges = plan.ranges;
  ranges_known(ranges);
  std::vector<float> range_max(static_cast<std::size_t>(ranges), 0.0f);
  const bool forward = options.direction != SequenceDirection::kReverse;
  const bool backward = options.direction != SequenceDirection::kForward;
  // Rows of D computed at once, into the ring: the Hamming kernel takes 16 queries over each
  // slice of references that stays in cache (HammingReferences::DistancesInto), so that the
  // references are read once per 16 rows rather than once per row (100k references are 3.2 MB,
  // more than a core's L2 cache); L2 and L1 compute blocks of 16 rows too.
  constexpr int block_rows = 16;
  std::atomic<int> rows_done{0};
  std::mutex progress_mutex;
  // Sequence_partial ahead: a cell with fewer than L terms takes the cell AheadShift steps
  // forward along its diagonal, which lies in one of the next L - 1 rows. Each range then
  // computes L - 1 rows past its end (as it computes L - 1 rows before its start), keeps its
  // last L rows of sums (each direction apart, before the smaller of the two is taken) and
  // finishes row i once row i + L - 1 is summed.
  const bool ahead = L > 1 && options.partial == SequencePartial::kAhead;
  const int look = ahead ? L - 1 : 0;
  const bool exact = SumsAreExactInFloat(metric, descriptors.cols, L);
  ParallelFor(ranges, threads, [&](int c) {
    const int r0 = q_begin + c * range_rows, r1 = std::min(q_end, r0 + range_rows);
    const int h0 = std::max(0, r0 - (L - 1));                     // first row summed
    const int rows_end = std::min(block.query_count, r1 + look);  // one past the last summed
    // The ring of D: blocks of block_rows rows, enough to hold rows i - L .. i and the rest of
    // the block of row i; row i (counted from h0) is row (i - h0) % slots. A block's rows are
    // contiguous, so that a block is computed straight into them.
    const int slots = ((L + block_rows - 1) / block_rows + 1) * block_rows;
    const std::size_t width = static_cast<std::size_t>(std::max(m, 1));
    std::vector<float> ring(static_cast<std::size_t>(slots) * width);
    const auto ring_row = [&](int i) {
      return &ring[static_cast<std::size_t>((i - h0) % slots) * width];
    };
    // The running sums of each direction: in float where that is exact, else in double.
    const std::size_t sums_f_size = forward && L > 1 ? width : 0;
    const std::size_t sums_r_size = backward && L > 1 ? width : 0;
    std::vector<double> prev_f(exact ? 0 : sums_f_size), cur_f(prev_f.size());
    std::vector<double> prev_r(exact ? 0 : sums_r_size), cur_r(prev_r.size());
    std::vector<float> prev_ef(exact ? sums_f_size : 0), cur_ef(prev_ef.size());
    std::vector<float> prev_er(exact ? sums_r_size : 0), cur_er(prev_er.size());
    std::vector<float> sum_f(L > 1 ? width : 0), sum_r(L > 1 && backward && forward ? width : 0);
    // ahead: the last L rows of sums of each direction, and the finished row(s).
    std::vector<float> sums_f(ahead && forward ? L * width : 0);
    std::vector<float> sums_r(ahead && backward ? L * width : 0);
    cv::Mat1f computed;
    // The rows' largest value: from the running sums of the rows of this range (the rows
    // before r0 are its history, whose sums are partial), or from the finished rows.
    float largest = 0.0f;
    const bool largest_from_sums = L > 1 && !(forward && backward);
    const auto keep = [&](int i, const float* s) {
      if (!largest_from_sums) largest = LargestFinite(s, m, largest);
      sink(c, i, s);
    };
    const auto summed = [&](int i, float row_largest) {
      if (largest_from_sums && i >= r0) largest = std::max(largest, row_largest);
    };
    // Row e of one direction, finished in place: its early cells (fewer than L terms) take the
    // cells ahead along their diagonals, in the rows kept in `sums`. Those are cells of L terms,
    // which no row changes, and row e is not read again once finished (later rows read only
    // rows after themselves), so the row is changed where it is.
    const auto finish = [&](int e, std::vector<float>& sums, bool rev) {
      float* own = &sums[static_cast<std::size_t>(e % L) * width];
      const int forward_rows = block.query_count - 1 - e;
      const auto cell = [&](int j) {
        const int t = std::min(e, rev ? m - 1 - j : j);
        if (t >= L - 1) return own[j];
        const int shift = AheadShift(L, t, std::min(forward_rows, rev ? j : m - 1 - j));
        if (shift < 0) return std::numeric_limits<float>::infinity();
        return sums[static_cast<std::size_t>((e + shift) % L) * width +
                    static_cast<std::size_t>(rev ? j - shift : j + shift)];
      };
      const int e0 = e < L - 1 ? 0 : rev ? std::max(0, m - (L - 1)) : 0;
      const int e1 = e < L - 1 ? m : rev ? m : std::min(m, L - 1);
      for (int j = e0; j < e1; ++j) own[j] = cell(j);
      return own;
    };
    const auto keep_ahead = [&](int e) {
      float* f = forward ? finish(e, sums_f, false) : nullptr;
      float* r = backward ? finish(e, sums_r, true) : nullptr;
      if (f && r)
        for (int j = 0; j < m; ++j) f[j] = std::min(f[j], r[j]);
      keep(e, f ? f : r);
    };
    for (int b0 = h0; b0 < rows_end; b0 += block_rows) {
      const int b1 = std::min(rows_end, b0 + block_rows);
      const cv::Mat queries = descriptors.rowRange(block.query_first + b0, block.query_first + b1);
      if (packed) {
        cv::Mat1f into(b1 - b0, m, ring_row(b0));  // blocks start on a block of the ring
        packed->DistancesInto(queries, into, 1);
      } else {
        computed = Distances(queries, references, metric, 1);
        for (int i = b0; i < b1; ++i) std::copy_n(computed.ptr<float>(i - b0), m, ring_row(i));
      }
      for (int i = b0; i < b1; ++i) {
        const float* d = ring_row(i);
        const float* s = d;
        if (L > 1) {
          const int steps = i - h0;
          const float* old = steps >= L ? ring_row(i - L) : d;  // read only when steps >= L
          // One direction's row of sums into `into`, its running sums (float or double) moved
          // on by one row; returns the row's largest value.
          const auto step = [&](auto& prev, auto& cur, float* into, bool reverse) {
            const float row_largest = SequenceRow(d, old, prev.data(), cur.data(), into, m, steps,
                                                  L, reverse, options.partial);
            std::swap(prev, cur);
            return row_largest;
          };
          // With Sequence_partial ahead, the sums go straight into the rows kept for it.
          float* sums =
              ahead && forward ? &sums_f[static_cast<std::size_t>(i % L) * width] : sum_f.data();
          if (forward) {
            summed(i,
                   exact ? step(prev_ef, cur_ef, sums, false) : step(prev_f, cur_f, sums, false));
          }
          if (backward) {
            float* into = ahead ? &sums_r[static_cast<std::size_t>(i % L) * width]
                                : (forward ? sum_r.data() : sum_f.data());
            summed(i, exact ? step(prev_er, cur_er, into, true) : step(prev_r, cur_r, into, true));
            if (forward && !ahead)  // both directions: the smaller of the two sums
              for (int j = 0; j < m; ++j) sum_f[j] = std::min(sum_f[j], sum_r[j]);
          }
          s = sum_f.data();
        }
        if (ahead) {
          if (i - look >= r0 && i - look < r1) keep_ahead(i - look);
        } else if (i >= r0 && i < r1) {
          keep(i, s);
        }
      }
    }
    for (int e = std::max(r0, rows_end - look); ahead && e < r1; ++e) keep_ahead(e);
    range_max[static_cast<std::size_t>(c)] = largest;
    rows_done += r1 - r0;
    // Progress from whichever thread gets the lock (the reporter is not thread-safe); the count
    // read under the lock only grows.
    if (progress && progress_mutex.try_lock()) {
      progress(rows_done.load(), queries);
      progress_mutex.unlock();
    }
  });
  if (progress) progress(queries, queries);
  float largest = 0.0f;
  for (const float v : range_max) largest = std::max(largest, v);
  return largest;
}

// The kept matches of every range, in the order of the ranges.
std::vector<Match> Concatenated(const std::vector<std::vector<Match>>& kept) {
  std::vector<Match> all;
  std::size_t total = 0;
  for (const auto& k : kept) total += k.size();
  all.reserve(total);
  for (const auto& k : kept) all.insert(all.end(), k.begin(), k.end());
  return all;
}

// Columns per tile for TiledMatches, 0 when it does not apply: sums along diagonals only (a
// tile reaches back to the columns before it, which the tiles before it computed) of exact
// distances (Hamming, L1: a slice of the references gives the floats of the whole row; an L2
// product may round otherwise), with few cells kept per query.
int TileColumns(const BoundedOptions& options, Metric metric, const KeepRules& rules) {
  if (options.tile_columns < 0 || options.direction != SequenceDirection::kForward ||
      metric == Metric::kL2 || SlicedKeep::KeptCells(rules) > 4096)
    return 0;
  const int chosen = options.tile_columns > 0 ? options.tile_columns : 1024;
  return (std::max(chosen, 2 * options.sequence_length) + 3) / 4 * 4;
}

// BoundedMatches in column tiles. SequenceRows holds whole rows of references: 100k of them
// are 400 KB a row, the ring of rows is megabytes, and every step (distances, sums, ahead
// cells, selection) streamed rows from memory (measured: the sums were bound by memory).
// Here each range of queries is computed one tile of `tile` references at a time, for all its
// rows: the tile's ring of distances, its sums and the rows finished by the ahead rule stay in
// the core's cache, and the rows' kept matches are gathered across tiles (SlicedKeep). Each
// row carries, from one tile to the next, the running sum at the tile's last column and its
// last L distances, which the sums of the next tile's first columns read: every sum is the
// same float as SequenceRows gives.
std::vector<Match> TiledMatches(const cv::Mat& descriptors, const MatchBlock& block,
                                const KeepRules& rules, const BoundedOptions& options, int tile,
                                float& max_distance,
                                const std::function<void(int, int)>& progress) {
  const int L = options.sequence_length;
  if (L < 1) throw std::logic_error("BoundedMatches: sequence length < 1");
  const int m = block.reference_count;
  const RangePlan plan = PlanRanges(block, options);
  const cv::Mat references = descriptors.rowRange(block.reference_first, block.reference_first + m);
  const Metric metric = options.metric.value_or(MetricOfType(descriptors.type()));
  std::unique_ptr<HammingReferences> packed;
  if (metric == Metric::kHamming) packed = std::make_unique<HammingReferences>(references);
  const bool ahead = L > 1 && options.partial == SequencePartial::kAhead;
  const int look = ahead ? L - 1 : 0;
  const bool exact = SumsAreExactInFloat(metric, descriptors.cols, L);
  constexpr int block_rows = 16;  // queries per call of the distance kernel, as SequenceRows
  std::vector<std::vector<Match>> kept(static_cast<std::size_t>(plan.ranges));
  std::vector<float> range_max(kept.size(), 0.0f);
  std::atomic<int> rows_done{0};
  std::mutex progress_mutex;
  ParallelFor(plan.ranges, plan.threads, [&](int c) {
    const int r0 = plan.begin + c * plan.range_rows, r1 = std::min(plan.end, r0 + plan.range_rows);
    const int h0 = std::max(0, r0 - (L - 1));
    const int rows_end = std::min(block.query_count, r1 + look);
    const int rows = rows_end - h0;
    // A tile computes its own columns and `look` beyond them, which the ahead rule reads
    // (the kernel writes whole blocks of four references); a ring row holds the L columns
    // before the tile, then the tile.
    const int span = (tile + look + 3) / 4 * 4;
    const std::size_t width = static_cast<std::size_t>(L + span);
    const int slots = ((L + block_rows - 1) / block_rows + 1) * block_rows;
    std::vector<float> ring(static_cast<std::size_t>(slots) * width);
    const auto ring_row = [&](int i) {
      return &ring[static_cast<std::size_t>((i - h0) % slots) * width];
    };
    // Carried from tile to tile, per row: its last L distances and its running sum.
    std::vector<float> edge_d(static_cast<std::size_t>(rows) * L);
    // Running sums in double, or in float where exact (as SequenceRows); slot 0 is column c0 - 1.
    std::vector<double> edge_w(exact ? 0 : rows), prev_w(exact ? 0 : span + 1);
    std::vector<double> cur_w(prev_w.size());
    std::vector<float> edge_e(exact ? rows : 0), prev_e(exact ? span + 1 : 0);
    std::vector<float> cur_e(prev_e.size());
    std::vector<float> sums(L > 1 ? static_cast<std::size_t>(ahead ? L : 1) * span : 0);
    std::vector<SlicedKeep> keep;
    keep.reserve(static_cast<std::size_t>(r1 - r0));
    for (int q = r0; q < r1; ++q) keep.emplace_back(q, m, rules);
    float largest = 0.0f;
    cv::Mat1f computed;
    for (int c0 = 0; c0 < m; c0 += tile) {
      const int c1 = std::min(m, c0 + tile), ce = std::min(m, c1 + look);
      const bool more = c1 < m;
      const auto hand = [&](int e, const float* s) {
        if (L == 1) largest = LargestFinite(s, c1 - c0, largest);  // else from the sums
        keep[static_cast<std::size_t>(e - r0)].Add(s, c0, c1);
      };
      // Row e finished in place by the ahead rule, as SequenceRows's finish going forward:
      // its early cells (column or row before L - 1) take the cell `shift` steps ahead along
      // the diagonal, within the last L rows of sums and the `look` columns past the tile.
      const auto finish = [&](int e) {
        float* own = &sums[static_cast<std::size_t>(e % L) * span];
        const int forward_rows = block.query_count - 1 - e;
        const int x1 = e < L - 1 ? c1 - c0 : std::clamp(L - 1 - c0, 0, c1 - c0);
        for (int x = 0; x < x1; ++x) {
          const int j = c0 + x, t = std::min(e, j);
          if (t >= L - 1) continue;
          const int shift = AheadShift(L, t, std::min(forward_rows, m - 1 - j));
          own[x] = shift < 0 ? std::numeric_limits<float>::infinity()
                             : sums[static_cast<std::size_t>((e + shift) % L) * span +
                                    static_cast<std::size_t>(x + shift)];
        }
        return own;
      };
      for (int b0 = h0; b0 < rows_end; b0 += block_rows) {
        const int b1 = std::min(rows_end, b0 + block_rows);
        const cv::Mat queries =
            descriptors.rowRange(block.query_first + b0, block.query_first + b1);
        if (packed) {
          packed->DistancesInto(queries, c0, ce, ring_row(b0) + L, width);
        } else {
          computed = Distances(queries, references.rowRange(c0, ce), metric, 1);
          for (int i = b0; i < b1; ++i)
            std::copy_n(computed.ptr<float>(i - b0), ce - c0, ring_row(i) + L);
        }
        for (int i = b0; i < b1; ++i) {
          float* d = ring_row(i) + L;
          float* edge = &edge_d[static_cast<std::size_t>(i - h0) * L];
          if (c0 > 0) std::copy_n(edge, L, d - L);
          if (more) std::copy_n(d + (c1 - c0 - L), L, edge);
          const float* s = d;
          if (L > 1) {
            const int steps = i - h0;
            const float* old = steps >= L ? ring_row(i - L) + L : d;
            float* into = &sums[static_cast<std::size_t>(ahead ? i % L : 0) * span];
            // Slot 0 of the running sums: the row's sum at column c0 - 1 (from the tile before),
            // read as prev[-1] by the next row.
            const auto step = [&](auto& prev, auto& cur, auto& edge_sum) {
              cur[0] = edge_sum[static_cast<std::size_t>(i - h0)];
              const float row_largest = SequenceRow(d, old, prev.data() + 1, cur.data() + 1, into,
                                                    ce - c0, steps, L, false, options.partial, c0);
              if (more) edge_sum[static_cast<std::size_t>(i - h0)] = cur[c1 - c0];
              std::swap(prev, cur);
              return row_largest;
            };
            const float row_largest =
                exact ? step(prev_e, cur_e, edge_e) : step(prev_w, cur_w, edge_w);
            if (i >= r0) largest = std::max(largest, row_largest);
            s = into;
          }
          if (ahead) {
            if (i - look >= r0 && i - look < r1) hand(i - look, finish(i - look));
          } else if (i >= r0 && i < r1) {
            hand(i, s);
          }
        }
      }
      for (int e = std::max(r0, rows_end - look); ahead && e < r1; ++e) hand(e, finish(e));
    }
    for (SlicedKeep& k : keep) k.Finish(kept[static_cast<std::size_t>(c)]);
    range_max[static_cast<std::size_t>(c)] = largest;
    rows_done += r1 - r0;
    if (progress && progress_mutex.try_lock()) {  // as SequenceRows
      progress(rows_done.load(), plan.end - plan.begin);
      progress_mutex.unlock();
    }
  });
  if (progress) progress(plan.end - plan.begin, plan.end - plan.begin);
  max_distance = 0.0f;
  for (const float v : range_max) max_distance = std::max(max_distance, v);
  std::vector<Match> all = Concatenated(kept);
  if (options.normalize) NormalizeMatches(all, max_distance, rules.score);
  return all;
}

}  // namespace

std::vector<Match> BoundedMatches(const cv::Mat& descriptors, const MatchBlock& block,
                                  const KeepRules& rules, const BoundedOptions& options,
                                  float& max_distance,
                                  const std::function<void(int, int)>& progress) {
  const Metric metric = options.metric.value_or(MetricOfType(descriptors.type()));
  if (const int tile = TileColumns(options, metric, rules); tile > 0)
    return TiledMatches(descriptors, block, rules, options, tile, max_distance, progress);
  // Per range: its kept matches, merged in the order of the ranges.
  std::vector<std::vector<Match>> kept;
  const int m = block.reference_count;
  const float max_seen = SequenceRows(
      descriptors, block, options,
      [&](int ranges) { kept.resize(static_cast<std::size_t>(ranges)); },
      [&](int c, int i, const float* s) {
        KeepRow(s, m, i, rules, kept[static_cast<std::size_t>(c)]);
      },
      progress);
  std::vector<Match> all = Concatenated(kept);
  max_distance = max_seen;
  if (options.normalize) NormalizeMatches(all, max_seen, rules.score);
  return all;
}

float SequenceMatrix(const cv::Mat& descriptors, const MatchBlock& block,
                     const BoundedOptions& options, cv::Mat1f& out,
                     const std::function<void(int, int)>& progress) {
  const int m = block.reference_count;
  BoundedOptions every_query = options;
  every_query.query_begin = 0;
  every_query.query_end = -1;
  return SequenceRows(
      descriptors, block, every_query, [](int) {},
      [&](int, int i, const float* s) {
        std::copy_n(s, m, out.ptr<float>(block.query_first + i) + block.reference_first);
      },
      progress);
}

std::vector<std::uint8_t> AcceptedMatches(const std::vector<Match>& matches, int queries,
                                          double threshold, const AgreementOptions* consistency) {
  std::vector<int> best(static_cast<std::size_t>(std::max(queries, 0)), -1);
  std::vector<float> score(best.size(), 0.0f);
  for (const Match& m : matches)
    if (m.rank == 1 && m.query >= 0 && m.query < queries) {
      best[static_cast<std::size_t>(m.query)] = m.reference;
      score[static_cast<std::size_t>(m.query)] = m.score;
    }
  std::vector<std::uint8_t> out(best.size(), 0);
  const std::vector<std::uint8_t> agree =
      consistency != nullptr ? AgreeingAnswers(best, *consistency) : std::vector<std::uint8_t>();
  for (std::size_t q = 0; q < best.size(); ++q)
    out[q] = best[q] >= 0 && score[q] <= threshold && (agree.empty() || agree[q]) ? 1 : 0;
  return out;
}

void NormalizeMatches(std::vector<Match>& matches, float max_distance,
                      const MatchScoreOptions& score) {
  if (max_distance > 0.0f)
    for (Match& k : matches) k.distance /= max_distance;
  if (score.kind == MatchScore::kDistance)
    for (Match& k : matches) k.score = k.distance;
}

}  // namespace openable
