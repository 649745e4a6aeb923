// openable_evaluate: evaluates saved distance matrices against ground truth, with the same
// protocols, keys and outputs as Test_OpenABLE's evaluation (docs/evaluation.md). A thin layer
// over openable::EvaluateMatrixFiles (OpenABLE/run/evaluate.h).
#include <algorithm>
#include <iostream>
#include <string>
#include <utility>
#include <vector>

#include "OpenABLE/OpenABLE.h"
#include "OpenABLE/cluster/cluster.h"
#include "OpenABLE/reports/html_report.h"
#include "OpenABLE/run/pipeline.h"

namespace {

// Command-line flags that stand for a Config.txt key.
const std::pair<const char*, const char*> kFlagKeys[] = {
    {"--gt-type", "Ground_truth_type"},     {"--ground-truth", "Ground_truth"},
    {"--ground-truth-2", "Ground_truth_2"}, {"--gt-base", "Ground_truth_base"},
    {"--radius", "Ground_truth_radius"},    {"--heading", "Ground_truth_heading"},
    {"--min-gap", "Ground_truth_min_gap"},  {"--axes", "Ground_truth_axes"},
    {"--tolerance", "Tolerance"},           {"--exclusion", "Exclusion"},
    {"--vicinity", "Vicinity"},             {"--first-frame", "Initial_image"},
    {"--output", "Evaluation_name"},        {"--report", "Report_name"},
    {"--images", "Images_path"},            {"--images-2", "Images_path_2"},
    {"--video", "Video_path_1"},
};

// The HTML report of the evaluation (Report_name), with the frames of the worst cases when the
// command line says where the frames are (Images_path, Images_path_2, Video_path_1).
std::string EncodeReport(const openable::Config& config, const openable::Evaluation& evaluation,
                         const std::vector<const cv::Mat1f*>& matrices,
                         const std::vector<openable::MatrixFile>& files) {
  openable::ReportInput report;
  report.program = "openable_evaluate";
  std::string labels;
  for (const auto& run : evaluation.runs) labels += (labels.empty() ? "" : " vs ") + run.label;
  report.title = "OpenABLE report: " + labels;
  report.settings = openable::ChangedSettings(config);
  report.evaluation = &evaluation;
  report.matrices = matrices;
  report.examples = config.evaluation.report_examples;
  const openable::InputOptions& input = config.input;
  const bool video = input.frame_mode != openable::FrameMode::kImageFolders;
  if (report.examples == 0) {
    report.frames.missing = "Report_examples is 0";
  } else if (video ? input.video_path_1.empty() : input.images_path.empty()) {
    report.frames.missing =
        "openable_evaluate was not told where the frames are (--images DIR, and --images-2 DIR "
        "for a second traversal, or --video FILE with --set Frame_mode=1)";
  } else {
    std::vector<std::unique_ptr<openable::FrameSource>> sources =
        openable::OpenFramesToShow(input);
    const std::string key = video ? "Video_path_1 (--video)" : "Images_path (--images)";
    int total = 0;
    for (const auto& s : sources) total += s->Size();
    // One mapping of rows and columns to frames serves every matrix: they must share a shape.
    const cv::Mat1f& first = *matrices.front();
    const bool non_square = first.rows != first.cols;
    for (std::size_t i = 0; i < matrices.size(); ++i) {
      const cv::Mat1f& m = *matrices[i];
      if (m.size() != first.size())
        throw openable::InputError(
            key + ": one set of frames for matrices of different sizes (" +
            openable::Quoted(files.front().path) + " is " + std::to_string(first.rows) + " x " +
            std::to_string(first.cols) + ", " + openable::Quoted(files[i].path) + " is " +
            std::to_string(m.rows) + " x " + std::to_string(m.cols) +
            "); expected matrices of the same frames, or a report per matrix");
      const bool fits = non_square ? sources.size() == 2 && m.rows == sources[1]->Size() &&
                                         m.cols == sources[0]->Size()
                                   : m.rows == total;
      if (!fits)
        throw openable::InputError(
            key + ": " + std::to_string(total) + " frames" +
            (sources.size() == 2 ? " (" + std::to_string(sources[0]->Size()) + " + " +
                                       std::to_string(sources[1]->Size()) + ")"
                                 : std::string()) +
            ", but the matrix " + openable::Quoted(files[i].path) + " is " +
            std::to_string(m.rows) + " x " + std::to_string(m.cols) +
            "; expected the frames the matrix was computed from (a queries x references "
            "matrix needs --images for the references and --images-2 for the queries)");
    }
    report.frames = openable::FramesFromSources(std::move(sources), non_square);
  }
  return openable::EncodeHtmlReport(report);
}

const char* kUsage =
    "Usage: openable_evaluate --matrix M.npy [--label NAME] [--matrix M2.npy --label NAME2 ...]\n"
    "                         --gt-type TYPE [--ground-truth FILE] [options]\n"
    "\n"
    "Evaluates distance matrices saved by Test_OpenABLE (Npy_name, Txt_name) or by any other\n"
    "tool against ground truth, with both protocols of docs/evaluation.md: per-query best\n"
    "match (AUC, R@100P, max F1, R@1/5/10) and the ABLE-P cell protocol (100 thresholds,\n"
    "temporal vicinity, average precision). Prints a table; with --output writes\n"
    "PREFIX.json, PREFIX_pr.png (all matrices in one figure) and, per matrix, the curves as\n"
    "CSV and the ground truth drawn over the matrix.\n"
    "\n"
    "Matrices: .npy (any numeric dtype), text (.txt/.csv), normalised by their maximum (Eq. 5;\n"
    "no change for Test_OpenABLE's M'). A non-square matrix is queries (rows) x references\n"
    "(columns). A square matrix is one sequence (loop closure), unless --reference-frames N\n"
    "says it covers two traversals: N reference frames, then the queries (Images_path_2).\n"
    "\n"
    "Options (each is also --set Key=Value with the Config.txt key in brackets):\n"
    "  --matrix FILE           a matrix to evaluate (repeatable)\n"
    "  --label NAME            legend label of the preceding --matrix (default: its file name)\n"
    "  --reference-frames N    square matrix over two traversals, the first N are the reference\n"
    "  --gt-type TYPE          matrix, pairs, aligned, kitti, tum, positions [Ground_truth_type]\n"
    "  --ground-truth FILE     ground-truth file; for poses of two traversals, the reference's\n"
    "                          [Ground_truth]\n"
    "  --ground-truth-2 FILE   poses of the query traversal [Ground_truth_2]\n"
    "  --gt-base 0|1|-1        pairs are 0- or 1-based; -1 reads the header [Ground_truth_base]\n"
    "  --radius R              poses: same place when closer than R (5) [Ground_truth_radius]\n"
    "  --heading DEG           poses: and headings closer than DEG (-1 off) "
    "[Ground_truth_heading]\n"
    "  --min-gap N             poses, one sequence: frames apart (-1 = Exclusion)\n"
    "                          [Ground_truth_min_gap]\n"
    "  --axes xyz|xz|xy        poses: axes of distance and heading (xyz) [Ground_truth_axes]\n"
    "  --tolerance N           frames of tolerance of a correct match (2) [Tolerance]\n"
    "  --exclusion N           one sequence: candidates N frames back or more (100) [Exclusion]\n"
    "  --vicinity N            ABLE-P temporal vicinity (7) [Vicinity]\n"
    "  --first-frame N         frame number of row 0 in pairs and pose files [Initial_image]\n"
    "  --output PREFIX         write the files [Evaluation_name]\n"
    "  --report FILE.html      one self-contained HTML page: settings, figures, PR figure, the\n"
    "                          matrix with the ground truth, and the worst cases [Report_name];\n"
    "                          their frames are shown when given by --images (and --images-2)\n"
    "                          or --video, else only named [Report_examples: how many]\n"
    "  --images DIR            the frames of the matrix (reference, or only, traversal)\n"
    "                          [Images_path]\n"
    "  --images-2 DIR          the frames of the query traversal [Images_path_2]\n"
    "  --video FILE            the frames as one video [Video_path_1; with Frame_mode 1]\n"
    "  --config FILE           take the keys above from a Config.txt first\n"
    "  --set Key=Value         any evaluation key of Config.txt\n"
    "  --quiet                 print only errors and the list of files written\n"
    "  --json                  print the evaluation as one JSON object on stdout (for scripts)\n"
    "  --help, --version\n"
    "\n"
    "Example (KITTI 00, loops within 5 m seen in the same direction):\n"
    "  openable_evaluate --matrix kitti.npy --gt-type kitti --ground-truth poses/00.txt \\\n"
    "      --axes xz --heading 45 --exclusion 100 --tolerance 3 --output results/kitti\n"
    "\n"
    "Exit status: 0 success, 1 bad input (one line on stderr), 2 bad command line, 3 bug.\n";

}  // namespace

