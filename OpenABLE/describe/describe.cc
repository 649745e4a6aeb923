#include "OpenABLE/describe/describe.h"

#include <algorithm>
#include <mutex>
#include <optional>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/module_loader.h"
#include "OpenABLE/base/threading.h"
#include "OpenABLE/image/preprocess.h"
#include "OpenABLE/io/module_api.h"

namespace openable {

namespace {

std::string SizeText(const cv::Size& s) {
  return std::to_string(s.width) + "x" + std::to_string(s.height);
}

}  // namespace

DescribedSequence DescribeSequence(const FrameSource& source, const FrameDescriber& describer,
                                   const DescribeOptions& options,
                                   const std::function<void(int, int)>& progress) {
  const int n = source.Size();
  const std::string prefix = options.key.empty() ? "" : options.key + ": ";
  cv::Mat rows(n, describer.RowWidth(), describer.RowType(), cv::Scalar(0));
  std::vector<char> ok(n, 0);
  std::vector<std::string> read_errors(n);

  std::mutex mutex;  // guards the first size, the first error and progress
  std::optional<cv::Size> first_size;
  std::string first_size_frame;
  int error_index = n;  // lowest index whose failure stops the run
  std::string error_message;
  int done = 0;
  auto fail = [&](int i, const std::string& message) {
    std::lock_guard<std::mutex> lock(mutex);
    if (i < error_index) error_index = i, error_message = message;
  };

  // Describes frame i once it is in memory; records a size mismatch as a failure.
  // Records the first frame size; a frame of another size is a failure (false).
  auto check_size = [&](int i, cv::Size size) {
    std::lock_guard<std::mutex> lock(mutex);
    if (!first_size) first_size = size, first_size_frame = source.FrameName(i);
    if (size != *first_size) {
      const std::string message = "image \"" + source.FrameName(i) + "\" is " +
                                  SizeText(size) + " but \"" + first_size_frame +
                                  "\" is " + SizeText(*first_size) +
                                  " (expected the frames of one sequence to have one size)";
      if (i < error_index) error_index = i, error_message = message;
      return false;
    }
    return true;
  };
  const NoiseOptions& noise = options.preprocess.noise;
  const bool illumination_invariance = options.preprocess.illumination_invariance;
  const double alpha = options.preprocess.Alpha();
  const std::vector<int> side_window_radii = options.preprocess.SideWindowRadii();
  auto describe = [&](int i, const cv::Mat& frame) {
    if (!check_size(i, frame.size())) return;
    // Grey (or Eq. 6) for every descriptor; grey + disparity (a stereo frame) for D-LDB.
    // Noise (robustness studies) on the frame as read, before any conversion.
    const cv::Mat input =
        noise.Any() ? AddNoise(frame, noise,
                               NoiseState(noise.seed, options.noise_stream,
                                          options.share_first + i))
                    : frame;
    cv::Mat image;
    try {
      image = describer.Channels() == 2          ? ToGrayDisparity8(input)
              : illumination_invariance ? cv::Mat(IlluminationInvariant(input, alpha))
                                                : cv::Mat(ToGray8(input));
    } catch (const InputError& e) {
      fail(i, "image " + Quoted(source.FrameName(i)) + ": " + e.what());
      return;
    }
    const cv::Size need = describer.MinimumFrame();
    if (image.cols < need.width || image.rows < need.height) {
      fail(i, "image " + Quoted(source.FrameName(i)) + " is " + SizeText(image.size()) +
                  "; the grid and sub-panoramas need at least " + SizeText(need) +
                  " (Grid_x x Panoramas by Grid_y pixels)");
      return;
    }
    if (!side_window_radii.empty()) image = SideWindowFusion(image, side_window_radii);
    describer.Describe(image, rows.row(i));
    ok[i] = 1;
    if (options.cache != nullptr && !options.show_images)
      options.cache->Store(source, i, rows.row(i), frame.size());
  };
  auto report = [&]() {
    std::lock_guard<std::mutex> lock(mutex);
    ++done;
    if (progress) progress(done, n);
  };
  auto read = [&](int i) -> std::optional<cv::Mat> {
    try {
      return source.Read(i);
    } catch (const InputError& e) {
      if (options.skip_unreadable) {
        read_errors[i] = e.what();
      } else {
        fail(i, e.what());
      }
      return std::nullopt;
    }
  };
  auto stopped = [&]() {
    std::lock_guard<std::mutex> lock(mutex);
    return error_index < n;
  };

  const int threads = options.show_images ? 1 : EffectiveThreads(options.threads);
  if (options.show_images || !source.ParallelReads()) {
    // One reader in order; description of a batch in parallel.
    const int batch = std::max(1, threads * 8);
    std::vector<std::pair<int, cv::Mat>> frames;
    for (int start = 0; start < n && !stopped(); start += batch) {
      frames.clear();
      for (int i = start; i < std::min(n, start + batch); ++i) {
        if (auto f = read(i)) {
          if (options.show_images) {
            // A stereo frame shows its rectified left image (channel 0).
            cv::Mat shown = *f;
            if (shown.channels() == 2) cv::extractChannel(*f, shown, 0);
            reinterpret_cast<OpenableGuiShow>(ModuleSymbol("gui", "openable_gui_show"))(shown);
          }
          frames.emplace_back(i, std::move(*f));
        } else {
          report();
        }
      }
      ParallelFor(static_cast<int>(frames.size()), threads, [&](int k) {
        describe(frames[k].first, frames[k].second);
        report();
      });
    }
  } else {
    ParallelFor(n, threads, [&](int i) {
      if (stopped()) return;
      cv::Size cached_size;
      if (options.cache != nullptr && options.cache->Lookup(source, i, rows.row(i), &cached_size)) {
        if (check_size(i, cached_size)) ok[i] = 1;
      } else if (auto f = read(i)) {
        describe(i, *f);
      }
      report();
    });
  }

  if (error_index < n) throw InputError(prefix + error_message);

  DescribedSequence out;
  for (int i = 0; i < n; ++i) {
    if (ok[i]) {
      out.kept.push_back(i);
    } else {
      out.skipped.push_back(read_errors[i]);
    }
  }
  if (out.kept.empty() && !options.share)
    throw InputError(prefix + "none of the " + std::to_string(n) +
                     " frames could be read (first failure: " +
                     (out.skipped.empty() ? std::string("none") : out.skipped.front()) + ")");
  if (out.kept.size() == static_cast<size_t>(n)) {
    out.rows = rows;
  } else {
    out.rows.create(static_cast<int>(out.kept.size()), rows.cols, rows.type());
    for (size_t k = 0; k < out.kept.size(); ++k) rows.row(out.kept[k]).copyTo(out.rows.row(k));
  }
  out.frame_size = first_size.value_or(cv::Size());
  return out;
}

}  // namespace openable
