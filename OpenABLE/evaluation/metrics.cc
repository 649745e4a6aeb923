#include "OpenABLE/evaluation/metrics.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/option_checks.h"
#include "OpenABLE/base/strings.h"
#include "OpenABLE/evaluation/answers.h"

namespace openable {
namespace {

void CheckShapes(const cv::Mat1f& matrix, const EvaluationLayout& layout,
                 const GroundTruth& truth) {
  if (layout.queries < 0 || layout.references < 0 || layout.row_offset < 0 ||
      layout.col_offset < 0 || layout.row_offset + layout.queries > matrix.rows ||
      layout.col_offset + layout.references > matrix.cols) {
    throw std::logic_error("evaluation: layout does not fit a " + std::to_string(matrix.rows) +
                           " x " + std::to_string(matrix.cols) + " matrix");
  }
  if (static_cast<int>(truth.matches.size()) != layout.queries) {
    throw std::logic_error("evaluation: ground truth has " + std::to_string(truth.matches.size()) +
                           " queries, layout " + std::to_string(layout.queries));
  }
  if (layout.kind == EvaluationLayout::Kind::kLoopClosure && layout.queries != layout.references)
    throw std::logic_error("evaluation: a loop-closure layout must be square");
}

// True matches of q among its candidates (matches are sorted, so this is a prefix).
std::vector<int> CandidateTruth(const std::vector<int>& matches, int end) {
  return std::vector<int>(matches.begin(), std::lower_bound(matches.begin(), matches.end(), end));
}

// Whether column c lies within `tolerance` of a sorted list of true columns.
bool NearTruth(const std::vector<int>& truth, int c, int tolerance) {
  const auto it = std::lower_bound(truth.begin(), truth.end(), c - tolerance);
  return it != truth.end() && *it <= c + tolerance;
}

double F1(double precision, double recall) {
  return precision + recall > 0 ? 2 * precision * recall / (precision + recall) : 0.0;
}

constexpr int kRecallAtN[] = {1, 5, 10};
constexpr int kMaxN = 10;

// Whether a right answer is among the first 1, 5 and 10 of `count` answers in rank order
// (column_of(n): the n-th answer's column), against the true columns `t`.
template <typename ColumnOf>
std::array<std::uint8_t, 3> HitsAtN(const std::vector<int>& t, int count, ColumnOf column_of,
                                    int tolerance) {
  std::array<std::uint8_t, 3> out = {0, 0, 0};
  bool hit = false;
  int k = 0;
  for (int n = 0; n < count && n < kMaxN; ++n) {
    hit = hit || NearTruth(t, column_of(n), tolerance);
    while (k < 3 && n + 1 == kRecallAtN[k]) out[k++] = hit ? 1 : 0;
  }
  for (; k < 3; ++k) out[k] = hit ? 1 : 0;  // fewer answers than N
  return out;
}

// The ground truth of query q among its candidates (`t`), its true pairs outside them, and
// whether it has candidates and is positive. False when it has no candidate.
bool BeginQuery(const EvaluationLayout& layout, const GroundTruth& truth,
                const EvaluationOptions& options, int q, PerQueryResult& r,
                std::vector<std::uint8_t>& has_candidates, std::vector<std::int64_t>& outside,
                std::vector<int>& t) {
  const int end = layout.CandidateEnd(q, options.exclusion);
  t = CandidateTruth(truth.matches[q], end);
  outside[q] = static_cast<std::int64_t>(truth.matches[q].size() - t.size());
  if (end == 0) return false;
  has_candidates[q] = 1;
  r.positive[q] = t.empty() ? 0 : 1;
  return true;
}

// Every query without an answer yet.
void NoAnswers(PerQueryResult& r, int nq) {
  r.best.assign(nq, -1);
  r.best_distance.assign(nq, std::numeric_limits<float>::infinity());
  r.score.assign(nq, std::numeric_limits<float>::infinity());
  r.positive.assign(nq, 0);
  r.correct.assign(nq, 0);
}

// The figures of the per-query protocol from each query's answer (r.best, r.score,
// r.correct, r.positive), whether it has candidates, its hits among the N best and its true
// pairs outside the candidates.
void Summarize(PerQueryResult& r, const std::vector<std::uint8_t>& has_candidates,
               const std::vector<std::array<std::uint8_t, 3>>& correct_at_n,
               const std::vector<std::int64_t>& outside, const EvaluationOptions& options) {
  const int nq = static_cast<int>(has_candidates.size());
  std::vector<int> order;
  std::array<int, 3> hits_at_n = {0, 0, 0};
  for (int q = 0; q < nq; ++q) {
    r.truth_pairs_outside_candidates += outside[q];
    if (!has_candidates[q]) continue;
    ++r.queries;
    if (r.positive[q]) ++r.positive_queries;
    if (r.best[q] < 0) {
      ++r.unanswered;
      continue;
    }
    order.push_back(q);
    if (r.positive[q])
      for (int k = 0; k < 3; ++k) hits_at_n[k] += correct_at_n[q][k];
  }
  const double positives = r.positive_queries;
  if (r.positive_queries > 0) {
    r.recall_at_1 = hits_at_n[0] / positives;
    r.recall_at_5 = hits_at_n[1] / positives;
    r.recall_at_10 = hits_at_n[2] / positives;
  }

  // Sweep the acceptance threshold over every distinct score of a best match.
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return r.score[a] < r.score[b]; });
  std::int64_t tp = 0, fp = 0;
  for (std::size_t i = 0; i < order.size();) {
    const float threshold = r.score[order[i]];
    for (; i < order.size() && r.score[order[i]] == threshold; ++i) {
      if (r.correct[order[i]])
        ++tp;
      else
        ++fp;
    }
    CurvePoint p;
    p.threshold = threshold;
    p.tp = tp;
    p.fp = fp;
    p.precision = static_cast<double>(tp) / static_cast<double>(tp + fp);
    p.recall = positives > 0 ? static_cast<double>(tp) / positives : 0.0;
    p.f1 = F1(p.precision, p.recall);
    r.curve.push_back(p);
  }
  r.auc = CurveArea(r.curve);
  if (options.accept_threshold >= 0) {
    // The answers accepted: score <= threshold, and, with Match_consistency, confirmed by
    // their partners (AcceptAnswers, the rule shown without ground truth too); counted over
    // the queries with candidates, as the curve counts them.
    r.has_operating_point = true;
    std::vector<std::uint8_t> within;
    AcceptAnswers(r.best, r.score, options, within, r.accepted);
    CurvePoint& p = r.operating_point;
    p.threshold = options.accept_threshold;
    for (int q = 0; q < nq; ++q) {
      if (!has_candidates[q] || !r.accepted[q]) {
        r.accepted[q] = 0;
        continue;
      }
      if (r.correct[q])
        ++p.tp;
      else
        ++p.fp;
    }
    p.precision =
        p.tp + p.fp > 0 ? static_cast<double>(p.tp) / static_cast<double>(p.tp + p.fp) : 1.0;
    p.recall = positives > 0 ? static_cast<double>(p.tp) / positives : 0.0;
    p.f1 = F1(p.precision, p.recall);
  }
  for (const CurvePoint& p : r.curve) {
    if (p.fp == 0 && p.tp > 0) r.recall_at_100p = p.recall;
    if (p.f1 > r.max_f1) {
      r.max_f1 = p.f1;
      r.max_f1_threshold = p.threshold;
      r.max_f1_precision = p.precision;
      r.max_f1_recall = p.recall;
    }
  }
}

}  // namespace

