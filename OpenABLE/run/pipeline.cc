#include "OpenABLE/run/pipeline.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <iostream>
#include <stdexcept>

#include "OpenABLE/base/error.h"
#include "OpenABLE/cluster/distributed.h"
#include "OpenABLE/describe/describe.h"
#include "OpenABLE/run/descriptor_cache.h"
#include "descriptors/registry.h"
#include "matching/contrast.h"
#include "matching/matrix.h"
#include "matching/normalize.h"
#include "matching/panorama.h"
#include "matching/sequence.h"

namespace openable {
namespace {

using Clock = std::chrono::steady_clock;

bool HasDisplay() {
  return std::getenv("DISPLAY") != nullptr || std::getenv("WAYLAND_DISPLAY") != nullptr;
}

// The frames of every source described with one descriptor.
struct Described {
  cv::Mat rows;  // the traversals' rows, concatenated
  std::vector<Traversal> traversals;
  std::string cache;
  std::vector<std::string> warnings, notes;
  double seconds = 0;
  int frames = 0;
};

// One descriptor of a run to describe: `config` is the run's with Image_descriptor that one
// descriptor (it keys the descriptor cache).
struct ToDescribe {
  const Config* config;
  const FrameDescriber* describer;
  std::string name;
};

// The descriptor cache of one descriptor, or nullptr with a note saying why it is not used.
std::unique_ptr<DescriptorCache> OpenDescriptorCache(const ToDescribe& d, const SourceSpec& first,
                                                     const DescribeOptions& options,
                                                     Described& out) {
  const ScaleOptions& scale = d.config->scale;
  if (scale.descriptor_cache.empty()) return nullptr;
  if (first.kind != SourceKind::kFolder) {
    out.notes.push_back(
        "Descriptor_cache: not used: the cache keeps rows of image "
        "files (Frame_mode 0, Camera_type 0 or 2), not of videos, bags "
        "or stereo pairs");
    return nullptr;
  }
  if (options.show_images) {
    out.notes.push_back("Descriptor_cache: not used with Show_images 1");
    return nullptr;
  }
  if (options.preprocess.noise.Any()) {
    // The noise of a frame depends on its position in the run, not only on its bytes.
    out.notes.push_back(
        "Descriptor_cache: not used with Noise_* (a frame's noise depends "
        "on its position in the run, not only on the image)");
    return nullptr;
  }
  // Spread over processes, each process keeps its own cache (its share of the frames) in a
  // folder of the cache named after it.
  const Cluster& cluster = Cluster::Get();
  return DescriptorCache::Open(
      cluster.Distributed()
          ? scale.descriptor_cache + "/process-" + std::to_string(cluster.Rank()) + "-of-" +
                std::to_string(cluster.Size())
          : scale.descriptor_cache,
      DescriptionSettingsText(*d.config,
                              d.describer->Fingerprint().empty()
                                  ? d.name
                                  : d.name + " (weights " + d.describer->Fingerprint() + ")",
                              d.describer->RowWidth(), d.describer->RowType()),
      d.describer->RowWidth(), d.describer->RowType(), out.warnings);
}

// The rows given for every source (Descriptors_path, OpenABLE/run/given_rows.h): nothing is
// described; the frames are listed (names, times) and the first one read for its size.
Described GivenRowsDescribed(const FrameDescriber& describer, const std::vector<SourceSpec>& specs,
                             const std::vector<std::unique_ptr<FrameSource>>& sources) {
  Described out;
  std::vector<cv::Mat> blocks;
  int row = 0;
  for (size_t s = 0; s < sources.size(); ++s) {
    const cv::Mat& rows = *describer.GivenRows(static_cast<int>(s));
    Traversal tr;
    tr.key = specs[s].key;
    tr.path = specs[s].path;
    tr.first_row = row;
    tr.frames = rows.rows;
    tr.frame_size = sources[s]->Read(0).size();
    for (int i = 0; i < sources[s]->Size(); ++i) {
      tr.names.push_back(sources[s]->FrameName(i));
      tr.times.push_back(sources[s]->Timestamp(i));
    }
    if (std::any_of(tr.times.begin(), tr.times.end(), [](double t) { return std::isnan(t); }))
      tr.times.clear();  // a source without times
    row += tr.frames;
    out.frames += sources[s]->Size();
    out.traversals.push_back(std::move(tr));
    blocks.push_back(rows);
  }
  cv::vconcat(blocks, out.rows);
  out.notes.push_back("Descriptors_path: the rows of " + std::to_string(out.frames) +
                      " frames given, none described");
  return out;
}

// Describes every source with each descriptor of `all`. In one process, each frame is read and
// converted once for all of them (DescribeSequences: decoding a KITTI frame costs more than
// describing it with LDB or HOG); spread over processes, one descriptor after the other
// (DescribeShared gathers the rows of one descriptor). The seconds of the shared pass are
// divided among the descriptors.
std::vector<Described> DescribeSources(const std::vector<ToDescribe>& all,
                                       const std::vector<SourceSpec>& specs,
                                       const std::vector<std::unique_ptr<FrameSource>>& sources,
                                       ProgressReporter& progress) {
  Cluster& cluster = Cluster::Get();
  if (all.size() > 1 && cluster.Distributed()) {
    std::vector<Described> out;
    for (const ToDescribe& d : all) {
      std::vector<Described> one = DescribeSources({d}, specs, sources, progress);
      out.push_back(std::move(one.front()));
    }
    return out;
  }
  const Config& config = *all.front().config;
  const InputOptions& input = config.input;
  const int count = static_cast<int>(all.size());
  if (count == 1 && all.front().describer->GivenRows(0) != nullptr)
    return {GivenRowsDescribed(*all.front().describer, specs, sources)};
  std::vector<Described> out(static_cast<size_t>(count));
  DescribeOptions options;
  options.threads = config.matching.threads;
  options.skip_unreadable = input.skip_unreadable;
  options.show_images = config.output.show_images && HasDisplay();
  options.preprocess = config.preprocess;

  // A descriptor that learns before describing (DenseVLAD's vocabulary) learns from frames
  // spread over the reference traversal, the same in every process, before its rows are
  // described or looked up in the cache (whose key holds what was learnt: Fingerprint).
  for (int k = 0; k < count; ++k) {
    const ToDescribe& d = all[static_cast<size_t>(k)];
    if (!d.describer->Learns() || !d.describer->Fingerprint().empty()) continue;
    progress.Begin("learning", 1, d.name + " from frames of " + specs.front().key);
    const int used =
        LearnFromSource(*sources.front(), *d.describer, options, d.describer->LearnFrames());
    progress.End();
    out[static_cast<size_t>(k)].notes.push_back(d.name + ": learnt from " + std::to_string(used) +
                                                " frames spread over " + specs.front().key +
                                                " (no ground truth)");
  }

  // Descriptor caches: image folders only (a video frame or a stereo pair has no one file).
  std::vector<std::unique_ptr<DescriptorCache>> caches;
  std::vector<const FrameDescriber*> describers;
  std::vector<RowCache*> row_caches;
  std::string names;
  for (int k = 0; k < count; ++k) {
    const ToDescribe& d = all[static_cast<size_t>(k)];
    caches.push_back(OpenDescriptorCache(d, specs.front(), options, out[static_cast<size_t>(k)]));
    describers.push_back(d.describer);
    row_caches.push_back(caches.back().get());
    names += (k ? ", " : "") + d.name;
  }
  options.cache = row_caches.front();  // the one descriptor of DescribeShared

  const auto t = Clock::now();
  std::vector<std::vector<cv::Mat>> blocks(static_cast<size_t>(count));
  int row = 0;
  for (size_t s = 0; s < sources.size(); ++s) {
    const bool stereo =
        specs[s].kind == SourceKind::kStereo || specs[s].kind == SourceKind::kStereoBag;
    options.key = stereo ? "" : specs[s].key;    // stereo read errors name their own key
    options.noise_stream = static_cast<int>(s);  // each traversal its own noise
    // Spread over processes: process 0's progress counts its share.
    const auto [share_first, share_last] = cluster.Share(sources[s]->Size());
    progress.Begin("describing", share_last - share_first,
                   stereo ? "stereo pairs (rectify" +
                                std::string(describers.front()->Channels() == 2 ? ", SGBM" : "") +
                                ", " + names + ")"
                          : "frames of " + specs[s].key + " (" + names + ")");
    const auto on_frames = [&](int done, int) { progress.Update(done); };
    std::vector<DescribedSequence> seqs;
    if (count == 1) {
      seqs.push_back(DescribeShared(cluster, *sources[s], *describers.front(), options, on_frames));
    } else {
      seqs = DescribeSequences(*sources[s], describers, row_caches, options, on_frames);
    }
    progress.End();
    const DescribedSequence& seq = seqs.front();
    Traversal tr;
    tr.key = specs[s].key;
    tr.path = specs[s].path;
    tr.first_row = row;
    tr.frames = seq.rows.rows;
    tr.skipped = seq.skipped;
    tr.frame_size = seq.frame_size;
    for (int i : seq.kept) {
      tr.names.push_back(sources[s]->FrameName(i));
      tr.times.push_back(sources[s]->Timestamp(i));
    }
    if (std::any_of(tr.times.begin(), tr.times.end(), [](double t) { return std::isnan(t); }))
      tr.times.clear();  // a source without times
    row += tr.frames;
    for (int k = 0; k < count; ++k) {
      Described& o = out[static_cast<size_t>(k)];
      o.frames += sources[s]->Size();
      o.traversals.push_back(tr);
      blocks[static_cast<size_t>(k)].push_back(seqs[static_cast<size_t>(k)].rows);
    }
  }
  const double seconds = SecondsSince(t) / count;
  for (int k = 0; k < count; ++k) {
    Described& o = out[static_cast<size_t>(k)];
    o.seconds = seconds;
    if (const DescriptorCache* cache = caches[static_cast<size_t>(k)].get()) {
      o.cache = std::to_string(cache->Hits()) + " of " + std::to_string(o.frames) +
                " frames from the cache, " + std::to_string(cache->Stored()) + " added (\"" +
                cache->Path() + "\")";
      const std::string problem = cache->WriteProblem();
      if (!problem.empty()) o.warnings.push_back(problem);
    }
    cv::vconcat(blocks[static_cast<size_t>(k)], o.rows);
  }
  return out;
}

// Describes every source with `describer` (DescribeSources of one descriptor).
Described DescribeSources(const Config& config, const FrameDescriber& describer,
                          const std::string& name, const std::vector<SourceSpec>& specs,
                          const std::vector<std::unique_ptr<FrameSource>>& sources,
                          ProgressReporter& progress) {
  return std::move(
      DescribeSources({ToDescribe{&config, &describer, name}}, specs, sources, progress).front());
}

// The best matches a run answered and accepted (Match_threshold, Match_consistency), from its
// matches of rank 1.
void CountAccepted(RunResult& result, const MatchingOptions& matching,
                   const std::vector<Match>& matches) {
  int queries = 0;
  result.answered_queries = 0;
  for (const Match& m : matches)
    if (m.rank == 1) {
      ++result.answered_queries;
      queries = std::max(queries, m.query + 1);
    }
  const AgreementOptions agreement = AgreementOf(matching);
  const std::vector<std::uint8_t> accepted =
      AcceptedMatches(matches, queries, matching.match_threshold,
                      matching.match_consistency > 0 ? &agreement : nullptr);
  result.accepted_queries = static_cast<int>(std::count(accepted.begin(), accepted.end(), 1));
}

// Adds `more` to `all`, each line once.
void AddLines(std::vector<std::string>& all, const std::vector<std::string>& more) {
  for (const std::string& line : more)
    if (std::find(all.begin(), all.end(), line) == all.end()) all.push_back(line);
}

// Steps 2 and 3 of a dense run (docs/architecture.md): the single-frame matrices of several
// descriptors each divided by its largest value (`largest_of` gives it over every process) and
// summed with their weights, then contrast enhancement. One matrix is used as it is, copied
// when `copy`.
cv::Mat1f FusedSingleFrame(const std::vector<const cv::Mat1f*>& singles,
                           const std::vector<double>& weights, const MatchingOptions& matching,
                           const std::vector<int>& starts, bool copy,
                           const std::function<double(double)>& largest_of) {
  cv::Mat1f distances;
  if (singles.size() == 1) {
    distances = copy ? singles.front()->clone() : *singles.front();
  } else {
    distances = cv::Mat1f::zeros(singles.front()->size());
    for (size_t k = 0; k < singles.size(); ++k) {
      double largest = 0;
      if (!singles[k]->empty()) cv::minMaxLoc(*singles[k], nullptr, &largest);
      largest = largest_of(largest);
      // A descriptor whose frames are all alike (largest 0) adds nothing.
      if (largest > 0) cv::scaleAdd(*singles[k], weights[k] / largest, distances, distances);
    }
  }
  if (matching.contrast.enabled)
    EnhanceContrast(distances, matching.contrast.window, starts, matching.threads);
  return distances;
}

// Sets the run's traversals from the first description; the next (the other descriptors of a
// fusion) must have read the same frames.
void SetTraversals(RunResult& result, std::vector<int>& starts,
                   const std::vector<Traversal>& traversals) {
  if (result.traversals.empty()) {
    result.traversals = traversals;
    for (const auto& tr : traversals) starts.push_back(tr.first_row);
    return;
  }
  // Every descriptor reads the same frames; a frame readable for one and not another would
  // misalign the fused matrices.
  for (size_t s = 0; s < traversals.size(); ++s)
    if (traversals[s].names != result.traversals[s].names)
      throw InputError(traversals[s].key +
                       ": the frames read differ between the fused "
                       "descriptors (a file changed during the run?); expected the same "
                       "frames for each");
}

// The frames of a run of one descriptor described, and what the run's result says of them:
// traversals (their first rows into `starts`), cache, warnings, notes and timings.
Described DescribeOne(const RunPlan& plan, ProgressReporter& progress, RunResult& result,
                      std::vector<int>& starts) {
  Described described = DescribeSources(plan.config, *plan.describers.front(), plan.names.front(),
                                        plan.specs, plan.sources, progress);
  SetTraversals(result, starts, described.traversals);
  result.cache = described.cache;
  AddLines(result.warnings, described.warnings);
  AddLines(result.notes, described.notes);
  result.timings.describe_seconds = described.seconds;
  result.timings.frames = described.frames;
  return described;
}

// What the run keeps of its matches: Best_matches and the band, with the evaluation's
// exclusion and the score of Match_score.
KeepRules KeepRulesOf(const Config& config, const MatchBlock& block) {
  KeepRules rules = config.scale.keep;
  rules.exclusion = config.evaluation.protocol.exclusion;
  rules.score = config.matching.score;
  rules.score.window = config.matching.score.window;
  rules.one_traversal = block.one_traversal;
  return rules;
}

// A bounded run: the rows of the one descriptor, then each query's best matches by ranges of
// rows (exact, or from an approximate index), shared over processes.
void ComputeBounded(const RunPlan& plan, ProgressReporter& progress, RunResult& result) {
  const Config& config = plan.config;
  const MatchingOptions& matching = config.matching;
  const ScaleOptions& scale = config.scale;
  std::vector<int> starts;
  const Described described = DescribeOne(plan, progress, result, starts);
  const std::int64_t n = described.rows.rows;
  const MatchBlock block = BlockOf(starts, static_cast<int>(n));
  const KeepRules rules = KeepRulesOf(config, block);
  const auto t = Clock::now();
  result.timings.pairs = static_cast<std::int64_t>(block.query_count) * block.reference_count;
  Cluster& cluster = Cluster::Get();
  const auto [query_first, query_last] = cluster.Share(block.query_count);
  progress.Begin("matching", query_last - query_first,
                 "queries (bounded: ranges of rows" +
                     std::string(cluster.Distributed() ? ", this process's share)" : ")"));
  BoundedOptions options;
  options.metric = result.descriptors.front().metric;
  options.sequence_length = matching.sequence_length;
  options.direction = matching.direction;
  options.partial = matching.partial;
  options.threads = matching.threads;
  // This process's share of the queries (all of them in a single process), raw or normalised
  // as `share` says.
  const auto match_share = [&](const BoundedOptions& share, float& largest) {
    if (scale.approximate_search)
      return ApproximateMatches(described.rows, block, rules, share, scale.approximate, largest);
    return BoundedMatches(described.rows, block, rules, share, largest,
                          [&](int done, int) { progress.Update(done); });
  };
  result.matches =
      SharedBoundedMatches(cluster, block, rules, options, match_share, result.max_distance);
  progress.End();
  cluster.Release();
  result.timings.match_seconds = SecondsSince(t);
  if (matching.match_threshold >= 0.0) CountAccepted(result, matching, result.matches);
}

// Step 1 of a dense run: one single-frame matrix per descriptor, every frame against every
// frame of the concatenated traversals, as the original, from the store when a sweep computed
// it already (kept there when computed), else into `computed`. Spread over processes, each
// computes the rows of its share (DenseShare).
std::vector<const SingleFrame*> DenseSingleFrames(const RunPlan& plan, ProgressReporter& progress,
                                                  SingleFrameStore* store,
                                                  std::vector<SingleFrame>& computed) {
  const Config& config = plan.config;
  const MatchingOptions& matching = config.matching;
  Cluster& cluster = Cluster::Get();
  const std::vector<std::string>& names = plan.names;
  std::vector<const SingleFrame*> singles;
  computed.reserve(names.size());
  // The descriptors whose matrices are not kept already are described together, each frame
  // read once for all of them (fused descriptors).
  std::vector<std::string> keys(names.size());
  std::vector<Config> ones(names.size(), config);
  std::vector<ToDescribe> to_describe;
  std::vector<size_t> described_index(names.size(), names.size());
  for (size_t k = 0; k < names.size(); ++k) {
    if (store) keys[k] = SingleFrameKey(config, names[k]);
    if (store && store->Find(keys[k])) continue;
    ones[k].descriptor.name = names[k];
    described_index[k] = to_describe.size();
    to_describe.push_back({&ones[k], plan.describers[k].get(), names[k]});
  }
  std::vector<Described> all_described =
      to_describe.empty() ? std::vector<Described>()
                          : DescribeSources(to_describe, plan.specs, plan.sources, progress);
  for (size_t k = 0; k < names.size(); ++k) {
    const std::string& key = keys[k];
    if (store)
      if (const SingleFrame* kept = store->Find(key)) {
        singles.push_back(kept);
        continue;
      }
    Described described = std::move(all_described[described_index[k]]);
    SingleFrame frame;
    frame.descriptor = plan.head.descriptors[k];
    frame.traversals = described.traversals;
    frame.cache = described.cache;
    frame.warnings = described.warnings;
    frame.notes = described.notes;
    frame.describe_seconds = described.seconds;
    frame.frames = described.frames;
    const std::int64_t n = described.rows.rows;
    frame.pairs = n * (n - 1) / 2;
    const auto t = Clock::now();
    // Spread over processes: this process's rows, with the L - 1 rows its sequences read.
    const DenseShare share = DenseShareOf(cluster, static_cast<int>(n), matching.sequence_length);
    const std::int64_t share_rows = share.last - share.history;
    const int strips = plan.strips;
    progress.Begin("matching", share_rows * n * (plan.cross ? strips * strips : 1),
                   std::string(plan.cross ? "cells of sub-panorama pairs" : "cells") +
                       (plan.Fused() ? " (" + names[k] + ")" : ""));
    const PairProgress on_pairs = [&](std::int64_t done, std::int64_t) { progress.Update(done); };
    cluster.Agree([&] {
      frame.distances =
          DistanceRows(described.rows, share.history, share.last, frame.descriptor.metric, strips,
                       matching.panorama_matching, matching.threads, on_pairs);
    });
    progress.End();
    frame.match_seconds = SecondsSince(t);
    if (store) {
      singles.push_back(&store->Keep(key, std::move(frame)));
    } else {
      computed.push_back(std::move(frame));
      singles.push_back(&computed.back());
    }
  }
  return singles;
}

// The single-frame matrices' traversals, cache lines, warnings, notes and timings, in the
// run's result.
void TakeSingleFrames(const std::vector<const SingleFrame*>& singles, bool fused, RunResult& result,
                      std::vector<int>& starts) {
  for (const SingleFrame* f : singles) {
    SetTraversals(result, starts, f->traversals);
    if (!f->cache.empty())
      result.cache += (result.cache.empty() ? "" : "; ") +
                      (fused ? f->descriptor.name + ": " : std::string()) + f->cache;
    AddLines(result.warnings, f->warnings);
    AddLines(result.notes, f->notes);
    result.timings.describe_seconds += f->describe_seconds;
    result.timings.match_seconds += f->match_seconds;
    result.timings.frames = f->frames;
    result.timings.pairs = f->pairs;
  }
}

void FinishNormalized(const Config& config, const std::vector<int>& starts, RunResult& result);

// Steps 2 to 6 of a dense run on `distances`, the fused and enhanced single-frame matrix:
// sequences, Eq. 5 (over every process's largest value, the rows gathered on process 0), the
// threshold of Eq. 9, the matches kept and the answers accepted. Returns false on the
// processes other than 0, which give their rows and stop.
bool FinishDense(const Config& config, cv::Mat1f distances, const std::vector<int>& starts,
                 RunResult& result) {
  const MatchingOptions& matching = config.matching;
  const SequenceDirection direction = matching.direction;
  Cluster& cluster = Cluster::Get();
  if (!cluster.Distributed()) {
    SequenceDistancesInPlace(distances, matching.sequence_length, starts, starts, direction,
                             matching.threads, matching.partial);
    result.normalized = distances;
    distances.release();
    result.max_distance = NormalizeByMax(result.normalized);
  } else {
    // This process's rows: the sequences over its rows and the L - 1 before (a start of the
    // computed rows for the sums, which the kept rows never reach back to), Eq. 5 with the
    // largest value of every process, the rows gathered on process 0.
    const int n = distances.cols;
    const DenseShare share = DenseShareOf(cluster, n, matching.sequence_length);
    cv::Mat1f rows;
    float largest = 0.0f;
    // Sequence_partial ahead reads cells of later rows, which may belong to the next share:
    // each process leaves its early cells without a value (skip; they never set the largest
    // value, which ahead only copies) and process 0 fills them in the gathered matrix.
    const bool ahead = matching.partial == SequencePartial::kAhead;
    cluster.Agree([&] {
      SequenceDistancesInPlace(distances, matching.sequence_length, ShareRowStarts(starts, share),
                               starts, direction, matching.threads,
                               ahead ? SequencePartial::kSkip : matching.partial);
      rows = distances.rowRange(share.first - share.history, share.last - share.history);
      largest = LargestFiniteEntry(rows);
    });
    result.max_distance = static_cast<float>(cluster.Max(largest));
    DivideByLargest(rows, result.max_distance);
    result.normalized = GatherRows(cluster, rows, n, n);
    distances.release();
    cluster.Release();
    if (cluster.Rank() != 0) return false;  // process 0 keeps the matrix and goes on
    if (ahead && matching.sequence_length > 1) {
      FillAheadCells(result.normalized, matching.sequence_length, starts, starts,
                     direction == SequenceDirection::kReverse);
    }
  }
  FinishNormalized(config, starts, result);
  return true;
}

// Steps 4 to 6 of a dense run on its normalised matrix: the threshold of Eq. 9, the matches
// kept and the answers accepted.
void FinishNormalized(const Config& config, const std::vector<int>& starts, RunResult& result) {
  const MatchingOptions& matching = config.matching;
  if (matching.partial != SequencePartial::kScale)
    result.empty_cells = static_cast<std::int64_t>(result.normalized.total()) -
                         cv::countNonZero(result.normalized <= 1.0f);
  if (matching.threshold >= 0.0)
    result.thresholded = ThresholdMatrix(result.normalized, static_cast<float>(matching.threshold));
  const MatchBlock block = BlockOf(starts, result.normalized.rows);
  const KeepRules rules = KeepRulesOf(config, block);
  if (!config.scale.matches_name.empty())
    result.matches = MatchesFromMatrix(result.normalized, block, rules);
  if (matching.match_threshold >= 0.0) {
    KeepRules best = rules;
    best.best = 1;
    best.band = -1;
    CountAccepted(result, matching, MatchesFromMatrix(result.normalized, block, best));
  }
}

// Whether a dense run can compute its matrix in one pass (FusedSequenceMatrix): nothing needs
// its single-frame matrix (no store keeping it for other runs, no fusion, no contrast
// enhancement), the frames are compared whole in one process, and their distances are integers
// (the L2 matrices keep the tiles a run spread over processes computes the same way).
bool OnePassFits(const RunPlan& plan, const SingleFrameStore* store) {
  return store == nullptr && !plan.Fused() && plan.strips == 1 &&
         !plan.config.matching.contrast.enabled && !Cluster::Get().Distributed() &&
         plan.head.descriptors.front().metric != Metric::kL2;
}

// A dense run in one pass: the frames described, then distances, sequence sums and the
// largest value computed together a few rows at a time (no single-frame matrix), one scaling
// pass (Eq. 5), and steps 4 to 6 as for any dense run. The same matrix as the other path.
RunResult ComputeOnePass(const RunPlan& plan, ProgressReporter& progress,
                         Clock::time_point run_start) {
  const Config& config = plan.config;
  const MatchingOptions& matching = config.matching;
  RunResult result = plan.head;
  std::vector<int> starts;
  Described described = DescribeOne(plan, progress, result, starts);
  const int n = described.rows.rows;
  result.timings.pairs = static_cast<std::int64_t>(n) * (n - 1) / 2;
  const auto t = Clock::now();
  progress.Begin("matching", n, "rows (distances and sequences in one pass)");
  float largest = 0.0f;
  result.normalized =
      FusedSequenceMatrix(described.rows, result.descriptors.front().metric,
                          matching.sequence_length, matching.direction, matching.partial, starts,
                          matching.threads, largest, [&](int done, int) { progress.Update(done); });
  progress.End();
  result.timings.match_seconds = SecondsSince(t);
  const auto t2 = Clock::now();
  described.rows.release();
  DivideByLargest(result.normalized, largest);
  result.max_distance = largest;
  FinishNormalized(config, starts, result);
  result.timings.sequence_seconds = SecondsSince(t2);
  result.timings.total_seconds = SecondsSince(run_start);
  return result;
}

// A run from its plan, to its single-frame matrices alone (`single_frames_only`) or to the end.
RunResult ComputePlanned(const RunPlan& plan, ProgressReporter& progress, SingleFrameStore* store,
                         bool single_frames_only) {
  const auto run_start = Clock::now();
  RunResult result = plan.head;
  if (result.bounded) {
    ComputeBounded(plan, progress, result);
    result.timings.total_seconds = SecondsSince(run_start);
    return result;
  }
  if (!single_frames_only && OnePassFits(plan, store))
    return ComputeOnePass(plan, progress, run_start);
  std::vector<SingleFrame> computed;  // without a store
  const std::vector<const SingleFrame*> singles =
      DenseSingleFrames(plan, progress, store, computed);
  std::vector<int> starts;
  TakeSingleFrames(singles, plan.Fused(), result, starts);
  if (single_frames_only) return result;

  // Fusion (each matrix over its largest value, weighted), contrast enhancement, sequences,
  // Eq. 5, Eq. 9.
  const auto t = Clock::now();
  std::vector<const cv::Mat1f*> matrices;
  for (const SingleFrame* f : singles) matrices.push_back(&f->distances);
  // The store keeps its matrix for the next run; without one, the matrix is taken over.
  cv::Mat1f distances = FusedSingleFrame(
      matrices, result.fusion_weights, plan.config.matching, starts, store != nullptr,
      [&](double largest) { return Cluster::Get().Max(largest); });
  if (!store && !plan.Fused()) computed.front().distances.release();
  if (!FinishDense(plan.config, std::move(distances), starts, result)) return result;
  result.timings.sequence_seconds = SecondsSince(t);
  result.timings.total_seconds = SecondsSince(run_start);
  return result;
}

}  // namespace

RunResult ComputeRun(const RunPlan& plan, ProgressReporter& progress, SingleFrameStore* store) {
  return ComputePlanned(plan, progress, store, false);
}

RunResult ComputeRun(const Config& config, ProgressReporter& progress, SingleFrameStore* store) {
  return ComputeRun(PlanRun(config), progress, store);
}

void CheckRun(const Config& config) { (void)PlanRun(config); }

RunResult ComputeSingleFrames(const Config& config, ProgressReporter& progress,
                              SingleFrameStore& store) {
  return ComputePlanned(PlanRun(config, PlanScope::kSingleFrames), progress, &store, true);
}

std::vector<RunResult> ComputeSingleFramesTogether(const std::vector<Config>& configs,
                                                   ProgressReporter& progress,
                                                   SingleFrameStore& store) {
  struct Group {
    std::string settings;  // SingleFrameKey without the descriptor
    Config config;         // the first run's
    std::vector<std::string> names;
  };
  std::vector<Group> groups;
  for (const Config& c : configs) {
    const std::string settings = SingleFrameKey(c, "");
    auto group = std::find_if(groups.begin(), groups.end(),
                              [&](const Group& g) { return g.settings == settings; });
    if (group == groups.end()) group = groups.insert(groups.end(), {settings, c, {}});
    for (const std::string& name : DescriptorList(c.descriptor.name))
      if (std::find(group->names.begin(), group->names.end(), name) == group->names.end())
        group->names.push_back(name);
  }
  std::vector<RunResult> out;
  for (const Group& g : groups) {
    Config together = g.config;
    together.descriptor.name.clear();
    for (const std::string& name : g.names)
      together.descriptor.name += (together.descriptor.name.empty() ? "" : "+") + name;
    // Weights only to make the fused run valid: the fused matrix is not computed.
    together.matching.fusion_weights.clear();
    if (g.names.size() > 1)
      for (size_t k = 0; k < g.names.size(); ++k)
        together.matching.fusion_weights += std::string(k ? "," : "") + "1";
    out.push_back(ComputeSingleFrames(together, progress, store));
  }
  return out;
}

const SingleFrame* SingleFrameStore::Find(const std::string& key) const {
  for (const auto& [k, frame] : kept_)
    if (k == key) return frame.get();
  return nullptr;
}

const SingleFrame& SingleFrameStore::Keep(const std::string& key, SingleFrame frame) {
  kept_.emplace_back(key, std::make_unique<SingleFrame>(std::move(frame)));
  return *kept_.back().second;
}

std::string SingleFrameKey(const Config& config, const std::string& name) {
  // Everything that can change a frame's row or a pair's distance stays; what acts after the
  // single-frame matrix (sequences, scores, fusion, outputs, evaluation, verification, tools)
  // is reset.
  Config c = config;
  c.descriptor.name = name;
  const PanoramaMatching panorama = c.matching.panorama_matching;
  c.matching = MatchingOptions();
  c.matching.panorama_matching = panorama;
  c.output = OutputOptions();
  c.scale = ScaleOptions();
  c.automatic = AutoOptions();
  c.evaluation = EvaluationConfig();
  c.snaps = snaps::SnapsOptions();
  c.odometry = odometry::OdometryOptions();
  c.verification = VerificationOptions();
  return FormatConfig(c);
}

cv::Mat1f SingleFrameMatrix(const Config& config, const SingleFrameStore& store,
                            const std::vector<int>& starts) {
  const std::vector<std::string> names = DescriptorList(config.descriptor.name);
  std::vector<const cv::Mat1f*> matrices;
  for (const std::string& name : names) {
    const SingleFrame* kept = store.Find(SingleFrameKey(config, name));
    if (kept == nullptr)
      throw std::logic_error("SingleFrameMatrix: no single-frame matrix of " + name);
    matrices.push_back(&kept->distances);
  }
  const std::vector<double> weights =
      names.size() > 1 ? config.matching.FusionWeights(static_cast<int>(names.size()))
                       : std::vector<double>{1.0};
  return FusedSingleFrame(matrices, weights, config.matching, starts, true,
                          [](double largest) { return largest; });
}

EvaluationLayout LayoutOf(const RunResult& result) {
  if (result.traversals.size() == 2)
    return EvaluationLayout::TwoTraversals(result.traversals[0].frames,
                                           result.traversals[1].frames);
  if (result.traversals.size() != 1)
    throw std::logic_error("LayoutOf: a run has one or two traversals");
  return EvaluationLayout::LoopClosure(result.normalized.rows);
}

}  // namespace openable
