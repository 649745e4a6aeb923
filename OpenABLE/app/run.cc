#include "OpenABLE/app/run.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "OpenABLE/base/output_batch.h"
#include "OpenABLE/base/strings.h"
#include "OpenABLE/base/version.h"
#include "OpenABLE/cluster/cluster.h"
#include "OpenABLE/evaluation/metrics.h"
#include "OpenABLE/evaluation/report.h"
#include "OpenABLE/outputs/run_outputs.h"

namespace openable {
namespace {

// A run that could yield no value, refused before any frame is read. With Sequence_partial
// ahead or skip a cell has a value only on a diagonal of at least L frames inside one block of
// the matrix (a traversal against itself, or one traversal against the other: sums never cross
// from one into the other). Sequences longer than every traversal leave the whole matrix +inf;
// with two traversals, longer than the shorter one leave the query-reference block (the
// queries' answers, the evaluation, the matches) +inf.
void CheckSequencesFit(const RunPlan& plan) {
  const MatchingOptions& m = plan.config.matching;
  if (m.partial == SequencePartial::kScale || m.sequence_length <= 1 || plan.sources.empty())
    return;
  int longest = 0, shortest = plan.sources.front()->Size();
  std::string frames;
  for (std::size_t i = 0; i < plan.sources.size(); ++i) {
    const int n = plan.sources[i]->Size();
    longest = std::max(longest, n);
    shortest = std::min(shortest, n);
    frames += (i ? " and " : "") + std::to_string(n) + " (" + plan.specs[i].key + ")";
  }
  const bool two = plan.sources.size() == 2;
  const int limit = two ? shortest : longest;
  if (m.sequence_length <= limit) return;
  throw InputError(
      "Image_sequences: " + std::to_string(m.sequence_length) + " frames, but the traversal" +
      (two ? "s have " : " has ") + frames + " frames: with Sequence_partial " +
      EnumName(m.partial) + " a cell has a value only on a diagonal of at least " +
      std::to_string(m.sequence_length) + " frames, so " +
      (two ? "no query of the second traversal would have a value against the first"
           : "the matrix would hold no value") +
      "; expected Image_sequences <= " + std::to_string(limit) + ", or Sequence_partial scale");
}

// One traversal: a run whose frames have no candidate with a value (their candidates are the
// frames at least Exclusion back) finds no loop, though its matrix is written. One line
// saying why; empty otherwise.
std::string NoCandidateWarning(const Config& config, const RunResult& result) {
  if (result.bounded || result.normalized.empty() || result.traversals.size() != 1) return "";
  const EvaluationLayout layout = LayoutOf(result);
  const int exclusion = config.evaluation.protocol.exclusion;
  if (layout.queries <= exclusion)
    return "Exclusion: " + std::to_string(exclusion) + " leaves no frame a candidate (the " +
           std::to_string(layout.queries) +
           " frames of the sequence; a frame's candidates are at least Exclusion frames back): "
           "the matrix is written, but no loop can be found; expected Exclusion < " +
           std::to_string(layout.queries);
  if (AnyCandidateHasValue(result.normalized, layout, exclusion)) return "";
  const MatchingOptions& m = config.matching;
  return "Image_sequences: " + std::to_string(m.sequence_length) +
         " leaves no candidate with a value (a frame's candidates are at least Exclusion " +
         std::to_string(exclusion) + " frames back, and with Sequence_partial " +
         EnumName(m.partial) + " a cell has a value only on a diagonal of at least " +
         std::to_string(m.sequence_length) + " of the " + std::to_string(layout.queries) +
         " frames): the matrix is written, but no loop can be found; expected a shorter "
         "Image_sequences, a smaller Exclusion, or Sequence_partial scale";
}

}  // namespace

RunOutcome Run(const Config& base, ProgressReporter& progress,
               const std::function<void(const std::string&)>& log) {
  if (base.output.show_images && std::getenv("DISPLAY") == nullptr &&
      std::getenv("WAYLAND_DISPLAY") == nullptr)
    log("warning: Show_images is 1 but there is no display (DISPLAY is not set); frames are "
        "not shown");
  RunOutcome out;
  // The check phase, before the long part of the run: no two outputs at one file, no prefix
  // that is a folder, the evaluation settings, then the run's plan (PlanRun: configuration,
  // descriptors, sources, mode). With Auto 1 the run's plan is made once the settings are
  // chosen. Spread over processes (cluster.h), every process checks, together, so that a check
  // that fails on one of them (a folder it cannot see) ends the run on all.
  Cluster& cluster = Cluster::Get();
  std::optional<RunPlan> plan;
  const auto check = [&] {
    CheckDistinctOutputs(PlannedOutputs(base));
    if (EvaluationRequested(base)) {
      CheckOutputPrefix("Evaluation_name", base.evaluation.name);
      (void)EvaluationSettingsFrom(base);
    }
    if (!base.automatic.enabled || cluster.Distributed()) {
      plan.emplace(PlanRun(base));
      CheckSequencesFit(*plan);
    }
    // An aligned ground truth of traversals of unequal length is refused before any frame
    // is read (the sources know their lengths).
    if (plan && plan->sources.size() == 2 &&
        base.evaluation.truth.type == GroundTruthType::kAligned)
      CheckAlignedLengths(plan->sources[1]->Size(), plan->sources[0]->Size());
  };
  if (cluster.Distributed())
    cluster.Agree(check);
  else
    check();
  // The evaluation's settings, checked above.
  if (EvaluationRequested(base)) {
    out.evaluation = std::make_unique<Evaluation>();
    out.evaluation->settings = EvaluationSettingsFrom(base);
  }
  if (!base.verification.enabled && !base.output.loops_name.empty())
    log("note: Loops_name: not written: Verification is 0 (no candidate is checked)");
  // Auto 1: the settings chosen from the data; the run goes on as a run of the chosen
  // configuration, from the single-frame matrices the choice computed.
  SingleFrameStore store;
  const Config* chosen = &base;
  if (base.automatic.enabled) {
    out.automatic = std::make_unique<AutoChoice>(ChooseSettings(base, progress, store, log));
    chosen = &out.automatic->config;
    if (!out.automatic->reliable)
      log("warning: Auto: no candidate is consistent enough to be trusted (the best confirms " +
          FormatFixed(100.0 * out.automatic->candidates[out.automatic->chosen].figures.consistency,
                      1) +
          " % of its best matches, Auto_min_consistency " +
          FormatNumber(100.0 * base.automatic.min_consistency) +
          " %): the outputs are written, but no match is accepted");
    if (out.evaluation) {
      out.evaluation->settings = EvaluationSettingsFrom(*chosen);
      out.evaluation->settings.options.accept_none = !out.automatic->reliable;
    }
  }
  const Config& config = *chosen;
  if (out.automatic) {
    plan.emplace(PlanRun(config));
    CheckSequencesFit(*plan);
  }
  out.result = ComputeRun(*plan, progress, out.automatic ? &store : nullptr);
  // Process 0 evaluates, verifies and writes; the others have given it their shares.
  if (cluster.Distributed() && cluster.Rank() != 0) return out;
  RunResult& result = out.result;
  for (const std::string& note : UnwrittenOutputNotes(config, result)) result.notes.push_back(note);
  if (const std::string w = NoCandidateWarning(config, result); !w.empty())
    result.warnings.push_back(w);
  if (out.automatic && !out.automatic->reliable && result.accepted_queries > 0)
    result.accepted_queries = 0;
  for (const std::string& w : result.warnings) log("warning: " + w);
  for (const std::string& note : result.notes) log("note: " + note);
  if (config.verification.enabled) {
    out.verification = std::make_unique<RunVerification>(VerifyRun(config, result, progress));
    result.timings.total_seconds += out.verification->seconds;
  }
  if (out.evaluation && result.bounded) {
    log("note: Ground_truth_type: no evaluation in bounded mode (the protocols need the dense "
        "matrix); evaluate Matches_name yourself or use Matrix_mode 1");
    out.evaluation.reset();
  }
  if (out.evaluation) {
    const auto start = std::chrono::steady_clock::now();
    const EvaluationLayout layout = LayoutOf(result);
    // Frames that carry times (ROS bags) take their TUM poses by time.
    GroundTruthOptions& truth = out.evaluation->settings.truth;
    if (!result.traversals.empty()) truth.frame_times = result.traversals[0].times;
    if (result.traversals.size() > 1) truth.frame_times_2 = result.traversals[1].times;
    if (out.verification) {
      const VerifiedAnswers answers = AnswersOf(*out.verification, layout);
      EvaluateMatrix(*out.evaluation, result.normalized, layout, RunLabel(config),
                     "Test_OpenABLE run", &answers);
    } else {
      EvaluateMatrix(*out.evaluation, result.normalized, layout, RunLabel(config),
                     "Test_OpenABLE run");
    }
    for (const std::string& w : out.evaluation->runs.back().warnings)
      log("warning: evaluation: " + w);
    result.timings.evaluate_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    result.timings.total_seconds += result.timings.evaluate_seconds;
  }
  if (out.automatic) result.timings.total_seconds += out.automatic->seconds;
  out.written = WriteOutputs(config, result, out.evaluation.get(), out.verification.get(),
                             out.automatic.get(), &progress);
  return out;
}

}  // namespace openable
