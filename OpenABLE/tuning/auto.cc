#include "OpenABLE/tuning/auto.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/strings.h"
#include "OpenABLE/base/threading.h"
#include "OpenABLE/cluster/cluster.h"
#include "OpenABLE/evaluation/report.h"
#include "OpenABLE/io/json.h"
#include "descriptors/registry.h"
#include "matching/sequence.h"

namespace openable {
namespace {

constexpr const char* kKey = "Auto_candidates";

// Keys of these groups may change the matrix a candidate is judged by.
bool ChangesTheMatrix(const OptionBinding& b) {
  static const std::set<std::string> after = {"Threads",
                                              "Threshold",
                                              "Match_score",
                                              "Match_score_window",
                                              "Match_threshold",
                                              "Match_consistency",
                                              "Noise_gaussian",
                                              "Noise_salt_pepper",
                                              "Noise_overexposure",
                                              "Noise_seed"};
  return (b.group == "Description and matching" || b.group == "Robustness") &&
         after.count(b.key) == 0;
}

std::string Example() { return std::string(AutoOptions::kDefaultCandidates); }

std::vector<std::string> Words(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string w; in >> w;) out.push_back(w);
  return out;
}

struct Axis {
  std::string key;
  std::vector<std::string> values;
};

Axis ParseAxis(const std::string& text) {
  const auto eq = text.find('=');
  if (eq == std::string::npos || eq == 0)
    throw InputError(std::string(kKey) + ": " + Quoted(text) +
                     " is not of the form Key=v1,v2,...; expected axes separated by spaces and "
                     "groups by |, e.g. " +
                     Quoted(Example()));
  Axis axis;
  axis.key = Trim(text.substr(0, eq));
  Config probe;
  const OptionTable table = ConfigTable(probe);
  const OptionBinding& b = table.Lookup(axis.key, kKey);
  if (b.key == "Exclusion" || b.key == "Ground_truth_min_gap")
    throw InputError(std::string(kKey) + ": " + b.key +
                     " is a setting of runs of one traversal "
                     "(loop closure: candidates frames back), while Auto chooses settings for "
                     "two traversals; expected keys of the Description and matching or "
                     "Robustness groups");
  if (b.group == "Datasets")
    throw InputError(std::string(kKey) + ": " + b.key +
                     " changes which frames are matched; "
                     "every candidate is judged on the run's frames; expected keys of the "
                     "Description and matching or Robustness groups");
  if (!ChangesTheMatrix(b))
    throw InputError(std::string(kKey) + ": " + b.key + " (" + b.group +
                     ") does not change "
                     "the matrix a candidate is judged by; set it for the run instead; "
                     "expected keys of the Description and matching or Robustness groups that "
                     "change the matrix (Image_descriptor, Image_sequences, Contrast_enhancement, "
                     "...)");
  const std::string list = text.substr(eq + 1);
  const char separator = list.find(';') != std::string::npos ? ';' : ',';
  std::set<std::string> seen;
  for (const std::string& value : SplitTrimmed(list, separator)) {
    if (value.empty())
      throw InputError(std::string(kKey) + ": " + axis.key + "=" + list +
                       " has an empty value; expected values separated by commas (or by "
                       "semicolons when a value holds commas)");
    if (!seen.insert(value).second)
      throw InputError(std::string(kKey) + ": " + axis.key + ": value " + Quoted(value) +
                       " is given twice; expected each value once");
    Config check;
    ApplyOverride(check, axis.key + "=" + value, kKey);
    axis.values.push_back(value);
  }
  return axis;
}

// Every combination of the axes' values, the last varying fastest.
std::vector<AutoSettings> Combinations(const std::vector<Axis>& axes) {
  std::vector<AutoSettings> all = {{}};
  for (const Axis& axis : axes) {
    std::vector<AutoSettings> next;
    for (const AutoSettings& partial : all)
      for (const std::string& v : axis.values) {
        next.push_back(partial);
        next.back().emplace_back(axis.key, v);
      }
    all = std::move(next);
  }
  return all;
}

bool Sets(const AutoSettings& settings, const std::string& key) {
  return std::any_of(settings.begin(), settings.end(),
                     [&](const auto& kv) { return kv.first == key; });
}

// The candidate's settings with equal Fusion_weights for a fused descriptor that gets no
// weights of its own (neither from the candidate nor, fitting, from the configuration).
AutoSettings Completed(const Config& config, AutoSettings settings) {
  if (Sets(settings, "Fusion_weights")) return settings;
  Config c = config;
  for (const auto& [key, value] : settings) ApplyOverride(c, key + "=" + value, kKey);
  const int names = static_cast<int>(DescriptorList(c.descriptor.name).size());
  if (names < 2) return settings;
  if (!c.matching.fusion_weights.empty()) {
    try {
      c.matching.FusionWeights(names);
      return settings;  // the configuration's weights fit
    } catch (const InputError&) {
    }
  }
  std::string weights = "1";
  for (int k = 1; k < names; ++k) weights += ",1";
  settings.emplace_back("Fusion_weights", weights);
  return settings;
}

int Traversals(const InputOptions& in) {
  switch (in.frame_mode) {
    case FrameMode::kImageFolders:
      return in.images_path_2.empty() ? 1 : 2;
    case FrameMode::kVideo:
      return 1;
    case FrameMode::kTwoVideos:
      return 2;
    case FrameMode::kBag:
      return in.bag_topic_2.empty() ? 1 : 2;
  }
  return 1;
}

// Candidates by agreement, best first (ties: the order of Auto_candidates).
std::vector<int> Ranking(const AutoChoice& c) {
  std::vector<int> order(c.candidates.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    return c.candidates[a].figures.agreement > c.candidates[b].figures.agreement;
  });
  return order;
}

}  // namespace

