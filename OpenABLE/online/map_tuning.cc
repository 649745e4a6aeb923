// OnlineDetector::Tune: a map's search settings chosen from two of its sessions by the auto
// mode's own judging (OpenABLE/tuning/auto.h, JudgeCandidates), on the map's rows. Apart from
// online.cc so that the detector itself does not depend on the run's pipeline and the tuning
// (the map fuzzer builds the detector alone).
#include <algorithm>
#include <cmath>
#include <iostream>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/progress.h"
#include "OpenABLE/base/strings.h"
#include "OpenABLE/io/json.h"
#include "OpenABLE/online/online.h"
#include "OpenABLE/run/pipeline.h"
#include "OpenABLE/tuning/auto.h"
#include "config/config.h"
#include "descriptors/registry.h"
#include "matching/contrast.h"
#include "matching/matrix.h"

namespace openable {
namespace {

// The distance the rows of descriptor `name` are compared with (its registry entry).
Metric MetricOfDescriptor(const std::string& name, const OnlineOptions& options) {
  DescriptorOptions d = options.descriptor;
  d.name = name;
  return MetricOf(*CreateDescriptor(d));
}

// The keys a map's tuning may vary: the rows are described already, so only what is computed
// from them.
const std::set<std::string>& TunableKeys() {
  static const std::set<std::string> keys = {"Image_descriptor", "Fusion_weights",
                                             "Image_sequences", "Contrast_enhancement",
                                             "Contrast_window"};
  return keys;
}

const MapSession& SessionNamed(const std::vector<MapSession>& sessions, const std::string& name,
                               const char* role) {
  for (const MapSession& m : sessions)
    if (m.name == name) return m;
  std::string names;
  for (const MapSession& m : sessions) names += (names.empty() ? "" : ", ") + m.name;
  throw InputError(std::string("tune: ") + role + " session " + Quoted(name) +
                   " is not in the map; its sessions: " + (names.empty() ? "none" : names));
}

}  // namespace

MapTuning OnlineDetector::Tune(const TuneOptions& t,
                               const std::function<void(const std::string&)>& log) {
  CheckMap();
  const OnlineOptions& options = Options();
  if (options.verification.enabled)
    throw InputError(
        "tune: verification is on (OnlineOptions::verification.enabled), which "
        "decides the accepted loops itself; expected a detector without it");
  const std::vector<MapSession>& sessions = Sessions();
  std::vector<MapSession> nonempty;
  for (const MapSession& m : sessions)
    if (m.count > 0) nonempty.push_back(m);
  if ((t.reference.empty() || t.query.empty()) && nonempty.size() < 2)
    throw InputError("tune: the map holds " + std::to_string(nonempty.size()) + " session" +
                     (nonempty.size() == 1 ? "" : "s") +
                     " with frames; expected two "
                     "traversals of the route (add a second session first)");
  const MapSession& ref =
      t.reference.empty() ? nonempty[0] : SessionNamed(sessions, t.reference, "reference");
  const MapSession& qry = t.query.empty() ? nonempty[1] : SessionNamed(sessions, t.query, "query");
  if (ref.name == qry.name)
    throw InputError("tune: reference and query are both session " + Quoted(ref.name) +
                     "; expected two sessions (two traversals of the route)");
  if (!(t.min_consistency >= 0 && t.min_consistency <= 1))
    throw InputError("tune: min_consistency = " + FormatNumber(t.min_consistency) +
                     ": expected a number in [0, 1] (Auto_min_consistency)");
  if (t.max_frames < 0)
    throw InputError("tune: max_frames = " + std::to_string(t.max_frames) +
                     ": expected >= 0 (0: every frame)");
  const int references = t.max_frames > 0 ? std::min(ref.count, t.max_frames) : ref.count;
  const int queries = t.max_frames > 0 ? std::min(qry.count, t.max_frames) : qry.count;

  // The configuration the candidates start from: the map's description and the ratio's
  // window of the detector. Candidates are judged as the auto mode judges them, with a whole
  // sequence for every query (Sequence_partial ahead), so that both choose alike from the same
  // frames: judged with the shorter sums the search gives the first L - 1 frames of a
  // traversal (scale), long sequences lose to short ones on short traversals for their first
  // frames alone (docs/benchmarks.md, "Maps: settings chosen from their sessions").
  const std::vector<std::string> channels = Channels();
  Config base;
  base.descriptor = options.descriptor;
  base.descriptor.name = JoinStrings(channels, "+");
  base.description.type = options.description;
  base.description.grid_x = options.grid_x;
  base.description.grid_y = options.grid_y;
  base.matching.partial = SequencePartial::kAhead;
  base.matching.score.window = options.score.window;
  const auto held = [&](const Config& c) {
    for (const std::string& name : DescriptorList(c.descriptor.name))
      if (std::find(channels.begin(), channels.end(), Upper(name)) == channels.end()) return false;
    return true;
  };
  const bool given = !t.candidates.empty();
  std::vector<AutoSettings> candidates;
  for (const AutoSettings& candidate :
       ParseAutoCandidates(given ? t.candidates : AutoOptions::kDefaultCandidates)) {
    for (const auto& [key, value] : candidate)
      if (TunableKeys().count(key) == 0)
        throw InputError("tune: Auto_candidates: " + key +
                         " changes how frames are described, "
                         "and the map's rows are described already; expected candidates of "
                         "Image_descriptor (among " +
                         JoinStrings(channels, ", ") +
                         "), "
                         "Fusion_weights, Image_sequences, Contrast_enhancement and "
                         "Contrast_window");
    Config c = AutoCandidateConfig(base, candidate);
    if (held(c)) {
      candidates.push_back(candidate);
    } else if (given) {
      throw InputError("tune: Auto_candidates: " + Quoted(AutoSettingsText(candidate)) +
                       " needs rows the map does not hold (it holds " +
                       JoinStrings(channels, ", ") +
                       "); expected descriptors among them, or a "
                       "map made with their rows (openable_map add --config "
                       "config/presets/auto.txt keeps those of the auto preset)");
    } else if (log) {
      log("tune: skipped " + AutoSettingsText(candidate) +
          " (the map holds no rows of its "
          "descriptor; a map made with config/presets/auto.txt keeps them)");
    }
  }
  if (candidates.empty())
    throw InputError("tune: none of the default candidates uses the map's descriptors (" +
                     JoinStrings(channels, ", ") +
                     "); expected candidates given with "
                     "--candidates (Auto_candidates' syntax)");
  const AutoPlan plan = PlanCandidates(base, candidates);

  // The single-frame matrix of every descriptor over both sessions, the reference's frames
  // first: the matrices a run of the two traversals compares (PairwiseDistances).
  std::set<std::string> names;
  for (const Config& c : plan.configs)
    for (const std::string& name : DescriptorList(c.descriptor.name)) names.insert(Upper(name));
  const double cells = static_cast<double>(references + queries) * (references + queries);
  const double bytes = cells * 4.0 * (static_cast<double>(names.size()) + 2);
  if (bytes > 16e9)
    throw InputError("tune: sessions of " + std::to_string(references) + " and " +
                     std::to_string(queries) + " frames need " + FormatFixed(bytes / 1e9, 1) +
                     " GB to compare every pair with " + std::to_string(names.size()) +
                     " descriptors; expected at most 16 GB (judge "
                     "on the first frames of each: max_frames, openable_map tune --frames N)");
  SingleFrameStore store;
  std::map<std::string, cv::Mat1f> matrices;
  for (const std::string& name : names) {
    const size_t c =
        static_cast<size_t>(std::find(channels.begin(), channels.end(), name) - channels.begin());
    const cv::Mat all = ChannelRows(static_cast<int>(c));
    cv::Mat rows;
    cv::vconcat(all.rowRange(ref.first, ref.first + references),
                all.rowRange(qry.first, qry.first + queries), rows);
    if (log) log("tune: comparing every pair of frames with " + name);
    matrices[name] = PairwiseDistances(rows, MetricOfDescriptor(name, options));
  }
  for (const Config& c : plan.configs)
    for (const std::string& name : DescriptorList(c.descriptor.name)) {
      const std::string key = SingleFrameKey(c, name);
      if (store.Find(key) != nullptr) continue;
      SingleFrame f;
      f.distances = matrices.at(Upper(name));
      store.Keep(key, std::move(f));
    }
  const std::vector<int> starts = {0, references, references + queries};
  ProgressReporter quiet(std::cerr, false, false);
  AutoChoice choice = JudgeCandidates(plan, t.min_consistency, store, starts, quiet, log);

  // The search of the chosen candidate, with the units and shift of its matrix.
  const MatchingOptions& m = choice.config.matching;
  OnlineOptions search = options;
  search.descriptor.name = choice.config.descriptor.name;
  const std::vector<std::string> chosen = DescriptorList(search.descriptor.name);
  search.fusion_weights =
      chosen.size() > 1 ? m.FusionWeights(static_cast<int>(chosen.size())) : std::vector<double>{};
  search.contrast = m.contrast;
  search.sequence_length = m.sequence_length;
  search.score.kind = MatchScore::kRatio;
  search.threshold =
      t.threshold >= 0 ? t.threshold : OnlineOptions::DefaultThreshold(MatchScore::kRatio);
  search.consistency = 1;
  search.Check();
  MapTuning tuning;
  tuning.tuned = true;
  tuning.reliable = choice.reliable;
  tuning.reference = ref.name;
  tuning.query = qry.name;
  tuning.time = MapTimeNow();
  tuning.chosen = AutoSettingsText(choice.candidates[static_cast<size_t>(choice.chosen)].settings);
  const UnsupervisedFigures& f = choice.candidates[static_cast<size_t>(choice.chosen)].figures;
  tuning.consistency = f.consistency;
  tuning.distinctiveness = f.distinctiveness;
  tuning.agreement = f.agreement;
  tuning.min_consistency = t.min_consistency;
  tuning.candidates_json = json::DumpLine(AutoJson(choice)["candidates"]);
  tuning.search = search;
  cv::Mat1f fused;
  for (size_t k = 0; k < chosen.size(); ++k) {
    const cv::Mat1f& d = matrices.at(Upper(chosen[k]));
    double largest = 0;
    cv::minMaxLoc(d, nullptr, &largest);
    tuning.units.push_back(largest);
    if (search.contrast.enabled) {
      const double w = chosen.size() > 1 ? search.fusion_weights[k] : 1.0;
      if (fused.empty()) fused = cv::Mat1f::zeros(d.size());
      if (chosen.size() == 1)
        d.copyTo(fused);
      else if (largest > 0)
        cv::scaleAdd(d, w / largest, fused, fused);
    }
  }
  if (chosen.size() == 1) tuning.units.clear();
  tuning.shift = 0;
  if (search.contrast.enabled) {
    const float smallest = EnhanceContrastUnshifted(fused, search.contrast.window, {0, references});
    tuning.shift = std::isfinite(smallest) ? -smallest : 0.0;
  }

  UseTuning(tuning);
  return tuning;
}

}  // namespace openable
