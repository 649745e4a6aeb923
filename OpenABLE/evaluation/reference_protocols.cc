#include "OpenABLE/evaluation/reference_protocols.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/strings.h"
#include "OpenABLE/evaluation/report.h"
#include "OpenABLE/io/json.h"

namespace openable {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The block of `layout` as distances with +inf (a cell without a value) replaced by the
// block's largest finite distance; both protocols need a finite similarity everywhere.
cv::Mat1f FiniteBlock(const cv::Mat1f& normalized, const EvaluationLayout& layout,
                      const GroundTruth& truth, const char* protocol) {
  if (layout.kind != EvaluationLayout::Kind::kQueryReference)
    throw InputError(std::string("Evaluation_protocol: ") + protocol +
                     " needs two traversals (a query traversal against a reference one: "
                     "Images_path_2, Frame_mode 2 or a non-square matrix); a loop-closure run "
                     "is evaluated by the toolbox's own protocol (openable)");
  if (layout.row_offset + layout.queries > normalized.rows ||
      layout.col_offset + layout.references > normalized.cols ||
      static_cast<int>(truth.matches.size()) != layout.queries)
    throw std::logic_error("reference protocol: layout, matrix and ground truth disagree");
  cv::Mat1f block =
      normalized(cv::Rect(layout.col_offset, layout.row_offset, layout.references, layout.queries))
          .clone();
  float largest = 0.f;
  for (int q = 0; q < block.rows; ++q)
    for (int c = 0; c < block.cols; ++c)
      if (std::isfinite(block(q, c))) largest = std::max(largest, block(q, c));
  for (int q = 0; q < block.rows; ++q)
    for (int c = 0; c < block.cols; ++c)
      if (!std::isfinite(block(q, c))) block(q, c) = largest;
  return block;
}

// The true columns of a query, 0/1 per reference: its ground truth widened by `tolerance`
// frames. One row at a time: a block of many queries and references is never held twice.
void TrueRow(const std::vector<int>& matches, int references, int tolerance,
             std::vector<std::uint8_t>& row) {
  row.assign(static_cast<std::size_t>(references), 0);
  for (int m : matches) {
    const int from = std::max(0, m - tolerance);  // m >= 0: no overflow
    const int to =
        static_cast<int>(std::min<std::int64_t>(references - 1, std::int64_t{m} + tolerance));
    for (int c = from; c <= to; ++c) row[static_cast<std::size_t>(c)] = 1;
  }
}

// The rank (0 = first) of column b in the order of increasing distance, lower column first
// among equal distances: the columns before it in that order.
int RankOf(const float* row, int columns, int b) {
  int rank = 0;
  for (int c = 0; c < columns; ++c)
    if (row[c] < row[b] || (row[c] == row[b] && c < b)) ++rank;
  return rank;
}

// The rank of the best-ranked true column of a query, or -1 without a true column.
int BestTrueRank(const float* row, const std::vector<std::uint8_t>& is_true, int columns) {
  int best = -1;
  for (int c = 0; c < columns; ++c)
    if (is_true[static_cast<std::size_t>(c)] && (best < 0 || row[c] < row[best])) best = c;
  return best < 0 ? -1 : RankOf(row, columns, best);
}

// The first column of the smallest distance (numpy.argmax of the similarity).
int BestColumn(const float* row, int columns) {
  int best = 0;
  for (int c = 1; c < columns; ++c)
    if (row[c] < row[best]) best = c;
  return best;
}

// numpy.trapz(y, x): the sum of (x[i+1] - x[i]) * (y[i+1] + y[i]) / 2.
double Trapezoids(const std::vector<double>& y, const std::vector<double>& x) {
  double area = 0;
  for (std::size_t i = 1; i < x.size(); ++i) area += (x[i] - x[i - 1]) * (y[i] + y[i - 1]) / 2.0;
  return area;
}

// numpy.linspace(start, stop, n) for n > 1: start + i * (stop - start) / (n - 1) in double,
// the last value exactly `stop`.
std::vector<double> Linspace(double start, double stop, int n) {
  std::vector<double> out(static_cast<std::size_t>(n));
  const double step = (stop - start) / (n - 1);
  for (int i = 0; i < n; ++i)
    out[static_cast<std::size_t>(i)] =
        step == 0 ? start + (static_cast<double>(i) / (n - 1)) * (stop - start) : i * step + start;
  out.back() = stop;
  return out;
}

// createPR's loop over its thresholds. `visit(f)` calls f(similarity, is_true) for every cell
// (multi-match) or every query's best match (single-match); `positives` is the GTP. The
// thresholds run from the largest similarity to the smallest (numpy.linspace in double); the
// similarities are float32 as the matrix is, so NumPy 1.x compares them with each threshold
// rounded to float32 (value-based casting), as here. Each value is counted once, at the first
// threshold it reaches (the thresholds never increase), so no value is kept.
template <typename Visit>
void ThresholdCurve(const Visit& visit, std::int64_t positives, std::vector<double>& precision,
                    std::vector<double>& recall) {
  precision = {1.0};
  recall = {0.0};
  float hi = -std::numeric_limits<float>::infinity(), lo = std::numeric_limits<float>::infinity();
  visit([&](float s, bool) {
    hi = std::max(hi, s);
    lo = std::min(lo, s);
  });
  if (!(hi >= lo)) return;  // nothing to threshold
  const int n = VprTutorialResult::kThresholds;
  std::vector<float> thresholds;
  for (double t : Linspace(hi, lo, n)) thresholds.push_back(static_cast<float>(t));
  std::vector<std::int64_t> right(static_cast<std::size_t>(n) + 1, 0), wrong = right;
  visit([&](float s, bool is_true) {
    const auto k = std::lower_bound(thresholds.begin(), thresholds.end(), s,
                                    [](float t, float v) { return t > v; }) -
                   thresholds.begin();
    ++(is_true ? right : wrong)[static_cast<std::size_t>(k)];
  });
  std::int64_t tp = 0, fp = 0;
  for (std::size_t k = 0; k < static_cast<std::size_t>(n); ++k) {
    tp += right[k];
    fp += wrong[k];
    precision.push_back(tp + fp > 0 ? static_cast<double>(tp) / static_cast<double>(tp + fp)
                                    : kNaN);
    recall.push_back(positives > 0 ? static_cast<double>(tp) / static_cast<double>(positives)
                                   : kNaN);
  }
}

double MaxRecallAtPrecisionOne(const std::vector<double>& precision,
                               const std::vector<double>& recall) {
  double best = 0;
  for (std::size_t i = 0; i < precision.size(); ++i)
    if (precision[i] == 1.0) best = std::max(best, recall[i]);
  return best;
}

}  // namespace

