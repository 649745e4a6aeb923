// openable_online: loop candidates frame by frame, as a SLAM system would ask for them.
//
// A program outside the OpenABLE build: it finds the installed library with
// find_package(OpenABLE) (CMakeLists.txt beside this file, docs/install.md), includes only
// <OpenABLE/OpenABLE.h> and feeds the images of a folder, in natural order, to
// openable::OnlineDetector one at a time.
#include <OpenABLE/OpenABLE.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

namespace {

const char* kUsage =
    "Usage: openable_online IMAGE_FOLDER [options]\n"
    "\n"
    "Feeds the images of IMAGE_FOLDER (PNG, JPEG, ... in natural order of their names) one by\n"
    "one to openable::OnlineDetector and prints, for each frame that has some, the accepted\n"
    "loop candidates (earlier frame and normalised distance); at the end the number of frames,\n"
    "of accepted candidates, and the mean and 99th percentile of the time of AddFrame.\n"
    "\n"
    "Options (defaults: those of openable::OnlineOptions):\n"
    "  --exclusion N         candidates of frame q are frames <= q - N\n"
    "  --sequence-length L   frames summed along the diagonal\n"
    "  --threshold T         accept a candidate whose normalised distance is <= T\n"
    "  --max-frames N        use only the first N images\n"
    "  -h, --help            this help\n"
    "\n"
    "Exit status: 0 success, 1 unusable folder, image or option value, 2 bad command line,\n"
    "3 internal error.\n";

int Usage(const std::string& problem) {
  std::cerr << "openable_online: " << problem << "\n\n" << kUsage;
  return 2;
}

// Parses the whole of `text` as a number; false when it is not one.
bool ParseInt(const std::string& text, int& value) {
  char* end = nullptr;
  const long v = std::strtol(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0' || v < -1000000000L || v > 1000000000L) return false;
  value = static_cast<int>(v);
  return true;
}
bool ParseDouble(const std::string& text, double& value) {
  char* end = nullptr;
  value = std::strtod(text.c_str(), &end);
  return !text.empty() && *end == '\0';
}

std::string Milliseconds(double seconds) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3f ms", seconds * 1e3);
  return buf;
}

}  // namespace

int main(int argc, char** argv) {
  std::string folder;
  openable::OnlineOptions options;
  int max_frames = -1;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "-h" || arg == "--help") {
      std::cout << kUsage;
      return 0;
    }
    const bool takes_value = arg == "--exclusion" || arg == "--sequence-length" ||
                             arg == "--threshold" || arg == "--max-frames";
    if (takes_value) {
      if (i + 1 == argc) return Usage(arg + " needs a value");
      const std::string value = argv[++i];
      bool ok = true;
      if (arg == "--exclusion") ok = ParseInt(value, options.exclusion);
      if (arg == "--sequence-length") ok = ParseInt(value, options.sequence_length);
      if (arg == "--threshold") ok = ParseDouble(value, options.threshold);
      if (arg == "--max-frames") ok = ParseInt(value, max_frames) && max_frames >= 1;
      if (!ok) return Usage("bad value \"" + value + "\" for " + arg);
    } else if (arg.rfind("-", 0) == 0) {
      return Usage("unknown option " + arg);
    } else if (folder.empty()) {
      folder = arg;
    } else {
      return Usage("more than one image folder (" + folder + ", " + arg + ")");
    }
  }
  if (folder.empty()) return Usage("no image folder given");

  try {
    // The library's image folder: natural order ("img2" before "img10"), every supported
    // extension, frames as CV_32FC1/CV_32FC3 in [0, 1], which AddFrame takes as they are.
    const std::unique_ptr<openable::FrameSource> frames =
        openable::OpenImageFolder(folder, "", 0, max_frames);
    openable::OnlineDetector detector(options);  // checks the options (InputError)

    std::vector<double> latencies;
    latencies.reserve(static_cast<std::size_t>(frames->Size()));
    int accepted = 0, frames_with_loops = 0;
    for (int i = 0; i < frames->Size(); ++i) {
      const cv::Mat image = frames->Read(i);
      const auto start = std::chrono::steady_clock::now();
      const openable::OnlineResult result = detector.AddFrame(image);
      latencies.push_back(
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());

      std::string line;
      for (const openable::LoopCandidate& c : result.candidates) {
        if (!c.accepted) continue;
        char buf[64];
        std::snprintf(buf, sizeof buf, " %d (%.4f)", c.frame, c.normalized);
        line += buf;
        ++accepted;
      }
      if (!line.empty()) {
        ++frames_with_loops;
        std::cout << "frame " << result.frame << ":" << line << "\n";
      }
    }

    std::cout << "frames: " << latencies.size() << "\n"
              << "loops: " << accepted << " accepted candidates in " << frames_with_loops
              << " frames\n";
    if (!latencies.empty()) {
      double sum = 0;
      for (const double t : latencies) sum += t;
      std::vector<double> sorted = latencies;
      std::sort(sorted.begin(), sorted.end());
      // Nearest rank: the smallest latency that at least 99% of the frames do not exceed.
      const std::size_t rank = (99 * sorted.size() + 99) / 100;
      std::cout << "latency per frame (AddFrame): mean "
                << Milliseconds(sum / static_cast<double>(sorted.size())) << ", 99th percentile "
                << Milliseconds(sorted[rank - 1]) << "\n";
    }
    return 0;
  } catch (const openable::InputError& e) {
    std::cerr << "openable_online: " << e.what() << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "openable_online: internal error: " << e.what() << "\n";
    return 3;
  }
}
