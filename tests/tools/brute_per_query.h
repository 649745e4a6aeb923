// A brute-force per-query evaluation written from docs/evaluation.md, independent of
// OpenABLE/evaluation/metrics.cc: the tests compare the library's figures with it on hand-made
// and real matrices, for both match scores.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <opencv2/core.hpp>
#include <vector>

namespace openable::testing {

struct BruteQuery {
  bool has_candidates = false, positive = false, answered = false, correct = false;
  int best = -1;
  double score = 0;
};

struct BruteFigures {
  std::vector<BruteQuery> queries;
  int positives = 0, unanswered = 0;
  double auc = 0, recall_at_100p = 0;
};

// `block`: the queries x references block (row q, column c). `loop`: one traversal, the
// candidates of q are columns c <= q - exclusion; otherwise every column. `truth[q]`: its true
// columns. ratio: the best distance over the smallest finite candidate distance more than
// `window` columns away (1 without one or when it is 0).
inline BruteFigures BrutePerQuery(const cv::Mat1f& block,
                                  const std::vector<std::vector<int>>& truth, bool loop,
                                  int exclusion, int tolerance, bool ratio, int window) {
  BruteFigures f;
  f.queries.resize(static_cast<size_t>(block.rows));
  for (int q = 0; q < block.rows; ++q) {
    BruteQuery& b = f.queries[static_cast<size_t>(q)];
    const int end = loop ? std::max(0, std::min(block.cols, q - exclusion + 1)) : block.cols;
    if (end == 0) continue;
    b.has_candidates = true;
    std::vector<int> t;
    for (int c : truth[static_cast<size_t>(q)])
      if (c < end) t.push_back(c);
    b.positive = !t.empty();
    f.positives += b.positive;
    for (int c = 0; c < end; ++c)
      if (std::isfinite(block(q, c)) && (b.best < 0 || block(q, c) < block(q, b.best))) b.best = c;
    if (b.best < 0) {
      ++f.unanswered;
      continue;
    }
    b.answered = true;
    for (int c : t) b.correct = b.correct || std::abs(c - b.best) <= tolerance;
    if (!ratio) {
      b.score = block(q, b.best);
      continue;
    }
    double rival = -1;
    for (int c = 0; c < end; ++c)
      if (std::abs(c - b.best) > window && std::isfinite(block(q, c)) &&
          (rival < 0 || block(q, c) < rival))
        rival = block(q, c);
    b.score = rival <= 0 ? 1.0 : static_cast<double>(block(q, b.best)) / rival;
  }
  // Accept answers in increasing score; a point per distinct score.
  std::vector<const BruteQuery*> order;
  for (const BruteQuery& b : f.queries)
    if (b.answered) order.push_back(&b);
  std::stable_sort(order.begin(), order.end(), [](const BruteQuery* a, const BruteQuery* b) {
    return static_cast<float>(a->score) < static_cast<float>(b->score);
  });
  int tp = 0, fp = 0;
  double previous = 0;
  for (size_t i = 0; i < order.size();) {
    const float s = static_cast<float>(order[i]->score);
    for (; i < order.size() && static_cast<float>(order[i]->score) == s; ++i)
      (order[i]->correct ? tp : fp) += 1;
    const double precision = static_cast<double>(tp) / (tp + fp);
    const double recall = f.positives ? static_cast<double>(tp) / f.positives : 0.0;
    f.auc += precision * (recall - previous);
    previous = recall;
    if (fp == 0 && tp > 0) f.recall_at_100p = recall;
  }
  return f;
}

}  // namespace openable::testing