VprBenchResult EvaluateVprBench(const cv::Mat1f& normalized, const EvaluationLayout& layout,
                                const GroundTruth& truth, int tolerance) {
  const cv::Mat1f block = FiniteBlock(normalized, layout, truth, "vpr_bench");
  VprBenchResult r;
  r.queries = layout.queries;
  const int nq = layout.queries, nr = layout.references;
  if (nq == 0 || nr == 0) return r;
  std::vector<float> score(static_cast<std::size_t>(nq));
  std::vector<std::uint8_t> match(static_cast<std::size_t>(nq));
  const int max_n = std::min(19, nr);
  std::vector<int> hits(static_cast<std::size_t>(max_n), 0);
  std::vector<std::uint8_t> is_true;
  for (int q = 0; q < nq; ++q) {
    const float* row = block[q];
    TrueRow(truth.matches[static_cast<std::size_t>(q)], nr, tolerance, is_true);
    const int best = BestColumn(row, nr);
    score[static_cast<std::size_t>(q)] = -row[best];
    match[static_cast<std::size_t>(q)] = is_true[static_cast<std::size_t>(best)];
    r.right_best_matches += match[static_cast<std::size_t>(q)];
    const int rank = BestTrueRank(row, is_true, nr);
    if (rank >= 0) ++r.queries_with_truth;
    for (int n = 1; n <= max_n; ++n)
      if (rank >= 0 && rank < n) ++hits[static_cast<std::size_t>(n - 1)];
  }
  for (int h : hits) r.recall_at_n.push_back(static_cast<double>(h) / nq);

  // scikit-learn's _binary_clf_curve: the scores in decreasing order; one point at the last
  // position of each distinct score, with the true and false positives up to it.
  std::vector<int> order(static_cast<std::size_t>(nq));
  for (int q = 0; q < nq; ++q) order[static_cast<std::size_t>(q)] = q;
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    return score[static_cast<std::size_t>(a)] > score[static_cast<std::size_t>(b)];
  });
  std::vector<double> tps, fps;
  std::int64_t tp = 0;
  for (int i = 0; i < nq; ++i) {
    tp += match[static_cast<std::size_t>(order[static_cast<std::size_t>(i)])];
    const bool last_of_value =
        i + 1 == nq || score[static_cast<std::size_t>(order[static_cast<std::size_t>(i + 1)])] !=
                           score[static_cast<std::size_t>(order[static_cast<std::size_t>(i)])];
    if (!last_of_value) continue;
    tps.push_back(static_cast<double>(tp));
    fps.push_back(static_cast<double>(i + 1 - tp));
  }
  // precision_recall_curve (scikit-learn 0.20): precision tps / (tps + fps), recall
  // tps / tps[-1]; the points from the first that reaches full recall back to the first,
  // then (recall 0, precision 1).
  const double total = tps.back();
  const std::size_t last =
      static_cast<std::size_t>(std::lower_bound(tps.begin(), tps.end(), total) - tps.begin());
  for (std::size_t k = last + 1; k-- > 0;) {
    r.precision.push_back(tps[k] / (tps[k] + fps[k]));
    r.recall.push_back(total > 0 ? tps[k] / total : kNaN);
  }
  r.precision.push_back(1.0);
  r.recall.push_back(0.0);
  // sklearn.metrics.auc(recall, precision): recall decreases, so the area is -trapz.
  r.auc_pr = total > 0 ? -Trapezoids(r.precision, r.recall) : kNaN;
  const double p_r0 = r.precision[r.precision.size() - 2];
  double r_p100 = 0;
  if (p_r0 >= 1.0) {
    for (std::size_t k = 0; k < r.precision.size(); ++k)
      if (r.precision[k] == 1.0) {
        r_p100 = r.recall[k];
        break;
      }
  }
  r.recall_at_100p = total > 0 ? r_p100 : kNaN;
  r.extended_precision = total > 0 ? (p_r0 + r_p100) / 2 : kNaN;
  return r;
}

