// Test_OpenABLE: Config.txt in, normalised distance matrix out. A thin layer over the library.
#include <chrono>
#include <cstdio>
#include <memory>
#include <cstring>
#include <iostream>
#include <string>
#include <vector>

#include <malloc.h>

#include <opencv2/core/utils/logger.hpp>

#include "OpenABLE/OpenABLE.h"
#include "config/command_line.h"

namespace {

constexpr int kInputError = 1;   // bad configuration or data: one line on stderr
constexpr int kInternalError = 3;

const char* kUsage =
    "Usage: Test_OpenABLE [Config.txt] [--set Key=Value ...] [options]\n"
    "\n"
    "Computes the normalised distance matrix (Eq. 5 of the OpenABLE paper) between every pair\n"
    "of frames of an image folder, a video, or two traversals of a route, and writes it as\n"
    "text, .npy and colour PNG (see Txt_name, Npy_name, Png_name).\n"
    "\n"
    "Options:\n"
    "  --set Key=Value   override one key of Config.txt (repeatable; also without a file)\n"
    "  --quiet           no progress lines (errors and the final report are still printed)\n"
    "  --print-config    print the configuration in effect (Config.txt format) and exit\n"
    "  --help-markdown   print the key reference as Markdown (docs/configuration.md)\n"
    "  --version         print the version\n"
    "  -h, --help        this help\n"
    "\n"
    "Exit status: 0 success, 1 bad configuration or input data (or an output that cannot be\n"
    "written: no output of the run is kept), 2 bad command line, 3 internal error,\n"
    "128 + signal when interrupted (130 SIGINT, 143 SIGTERM, 129 SIGHUP; temporaries removed).\n"
    "\n"
    "Example:\n"
    "  Test_OpenABLE config/Config.txt --set Image_sequences=20 --set Image_descriptor=HOG\n"
    "\n"
    "Configuration keys (Config.txt: one 'Key: value' per line, '#' comments):\n";

std::string Fixed(double v, int decimals) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

void PrintReport(const openable::Config& c, const openable::RunResult& r,
                 const openable::Evaluation* evaluation, const std::vector<std::string>& written) {
  std::cout << "OpenABLE " << openable::kVersion << ": " << r.descriptor << " ("
            << r.row_width << (r.binary ? " bytes, Hamming" : " floats, L2") << "), "
            << (c.description_type == 0 ? "global " : "grid ")
            << (c.description_type == 0
                    ? std::to_string(c.patch_size) + "x" + std::to_string(c.patch_size)
                    : std::to_string(c.grid_x) + "x" + std::to_string(c.grid_y) + " cells of " +
                          std::to_string(c.patch_size) + "x" + std::to_string(c.patch_size))
            << ", sequence length " << c.image_sequences << "\n";
  if (!r.camera.empty()) std::cout << "  camera: " << r.camera << "\n";
  if (!r.cache.empty()) std::cout << "  descriptor cache: " << r.cache << "\n";
  for (const auto& t : r.traversals) {
    std::cout << "  " << t.key << ": " << t.frames << " frames of " << t.frame_size.width << "x"
              << t.frame_size.height << " from \"" << t.path << "\" (rows " << t.first_row
              << "-" << t.first_row + t.frames - 1 << ")\n";
    for (const auto& s : t.skipped) std::cout << "    skipped: " << s << "\n";
  }
  const auto& tm = r.timings;
  std::cout << "  mode: " << r.mode_reason << "\n";
  if (r.bounded) {
    std::cout << "  bounded: " << r.matches.size() << " matches kept (Best_matches "
              << c.best_matches << ", Band_width " << c.band_width << "), max distance "
              << r.max_distance << " (Eq. 5 divisor over the cells computed)";
  } else {
    std::cout << "  matrix: " << r.normalized.rows << "x" << r.normalized.cols
              << ", max distance " << r.max_distance << " (Eq. 5 divisor)";
  }
  if (!r.thresholded.empty())
    std::cout << ", threshold " << c.threshold << ": "
              << r.thresholded.total() - static_cast<size_t>(cv::countNonZero(r.thresholded))
              << " cells below";
  std::cout << "\nTimings (wall clock):\n"
            << "  total            " << Fixed(tm.total_seconds, 3) << " s\n"
            << "  description      " << Fixed(tm.describe_seconds, 3) << " s  ("
            << Fixed(tm.frames ? 1e3 * tm.describe_seconds / tm.frames : 0, 3)
            << " ms per image, " << tm.frames << " images, reading included)\n"
            << "  matching         " << Fixed(tm.match_seconds, 3) << " s  ("
            << Fixed(tm.pairs ? 1e9 * tm.match_seconds / static_cast<double>(tm.pairs) : 0, 1)
            << " ns per pair, " << tm.pairs << " pairs)\n"
            << "  sequences+norm.  " << Fixed(tm.sequence_seconds, 3) << " s\n";
  if (evaluation != nullptr)
    std::cout << "  evaluation       " << Fixed(tm.evaluate_seconds, 3) << " s\n";
  std::cout << "  export           " << Fixed(tm.export_seconds, 3) << " s\n";
  if (evaluation != nullptr)
    std::cout << openable::FormatEvaluationTable(evaluation->settings, evaluation->runs);
  if (written.empty()) {
    std::cout << "No output file was asked for (set Txt_name, Npy_name or Png_name).\n";
  } else {
    std::cout << "Wrote:\n";
    for (const auto& p : written) std::cout << "  " << p << "\n";
  }
}

}  // namespace