int main(int argc, char** argv) {
  openable::InstallInterruptCleanup("openable_evaluate");  // signals remove the temporaries
  // One process: started by mpirun with several, process 0 says so and every process stops.
  if (const openable::Cluster& cluster = openable::Cluster::Get(); cluster.LaunchSize() > 1) {
    if (cluster.LaunchRank() == 0)
      std::cerr << "openable_evaluate: error: openable_evaluate runs as one process, but mpirun "
                   "started "
                << cluster.LaunchSize()
                << "; expected one (Test_OpenABLE spreads a run over processes)\n";
    return openable::kExitInputError;
  }
  std::vector<openable::MatrixFile> matrices;
  std::vector<std::string> overrides;
  std::string config_path;
  int reference_frames = 0;
  bool quiet = false, json = false;
  auto value_of = [&](int& i, const std::string& flag) -> std::string {
    if (i + 1 >= argc) throw std::invalid_argument(flag + " needs a value");
    return argv[++i];
  };
  try {
    for (int i = 1; i < argc; ++i) {
      const std::string a = argv[i];
      const auto flag = std::find_if(std::begin(kFlagKeys), std::end(kFlagKeys),
                                     [&](const auto& f) { return a == f.first; });
      if (flag != std::end(kFlagKeys)) {
        overrides.push_back(std::string(flag->second) + "=" + value_of(i, a));
      } else if (a == "--help" || a == "-h" || a == "--version") {
        std::cout << (a == "--version" ? "OpenABLE " + std::string(openable::kVersion) + "\n"
                                       : std::string(kUsage));
        return 0;
      } else if (a == "--matrix") {
        matrices.push_back({value_of(i, a), ""});
      } else if (a == "--label") {
        if (matrices.empty()) throw std::invalid_argument("--label must follow a --matrix");
        matrices.back().label = value_of(i, a);
      } else if (a == "--reference-frames") {
        const std::string v = value_of(i, a);
        std::size_t used = 0;
        try {
          reference_frames = std::stoi(v, &used);
        } catch (const std::exception&) {
          used = 0;
        }
        if (used != v.size() || reference_frames < 1)
          throw std::invalid_argument("--reference-frames: \"" + v +
                                      "\" is not valid; expected a number of frames >= 1");
      } else if (a == "--config") {
        config_path = value_of(i, a);
      } else if (a == "--set") {
        overrides.push_back(value_of(i, a));
      } else if (a == "--quiet" || a == "-q") {
        quiet = true;
      } else if (a == "--json") {
        json = true;
      } else {
        throw std::invalid_argument("unknown option \"" + a + "\"");
      }
    }
    if (matrices.empty()) throw std::invalid_argument("no --matrix given");
  } catch (const std::invalid_argument& e) {
    std::cerr << "openable_evaluate: " << e.what() << " (see --help)\n";
    return openable::kExitUsageError;
  }

  return openable::RunProgram("openable_evaluate", [&] {
    openable::Config config =
        config_path.empty() ? openable::Config() : openable::LoadConfig(config_path);
    for (const auto& o : overrides) openable::ApplyOverride(config, o);
    if (!openable::EvaluationRequested(config))
      throw openable::InputError(
          "Ground_truth_type: not set; expected --gt-type matrix, pairs, aligned, kitti, tum or "
          "positions");
    openable::CheckEvaluationConfig(config);
    openable::CheckOutputPrefix("Evaluation_name", config.evaluation.name);
    openable::Evaluation evaluation;
    evaluation.settings = openable::EvaluationSettingsFrom(config);
    const std::vector<cv::Mat1f> loaded =
        openable::EvaluateMatrixFiles(evaluation, matrices, reference_frames);
    if (!quiet && !json)
      std::cout << openable::FormatEvaluationTable(evaluation.settings, evaluation.runs);
    openable::OutputBatch batch;
    std::vector<const cv::Mat1f*> pointers;
    for (const auto& m : loaded) pointers.push_back(&m);
    if (!config.evaluation.name.empty())
      openable::StageEvaluation(batch, "Evaluation_name", config.evaluation.name, evaluation,
                                pointers);
    if (!config.evaluation.report_name.empty())
      batch.Stage("Report_name", config.evaluation.report_name,
                  EncodeReport(config, evaluation, pointers, matrices));
    const std::vector<std::string> paths = batch.Paths();
    batch.Commit();
    if (json) {
      std::cout << openable::ProgramJson(
          "openable_evaluate",
          {{"evaluation", openable::EncodeEvaluationJson(evaluation.settings, evaluation.runs,
                                                         openable::kVersion)}},
          paths);
      return 0;
    }
    if (paths.empty()) return 0;
    std::cout << "Wrote:\n";
    for (const auto& p : paths) std::cout << "  " << p << "\n";
    return 0;
  });
}