std::vector<AutoSettings> ParseAutoCandidates(const std::string& text) {
  if (Trim(text).empty())
    throw InputError(std::string(kKey) +
                     ": empty; expected groups of Key=v1,v2 axes separated "
                     "by |, e.g. " +
                     Quoted(Example()));
  const std::vector<std::string> groups = SplitTrimmed(text, '|');
  std::vector<AutoSettings> out;
  std::set<AutoSettings> seen;
  for (size_t g = 0; g < groups.size(); ++g) {
    if (groups[g].empty())
      throw InputError(std::string(kKey) + ": group " + std::to_string(g + 1) + " of " +
                       std::to_string(groups.size()) +
                       " is empty; expected Key=v1,v2 axes "
                       "separated by spaces between the |");
    std::vector<Axis> axes;
    std::set<std::string> keys;
    for (const std::string& word : Words(groups[g])) {
      axes.push_back(ParseAxis(word));
      if (!keys.insert(axes.back().key).second)
        throw InputError(std::string(kKey) + ": " + axes.back().key + " is given twice in " +
                         Quoted(groups[g]) +
                         "; expected each key once per group, with all its "
                         "values");
    }
    for (AutoSettings& candidate : Combinations(axes)) {
      AutoSettings sorted = candidate;
      std::sort(sorted.begin(), sorted.end());
      if (!seen.insert(sorted).second)
        throw InputError(std::string(kKey) + ": the candidate " +
                         Quoted(AutoSettingsText(candidate)) +
                         " is given twice; expected each "
                         "setting once");
      out.push_back(std::move(candidate));
    }
  }
  return out;
}

std::string AutoSettingsText(const AutoSettings& settings) {
  std::string out;
  for (const auto& [key, value] : settings) out += (out.empty() ? "" : " ") + key + "=" + value;
  return out;
}

Config AutoCandidateConfig(const Config& config, const AutoSettings& candidate) {
  Config c = config;
  for (const auto& [key, value] : candidate) ApplyOverride(c, key + "=" + value, kKey);
  c.automatic.enabled = false;
  // Rows given by files: every candidate's single-frame matrix is theirs (the run's "NPY").
  if (!c.input.descriptors_path.empty()) c.descriptor.name = "NPY";
  return c;
}