VprTutorialResult EvaluateVprTutorial(const cv::Mat1f& normalized, const EvaluationLayout& layout,
                                      const GroundTruth& truth, int tolerance) {
  const cv::Mat1f block = FiniteBlock(normalized, layout, truth, "vpr_tutorial");
  VprTutorialResult r;
  const int nq = layout.queries, nr = layout.references;
  r.soft = !truth.soft.empty();
  if (nq == 0 || nr == 0) return r;

  // Each query's best match, whether it is true, and the rank of its best-ranked true
  // reference (single-match and recallAtK); the true cells (multi-match's GTP).
  std::vector<float> best_score(static_cast<std::size_t>(nq));
  std::vector<std::uint8_t> best_true(static_cast<std::size_t>(nq));
  std::int64_t true_cells = 0;
  int hits[3] = {0, 0, 0};
  std::vector<std::uint8_t> is_true;
  for (int q = 0; q < nq; ++q) {
    const float* row = block[q];
    TrueRow(truth.matches[static_cast<std::size_t>(q)], nr, tolerance, is_true);
    true_cells += std::count(is_true.begin(), is_true.end(), std::uint8_t{1});
    const int best = BestColumn(row, nr);
    best_score[static_cast<std::size_t>(q)] = -row[best];
    best_true[static_cast<std::size_t>(q)] = is_true[static_cast<std::size_t>(best)];
    const int rank = BestTrueRank(row, is_true, nr);
    if (rank < 0) continue;
    ++r.queries_with_truth;
    for (std::size_t k = 0; k < r.k.size(); ++k)
      if (rank < r.k[k]) ++hits[k];
  }
  // recallAtK fails for K above the database's size (NaN here).
  for (std::size_t k = 0; k < r.k.size(); ++k)
    r.recall_at_k.push_back(r.queries_with_truth > 0 && r.k[k] <= nr
                                ? static_cast<double>(hits[k]) / r.queries_with_truth
                                : kNaN);

  // Multi-match: every cell, S = -D; cells only in GTsoft take min(S), the similarity of the
  // largest distance.
  float largest = 0.f;
  for (int q = 0; q < nq; ++q)
    for (int c = 0; c < nr; ++c) largest = std::max(largest, block(q, c));
  const auto every_cell = [&](const auto& f) {
    std::vector<std::uint8_t> row_true, soft_only;
    for (int q = 0; q < nq; ++q) {
      TrueRow(truth.matches[static_cast<std::size_t>(q)], nr, tolerance, row_true);
      soft_only.assign(static_cast<std::size_t>(nr), 0);
      if (r.soft)
        for (int c : truth.soft[static_cast<std::size_t>(q)])
          soft_only[static_cast<std::size_t>(c)] = 1;
      for (int c = 0; c < nr; ++c) {
        const auto cu = static_cast<std::size_t>(c);
        const bool right = row_true[cu] != 0;
        f(!right && soft_only[cu] ? -largest : -block(q, c), right);
      }
    }
  };
  ThresholdCurve(every_cell, true_cells, r.precision_multi, r.recall_multi);
  r.auc_multi = Trapezoids(r.precision_multi, r.recall_multi);
  r.recall_at_100p_multi = MaxRecallAtPrecisionOne(r.precision_multi, r.recall_multi);

  // Single-match, without GTsoft: each query's best match.
  if (!r.soft) {
    r.single = true;
    const auto every_query = [&](const auto& f) {
      for (std::size_t q = 0; q < best_score.size(); ++q) f(best_score[q], best_true[q] != 0);
    };
    ThresholdCurve(every_query, r.queries_with_truth, r.precision_single, r.recall_single);
    r.auc_single = Trapezoids(r.precision_single, r.recall_single);
    r.recall_at_100p_single = MaxRecallAtPrecisionOne(r.precision_single, r.recall_single);
  }
  return r;
}

