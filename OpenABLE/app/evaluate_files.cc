#include "OpenABLE/app/evaluate_files.h"

#include <algorithm>
#include <filesystem>
#include <iterator>
#include <map>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "OpenABLE/app/command_line.h"
#include "OpenABLE/base/error.h"
#include "OpenABLE/base/output_batch.h"
#include "OpenABLE/base/strings.h"
#include "OpenABLE/evaluation/matrix_file.h"
#include "OpenABLE/evaluation/report.h"
#include "OpenABLE/outputs/matrix_settings.h"
#include "OpenABLE/reports/evaluation_files.h"
#include "OpenABLE/reports/html_report.h"
#include "OpenABLE/run/pipeline.h"

namespace openable {
namespace {

// Command-line flags that stand for a Config.txt key.
const std::pair<const char*, const char*> kFlagKeys[] = {
    {"--gt-type", "Ground_truth_type"},
    {"--ground-truth", "Ground_truth"},
    {"--ground-truth-2", "Ground_truth_2"},
    {"--gt-base", "Ground_truth_base"},
    {"--radius", "Ground_truth_radius"},
    {"--heading", "Ground_truth_heading"},
    {"--min-gap", "Ground_truth_min_gap"},
    {"--axes", "Ground_truth_axes"},
    {"--ground-truth-soft", "Ground_truth_soft"},
    {"--protocol", "Evaluation_protocol"},
    {"--tolerance", "Tolerance"},
    {"--exclusion", "Exclusion"},
    {"--vicinity", "Vicinity"},
    {"--first-frame", "Initial_image"},
    {"--output", "Evaluation_name"},
    {"--report", "Report_name"},
    {"--images", "Images_path"},
    {"--images-2", "Images_path_2"},
    {"--video", "Video_path_1"},
};

// The HTML report of the evaluation (Report_name), with the frames of the worst cases when the
// command line says where the frames are (Images_path, Images_path_2, Video_path_1).
std::string EncodeReport(const Config& config, const Evaluation& evaluation,
                         const std::vector<const cv::Mat1f*>& matrices,
                         const std::vector<MatrixFile>& files) {
  ReportInput report;
  report.program = "openable_evaluate";
  std::string labels;
  for (const auto& run : evaluation.runs) labels += (labels.empty() ? "" : " vs ") + run.label;
  report.title = "OpenABLE report: " + labels;
  report.settings = ChangedSettings(config);
  report.evaluation = &evaluation;
  report.matrices = matrices;
  report.examples = config.evaluation.report_examples;
  const InputOptions& input = config.input;
  const bool video = input.frame_mode != FrameMode::kImageFolders;
  if (report.examples == 0) {
    report.frames.missing = "Report_examples is 0";
  } else if (video ? input.video_path_1.empty() : input.images_path.empty()) {
    report.frames.missing =
        "openable_evaluate was not told where the frames are (--images DIR, and --images-2 DIR "
        "for a second traversal, or --video FILE with --set Frame_mode=1)";
  } else {
    std::vector<std::unique_ptr<FrameSource>> sources = OpenFramesToShow(input);
    const std::string key = video ? "Video_path_1 (--video)" : "Images_path (--images)";
    int total = 0;
    for (const auto& s : sources) total += s->Size();
    // One mapping of rows and columns to frames serves every matrix: they must share a shape.
    const cv::Mat1f& first = *matrices.front();
    const bool non_square = first.rows != first.cols;
    for (std::size_t i = 0; i < matrices.size(); ++i) {
      const cv::Mat1f& m = *matrices[i];
      if (m.size() != first.size())
        throw InputError(key + ": one set of frames for matrices of different sizes (" +
                         Quoted(files.front().path) + " is " + std::to_string(first.rows) + " x " +
                         std::to_string(first.cols) + ", " + Quoted(files[i].path) + " is " +
                         std::to_string(m.rows) + " x " + std::to_string(m.cols) +
                         "); expected matrices of the same frames, or a report per matrix");
      const bool fits = non_square ? sources.size() == 2 && m.rows == sources[1]->Size() &&
                                         m.cols == sources[0]->Size()
                                   : m.rows == total;
      if (!fits)
        throw InputError(
            key + ": " + std::to_string(total) + " frames" +
            (sources.size() == 2 ? " (" + std::to_string(sources[0]->Size()) + " + " +
                                       std::to_string(sources[1]->Size()) + ")"
                                 : std::string()) +
            ", but the matrix " + Quoted(files[i].path) + " is " + std::to_string(m.rows) + " x " +
            std::to_string(m.cols) +
            "; expected the frames the matrix was computed from (a queries x references "
            "matrix needs --images for the references and --images-2 for the queries)");
    }
    report.frames = FramesFromSources(std::move(sources), non_square);
  }
  return EncodeHtmlReport(report);
}

}  // namespace

std::string ParseEvaluateCommandLine(int argc, const char* const* argv, EvaluateCommandLine& out) {
  // The shared command line (command_line.h), with the flags that stand for keys and the
  // program's own options; a configuration is optional (--config, or a file given alone).
  ProgramOptions program;
  program.value_options = {"--matrix", "--label", "--reference-frames", "--layout", "--config"};
  for (const auto& [flag, key] : kFlagKeys) program.key_flags.emplace_back(flag, key);
  program.needs_configuration = false;
  CommandLine line;
  const std::string error = ParseCommandLine(argc, argv, "openable_evaluate", line, program);
  if (!error.empty()) return error;
  out = EvaluateCommandLine();
  out.help = line.help || line.help_markdown;
  out.help_keys = line.help_keys;
  out.help_group = line.help_group;
  out.version = line.version;
  if (out.help || out.help_keys || out.version) return "";
  if (line.print_config)
    return "openable_evaluate: --print-config is for the programs that run a configuration; "
           "expected --config FILE or the flags below (see --help)";
  out.overrides = line.overrides;
  out.config_path = line.config_path;
  out.quiet = line.quiet;
  out.json = line.json;
  const auto refuse = [](const std::string& what) {
    return "openable_evaluate: " + what + " (see --help)";
  };
  for (const auto& [option, value] : line.options) {
    if (option == "--matrix") {
      out.matrices.push_back({value, ""});
    } else if (option == "--label") {
      if (out.matrices.empty()) return refuse("--label must follow a --matrix");
      out.matrices.back().label = value;
    } else if (option == "--reference-frames") {
      std::size_t used = 0;
      try {
        out.reference_frames = std::stoi(value, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used != value.size() || out.reference_frames < 1)
        return refuse("--reference-frames: \"" + value +
                      "\" is not valid; expected a number of frames >= 1");
    } else if (option == "--layout") {
      if (value == "query_reference") {
        out.query_reference = true;
      } else if (value != "auto") {
        return refuse("--layout: \"" + value +
                      "\" is not valid; expected query_reference (a square matrix of queries x "
                      "references) or auto (the default: by its shape and --reference-frames)");
      }
    } else if (!out.config_path.empty()) {  // --config, after a file or another --config
      return refuse("more than one configuration file (\"" + out.config_path + "\" and \"" + value +
                    "\"); expected one");
    } else {
      out.config_path = value;
    }
  }
  if (out.matrices.empty()) return refuse("no --matrix given");
  return "";
}

namespace {

using Remembered = std::map<std::string, std::pair<std::string, std::string>>;

// Two paths of the same existing file.
bool SameFile(const std::string& a, const std::string& b) {
  std::error_code ec;
  return std::filesystem::equivalent(a, b, ec) && !ec;
}

}  // namespace

EvaluatedFiles EvaluateFiles(const EvaluateCommandLine& command_line) {
  // The settings the matrices remember (matrix_settings.h) come first, then the configuration
  // file's keys and the command line's, which override them (and are said to).
  Remembered remembered;        // key: its value, the settings file it came from
  std::set<std::string> given;  // keys the command line sets
  for (const auto& o : command_line.overrides) given.insert(Trim(o.substr(0, o.find('='))));
  int reference_frames = command_line.reference_frames;
  std::string reference_file;
  for (const MatrixFile& m : command_line.matrices) {
    const std::optional<SavedMatrixSettings> saved = ReadMatrixSettings(m.path);
    if (!saved) continue;
    // A settings file beside another run's matrix would evaluate a wrong block: refused
    // before anything is taken from it.
    const cv::Size size = MatrixFileSize(m.path);
    CheckMatrixFitsSettings(*saved, m.path, size.height, size.width);
    if (saved->thresholded)
      throw InputError("--matrix " + Quoted(m.path) +
                       ": holds the thresholded matrix M'' of Eq. 9, not distances (" +
                       saved->path +
                       "); expected a distance matrix (Npy_name, or Txt_name "
                       "without Threshold)");
    for (const auto& [key, value] : saved->keys) {
      const auto known = remembered.find(key);
      if (known != remembered.end() && known->second.first != value && !given.count(key))
        throw InputError("--matrix " + Quoted(m.path) + ": its run had " + key + " " +
                         Quoted(value) + " (" + saved->path + "), the run of " +
                         known->second.second + " had " + Quoted(known->second.first) +
                         "; expected one value: give --set " + key + "=VALUE for all");
      remembered.emplace(key, std::make_pair(value, saved->path));
    }
    if (command_line.reference_frames == 0 && saved->reference_frames > 0) {
      if (reference_frames > 0 && reference_frames != saved->reference_frames)
        throw InputError("--matrix " + Quoted(m.path) + ": its run had " +
                         std::to_string(saved->reference_frames) + " reference frames (" +
                         saved->path + "), the run of " + reference_file + " had " +
                         std::to_string(reference_frames) +
                         "; expected one value: give --reference-frames N");
      reference_frames = saved->reference_frames;
      reference_file = saved->path;
    }
  }
  Config config;
  for (const auto& [key, value_file] : remembered)
    ApplyOverride(config, key + "=" + value_file.first, value_file.second);
  if (!command_line.config_path.empty()) config = LoadConfig(command_line.config_path, config);
  for (const auto& o : command_line.overrides) ApplyOverride(config, o);
  if (!EvaluationRequested(config))
    throw InputError("Ground_truth_type: not set; expected --gt-type " + GroundTruthFormatList());
  CheckEvaluationConfig(config);
  CheckOutputPrefix("Evaluation_name", config.evaluation.name);
  EvaluatedFiles out;
  out.config = config;
  out.evaluation.settings = EvaluationSettingsFrom(config);
  // Say where the settings came from, and which of them this evaluation changed.
  std::string applied;
  const Config defaults;
  for (const auto& [key, value_file] : remembered) {
    const auto& [value, file] = value_file;
    const std::string plain = MatrixSettingValue(config, key);
    const bool same = plain == value || (key.rfind("Ground_truth", 0) == 0 && !plain.empty() &&
                                         SameFile(plain, value));
    if (!same && !(value.empty() && key.rfind("Ground_truth", 0) == 0))
      out.notes.push_back(key + " " + Quoted(plain) + " as given here, not " + Quoted(value) +
                          " as the matrix's run had it (" + file +
                          "): the figures may differ from the run's");
    else if (MatrixSettingValue(defaults, key) != plain)
      applied += (applied.empty() ? "" : ", ") + key + " " + plain;
  }
  if (!remembered.empty())
    out.notes.insert(out.notes.begin(), "evaluated with the settings the matrix's run had (" +
                                            remembered.begin()->second.second + ")" +
                                            (applied.empty() ? "" : ": " + applied));
  if (command_line.query_reference && reference_frames > 0)
    throw InputError(
        "--layout query_reference: the matrix is queries x references as a whole, "
        "but --reference-frames (or its run's settings) says it holds two traversals "
        "of " +
        std::to_string(reference_frames) +
        " reference frames; expected one "
        "of them");
  out.matrices = EvaluateMatrixFiles(out.evaluation, command_line.matrices, reference_frames,
                                     command_line.query_reference);
  return out;
}

std::vector<std::string> WriteEvaluatedFiles(const EvaluatedFiles& evaluated,
                                             const std::vector<MatrixFile>& files) {
  const Config& config = evaluated.config;
  OutputBatch batch;
  std::vector<const cv::Mat1f*> pointers;
  for (const auto& m : evaluated.matrices) pointers.push_back(&m);
  if (!config.evaluation.name.empty())
    StageEvaluation(batch, "Evaluation_name", config.evaluation.name, evaluated.evaluation,
                    pointers);
  if (!config.evaluation.report_name.empty())
    batch.Stage("Report_name", config.evaluation.report_name,
                EncodeReport(config, evaluated.evaluation, pointers, files));
  const std::vector<std::string> paths = batch.Paths();
  batch.Commit();
  return paths;
}

}  // namespace openable