void CheckAuto(const Config& config) {
  const int traversals = Traversals(config.input);
  if (traversals != 2)
    throw InputError(
        "Auto: 1 chooses settings for two traversals of a route (Images_path and "
        "Images_path_2, Frame_mode 2, or Bag_topic_2), but this run has one; for "
        "loop closure in one traversal start from config/presets/loop_closure.txt "
        "(openable_sweep --rank-by agreement ranks settings of one traversal "
        "without ground truth)");
  if (config.scale.matrix_mode == MatrixMode::kBounded || config.scale.approximate_search)
    throw InputError(std::string("Auto: 1 compares dense matrices, but ") +
                     (config.scale.approximate_search ? "Approximate_search is 1"
                                                      : "Matrix_mode is 2 (bounded)") +
                     "; expected Matrix_mode 0 or 1 and Approximate_search 0");
  if (Cluster::Get().Distributed())
    throw InputError(
        "Auto: 1 runs on one process; expected Test_OpenABLE without mpirun (the "
        "chosen settings can then be run over processes with Auto 0)");
  for (const AutoSettings& candidate : ParseAutoCandidates(AutoCandidatesOf(config))) {
    if (!config.input.descriptors_path.empty())
      for (const auto& [key, value] : candidate)
        if (key == "Image_descriptor" || key == "Patch_size" || key == "Description_type")
          throw InputError(std::string(kKey) + ": " + AutoSettingsText(candidate) + " sets " + key +
                           ", but the rows come from Descriptors_path; expected "
                           "candidates of matching settings only (e.g. Image_sequences=10,20,40)");
    try {
      CheckRun(AutoCandidateConfig(config, Completed(config, candidate)));
    } catch (const InputError& e) {
      throw InputError(std::string(kKey) + ": with " + AutoSettingsText(candidate) + ": " +
                       e.what());
    }
  }
}

std::string AutoCandidatesOf(const Config& config) {
  const std::string& text = config.automatic.candidates;
  // Rows given by files (Descriptors_path): one descriptor, so the default candidates are the
  // default's matching without a descriptor: sequences, and contrast enhancement with them.
  if (!config.input.descriptors_path.empty())
    return text == AutoOptions::kDefaultCandidates
               ? "Image_sequences=10,20,40 | Contrast_enhancement=1 Image_sequences=10,20,40"
               : text;
  if (config.descriptor.model_path.empty() || Upper(text).find("ONNX") != std::string::npos)
    return text;
  // A configured network joins the candidates, with the sequences of the default groups.
  return text + " | Image_descriptor=ONNX Image_sequences=10,20,40";
}

AutoPlan PlanCandidates(const Config& config, const std::vector<AutoSettings>& candidates) {
  AutoPlan plan;
  for (const AutoSettings& candidate : candidates) {
    plan.settings.push_back(Completed(config, candidate));
    plan.configs.push_back(AutoCandidateConfig(config, plan.settings.back()));
  }
  return plan;
}

