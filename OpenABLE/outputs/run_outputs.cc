#include "OpenABLE/outputs/run_outputs.h"

#include <algorithm>
#include <chrono>
#include <functional>
#include <future>
#include <limits>
#include <memory>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/output_batch.h"
#include "OpenABLE/base/strings.h"
#include "OpenABLE/io/npy.h"
#include "OpenABLE/outputs/matrix_files.h"
#include "OpenABLE/outputs/matrix_settings.h"
#include "OpenABLE/reports/evaluation_files.h"
#include "OpenABLE/reports/figures.h"
#include "OpenABLE/reports/html_report.h"
#include "OpenABLE/run/pipeline.h"
#include "OpenABLE/run/verify.h"
#include "OpenABLE/tuning/auto.h"

namespace openable {

using Clock = std::chrono::steady_clock;

std::string ThresholdPngPath(const Config& config) {
  return config.output.ThresholdPngPath(config.matching.threshold >= 0.0);
}

namespace {

using Planned = std::vector<std::pair<std::string, std::string>>;

// What the files of a run are made from.
struct OutputInput {
  const Config& config;
  const RunResult& result;
  const cv::Mat1f& shown;  // cells without a value as the largest finite value (text, images)
  const Evaluation* evaluation;
  const RunVerification* verification;
  const AutoChoice* automatic;
  ProgressReporter* progress;  // null: no progress lines
};

// Stages a file in the batch; empty when the run writes no such file.
using Stager = std::function<void(OutputBatch&)>;

// One kind of output file of a run. WriteOutputs prepares every kind in the registry's order
// (an encoder may start on its own thread then), then stages them in the same order, which is
// the order of the paths it returns; PlannedOutputs lists their paths from the same entries,
// so that the files checked before a run are the files written after it.
struct RunOutput {
  bool dense_only;  // made from the dense matrix: a bounded run writes no such file
  // Written beside another output (the settings beside a matrix): not noted on its own when
  // a bounded run leaves it out.
  bool companion;
  Planned (*planned)(const Config& config);  // the (key, path) of the files `config` asks for
  Stager (*prepare)(const OutputInput& in);
};

// One file of one key when its path is set.
Planned One(const char* key, const std::string& path) {
  return path.empty() ? Planned() : Planned{{key, path}};
}

// A PNG image encoded on its own thread while the other files are written: OpenCV's PNG
// encoder is single-threaded and the images dominate the time of the outputs.
Stager EncodedInBackground(const std::string& key, const std::string& path,
                           std::function<std::string()> encode) {
  auto bytes =
      std::make_shared<std::future<std::string>>(std::async(std::launch::async, std::move(encode)));
  return [key, path, bytes](OutputBatch& batch) { batch.Stage(key, path, bytes->get()); };
}

// The answers of a run without ground truth for its report: the matrix's best matches, or
// with verification the verified answers (every one accepted unless Match_threshold is set),
// accepted at the run's operating point (none when the auto mode trusted no setting).
ReportAnswers RunAnswersForReport(const OutputInput& in) {
  const Config& config = in.config;
  EvaluationOptions options = EvaluationSettingsFrom(config).options;
  options.accept_none = in.automatic != nullptr && !in.automatic->reliable;
  const EvaluationLayout layout = LayoutOf(in.result);
  ReportAnswers report = AnswersForReport(in.result.normalized, layout, RunLabel(config),
                                          "Test_OpenABLE run", options);
  if (in.verification != nullptr) {
    if (options.accept_threshold < 0)
      options.accept_threshold = std::numeric_limits<double>::infinity();
    report.answers =
        AnswersOfCandidates(layout, AnswersOf(*in.verification, layout).accepted, options);
    report.threshold = options.accept_threshold;
    report.verified = true;
  }
  return report;
}

const std::vector<RunOutput>& RunOutputs() {
  static const std::vector<RunOutput> outputs = {
      // Npy_name: written from the matrix itself while the images are being encoded.
      {true, false, [](const Config& c) { return One("Npy_name", c.output.npy_name); },
       [](const OutputInput& in) -> Stager {
         const std::string& path = in.config.output.npy_name;
         if (path.empty()) return {};
         return [&in, path](OutputBatch& batch) {
           const cv::Mat1f& saved = in.result.normalized;  // +inf kept (no value)
           const std::string header = NpyHeader(saved.rows, saved.cols);
           std::vector<std::string_view> parts = {header};
           for (int i = 0; i < saved.rows; ++i)
             parts.emplace_back(reinterpret_cast<const char*>(saved.ptr<float>(i)),
                                saved.cols * sizeof(float));
           batch.Stage("Npy_name", path, parts);
         };
       }},
      // Txt_name: formatted in pieces and written as they come (the images encode meanwhile):
      // the text of a large matrix is never whole in memory. The thresholded matrix when
      // Threshold is set.
      {true, false, [](const Config& c) { return One("Txt_name", c.output.txt_name); },
       [](const OutputInput& in) -> Stager {
         const std::string& path = in.config.output.txt_name;
         if (path.empty()) return {};
         return [&in, path](OutputBatch& batch) {
           TextChunks text(in.result.thresholded.empty() ? cv::Mat(in.shown)
                                                         : cv::Mat(in.result.thresholded));
           batch.Stage("Txt_name", path, [&](std::string_view& piece) { return text.Next(piece); });
         };
       }},
      // Beside each matrix file, the settings that shaped it and those of its evaluation
      // (matrix_settings.h), so that openable_evaluate and Python evaluate it as the run did.
      {true, true,
       [](const Config& c) {
         Planned p = One("Npy_name (settings)",
                         c.output.npy_name.empty() ? "" : MatrixSettingsPath(c.output.npy_name));
         const Planned t =
             One("Txt_name (settings)",
                 c.output.txt_name.empty() ? "" : MatrixSettingsPath(c.output.txt_name));
         p.insert(p.end(), t.begin(), t.end());
         return p;
       },
       [](const OutputInput& in) -> Stager {
         const OutputOptions& o = in.config.output;
         if (o.npy_name.empty() && o.txt_name.empty()) return {};
         return [&in](OutputBatch& batch) {
           const OutputOptions& o = in.config.output;
           if (!o.npy_name.empty())
             batch.Stage("Npy_name", MatrixSettingsPath(o.npy_name),
                         EncodeMatrixSettings(in.config, in.result, o.npy_name, false));
           if (!o.txt_name.empty())
             batch.Stage("Txt_name", MatrixSettingsPath(o.txt_name),
                         EncodeMatrixSettings(in.config, in.result, o.txt_name,
                                              !in.result.thresholded.empty()));
         };
       }},
      {true, false, [](const Config& c) { return One("Png_name", c.output.png_name); },
       [](const OutputInput& in) -> Stager {
         const OutputOptions& o = in.config.output;
         if (o.png_name.empty()) return {};
         return EncodedInBackground("Png_name", o.png_name, [&in] {
           return EncodePng(ColorizeMatrix(in.shown, in.config.output.matrix_color));
         });
       }},
      // The thresholded image (Eq. 9): Png_threshold_name, or Png_name's path with
      // "_thresholded".
      {true, false,
       [](const Config& c) {
         return One(c.output.png_threshold_name.empty() ? "Png_name (thresholded image)"
                                                        : "Png_threshold_name",
                    ThresholdPngPath(c));
       },
       [](const OutputInput& in) -> Stager {
         const std::string path = ThresholdPngPath(in.config);
         if (path.empty()) return {};
         return EncodedInBackground(
             in.config.output.png_threshold_name.empty() ? "Png_name" : "Png_threshold_name", path,
             [&in] {
               cv::Mat1f binary;
               in.result.thresholded.convertTo(binary, CV_32F);
               return EncodePng(ColorizeMatrix(binary, in.config.output.matrix_color));
             });
       }},
      {false, false, [](const Config& c) { return One("Matches_name", c.scale.matches_name); },
       [](const OutputInput& in) -> Stager {
         const std::string& path = in.config.scale.matches_name;
         if (path.empty()) return {};
         return [&in, path](OutputBatch& batch) {
           const bool csv = path.size() >= 4 && path.compare(path.size() - 4, 4, ".csv") == 0;
           // The verdicts of Match_threshold and Match_consistency on each best match, as the
           // run counted them (none when the auto mode trusted no setting).
           const MatchingOptions& m = in.config.matching;
           const AgreementOptions agreement = AgreementOf(m);
           const MatchVerdicts verdicts = VerdictsOf(
               in.result.matches, m.match_threshold, m.match_consistency > 0 ? &agreement : nullptr,
               in.automatic != nullptr && !in.automatic->reliable);
           batch.Stage("Matches_name", path, EncodeMatches(in.result.matches, csv, verdicts));
         };
       }},
      {false, false,
       [](const Config& c) {
         return c.verification.enabled ? One("Loops_name", c.output.loops_name) : Planned();
       },
       [](const OutputInput& in) -> Stager {
         const std::string& path = in.config.output.loops_name;
         if (in.verification == nullptr || path.empty()) return {};
         return [&in, path](OutputBatch& batch) {
           batch.Stage("Loops_name", path, EncodeLoops(*in.verification));
         };
       }},
      // Timestamps_name: "<row> <seconds>" per row, nanosecond resolution (the stamps of ROS
      // messages).
      {false, false,
       [](const Config& c) { return One("Timestamps_name", c.output.timestamps_name); },
       [](const OutputInput& in) -> Stager {
         const std::string& path = in.config.output.timestamps_name;
         if (path.empty()) return {};
         return [&in, path](OutputBatch& batch) {
           std::string text = "# row seconds (frame times of the matrix's rows)\n";
           for (const Traversal& tr : in.result.traversals) {
             if (static_cast<int>(tr.times.size()) != tr.frames)
               throw InputError("Timestamps_name: the frames of " + tr.key +
                                " carry no times; "
                                "expected frames of a ROS bag (Frame_mode 3)");
             for (int i = 0; i < tr.frames; ++i)
               text += std::to_string(tr.first_row + i) + " " + FormatFixed(tr.times[i], 9) + "\n";
           }
           batch.Stage("Timestamps_name", path, text);
         };
       }},
      // Evaluation_name: the evaluation's files of one run (no label in the names).
      {false, false,
       [](const Config& c) {
         Planned out;
         const std::string& prefix = c.evaluation.name;
         if (!EvaluationRequested(c) || prefix.empty()) return out;
         for (const char* suffix : kEvaluationSetSuffixes)
           out.emplace_back("Evaluation_name", prefix + suffix);
         for (const char* suffix : kEvaluationRunSuffixes)
           out.emplace_back("Evaluation_name", prefix + suffix);
         // Per run, each reference protocol's curve (its suffix in the table of protocols).
         for (const std::string& name : c.evaluation.protocol.protocols.reference)
           out.emplace_back("Evaluation_name", prefix + FindReferenceProtocol(name)->csv_suffix);
         return out;
       },
       [](const OutputInput& in) -> Stager {
         if (in.evaluation == nullptr || in.config.evaluation.name.empty()) return {};
         return [&in](OutputBatch& batch) {
           StageEvaluation(batch, "Evaluation_name", in.config.evaluation.name, *in.evaluation,
                           {&in.result.normalized});
         };
       }},
      // Report_name: with ground truth the page of the evaluation, else the page of the run's
      // answers (html_report.h). It shows the matrix: a bounded run writes none.
      {true, false, [](const Config& c) { return One("Report_name", c.evaluation.report_name); },
       [](const OutputInput& in) -> Stager {
         if (in.config.evaluation.report_name.empty()) return {};
         // Made here, before the other files are staged (the images encode meanwhile), with a
         // progress line of its own: reading the frames it shows is the long part.
         auto page = std::make_shared<std::string>();
         {
           const Config& config = in.config;
           ReportInput report;
           report.program = "Test_OpenABLE";
           report.title = "OpenABLE report: " + RunLabel(config);
           report.settings = ChangedSettings(config);
           report.all_settings = FormatConfig(config);
           report.evaluation = in.evaluation;
           report.matrices = {&in.result.normalized};
           if (in.evaluation == nullptr) report.answers = {RunAnswersForReport(in)};
           report.examples = config.evaluation.report_examples;
           if (in.automatic != nullptr) report.tables.push_back(AutoReportTable(*in.automatic));
           if (report.examples > 0) {
             // Row i of a traversal is its i-th kept frame: frames skipped as unreadable
             // would otherwise shift every later frame's name and thumbnail.
             try {
               report.frames = FramesFromSources(
                   FramesOfRows(OpenFramesToShow(config.input), in.result.traversals), false);
             } catch (const std::logic_error& e) {
               report.frames.missing =
                   std::string("the frames of the rows could not be found (") + e.what() + ")";
             }
           }
           bool begun = false;
           if (in.progress != nullptr)
             report.on_progress = [&](std::int64_t done, std::int64_t total) {
               if (!begun) in.progress->Begin("report", total, "steps (frames and figures)");
               begun = true;
               in.progress->Update(done);
             };
           *page = EncodeHtmlReport(report);
           if (begun) in.progress->End();
         }
         return [&in, page](OutputBatch& batch) {
           batch.Stage("Report_name", in.config.evaluation.report_name, *page);
         };
       }},
  };
  return outputs;
}

}  // namespace

std::vector<std::pair<std::string, std::string>> PlannedOutputs(const Config& config) {
  Planned out;
  for (const RunOutput& output : RunOutputs()) {
    const Planned files = output.planned(config);
    out.insert(out.end(), files.begin(), files.end());
  }
  return out;
}

std::vector<std::string> UnwrittenOutputNotes(const Config& config, const RunResult& result) {
  std::vector<std::string> notes;
  if (!result.bounded) return notes;
  for (const RunOutput& output : RunOutputs())
    if (output.dense_only && !output.companion)
      for (const auto& [key, path] : output.planned(config))
        notes.push_back(key +
                        ": not written: the run is bounded and keeps no dense matrix "
                        "(see Matches_name)");
  return notes;
}

std::vector<std::string> WriteOutputs(const Config& config, RunResult& result,
                                      const Evaluation* evaluation,
                                      const RunVerification* verification,
                                      const AutoChoice* automatic, ProgressReporter* progress) {
  const auto t = Clock::now();
  const OutputOptions& out = config.output;
  const bool dense = !result.bounded;  // bounded runs keep no matrix: only Matches_name
  // Cells without a value (+inf) are shown as the largest finite value in the text and the
  // image (readable exports), and stay +inf in the .npy file, where NaN would be
  // indistinguishable from damage (readers refuse NaN: DistancesForEvaluation).
  cv::Mat1f shown = result.normalized;
  if (dense && result.empty_cells > 0) {
    const cv::Mat1b empty = result.normalized == std::numeric_limits<float>::infinity();
    double largest = 0;
    cv::minMaxLoc(result.normalized, nullptr, &largest, nullptr, nullptr, ~empty);
    if (!out.txt_name.empty() || !out.png_name.empty()) {
      shown = result.normalized.clone();
      shown.setTo(largest, empty);
    }
  }
  const OutputInput in{config, result, shown, evaluation, verification, automatic, progress};
  // Declared after the matrices the encoders read: when a write fails and the exception
  // unwinds, the stagers (which hold the encoders' futures, whose destructors wait for their
  // threads) go first, so no encoder is left reading a freed matrix.
  std::vector<Stager> stagers;
  for (const RunOutput& output : RunOutputs())
    if (dense || !output.dense_only) stagers.push_back(output.prepare(in));
  // One step per kind of output staged, then the commit (files synced and renamed).
  const auto steps = std::count_if(stagers.begin(), stagers.end(),
                                   [](const Stager& stage) { return static_cast<bool>(stage); });
  if (progress != nullptr) progress->Begin("writing", steps + 1, "steps (outputs, then commit)");
  OutputBatch batch;
  std::int64_t done = 0;
  for (const Stager& stage : stagers)
    if (stage) {
      stage(batch);
      if (progress != nullptr) progress->Update(++done);
    }
  const std::vector<std::string> paths = batch.Paths();
  batch.Commit();
  if (progress != nullptr) progress->End();
  const double seconds = SecondsSince(t);
  result.timings.export_seconds += seconds;
  result.timings.total_seconds += seconds;
  return paths;
}

}  // namespace openable
