#include "OpenABLE/outputs/run_outputs.h"

#include <chrono>
#include <future>
#include <limits>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/strings.h"
#include "OpenABLE/base/output_batch.h"
#include "OpenABLE/io/npy.h"
#include "OpenABLE/outputs/matrix_files.h"
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

std::vector<std::pair<std::string, std::string>> PlannedOutputs(const Config& config) {
  std::vector<std::pair<std::string, std::string>> out;
  const OutputOptions& o = config.output;
  if (!o.txt_name.empty()) out.emplace_back("Txt_name", o.txt_name);
  if (!o.npy_name.empty()) out.emplace_back("Npy_name", o.npy_name);
  if (!o.png_name.empty()) out.emplace_back("Png_name", o.png_name);
  const std::string threshold_png = ThresholdPngPath(config);
  if (!threshold_png.empty())
    out.emplace_back(
        o.png_threshold_name.empty() ? "Png_name (thresholded image)" : "Png_threshold_name",
        threshold_png);
  if (!config.scale.matches_name.empty())
    out.emplace_back("Matches_name", config.scale.matches_name);
  if (config.verification.enabled && !o.loops_name.empty())
    out.emplace_back("Loops_name", o.loops_name);
  const std::string& prefix = config.evaluation.name;
  if (EvaluationRequested(config) && !prefix.empty()) {  // one run: no label in the names
    for (const char* suffix : kEvaluationSetSuffixes)
      out.emplace_back("Evaluation_name", prefix + suffix);
    for (const char* suffix : kEvaluationRunSuffixes)
      out.emplace_back("Evaluation_name", prefix + suffix);
  }
  if (EvaluationRequested(config) && !config.evaluation.report_name.empty())
    out.emplace_back("Report_name", config.evaluation.report_name);
  if (!o.timestamps_name.empty()) out.emplace_back("Timestamps_name", o.timestamps_name);
  return out;
}

std::vector<std::string> WriteOutputs(const Config& config, RunResult& result,
                                      const Evaluation* evaluation,
                                      const RunVerification* verification,
                                      const AutoChoice* automatic) {
  const auto t = Clock::now();
  const OutputOptions& out = config.output;
  const bool dense = !result.bounded;  // bounded runs keep no matrix: only Matches_name
  // Cells without a value (+inf) are shown as the largest finite value in the text and the
  // image, and are NaN in the .npy file: readable exports, and NumPy code that skips NaN.
  cv::Mat1f shown = result.normalized, saved = result.normalized;
  if (dense && result.empty_cells > 0) {
    const cv::Mat1b empty = result.normalized == std::numeric_limits<float>::infinity();
    double largest = 0;
    cv::minMaxLoc(result.normalized, nullptr, &largest, nullptr, nullptr, ~empty);
    if (!out.txt_name.empty() || !out.png_name.empty()) {
      shown = result.normalized.clone();
      shown.setTo(largest, empty);
    }
    if (!out.npy_name.empty()) {
      saved = result.normalized.clone();
      saved.setTo(std::numeric_limits<float>::quiet_NaN(), empty);
    }
  }
  // The encodings are independent; the two PNG images dominate (OpenCV's PNG encoder is
  // single-threaded), so each is encoded on its own thread while the .npy and the text are
  // written, then staged in order.
  struct Pending {
    std::string key, path;
    std::future<std::string> bytes;
  };
  // Declared after the matrices the encoders read: when a write fails and the exception
  // unwinds, the futures (whose destructors wait for their threads) go first, so no encoder
  // is left reading a freed matrix.
  std::vector<Pending> pending;
  auto encode = [&](const std::string& key, const std::string& path, auto make) {
    pending.push_back({key, path, std::async(std::launch::async, make)});
  };
  if (dense && !out.png_name.empty())
    encode("Png_name", out.png_name,
           [&] { return EncodePng(ColorizeMatrix(shown, out.matrix_color)); });
  const std::string threshold_png = ThresholdPngPath(config);
  if (dense && !threshold_png.empty()) {
    encode(out.png_threshold_name.empty() ? "Png_name" : "Png_threshold_name", threshold_png, [&] {
      cv::Mat1f binary;
      result.thresholded.convertTo(binary, CV_32F);
      return EncodePng(ColorizeMatrix(binary, out.matrix_color));
    });
  }
  OutputBatch batch;
  if (dense && !out.npy_name.empty()) {
    // Written from the matrix itself while the other outputs are being encoded.
    const std::string header = NpyHeader(saved.rows, saved.cols);
    std::vector<std::string_view> parts = {header};
    for (int i = 0; i < saved.rows; ++i)
      parts.emplace_back(reinterpret_cast<const char*>(saved.ptr<float>(i)),
                         saved.cols * sizeof(float));
    batch.Stage("Npy_name", out.npy_name, parts);
  }
  if (dense && !out.txt_name.empty()) {
    // Formatted in pieces and written as they come (the PNGs encode meanwhile): the text of a
    // large matrix is never whole in memory.
    TextChunks text(result.thresholded.empty() ? cv::Mat(shown) : cv::Mat(result.thresholded));
    batch.Stage("Txt_name", out.txt_name,
                [&](std::string_view& piece) { return text.Next(piece); });
  }
  for (Pending& p : pending) batch.Stage(p.key, p.path, p.bytes.get());
  const std::string& matches = config.scale.matches_name;
  if (!matches.empty()) {
    const bool csv = matches.size() >= 4 && matches.compare(matches.size() - 4, 4, ".csv") == 0;
    batch.Stage("Matches_name", matches, EncodeMatches(result.matches, csv));
  }
  if (verification != nullptr && !out.loops_name.empty())
    batch.Stage("Loops_name", out.loops_name, EncodeLoops(*verification));
  if (!out.timestamps_name.empty()) {
    // "<row> <seconds>" per row, nanosecond resolution (the stamps of ROS messages).
    std::string text = "# row seconds (frame times of the matrix's rows)\n";
    for (const Traversal& tr : result.traversals) {
      if (static_cast<int>(tr.times.size()) != tr.frames)
        throw InputError("Timestamps_name: the frames of " + tr.key +
                         " carry no times; "
                         "expected frames of a ROS bag (Frame_mode 3)");
      for (int i = 0; i < tr.frames; ++i)
        text += std::to_string(tr.first_row + i) + " " + FormatFixed(tr.times[i], 9) + "\n";
    }
    batch.Stage("Timestamps_name", out.timestamps_name, text);
  }
  if (evaluation != nullptr && !config.evaluation.name.empty())
    StageEvaluation(batch, "Evaluation_name", config.evaluation.name, *evaluation,
                    {&result.normalized});
  if (evaluation != nullptr && !config.evaluation.report_name.empty()) {
    ReportInput report;
    report.program = "Test_OpenABLE";
    report.title = "OpenABLE report: " + RunLabel(config);
    report.settings = ChangedSettings(config);
    report.all_settings = FormatConfig(config);
    report.evaluation = evaluation;
    report.matrices = {&result.normalized};
    report.examples = config.evaluation.report_examples;
    if (automatic != nullptr) report.tables.push_back(AutoReportTable(*automatic));
    if (report.examples > 0)
      report.frames = FramesFromSources(OpenFramesToShow(config.input), false);
    batch.Stage("Report_name", config.evaluation.report_name, EncodeHtmlReport(report));
  }
  const std::vector<std::string> paths = batch.Paths();
  batch.Commit();
  const double seconds = SecondsSince(t);
  result.timings.export_seconds += seconds;
  result.timings.total_seconds += seconds;
  return paths;
}

}  // namespace openable