int main(int argc, char** argv) {
  // OpenCV's video back ends print [ WARN ] lines of their own when a file cannot be opened;
  // the library already reports that as one InputError line, so keep only OpenCV errors.
  cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_ERROR);
  // Every frame passes through buffers of several MB (a 960x540 colour frame as float is
  // 6 MB). glibc serves such blocks with mmap and returns them at free, so each frame paid
  // for fresh zeroed pages: 63% of a Gardens Point run was page faults in the kernel. Keeping
  // blocks up to 256 MB on the heap lets them be reused (Gardens Point 3.0 s -> 1.1 s).
  mallopt(M_MMAP_THRESHOLD, 256 << 20);
  mallopt(M_TRIM_THRESHOLD, 1 << 30);
  // SIGINT/SIGTERM/SIGHUP remove the staged temporaries and exit with 128 + signal.
  openable::InstallInterruptCleanup("Test_OpenABLE");
  openable::CommandLine cl;
  const std::string usage_error = openable::ParseCommandLine(argc, argv, "Test_OpenABLE", cl);
  const int answered = openable::AnswerWithoutRunning(cl, usage_error, kUsage, "OpenABLE " + std::string(openable::kVersion));
  if (answered >= 0) return answered;
  const bool quiet = cl.quiet;
  try {
    openable::Config config = openable::ConfigOf(cl);
    if (cl.print_config) {
      std::cout << openable::FormatConfig(config);
      return 0;
    }
    openable::ProgressReporter progress(std::cerr, !quiet, openable::IsTerminal(2));
    if (config.show_images == 1 && std::getenv("DISPLAY") == nullptr &&
        std::getenv("WAYLAND_DISPLAY") == nullptr)
      std::cerr << "Test_OpenABLE: warning: Show_images is 1 but there is no display "
                   "(DISPLAY is not set); frames are not shown\n";
    // Evaluation settings are checked before the long part of the run.
    std::unique_ptr<openable::Evaluation> evaluation;
    if (openable::EvaluationRequested(config)) {
      evaluation = std::make_unique<openable::Evaluation>();
      evaluation->settings = openable::EvaluationSettingsFrom(config);
    }
    openable::RunResult result = openable::ComputeRun(config, progress);
    for (const std::string& w : result.warnings) std::cerr << "Test_OpenABLE: warning: " << w << "\n";
    for (const std::string& note : result.notes) std::cerr << "Test_OpenABLE: note: " << note << "\n";
    if (evaluation && result.bounded) {
      std::cerr << "Test_OpenABLE: note: Ground_truth_type: no evaluation in bounded mode (the "
                   "protocols need the dense matrix); evaluate Matches_name yourself or use "
                   "Matrix_mode 1\n";
      evaluation.reset();
    }
    if (evaluation) {
      const auto start = std::chrono::steady_clock::now();
      openable::EvaluateMatrix(*evaluation, result.normalized, openable::LayoutOf(result),
                               openable::RunLabel(config), "Test_OpenABLE run");
      result.timings.evaluate_seconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      result.timings.total_seconds += result.timings.evaluate_seconds;
    }
    const std::vector<std::string> written =
        openable::WriteOutputs(config, result, evaluation.get());
    PrintReport(config, result, evaluation.get(), written);
    return 0;
  } catch (const openable::InputError& e) {
    std::cerr << "Test_OpenABLE: error: " << e.what() << "\n";
    return kInputError;
  } catch (const std::exception& e) {
    std::cerr << "Test_OpenABLE: internal error (please report): " << e.what() << "\n";
    return kInternalError;
  }
}