double CurveArea(const std::vector<CurvePoint>& curve) {
  double area = 0, previous = 0;
  for (const CurvePoint& p : curve) {
    area += p.precision * (p.recall - previous);
    previous = p.recall;
  }
  return area;
}

void EvaluationOptions::Check() const {
  if (tolerance < 0)
    throw InputError("Tolerance: " + std::to_string(tolerance) +
                     " is negative; expected a number of frames >= 0");
  if (exclusion < 1)
    throw InputError(
        "Exclusion: " + std::to_string(exclusion) +
        " is too small; expected a number of frames >= 1 (a frame is not its own loop)");
  if (vicinity < 0)
    throw InputError("Vicinity: " + std::to_string(vicinity) +
                     " is negative; expected a number of frames >= 0");
  CheckIntAtLeast("able_thresholds", able_thresholds, 2);
  score.Check();
  if (!(accept_threshold == -1.0 || accept_threshold >= 0.0))
    RefuseOption("Match_threshold", FormatNumber(accept_threshold), "-1 (none) or a number >= 0");
  CheckIntRange("Match_consistency", accept_consistency, 0, 1000);
  CheckIntAtLeast("Image_sequences", agreement.sequence_length, 1);
}

PerQueryResult EvaluatePerQuery(const cv::Mat1f& matrix, const EvaluationLayout& layout,
                                const GroundTruth& truth, const EvaluationOptions& options) {
  CheckShapes(matrix, layout, truth);
  const int nq = layout.queries;
  PerQueryResult r;
  NoAnswers(r, nq);
  options.score.CheckRivals(layout.references, "");
  std::vector<std::uint8_t> has_candidates(nq, 0);
  std::vector<std::array<std::uint8_t, 3>> correct_at_n(nq, {0, 0, 0});
  std::vector<std::int64_t> outside(nq, 0);

  // Each query row is independent: best candidate, its correctness, and the N best for R@N.
  cv::parallel_for_(cv::Range(0, nq), [&](const cv::Range& range) {
    std::vector<std::pair<float, int>> top;  // up to kMaxN best (distance, column), sorted
    std::vector<int> t;
    for (int q = range.start; q < range.end; ++q) {
      if (!BeginQuery(layout, truth, options, q, r, has_candidates, outside, t)) continue;
      const int end = layout.CandidateEnd(q, options.exclusion);
      const float* row = matrix.ptr<float>(layout.row_offset + q) + layout.col_offset;
      top.clear();
      for (int c = 0; c < end; ++c) {
        const float v = row[c];
        if (!std::isfinite(v)) continue;  // a skipped sequence cell is no candidate
        // Strictly smaller than the worst kept: ties keep the lower column.
        if (static_cast<int>(top.size()) < kMaxN || v < top.back().first) {
          auto pos =
              std::upper_bound(top.begin(), top.end(), v,
                               [](float x, const std::pair<float, int>& e) { return x < e.first; });
          top.insert(pos, {v, c});
          if (static_cast<int>(top.size()) > kMaxN) top.pop_back();
        }
      }
      if (top.empty()) continue;  // no finite candidate: no answer
      r.best[q] = top.front().second;
      r.best_distance[q] = top.front().first;
      r.score[q] = ScoreOfCandidate(row, end, r.best[q], options.score);
      if (t.empty()) continue;
      r.correct[q] = NearTruth(t, r.best[q], options.tolerance) ? 1 : 0;
      correct_at_n[q] = HitsAtN(
          t, static_cast<int>(top.size()), [&](int n) { return top[n].second; }, options.tolerance);
    }
  });

  Summarize(r, has_candidates, correct_at_n, outside, options);
  return r;
}