AutoChoice JudgeCandidates(const AutoPlan& plan, double min_consistency,
                           const SingleFrameStore& store, const std::vector<int>& starts,
                           ProgressReporter& progress,
                           const std::function<void(const std::string&)>& log) {
  if (starts.size() != 3 || plan.configs.empty())
    throw std::logic_error("JudgeCandidates: expected two traversals and a candidate");
  AutoChoice choice;
  choice.min_consistency = min_consistency;
  for (const AutoSettings& settings : plan.settings) choice.candidates.push_back({settings, {}});
  const int references = starts[1], queries = starts[2] - starts[1];
  const std::vector<int> first_rows(starts.begin(), starts.end() - 1);
  const std::vector<Config>& configs = plan.configs;
  // Each candidate's query-reference block: single-frame matrices fused and enhanced (kept for
  // the candidates that differ only in sequences), then its sequence sums and its criteria.
  std::map<std::string, cv::Mat1f> blocks;
  const EvaluationLayout layout = EvaluationLayout::QueryReference(queries, references);
  progress.Begin("judging", static_cast<std::int64_t>(configs.size()),
                 "candidates (Auto, no ground truth)");
  for (size_t i = 0; i < configs.size(); ++i) {
    CheckForInterrupt();
    const Config& c = configs[i];
    const MatchingOptions& m = c.matching;
    const std::string key = SingleFrameKey(c, c.descriptor.name) + "\n" + m.fusion_weights + "\n" +
                            std::to_string(m.contrast.enabled) + " " +
                            std::to_string(m.contrast.window);
    auto it = blocks.find(key);
    if (it == blocks.end()) {
      const cv::Mat1f single = SingleFrameMatrix(c, store, first_rows);
      it = blocks.emplace(key, single(cv::Rect(0, references, references, queries)).clone()).first;
    }
    cv::Mat1f sums = it->second.clone();
    SequenceDistancesInPlace(sums, m.sequence_length, {}, {}, m.direction, m.threads, m.partial);
    UnsupervisedOptions options;
    options.agreement = AgreementOf(m);
    options.agreement.partners = 1;
    options.exclusion = c.evaluation.protocol.exclusion;
    options.score.window = m.score.window;
    UnsupervisedFigures f = UnsupervisedCriteria(sums, layout, options);
    f.best.clear();
    f.ratio.clear();
    f.agrees.clear();
    choice.candidates[i].figures = f;
    progress.Update(static_cast<std::int64_t>(i + 1));
    if (log)
      log("auto: " + std::to_string(i + 1) + " of " + std::to_string(configs.size()) + ": " +
          AutoSettingsText(choice.candidates[i].settings) + ": consistency " +
          FormatFixed(f.consistency, 3) + ", distinctiveness " + FormatFixed(f.distinctiveness, 3) +
          ", agreement " + FormatFixed(f.agreement, 3));
  }
  progress.End();

  choice.chosen = Ranking(choice).front();
  const UnsupervisedFigures& best = choice.candidates[choice.chosen].figures;
  choice.reliable = best.consistency >= choice.min_consistency;
  choice.config = configs[choice.chosen];
  return choice;
}

AutoChoice ChooseSettings(const Config& config, ProgressReporter& progress, SingleFrameStore& store,
                          const std::function<void(const std::string&)>& log) {
  const auto start = std::chrono::steady_clock::now();
  CheckAuto(config);
  const AutoPlan plan = PlanCandidates(config, ParseAutoCandidates(AutoCandidatesOf(config)));

  // Every descriptor of every candidate, described and compared once, each frame read once
  // for all the descriptors of candidates that share their description settings.
  const int kept_before = store.Size();
  std::vector<int> starts;
  for (const RunResult& r : ComputeSingleFramesTogether(plan.configs, progress, store)) {
    if (starts.empty()) {
      for (const Traversal& t : r.traversals) starts.push_back(t.first_row);
      starts.push_back(r.traversals.at(1).first_row + r.traversals.at(1).frames);
    }
  }
  AutoChoice choice =
      JudgeCandidates(plan, config.automatic.min_consistency, store, starts, progress, log);
  choice.descriptions = store.Size() - kept_before;
  choice.seconds = SecondsSince(start);
  return choice;
}

