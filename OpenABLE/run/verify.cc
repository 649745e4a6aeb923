#include "OpenABLE/run/verify.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <unordered_map>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/strings.h"
#include "OpenABLE/base/threading.h"
#include "OpenABLE/evaluation/layout.h"
#include "OpenABLE/io/frame_source.h"
#include "OpenABLE/run/pipeline.h"
#include "matching/bounded.h"
#include "matching/score.h"

namespace openable {
namespace {

using Clock = std::chrono::steady_clock;

double Ms(Clock::time_point since) {
  return std::chrono::duration<double, std::milli>(Clock::now() - since).count();
}

int FrameCount(const RunResult& result) {
  int n = 0;
  for (const Traversal& t : result.traversals) n += t.frames;
  return n;
}

// The candidates `chosen` (DistinctBest, best first) of one query's (distance, reference)
// cells, with the score of each.
QueryVerification FromCandidates(int query, const std::vector<std::pair<float, int>>& cells,
                                 const std::vector<std::size_t>& chosen,
                                 const std::vector<float>& scores) {
  QueryVerification v;
  v.query = query;
  int rank = 0;
  for (const std::size_t i : chosen) {
    VerifiedCandidate c;
    c.reference = cells[i].second;
    c.rank = ++rank;
    c.distance = cells[i].first;
    c.score = scores[i];
    v.candidates.push_back(c);
  }
  return v;
}

// Features of frames by global row, kept while they fit in the byte budget; the least
// recently used are dropped between batches of queries.
class FeatureCache {
 public:
  explicit FeatureCache(double megabytes) : limit_(megabytes * 1024 * 1024) {}
  const FrameFeatures* Find(int frame) {
    const auto it = kept_.find(frame);
    if (it == kept_.end()) return nullptr;
    it->second.last_use = ++clock_;
    return &it->second.features;
  }
  void Put(int frame, FrameFeatures features) {
    bytes_ += static_cast<double>(features.Bytes());
    kept_[frame] = {std::move(features), ++clock_};
  }
  void Trim() {
    while (bytes_ > limit_ && !kept_.empty()) {
      auto oldest = kept_.begin();
      for (auto it = kept_.begin(); it != kept_.end(); ++it)
        if (it->second.last_use < oldest->second.last_use) oldest = it;
      bytes_ -= static_cast<double>(oldest->second.features.Bytes());
      kept_.erase(oldest);
    }
  }