namespace {

// The n-th value (from 1) of a list of recalls, NaN past its end.
double AtN(const std::vector<double>& recalls, int n) {
  return n >= 1 && static_cast<std::size_t>(n) <= recalls.size()
             ? recalls[static_cast<std::size_t>(n - 1)]
             : kNaN;
}

// A row of the "By protocol" table: AUC, R@100P, R@1, R@5, R@10.
void SetRow(ProtocolFigures& f, double auc, double at_100p, double at_1, double at_5,
            double at_10) {
  f.auc = auc;
  f.recall_at_100p = at_100p;
  f.recall_at_1 = at_1;
  f.recall_at_5 = at_5;
  f.recall_at_10 = at_10;
}

}  // namespace

ProtocolFigures VprBenchFigures(const cv::Mat1f& normalized, const EvaluationLayout& layout,
                                const GroundTruth& truth, int tolerance) {
  const VprBenchResult r = EvaluateVprBench(normalized, layout, truth, tolerance);
  ProtocolFigures f;
  SetRow(f, r.auc_pr, r.recall_at_100p, AtN(r.recall_at_n, 1), AtN(r.recall_at_n, 5),
         AtN(r.recall_at_n, 10));
  f.more = "EP " + FigureText(r.extended_precision) + "; " + std::to_string(r.queries) +
           " queries, " + std::to_string(r.queries_with_truth) + " with a true reference";
  nlohmann::ordered_json& o = f.json;
  o["auc_pr"] = json::Number(r.auc_pr);
  o["recall_at_100p"] = json::Number(r.recall_at_100p);
  o["extended_precision"] = json::Number(r.extended_precision);
  nlohmann::ordered_json& at_n = o["recall_at_n"] = nlohmann::ordered_json::array();
  for (double v : r.recall_at_n) at_n.push_back(json::Number(v));
  o["queries"] = r.queries;
  o["queries_with_truth"] = r.queries_with_truth;
  o["right_best_matches"] = r.right_best_matches;
  // Python's dict: the figures as doubles (NaN stays NaN) and the curve.
  f.details = {{"auc_pr", r.auc_pr},
               {"recall_at_100p", r.recall_at_100p},
               {"extended_precision", r.extended_precision},
               {"recall_at_n", r.recall_at_n},
               {"precision", r.precision},
               {"recall", r.recall},
               {"queries", r.queries},
               {"queries_with_truth", r.queries_with_truth},
               {"right_best_matches", r.right_best_matches}};
  // The curve in the reference code's order.
  f.csv = "precision,recall\n";
  for (std::size_t k = 0; k < r.precision.size(); ++k)
    f.csv += CsvNumber(r.precision[k]) + "," + CsvNumber(r.recall[k]) + "\n";
  return f;
}