std::string FormatAutoReport(const AutoChoice& c) {
  std::ostringstream o;
  const AutoCandidate& chosen = c.candidates.at(c.chosen);
  o << "  auto: " << c.candidates.size() << " candidates judged without ground truth ("
    << c.descriptions << (c.descriptions == 1 ? " description" : " descriptions") << ", "
    << FormatFixed(c.seconds, 1) << " s), ranked by agreement (docs/evaluation.md):\n";
  o << "    rank  consistency  distinctiveness  agreement  settings\n";
  const std::vector<int> order = Ranking(c);
  for (size_t r = 0; r < order.size(); ++r) {
    const AutoCandidate& a = c.candidates[order[r]];
    char line[96];
    std::snprintf(line, sizeof line, "    %4zu  %11.3f  %15.3f  %9.3f  ", r + 1,
                  a.figures.consistency, a.figures.distinctiveness, a.figures.agreement);
    o << line << AutoSettingsText(a.settings) << (order[r] == c.chosen ? "  <- chosen" : "")
      << "\n";
  }
  if (c.reliable) {
    o << "    chosen: " << AutoSettingsText(chosen.settings)
      << "; reliable: " << FormatFixed(100.0 * chosen.figures.consistency, 1)
      << " % of its best matches agree with an independent query's (Auto_min_consistency "
      << FormatNumber(c.min_consistency) << ")\n";
  } else {
    o << "    UNRELIABLE: no candidate is consistent enough to be trusted; the best, "
      << AutoSettingsText(chosen.settings) << ", confirms "
      << FormatFixed(100.0 * chosen.figures.consistency, 1)
      << " % of its best matches (Auto_min_consistency " << FormatNumber(c.min_consistency)
      << "); its outputs are written, but no match is accepted\n";
  }
  return o.str();
}

ReportTable AutoReportTable(const AutoChoice& c) {
  ReportTable t;
  t.id = "auto";
  t.title = "Auto: settings chosen from the data";
  t.header = {"rank", "settings", "consistency", "distinctiveness", "agreement", "answered"};
  t.numeric = {true, false, true, true, true, true};
  const std::vector<int> order = Ranking(c);
  for (size_t r = 0; r < order.size(); ++r) {
    const AutoCandidate& a = c.candidates[order[r]];
    t.rows.push_back(
        {std::to_string(r + 1), AutoSettingsText(a.settings), FormatFixed(a.figures.consistency, 3),
         FormatFixed(a.figures.distinctiveness, 3), FormatFixed(a.figures.agreement, 3),
         std::to_string(a.figures.answered) + " of " + std::to_string(a.figures.queries)});
    if (order[r] == c.chosen) t.highlight = static_cast<int>(r);
  }
  const double consistency = c.candidates.at(c.chosen).figures.consistency;
  t.note = std::string(c.reliable ? "Chosen (bold): " : "UNRELIABLE: ") +
           AutoSettingsText(c.candidates.at(c.chosen).settings) + "; " +
           FormatFixed(100.0 * consistency, 1) +
           " % of its best matches agree with the best match of an independent query (" +
           (c.reliable ? "at least" : "below") + " Auto_min_consistency " +
           FormatNumber(100.0 * c.min_consistency) + " %)" +
           (c.reliable ? "." : ": no match is accepted.") +
           " Judged without ground truth; the figures below are those of the chosen setting.";
  return t;
}

Json AutoJson(const AutoChoice& c) {
  const AutoCandidate& chosen = c.candidates.at(c.chosen);
  Json o;
  o["chosen"] = AutoSettingsText(chosen.settings);
  Json& settings = o["chosen_settings"] = Json::object();
  for (const auto& [key, value] : chosen.settings) settings[key] = value;
  o["reliable"] = c.reliable;
  o["criterion"] = "agreement";
  o["min_consistency"] = json::Number(c.min_consistency);
  o["descriptions"] = c.descriptions;
  o["seconds"] = json::Number(c.seconds);
  const std::vector<int> order = Ranking(c);
  std::vector<int> rank(order.size());
  for (size_t r = 0; r < order.size(); ++r) rank[order[r]] = static_cast<int>(r + 1);
  Json& candidates = o["candidates"] = Json::array();
  for (size_t i = 0; i < c.candidates.size(); ++i) {
    const UnsupervisedFigures& f = c.candidates[i].figures;
    candidates.push_back({{"settings", AutoSettingsText(c.candidates[i].settings)},
                          {"rank", rank[i]},
                          {"queries", f.queries},
                          {"answered", f.answered},
                          {"agreeing", f.agreeing},
                          {"consistency", json::Number(f.consistency)},
                          {"distinctiveness", json::Number(f.distinctiveness)},
                          {"agreement", json::Number(f.agreement)},
                          {"gap", f.gap},
                          {"tolerance", f.tolerance}});
  }
  return o;
}

}  // namespace openable