 private:
  struct Entry {
    FrameFeatures features;
    std::uint64_t last_use = 0;
  };
  double limit_, bytes_ = 0;
  std::uint64_t clock_ = 0;
  std::unordered_map<int, Entry> kept_;
};

}  // namespace

void CheckVerification(const Config& config, bool from_video, int queries,
                       const std::string& first_frame, const cv::Size& size) {
  const VerificationOptions& v = config.verification;
  if (!v.enabled) return;
  v.Check();
  if (from_video)
    throw InputError(
        "Verification: 1 reads the frames of the candidates again, by file, but "
        "the run reads a video or a bag (Frame_mode " +
        std::to_string(static_cast<int>(config.input.frame_mode)) +
        "), whose frames cannot be read again by name; expected Verification 0, "
        "or the frames extracted to a folder (Frame_mode 0)");
  if (!v.calibration.empty()) {
    const CameraIntrinsics camera =
        ReadVerificationCalibration(v.calibration, v.calibration_scale, "Verification_calibration");
    CheckIntrinsicsFit(camera, v.calibration, size, first_frame, "Verification_calibration");
  }
  if (v.consistency > 0 && v.consistency >= queries)
    throw InputError("Verification_consistency: " + std::to_string(v.consistency) +
                     " queries before a loop must also have loops, but the run has " +
                     std::to_string(queries) + " queries; expected fewer than " +
                     std::to_string(queries) + " (0 switches the consistency off)");
}

std::vector<QueryVerification> VerificationCandidates(const Config& config,
                                                      const RunResult& result) {
  const VerificationOptions& v = config.verification;
  const MatchingOptions& m = config.matching;
  std::vector<QueryVerification> out;
  std::vector<std::pair<float, int>> cells;
  std::vector<float> scores;
  if (!result.bounded) {
    // The candidates of the evaluation (EvaluationLayout::CandidateEnd).
    const EvaluationLayout layout = LayoutOf(result);
    for (int q = 0; q < layout.queries; ++q) {
      const int end = layout.CandidateEnd(q, config.evaluation.protocol.exclusion);
      if (end == 0) continue;
      const float* row = result.normalized.ptr<float>(layout.row_offset + q) + layout.col_offset;
      cells.clear();
      for (int c = 0; c < end; ++c) cells.emplace_back(row[c], c);
      const std::vector<std::size_t> chosen = DistinctBest(cells, v.candidates, m.score.window);
      if (chosen.empty()) continue;
      // Scores of the chosen candidates only: ScoreOfCandidate is linear in the row.
      scores.assign(cells.size(), 0.0f);
      for (const std::size_t i : chosen)
        scores[i] = ScoreOfCandidate(row, end, cells[i].second, m.score);
      out.push_back(FromCandidates(q, cells, chosen, scores));
    }
    return out;
  }
  // Bounded: the kept matches of each query (Best_matches of them, and band cells).
  std::map<int, std::vector<const Match*>> by_query;
  for (const Match& match : result.matches) by_query[match.query].push_back(&match);
  for (const auto& [q, matches] : by_query) {
    cells.clear();
    scores.clear();
    for (const Match* match : matches) {
      cells.emplace_back(match->distance, match->reference);
      scores.push_back(match->score);
    }
    const std::vector<std::size_t> chosen = DistinctBest(cells, v.candidates, m.score.window);
    if (!chosen.empty()) out.push_back(FromCandidates(q, cells, chosen, scores));
  }
  return out;
}

RunVerification VerifyRun(const Config& config, const RunResult& result,
                          ProgressReporter& progress) {
  const auto start = Clock::now();
  RunVerification out;
  out.options = config.verification;
  out.options.tolerance = config.evaluation.protocol.tolerance;
  std::optional<CameraIntrinsics> camera;
  if (!out.options.calibration.empty()) {
    camera = ReadVerificationCalibration(out.options.calibration, out.options.calibration_scale,
                                         "Verification_calibration");
    char text[160];
    std::snprintf(text, sizeof text, "essential matrix (fx %.1f, fy %.1f, cx %.1f, cy %.1f)",
                  camera->fx, camera->fy, camera->cx, camera->cy);
    out.geometry = text;
  } else {
    out.geometry = "fundamental matrix (uncalibrated)";
  }
  const PairVerifier verifier(out.options, camera);
  out.queries = VerificationCandidates(config, result);

  const Traversal& reference = result.traversals.front();
  const Traversal& query = result.traversals.back();
  // Global rows key the cache: with one traversal a query and a reference may be one frame.
  auto name_of = [&](int row) -> const std::string& {
    for (const Traversal& t : result.traversals)
      if (row >= t.first_row && row < t.first_row + t.frames) return t.names[row - t.first_row];
    throw std::logic_error("VerifyRun: row outside the run");
  };
  FeatureCache cache(out.options.cache_mb);
  std::vector<char> seen(FrameCount(result), 0);
  const int threads = config.matching.threads;
  constexpr int kBatch = 64;  // queries whose frames are read together
  const int total = static_cast<int>(out.queries.size());
  progress.Begin("verifying", total,
                 "queries (" + std::to_string(out.options.candidates) + " candidates each, " +
                     EnumName(out.options.features) + ")");
  std::mutex mutex;
  for (int first = 0; first < total; first += kBatch) {
    const int last = std::min(total, first + kBatch);
    // The frames of the batch whose features are not kept, each once, in row order.
    std::vector<int> rows;
    for (int i = first; i < last; ++i) {
      rows.push_back(query.first_row + out.queries[i].query);
      for (const VerifiedCandidate& c : out.queries[i].candidates)
        rows.push_back(reference.first_row + c.reference);
    }
    std::sort(rows.begin(), rows.end());
    rows.erase(std::unique(rows.begin(), rows.end()), rows.end());
    std::vector<int> missing;
    for (const int row : rows)
      if (cache.Find(row) == nullptr) missing.push_back(row);
    std::vector<FrameFeatures> computed(missing.size());
    std::vector<float> computed_ms(missing.size());
    ParallelFor(static_cast<int>(missing.size()), threads, [&](int i) {
      const auto t = Clock::now();
      computed[i] = verifier.Extract(ReadImageFile(name_of(missing[i])));
      computed_ms[i] = static_cast<float>(Ms(t));
    });
    for (std::size_t i = 0; i < missing.size(); ++i) {
      if (!seen[missing[i]]) ++out.frames;
      seen[missing[i]] = 1;
      ++out.extractions;
      out.extract_ms.push_back(computed_ms[i]);
      cache.Put(missing[i], std::move(computed[i]));
    }
    // Every frame of the batch is kept now (the cache is trimmed only after the batch).
    std::vector<const FrameFeatures*> query_features(last - first);
    std::vector<std::vector<const FrameFeatures*>> reference_features(last - first);
    for (int i = first; i < last; ++i) {
      query_features[i - first] = cache.Find(query.first_row + out.queries[i].query);
      for (const VerifiedCandidate& c : out.queries[i].candidates)
        reference_features[i - first].push_back(cache.Find(reference.first_row + c.reference));
    }
    ParallelFor(last - first, threads, [&](int b) {
      QueryVerification& q = out.queries[first + b];
      std::vector<float> ms;
      for (std::size_t c = 0; c < q.candidates.size(); ++c) {
        const auto t = Clock::now();
        q.candidates[c].check = verifier.Verify(*query_features[b], *reference_features[b][c]);
        ms.push_back(static_cast<float>(Ms(t)));
      }
      std::lock_guard<std::mutex> lock(mutex);
      out.pair_ms.insert(out.pair_ms.end(), ms.begin(), ms.end());
    });
    cache.Trim();
    progress.Update(last);
  }
  progress.End();
  ApplyTemporalConsistency(out.queries, out.options.consistency, out.options.tolerance);
  for (const QueryVerification& q : out.queries) {
    out.pairs += static_cast<int>(q.candidates.size());
    for (const VerifiedCandidate& c : q.candidates) out.geometric += c.check.verified ? 1 : 0;
    out.answered += q.answer >= 0 ? 1 : 0;
  }
  out.seconds = SecondsSince(start);
  return out;
}

LatencySummary Summarize(const std::vector<float>& milliseconds) {
  LatencySummary s;
  if (milliseconds.empty()) return s;
  std::vector<float> sorted = milliseconds;
  std::sort(sorted.begin(), sorted.end());
  double sum = 0;
  for (const float x : sorted) sum += x;
  s.mean = sum / static_cast<double>(sorted.size());
  // Nearest rank: the smallest value with at least 99 % of the values at or below it.
  const std::size_t rank = (99 * sorted.size() + 99) / 100;
  s.p99 = sorted[std::min(sorted.size(), std::max<std::size_t>(rank, 1)) - 1];
  return s;
}

std::string EncodeLoops(const RunVerification& v) {
  std::string out =
      "query,reference,rank,distance,score,matches,inliers,model,geometric,streak,verified\n";
  for (const QueryVerification& q : v.queries)
    for (const VerifiedCandidate& c : q.candidates)
      out += std::to_string(q.query) + "," + std::to_string(c.reference) + "," +
             std::to_string(c.rank) + "," + FormatNumber(c.distance, 9) + "," +
             FormatNumber(c.score, 9) + "," + std::to_string(c.check.matches) + "," +
             std::to_string(c.check.inliers) + "," + EnumName(c.check.model) + "," +
             (c.check.verified ? "1" : "0") + "," + std::to_string(c.streak) + "," +
             (c.accepted ? "1" : "0") + "\n";
  return out;
}

VerifiedAnswers AnswersOf(const RunVerification& verification, const EvaluationLayout& layout) {
  VerifiedAnswers out;
  out.accepted.resize(layout.queries);
  for (const QueryVerification& q : verification.queries) {
    if (q.query < 0 || q.query >= layout.queries)
      throw std::logic_error("AnswersOf: a query outside the layout");
    for (const VerifiedCandidate& c : q.candidates) {
      if (c.accepted)
        out.accepted[q.query].push_back({c.reference, c.distance, c.score});
      else
        out.rejected.emplace_back(c.reference, q.query);
    }
  }
  return out;
}

}  // namespace openable
