#include "matching/bounded.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <limits>
#include <mutex>
#include <queue>
#include <stdexcept>

#include <opencv2/core/hal/intrin.hpp>

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

void KeepRow(const float* s, int references, int q, const KeepRules& rules,
             std::vector<Match>& out) {
  // k best: a max-heap of (distance, reference) holding the k smallest seen; ties go to the
  // smaller reference number.
  const int limit = rules.one_traversal ? std::min(references, q - rules.exclusion + 1)
                                        : references;
  using Entry = std::pair<float, int>;
  std::priority_queue<Entry> heap;
  if (rules.best > 0) {
    int j = 0;
    for (; j < limit && static_cast<int>(heap.size()) < rules.best; ++j)
      if (std::isfinite(s[j])) heap.push({s[j], j});
    // The heap is full: a cell enters when it is below the worst kept (a tie loses, being at a
    // larger reference than every kept one). Most rows' cells do not, so blocks of 16 cells
    // are first tested together.
    float worst = heap.empty() ? 0.0f : heap.top().first;
    auto visit = [&](int c) {
      if (s[c] < worst && std::isfinite(s[c])) {
        heap.pop();
        heap.push({s[c], c});
        worst = heap.top().first;
      }
    };
    // Blocks of 16 cells tested with OpenCV's universal intrinsics (SSE2 at the x86-64
    // baseline, NEON on ARM): the compiler leaves this test scalar when written as a loop.
    // NaN is never below; visit() decides exactly for the cells of a block that has one.
    for (; j + 16 <= limit; j += 16) {
      const cv::v_float32x4 w = cv::v_setall_f32(worst);
      const cv::v_float32x4 below = (cv::v_load(s + j) < w) | (cv::v_load(s + j + 4) < w) |
                                    (cv::v_load(s + j + 8) < w) | (cv::v_load(s + j + 12) < w);
      if (cv::v_check_any(below))
        for (int u = 0; u < 16; ++u) visit(j + u);
    }
    for (; j < limit; ++j) visit(j);
  }
  std::vector<Entry> best;
  best.reserve(heap.size());
  for (; !heap.empty(); heap.pop()) best.push_back(heap.top());
  std::reverse(best.begin(), best.end());
  const auto score = [&](int j) {
    return ScoreOfCandidate(s, std::max(0, limit), j, rules.score, rules.score_window);
  };
  for (size_t r = 0; r < best.size(); ++r)
    out.push_back({q, best[r].second, best[r].first, static_cast<int>(r + 1),
                   score(best[r].second)});
  if (rules.band >= 0) {
    const int j0 = std::max(0, q - rules.band), j1 = std::min(references - 1, q + rules.band);
    for (int j = j0; j <= j1; ++j) {
      const bool ranked = std::any_of(best.begin(), best.end(),
                                      [&](const Entry& e) { return e.second == j; });
      if (!ranked && std::isfinite(s[j])) out.push_back({q, j, s[j], 0, score(j)});
    }
  }
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
template <typename Acc>
float SequenceRow(const float* row, const float* old, const Acc* prev, Acc* cur, float* out,
                  int m, int steps, int L, bool reverse, SequencePartial partial) {
  float largest = 0.0f;
  // Columns whose sums reach back a full L - 1 steps along the columns too: [L, m) going
  // forward, [0, m - L) in reverse; the other L columns go through the general case.
  const int bulk0 = reverse ? 0 : std::min(L, m), bulk1 = reverse ? std::max(0, m - L) : m;
  auto general = [&](int j) {
    double w = row[j];
    const int t = std::min(steps, reverse ? m - 1 - j : j);
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

float SequenceRows(const cv::Mat& descriptors, const MatchBlock& block,
                   const BoundedOptions& options, const std::function<void(int)>& ranges_known,
                   const RowSink& sink, const std::function<void(int, int)>& progress) {
  const int L = options.sequence_length;
  if (L < 1) throw std::logic_error("BoundedMatches: sequence length < 1");
  const int m = block.reference_count;
  const int q_begin = std::clamp(options.query_begin, 0, block.query_count);
  const int q_end = options.query_end < 0 ? block.query_count
                                          : std::clamp(options.query_end, q_begin,
                                                       block.query_count);
  const int queries = q_end - q_begin;
  const cv::Mat references = descriptors.rowRange(block.reference_first,
                                                  block.reference_first + m);
  const Metric metric = options.metric.value_or(MetricOfType(descriptors.type()));
  std::unique_ptr<HammingReferences> packed;
  if (metric == Metric::kHamming) packed = std::make_unique<HammingReferences>(references);
  const int threads = EffectiveThreads(options.threads);
  // Ranges of query rows: several per thread for balance, large enough that the L - 1 rows
  // computed twice (once as history) cost little.
  const int range_rows = options.range_rows > 0
                             ? options.range_rows
                             : std::clamp(queries / (8 * threads), 64, 1024);
  const int ranges = queries <= 0 ? 0 : (queries + range_rows - 1) / range_rows;
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
    const int h0 = std::max(0, r0 - (L - 1));  // first row summed
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
      const cv::Mat queries =
          descriptors.rowRange(block.query_first + b0, block.query_first + b1);
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
            const float row_largest = SequenceRow(d, old, prev.data(), cur.data(), into, m,
                                                  steps, L, reverse, options.partial);
            std::swap(prev, cur);
            return row_largest;
          };
          // With Sequence_partial ahead, the sums go straight into the rows kept for it.
          float* sums = ahead && forward ? &sums_f[static_cast<std::size_t>(i % L) * width]
                                         : sum_f.data();
          if (forward) {
            summed(i, exact ? step(prev_ef, cur_ef, sums, false)
                            : step(prev_f, cur_f, sums, false));
          }
          if (backward) {
            float* into = ahead ? &sums_r[static_cast<std::size_t>(i % L) * width]
                                : (forward ? sum_r.data() : sum_f.data());
            summed(i, exact ? step(prev_er, cur_er, into, true)
                            : step(prev_r, cur_r, into, true));
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

}  // namespace

std::vector<Match> BoundedMatches(const cv::Mat& descriptors, const MatchBlock& block,
                                  const KeepRules& rules, const BoundedOptions& options,
                                  float& max_distance,
                                  const std::function<void(int, int)>& progress) {
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
  std::vector<Match> all;
  std::size_t total = 0;
  for (const auto& k : kept) total += k.size();
  all.reserve(total);
  for (auto& k : kept) all.insert(all.end(), k.begin(), k.end());
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
                                          double threshold,
                                          const AgreementOptions* consistency) {
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

void NormalizeMatches(std::vector<Match>& matches, float max_distance, MatchScore score) {
  if (max_distance > 0.0f)
    for (Match& k : matches) k.distance /= max_distance;
  if (score == MatchScore::kDistance)
    for (Match& k : matches) k.score = k.distance;
}

}  // namespace openable