PerQueryResult EvaluateAnswers(const EvaluationLayout& layout, const GroundTruth& truth,
                               const std::vector<std::vector<Answer>>& answers,
                               const EvaluationOptions& options) {
  const int nq = layout.queries;
  if (static_cast<int>(answers.size()) != nq || static_cast<int>(truth.matches.size()) != nq)
    throw std::logic_error("EvaluateAnswers: one answer list and one truth row per query");
  PerQueryResult r;
  NoAnswers(r, nq);
  std::vector<std::uint8_t> has_candidates(nq, 0);
  std::vector<std::array<std::uint8_t, 3>> correct_at_n(nq, {0, 0, 0});
  std::vector<std::int64_t> outside(nq, 0);
  std::vector<int> t;
  for (int q = 0; q < nq; ++q) {
    if (!BeginQuery(layout, truth, options, q, r, has_candidates, outside, t)) continue;
    const int end = layout.CandidateEnd(q, options.exclusion);
    const std::vector<Answer>& a = answers[q];
    if (a.empty()) continue;  // no accepted candidate: no answer
    for (const Answer& x : a)
      if (x.column < 0 || x.column >= end)
        throw std::logic_error("EvaluateAnswers: an answer outside the query's candidates");
    r.best[q] = a.front().column;
    r.best_distance[q] = a.front().distance;
    r.score[q] = a.front().score;
    if (t.empty()) continue;
    r.correct[q] = NearTruth(t, r.best[q], options.tolerance) ? 1 : 0;
    correct_at_n[q] = HitsAtN(
        t, static_cast<int>(a.size()), [&](int n) { return a[n].column; }, options.tolerance);
  }
  Summarize(r, has_candidates, correct_at_n, outside, options);
  return r;
}

