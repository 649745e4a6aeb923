#include "OpenABLE/tuning/sweep.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <set>
#include <sstream>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/output_batch.h"
#include "OpenABLE/base/strings.h"
#include "OpenABLE/base/threading.h"
#include "OpenABLE/base/version.h"
#include "OpenABLE/evaluation/plots.h"
#include "OpenABLE/io/json.h"
#include "OpenABLE/reports/figures.h"
#include "OpenABLE/run/evaluate.h"
#include "OpenABLE/run/pipeline.h"
#include "OpenABLE/run/verify.h"
#include "descriptors/registry.h"

namespace openable {
namespace {

using Clock = std::chrono::steady_clock;

// Groups whose keys a sweep does not vary: outputs (a sweep writes only its own files), the
// bounded mode and its matches (a sweep evaluates dense matrices), and the tools that do not
// compute a matrix.
const std::set<std::string>& FixedGroups() {
  static const std::set<std::string> groups = {"Representation", "Scale", "SNAPS", "Odometry"};
  return groups;
}

bool IsFixedKey(const std::string& key) {
  return key == "Evaluation_name" || key == "Evaluation_label";
}

// Values separated by commas, or by semicolons when a value holds commas.
std::vector<std::string> SplitValues(const std::string& text) {
  return SplitTrimmed(text, text.find(';') != std::string::npos ? ';' : ',');
}

double RankFigure(const SweepRun& run, SweepRank rank) {
  const PerQueryResult& q = run.evaluation.per_query;
  switch (rank) {
    case SweepRank::kAuc:
      return q.auc;
    case SweepRank::kRecallAt100p:
      return q.recall_at_100p;
    case SweepRank::kRecallAt1:
      return q.recall_at_1;
    case SweepRank::kMaxF1:
      return q.max_f1;
    case SweepRank::kAveragePrecision:
      return run.evaluation.able_p.average_precision;
    case SweepRank::kDistinctiveness:
      return run.unsupervised.distinctiveness;
    case SweepRank::kConsistency:
      return run.unsupervised.consistency;
    case SweepRank::kAgreement:
      return run.unsupervised.agreement;
  }
  return 0;
}

const char* RankTitle(SweepRank rank) {
  switch (rank) {
    case SweepRank::kAuc:
      return "AUC";
    case SweepRank::kRecallAt100p:
      return "recall at 100% precision";
    case SweepRank::kRecallAt1:
      return "recall at 1";
    case SweepRank::kMaxF1:
      return "max F1";
    case SweepRank::kAveragePrecision:
      return "ABLE-P average precision";
    case SweepRank::kDistinctiveness:
      return "distinctiveness (no ground truth)";
    case SweepRank::kConsistency:
      return "consistency (no ground truth)";
    case SweepRank::kAgreement:
      return "agreement (no ground truth)";
  }
  return "";
}

// Each run's rank (1 = best) by `rank`, ties keeping the order of the runs.
std::vector<int> RanksBy(const std::vector<SweepRun>& runs, SweepRank rank) {
  std::vector<int> order(runs.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    return RankFigure(runs[a], rank) > RankFigure(runs[b], rank);
  });
  std::vector<int> out(runs.size());
  for (size_t r = 0; r < order.size(); ++r) out[order[r]] = static_cast<int>(r + 1);
  return out;
}

// The other kind of ranking the table shows beside the chosen one.
SweepRank Counterpart(SweepRank rank) {
  return Unsupervised(rank) ? SweepRank::kAuc : SweepRank::kAgreement;
}

// The combination's label: descriptor and sequence length (always, as Test_OpenABLE labels a
// run), then every other varied key with its value.
std::string LabelOf(const Config& config, const std::vector<SweepAxis>& axes,
                    const std::vector<std::string>& values) {
  std::string label = config.descriptor.name;
  if (config.description.type == DescriptionType::kGrid)
    label += " " + std::to_string(config.description.grid_x) + "x" +
             std::to_string(config.description.grid_y);
  label += " L=" + std::to_string(config.matching.sequence_length);
  for (size_t i = 0; i < axes.size(); ++i)
    if (axes[i].key != "Image_descriptor" && axes[i].key != "Image_sequences")
      label += " " + axes[i].key + "=" + values[i];
  return label;
}

// Every combination of the axes' values, the last axis varying fastest.
std::vector<std::vector<std::string>> Combinations(const std::vector<SweepAxis>& axes) {
  std::vector<std::vector<std::string>> all = {{}};
  for (const SweepAxis& axis : axes) {
    std::vector<std::vector<std::string>> next;
    for (const auto& partial : all)
      for (const std::string& v : axis.values) {
        next.push_back(partial);
        next.back().push_back(v);
      }
    all = std::move(next);
  }
  return all;
}

// A CSV field: the text shown by ToValidUtf8 (a value naming a folder in another encoding),
// quoted when it holds a comma, a quote or a line break.
std::string CsvField(const std::string& s) {
  const std::string text = ToValidUtf8(s);
  if (text.find_first_of(",\"\n") == std::string::npos) return text;
  std::string out = "\"";
  for (const char c : text) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

}  // namespace

SweepAxis ParseSweepAxis(const std::string& text) {
  const auto eq = text.find('=');
  if (eq == std::string::npos || eq == 0)
    throw InputError("--vary: " + Quoted(text) + " is not of the form Key=v1,v2,...");
  SweepAxis axis;
  axis.key = Trim(text.substr(0, eq));
  Config probe;
  const OptionTable table = ConfigTable(probe);
  const OptionBinding& binding = table.Lookup(axis.key, "--vary");
  if (FixedGroups().count(binding.group) || IsFixedKey(axis.key))
    throw InputError("--vary: " + axis.key + " (" + binding.group +
                     ") cannot be varied: a sweep evaluates dense matrices and writes only its "
                     "own files (--output); expected a key of the Datasets, Description and "
                     "matching, Robustness or Evaluation groups");
  const std::string list = text.substr(eq + 1);
  std::set<std::string> seen;
  for (const std::string& value : SplitValues(list)) {
    if (value.empty())
      throw InputError("--vary: " + axis.key + ": " + Quoted(list) +
                       " has an empty value; expected values separated by commas (or by "
                       "semicolons when a value holds commas)");
    if (!seen.insert(value).second)
      throw InputError("--vary: " + axis.key + ": value " + Quoted(value) +
                       " is given twice; expected each value once");
    Config check;
    ApplyOverride(check, axis.key + "=" + value, "--vary");
    axis.values.push_back(value);
  }
  return axis;
}

Config SweepRunConfig(const Config& base, const std::vector<SweepAxis>& axes,
                      const std::vector<std::string>& values) {
  Config c = base;
  for (size_t i = 0; i < axes.size(); ++i)
    ApplyOverride(c, axes[i].key + "=" + values[i], "--vary");
  c.output.txt_name.clear();
  c.output.npy_name.clear();
  c.output.png_name.clear();
  c.output.png_threshold_name.clear();
  c.output.show_images = false;
  c.scale.matrix_mode = MatrixMode::kDense;
  c.scale.matches_name.clear();
  c.evaluation.name.clear();
  c.evaluation.label.clear();
  return c;
}

SweepResult RunSweep(const Config& base, const SweepOptions& options, ProgressReporter& progress,
                     const std::function<void(const std::string&)>& log) {
  if (options.axes.empty())
    throw InputError("--vary: none given; expected at least one --vary Key=v1,v2,...");
  std::set<std::string> keys;
  for (const SweepAxis& axis : options.axes)
    if (!keys.insert(axis.key).second)
      throw InputError("--vary: " + axis.key +
                       " is given twice; expected each key once, with "
                       "all its values in one --vary");
  if (options.best < 1)
    throw InputError("--best: " + std::to_string(options.best) +
                     " is not valid; expected the number of runs to draw, >= 1");
  if (!EvaluationRequested(base) && !Unsupervised(options.rank_by))
    throw InputError(
        "Ground_truth_type: empty; expected the ground truth the sweep ranks its "
        "runs by (--rank-by " +
        EnumName(options.rank_by) +
        ", docs/evaluation.md), "
        "or --rank-by agreement, consistency or distinctiveness, which need none");
  if (base.automatic.enabled)
    throw InputError(
        "Auto: 1: a sweep runs each combination as given; expected Auto 0 "
        "(--rank-by agreement ranks settings without ground truth as Auto does)");
  if (base.scale.matrix_mode == MatrixMode::kBounded || base.scale.approximate_search)
    throw InputError(
        std::string(base.scale.approximate_search ? "Approximate_search: 1" : "Matrix_mode: 2") +
        " keeps no dense matrix, which a sweep evaluates; expected Matrix_mode 0 "
        "or 1 and Approximate_search 0");

  // Every combination is checked before the first frame is read: a bad value in the last
  // combination must not cost the time of the others.
  const std::vector<std::vector<std::string>> combinations = Combinations(options.axes);
  std::vector<Config> configs;
  for (const auto& values : combinations) {
    std::string where;
    for (size_t i = 0; i < values.size(); ++i)
      where += (i ? ", " : "") + options.axes[i].key + "=" + values[i];
    try {
      configs.push_back(SweepRunConfig(base, options.axes, values));
      CheckRun(configs.back());
      if (EvaluationRequested(configs.back())) EvaluationSettingsFrom(configs.back());
    } catch (const InputError& e) {
      throw InputError("with " + where + ": " + e.what());
    }
  }

  SweepResult out;
  out.axes = options.axes;
  out.rank_by = options.rank_by;
  out.best = options.best;
  out.evaluated = EvaluationRequested(base);
  if (out.evaluated) out.settings = EvaluationSettingsFrom(base);
  const auto start = Clock::now();
  SingleFrameStore store;
  // Every descriptor of every combination described before the first run, each frame read and
  // decoded once for all the descriptors of combinations that share their description
  // settings; the runs then take their single-frame matrices from the store. A run is marked
  // as having described the frames for the descriptors no earlier run used.
  out.frame_reads = static_cast<int>(ComputeSingleFramesTogether(configs, progress, store).size());
  std::set<std::string> credited;  // single-frame keys an earlier run used
  std::set<std::string> said;
  const int n = static_cast<int>(configs.size());
  for (int i = 0; i < n; ++i) {
    const Config& config = configs[i];
    SweepRun run;
    run.values = combinations[i];
    run.label = LabelOf(config, options.axes, run.values);
    // A run that reuses kept matrices may not pass through ParallelFor: check between runs.
    CheckForInterrupt();
    log("run " + std::to_string(i + 1) + " of " + std::to_string(n) + ": " + run.label);
    const auto t = Clock::now();
    const RunResult result = ComputeRun(config, progress, &store);
    for (const std::string& name : DescriptorList(config.descriptor.name))
      run.described = credited.insert(SingleFrameKey(config, name)).second || run.described;
    for (const std::string& w : result.warnings)
      if (said.insert("warning: " + w).second) log("warning: " + w);
    for (const std::string& note : result.notes)
      if (said.insert("note: " + note).second) log("note: " + note);
    // The criteria without ground truth, from the matrix alone.
    const EvaluationLayout layout = LayoutOf(result);
    UnsupervisedOptions unsupervised;
    unsupervised.agreement = AgreementOf(config.matching);
    unsupervised.agreement.partners = 1;
    unsupervised.exclusion = config.evaluation.protocol.exclusion;
    unsupervised.score.window = config.matching.score.window;
    run.unsupervised = UnsupervisedCriteria(result.normalized, layout, unsupervised);
    run.unsupervised.best.clear();
    run.unsupervised.ratio.clear();
    run.unsupervised.agrees.clear();
    if (Unsupervised(options.rank_by) && run.unsupervised.queries < 2)
      throw InputError("--rank-by " + EnumName(options.rank_by) + ": the run " + run.label +
                       " has " + std::to_string(run.unsupervised.queries) +
                       (run.unsupervised.queries == 1 ? " query" : " queries") +
                       " with candidates (" + std::to_string(result.normalized.rows) +
                       " frames); expected at least two, whose best matches can be compared "
                       "(more frames, or a smaller Exclusion in one traversal)");
    if (out.evaluated) {
      Evaluation evaluation;
      evaluation.settings = EvaluationSettingsFrom(config);
      if (config.verification.enabled) {
        // Verified answers rank the run (per_query), the matrix's best matches beside them.
        const RunVerification verification = VerifyRun(config, result, progress);
        const VerifiedAnswers answers = AnswersOf(verification, layout);
        EvaluateMatrix(evaluation, result.normalized, layout, run.label, "openable_sweep run",
                       &answers);
      } else {
        EvaluateMatrix(evaluation, result.normalized, layout, run.label, "openable_sweep run");
      }
      run.evaluation = std::move(evaluation.runs.front());
    }
    run.seconds = SecondsSince(t);
    out.runs.push_back(std::move(run));
  }
  out.descriptions = store.Size();
  out.seconds = SecondsSince(start);
  std::stable_sort(out.runs.begin(), out.runs.end(), [&](const SweepRun& a, const SweepRun& b) {
    return RankFigure(a, options.rank_by) > RankFigure(b, options.rank_by);
  });
  return out;
}

std::string FormatSweepTable(const SweepResult& r) {
  std::ostringstream o;
  std::string keys;
  for (const SweepAxis& a : r.axes) keys += (keys.empty() ? "" : " x ") + a.key;
  o << "Sweep: " << r.runs.size() << " runs (" << keys << "), ranked by " << RankTitle(r.rank_by)
    << "; frames described " << r.descriptions << (r.descriptions == 1 ? " time" : " times")
    << " (once per descriptor), read " << r.frame_reads << (r.frame_reads == 1 ? " time" : " times")
    << " (once per description setting), " << FormatFixed(r.seconds, 1) << " s\n";
  const bool loop =
      !r.runs.empty() && r.runs[0].evaluation.layout.kind == EvaluationLayout::Kind::kLoopClosure;
  if (r.evaluated) {
    const EvaluationSettings& s = r.settings;
    o << "Evaluation against " << GroundTruthTypeName(s.truth.type) << " ground truth"
      << (s.truth.path.empty() ? "" : " \"" + s.truth.path + "\"") << ": tolerance +-"
      << s.options.tolerance << " frames";
    if (loop) o << ", candidates at least " << s.options.exclusion << " frames back";
    // The per-query figures rank each query's best match by its score: say which.
    const bool score_varied = std::any_of(
        r.axes.begin(), r.axes.end(), [](const SweepAxis& a) { return a.key == "Match_score"; });
    if (score_varied)
      o << "; score: each run's Match_score";
    else if (s.options.score.kind == MatchScore::kRatio)
      o << "; score: ratio to the best rival beyond +-" << s.options.score.window << " frames";
    else
      o << "; score: distance";
    o << "; ABLE-P vicinity " << s.options.vicinity << "\n";
  } else {
    o << "No ground truth (Ground_truth_type empty): the criteria of the matrices alone "
         "(docs/evaluation.md, \"Without ground truth\")\n";
  }

  // Columns as wide as their longest entry.
  const bool both = r.evaluated;
  const SweepRank other = Counterpart(r.rank_by);
  const std::vector<int> other_rank = both ? RanksBy(r.runs, other) : std::vector<int>();
  std::vector<std::string> header = {"rank"};
  for (const SweepAxis& a : r.axes) header.push_back(a.key);
  for (const char* h : {"consist.", "distinct.", "agreement"}) header.push_back(h);
  if (both)
    for (const char* h : {"AUC", "R@100P", "max F1", "R@1", "R@5", "AP %"}) header.push_back(h);
  if (both) header.push_back(Unsupervised(r.rank_by) ? "AUC rank" : "agr. rank");
  header.push_back("seconds");
  header.push_back("");
  std::vector<std::vector<std::string>> rows = {header};
  for (size_t i = 0; i < r.runs.size(); ++i) {
    const SweepRun& run = r.runs[i];
    const PerQueryResult& q = run.evaluation.per_query;
    std::vector<std::string> row = {std::to_string(i + 1)};
    for (const std::string& v : run.values) row.push_back(v);
    row.push_back(FormatFixed(run.unsupervised.consistency, 3));
    row.push_back(FormatFixed(run.unsupervised.distinctiveness, 3));
    row.push_back(FormatFixed(run.unsupervised.agreement, 3));
    if (both) {
      row.push_back(FormatFixed(q.auc, 3));
      row.push_back(FormatFixed(q.recall_at_100p, 3));
      row.push_back(FormatFixed(q.max_f1, 3));
      row.push_back(FormatFixed(q.recall_at_1, 3));
      row.push_back(FormatFixed(q.recall_at_5, 3));
      row.push_back(FormatFixed(run.evaluation.able_p.average_precision, 1));
      row.push_back(std::to_string(other_rank[i]));
    }
    row.push_back(FormatFixed(run.seconds, 3));
    row.push_back(run.described ? "" : "*");
    rows.push_back(row);
  }
  std::vector<size_t> width(header.size(), 0);
  for (const auto& row : rows)
    for (size_t c = 0; c < row.size(); ++c) width[c] = std::max(width[c], row[c].size());
  const size_t first_figure = 1 + r.axes.size();
  for (const auto& row : rows) {
    std::string line = " ";
    for (size_t c = 0; c < row.size(); ++c) {
      const std::string pad(width[c] - row[c].size(), ' ');
      // Settings left-aligned, numbers right-aligned.
      line += " " + (c == 0 || c >= first_figure ? pad + row[c] : row[c] + pad);
    }
    o << line.substr(0, line.find_last_not_of(' ') + 1) << "\n";
  }
  o << "  (*: the run took the single-frame matrices of an earlier run; no frame described)\n";
  if (both && !r.runs.empty() && Unsupervised(r.rank_by)) {
    double best_auc = 0;
    for (const SweepRun& run : r.runs) best_auc = std::max(best_auc, run.evaluation.per_query.auc);
    o << "  The first by " << EnumName(r.rank_by) << ", chosen without ground truth, has AUC "
      << FormatFixed(r.runs[0].evaluation.per_query.auc, 3) << ": rank " << other_rank[0] << " of "
      << r.runs.size() << " by AUC (the best AUC is " << FormatFixed(best_auc, 3) << ")\n";
  }
  return ToValidUtf8(o.str());
}

std::string EncodeSweepCsv(const SweepResult& r) {
  std::string out = "rank";
  for (const SweepAxis& a : r.axes) out += "," + CsvField(a.key);
  out +=
      ",label,auc,recall_at_100p,max_f1,max_f1_threshold,recall_at_1,recall_at_5,"
      "recall_at_10,average_precision_percent,queries,unanswered_queries,consistency,"
      "distinctiveness,agreement,seconds,described\n";
  for (size_t i = 0; i < r.runs.size(); ++i) {
    const SweepRun& run = r.runs[i];
    const PerQueryResult& q = run.evaluation.per_query;
    const UnsupervisedFigures& u = run.unsupervised;
    out += std::to_string(i + 1);
    for (const std::string& v : run.values) out += "," + CsvField(v);
    out += "," + CsvField(run.label);
    if (r.evaluated) {
      out += "," + CsvNumber(q.auc) + "," + CsvNumber(q.recall_at_100p) + "," +
             CsvNumber(q.max_f1) + "," + CsvNumber(q.max_f1_threshold) + "," +
             CsvNumber(q.recall_at_1) + "," + CsvNumber(q.recall_at_5) + "," +
             CsvNumber(q.recall_at_10) + "," + CsvNumber(run.evaluation.able_p.average_precision) +
             "," + std::to_string(q.queries) + "," + std::to_string(q.unanswered);
    } else {  // no ground truth: the figures are empty; queries from the criteria
      out += ",,,,,,,,," + std::to_string(u.queries) + "," + std::to_string(u.queries - u.answered);
    }
    out += "," + CsvNumber(u.consistency) + "," + CsvNumber(u.distinctiveness) + "," +
           CsvNumber(u.agreement) + "," + CsvNumber(run.seconds) + "," +
           (run.described ? "1" : "0") + "\n";
  }
  return out;
}

Json SweepJson(const SweepResult& r, const std::string& version) {
  Json o;
  o["openable_version"] = version;
  o["rank_by"] = EnumName(r.rank_by);
  Json& varied = o["varied"] = Json::array();
  for (const SweepAxis& a : r.axes)
    varied.push_back({{"key", a.key}, {"values", json::Strings(a.values)}});
  o["descriptions"] = r.descriptions;
  o["frame_reads"] = r.frame_reads;
  o["seconds"] = json::Number(r.seconds);
  o["evaluation"] = r.evaluated ? EvaluationSettingsJson(r.settings) : Json();
  const std::vector<int> by_auc =
      r.evaluated ? RanksBy(r.runs, SweepRank::kAuc) : std::vector<int>();
  const std::vector<int> by_agreement = RanksBy(r.runs, SweepRank::kAgreement);
  Json& runs = o["runs"] = Json::array();
  for (size_t i = 0; i < r.runs.size(); ++i) {
    const SweepRun& run = r.runs[i];
    const UnsupervisedFigures& u = run.unsupervised;
    Json entry;
    entry["rank"] = i + 1;
    Json& settings = entry["settings"] = Json::object();
    for (size_t a = 0; a < r.axes.size(); ++a) settings[r.axes[a].key] = run.values[a];
    entry["seconds"] = json::Number(run.seconds);
    entry["described"] = run.described;
    entry["unsupervised"] = {{"consistency", json::Number(u.consistency)},
                             {"distinctiveness", json::Number(u.distinctiveness)},
                             {"agreement", json::Number(u.agreement)},
                             {"queries", u.queries},
                             {"answered", u.answered},
                             {"agreeing", u.agreeing},
                             {"gap", u.gap},
                             {"tolerance", u.tolerance},
                             {"rank_by_agreement", by_agreement[i]}};
    if (r.evaluated) {
      entry["rank_by_auc"] = by_auc[i];
      AddEvaluatedRunJson(entry, run.evaluation);
    } else {
      entry["label"] = run.label;
    }
    runs.push_back(std::move(entry));
  }
  return o;
}

std::string EncodeSweepJson(const SweepResult& r, const std::string& version) {
  return json::Dump(SweepJson(r, version));
}

std::vector<std::string> WriteSweep(const std::string& prefix, const SweepResult& r) {
  OutputBatch batch;
  batch.Stage("--output", prefix + ".csv", EncodeSweepCsv(r));
  batch.Stage("--output", prefix + ".json", EncodeSweepJson(r, kVersion));
  if (!r.evaluated) {  // no ground truth, no precision-recall curve
    const std::vector<std::string> paths = batch.Paths();
    batch.Commit();
    return paths;
  }
  std::vector<PrSeries> series;
  const size_t shown = std::min(r.runs.size(), static_cast<size_t>(r.best));
  for (size_t i = 0; i < shown; ++i)
    series.push_back(
        {r.runs[i].label, r.runs[i].evaluation.per_query.curve, r.runs[i].evaluation.able_p.curve});
  const EvaluationSettings& s = r.settings;
  std::string title = "Best " + std::to_string(shown) + " of " + std::to_string(r.runs.size()) +
                      " runs by " + RankTitle(r.rank_by) + ", " +
                      GroundTruthTypeName(s.truth.type) + " ground truth, tolerance +-" +
                      std::to_string(s.options.tolerance);
  if (!r.runs.empty() && r.runs[0].evaluation.layout.kind == EvaluationLayout::Kind::kLoopClosure)
    title += ", exclusion " + std::to_string(s.options.exclusion);
  batch.Stage("--output", prefix + "_pr.png",
              EncodePng(RenderPrPlot(series, title, s.options.vicinity)));
  const std::vector<std::string> paths = batch.Paths();
  batch.Commit();
  return paths;
}

}  // namespace openable