ProtocolFigures VprTutorialFigures(const cv::Mat1f& normalized, const EvaluationLayout& layout,
                                   const GroundTruth& truth, int tolerance) {
  const VprTutorialResult t = EvaluateVprTutorial(normalized, layout, truth, tolerance);
  ProtocolFigures f;
  // recall_at_k holds K = 1, 5, 10 in its positions 1, 2, 3.
  SetRow(f, t.auc_multi, t.recall_at_100p_multi, AtN(t.recall_at_k, 1), AtN(t.recall_at_k, 2),
         AtN(t.recall_at_k, 3));
  const std::string single = t.single ? "single-match AUC " + FigureText(t.auc_single) +
                                            ", R@100P " + FigureText(t.recall_at_100p_single)
                                      : std::string("single-match: not with GTsoft");
  f.more = "multi-match; " + single + (t.soft ? "; GTsoft cells ignored" : "");
  nlohmann::ordered_json& o = f.json;
  o["soft_ground_truth"] = t.soft;
  o["multi"] = {{"auc", json::Number(t.auc_multi)},
                {"recall_at_100p", json::Number(t.recall_at_100p_multi)}};
  if (t.single)
    o["single"] = {{"auc", json::Number(t.auc_single)},
                   {"recall_at_100p", json::Number(t.recall_at_100p_single)}};
  else
    o["single"] = nullptr;
  nlohmann::ordered_json& at_k = o["recall_at_k"] = nlohmann::ordered_json::object();
  for (std::size_t k = 0; k < t.k.size() && k < t.recall_at_k.size(); ++k)
    at_k[std::to_string(t.k[k])] = json::Number(t.recall_at_k[k]);
  o["queries_with_truth"] = t.queries_with_truth;
  // Python's dict (recall_at_k's keys, whole numbers, become ints there).
  nlohmann::ordered_json& d = f.details;
  d["auc_multi"] = t.auc_multi;
  d["recall_at_100p_multi"] = t.recall_at_100p_multi;
  d["precision_multi"] = t.precision_multi;
  d["recall_multi"] = t.recall_multi;
  if (t.single) {
    d["auc_single"] = t.auc_single;
    d["recall_at_100p_single"] = t.recall_at_100p_single;
    d["precision_single"] = t.precision_single;
    d["recall_single"] = t.recall_single;
  }
  nlohmann::ordered_json& k_of = d["recall_at_k"] = nlohmann::ordered_json::object();
  for (std::size_t k = 0; k < t.k.size() && k < t.recall_at_k.size(); ++k)
    k_of[std::to_string(t.k[k])] = t.recall_at_k[k];
  d["soft_ground_truth"] = t.soft;
  d["queries_with_truth"] = t.queries_with_truth;
  // The multi-match points, then the single-match ones.
  f.csv = "matching,precision,recall\n";
  for (std::size_t k = 0; k < t.precision_multi.size(); ++k)
    f.csv += "multi," + CsvNumber(t.precision_multi[k]) + "," + CsvNumber(t.recall_multi[k]) + "\n";
  for (std::size_t k = 0; k < t.precision_single.size(); ++k)
    f.csv +=
        "single," + CsvNumber(t.precision_single[k]) + "," + CsvNumber(t.recall_single[k]) + "\n";
  return f;
}

}  // namespace openable