AblePResult EvaluateAbleP(const cv::Mat1f& matrix, const EvaluationLayout& layout,
                          const GroundTruth& truth, const EvaluationOptions& options) {
  CheckShapes(matrix, layout, truth);
  const int nq = layout.queries, nr = layout.references, k_count = options.able_thresholds;
  AblePResult result;
  std::vector<double> thresholds(k_count);
  for (int k = 0; k < k_count; ++k) thresholds[k] = static_cast<double>(k) / (k_count - 1);
  // Index of the first threshold that detects value v (v < theta_k), k_count if none.
  const auto first_detecting = [&](float v) {
    if (!(v < 1.0f)) return k_count;  // theta_max = 1, so v >= 1 (or NaN) is never detected
    const double vd = v;
    int k = vd <= 0 ? 0 : static_cast<int>(std::floor(vd * (k_count - 1))) + 1;
    k = std::min(std::max(k, 0), k_count - 1);
    while (k > 0 && vd < thresholds[k - 1]) --k;
    while (k < k_count && !(vd < thresholds[k])) ++k;
    return k;
  };

  // Ground-truth cells among the candidates, and their vicinity (dilation by 2V+1).
  cv::Mat1b truth_mask(nq, nr, std::uint8_t{0});
  cv::Mat1f values(nq, nr);  // candidate values, +inf elsewhere
  const float kNotCandidate = std::numeric_limits<float>::infinity();
  for (int q = 0; q < nq; ++q) {
    const int end = layout.CandidateEnd(q, options.exclusion);
    const float* row = matrix.ptr<float>(layout.row_offset + q) + layout.col_offset;
    float* out = values.ptr<float>(q);
    for (int c = 0; c < nr; ++c) out[c] = c < end ? row[c] : kNotCandidate;
    result.candidate_cells += end;
    for (int c : truth.matches[q]) {
      if (c >= end) break;
      truth_mask(q, c) = 1;
      ++result.truth_cells;
    }
  }
  const cv::Mat kernel = cv::getStructuringElement(
      cv::MORPH_RECT, cv::Size(2 * options.vicinity + 1, 2 * options.vicinity + 1));
  cv::Mat1b near_truth;
  cv::dilate(truth_mask, near_truth, kernel, cv::Point(-1, -1), 1, cv::BORDER_CONSTANT,
             cv::Scalar(0));
  // Smallest candidate value within the vicinity of each cell: a ground-truth cell is found at
  // theta when that minimum is below theta.
  cv::Mat1f nearest_value;
  cv::erode(values, nearest_value, kernel, cv::Point(-1, -1), 1, cv::BORDER_CONSTANT,
            cv::Scalar(kNotCandidate));

  std::vector<std::int64_t> detections(k_count + 1, 0), true_detections(k_count + 1, 0),
      found(k_count + 1, 0);
  for (int q = 0; q < nq; ++q) {
    const float* v = values.ptr<float>(q);
    const std::uint8_t* nt = near_truth.ptr<std::uint8_t>(q);
    const std::uint8_t* t = truth_mask.ptr<std::uint8_t>(q);
    const float* nv = nearest_value.ptr<float>(q);
    for (int c = 0; c < nr; ++c) {
      if (v[c] != kNotCandidate) {
        const int k = first_detecting(v[c]);
        ++detections[k];
        if (nt[c]) ++true_detections[k];
      }
      if (t[c]) ++found[first_detecting(nv[c])];
    }
  }
  std::int64_t det = 0, tdet = 0, fnd = 0;
  for (int k = 0; k < k_count; ++k) {
    det += detections[k];
    tdet += true_detections[k];
    fnd += found[k];
    CurvePoint p;
    p.threshold = thresholds[k];
    p.tp = tdet;
    p.fp = det - tdet;
    p.precision = det > 0 ? static_cast<double>(tdet) / static_cast<double>(det) : 1.0;
    p.recall = result.truth_cells > 0
                   ? static_cast<double>(fnd) / static_cast<double>(result.truth_cells)
                   : 0.0;
    p.f1 = F1(p.precision, p.recall);
    result.curve.push_back(p);
  }
  result.average_precision = 100.0 * CurveArea(result.curve);
  return result;
}

bool AnyCandidateHasValue(const cv::Mat1f& matrix, const EvaluationLayout& layout, int exclusion) {
  for (int q = 0; q < layout.queries; ++q) {
    const float* row = matrix.ptr<float>(layout.row_offset + q) + layout.col_offset;
    const int end = layout.CandidateEnd(q, exclusion);
    for (int c = 0; c < end; ++c)
      if (std::isfinite(row[c])) return true;
  }
  return false;
}

double ReversedAuc(const cv::Mat1f& matrix, const EvaluationLayout& layout,
                   const GroundTruth& truth, const EvaluationOptions& options) {
  CheckShapes(matrix, layout, truth);
  cv::Mat1f block =
      matrix(cv::Rect(layout.col_offset, layout.row_offset, layout.references, layout.queries))
          .clone();
  float largest = 0.0f;
  for (int q = 0; q < block.rows; ++q)
    for (int c = 0; c < block.cols; ++c)
      if (std::isfinite(block(q, c))) largest = std::max(largest, block(q, c));
  for (int q = 0; q < block.rows; ++q)
    for (int c = 0; c < block.cols; ++c)
      if (std::isfinite(block(q, c))) block(q, c) = largest - block(q, c);
  EvaluationLayout own = layout;
  own.row_offset = 0;
  own.col_offset = 0;
  EvaluationOptions plain = options;
  plain.accept_threshold = -1.0;
  plain.accept_consistency = 0;
  return EvaluatePerQuery(block, own, truth, plain).auc;
}

std::vector<std::string> EvaluationWarnings(const cv::Mat1f& matrix, const EvaluationLayout& layout,
                                            const GroundTruth& truth,
                                            const EvaluationOptions& options,
                                            const PerQueryResult& result) {
  std::vector<std::string> out;
  const bool loop = layout.kind == EvaluationLayout::Kind::kLoopClosure;
  if (result.queries == 0) {
    out.push_back("no query has a candidate: " + std::to_string(layout.queries) +
                  " frames of one sequence, and a frame's candidates are at least " +
                  std::to_string(options.exclusion) +
                  " frames back (the exclusion), so every figure is 0; expected an exclusion "
                  "below the frames");
    return out;
  }
  if (result.positive_queries == 0) {
    const std::int64_t pairs = truth.PairCount();
    std::string why = std::to_string(pairs) + (pairs == 1 ? " pair" : " pairs") +
                      " of the ground truth over the evaluated block";
    if (loop && result.truth_pairs_outside_candidates > 0)
      why += ", " + std::to_string(result.truth_pairs_outside_candidates) +
             " of them closer than the exclusion (" + std::to_string(options.exclusion) +
             " frames)";
    out.push_back("no query has a true place among its candidates (" +
                  std::to_string(result.queries) + " queries; " + why +
                  "), so recall, AUC and R@N are 0 whatever the matrix; expected a ground truth "
                  "of the matrix's frames (its file, type and first frame)");
    return out;
  }
  if (result.unanswered == result.queries) {
    out.push_back("no query has a candidate with a value (every candidate cell of the " +
                  std::to_string(layout.queries) + "x" + std::to_string(layout.references) +
                  " block is +inf: sequences longer than the frames, or skipped), so every "
                  "figure is 0; expected a matrix with values among the candidates");
    return out;
  }
  if (result.auc < kReversedAucBelow) {
    const double reversed = ReversedAuc(matrix, layout, truth, options);
    if (reversed >= kReversedAucAtLeast)
      out.push_back("the ranking looks reversed: per-query AUC " + FormatFixed(result.auc, 3) +
                    " with the smallest values as best matches, " + FormatFixed(reversed, 3) +
                    " with the largest (the matrix reversed, max - M): the matrix looks like a "
                    "similarity (large = same place), but OpenABLE reads distances (small = "
                    "same place); expected distances, e.g. 1 - S for a similarity S in [0, 1]");
  }
  return out;
}

}  // namespace openable
