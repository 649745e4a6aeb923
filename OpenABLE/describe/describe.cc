#include "OpenABLE/describe/describe.h"

#include <algorithm>
#include <mutex>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <stdexcept>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/module_loader.h"
#include "OpenABLE/base/strings.h"
#include "OpenABLE/base/threading.h"
#include "OpenABLE/image/preprocess.h"
#include "OpenABLE/io/module_api.h"

namespace openable {

namespace {

// Frame `i` of a traversal as a describer of `kind` takes it (0: grey, or Eq. 6, then side-window
// fusion; 1: grey + disparity; 2: colour, BGR), after the noise of robustness studies.
cv::Mat ConvertFrame(const cv::Mat& frame, int kind, int i, const DescribeOptions& options) {
  const NoiseOptions& noise = options.preprocess.noise;
  const cv::Mat input =
      noise.Any() ? AddNoise(frame, noise,
                             NoiseState(noise.seed, options.noise_stream, options.share_first + i))
                  : frame;
  if (kind == 1) return ToGrayDisparity8(input);
  if (kind == 2) return ToColour8(input);
  cv::Mat image = options.preprocess.illumination_invariance
                      ? cv::Mat(IlluminationInvariant(input, options.preprocess.Alpha()))
                      : cv::Mat(ToGray8(input));
  const std::vector<int> radii = options.preprocess.SideWindowRadii();
  if (!radii.empty()) image = SideWindowFusion(image, radii);
  return image;
}

int KindOf(const FrameDescriber& describer) {
  return describer.Channels() == 2 ? 1 : describer.Channels() == 3 ? 2 : 0;
}

}  // namespace

int LearnFromSource(const FrameSource& source, const FrameDescriber& describer,
                    const DescribeOptions& options, int frames) {
  const int n = source.Size();
  const int count = std::min(n, std::max(1, frames));
  std::vector<cv::Mat> images(static_cast<size_t>(count));
  // Frames evenly spread over the traversal, read and converted in parallel when the source
  // allows it (not a video); an unreadable one is left out here (describing reports it).
  const int threads = source.ParallelReads() ? EffectiveThreads(options.threads) : 1;
  ParallelFor(count, threads, [&](int j) {
    const int i = static_cast<int>((2LL * j + 1) * n / (2LL * count));
    try {
      const cv::Mat image = ConvertFrame(source.Read(i), KindOf(describer), i, options);
      const cv::Size need = describer.MinimumFrame();
      if (image.cols >= need.width && image.rows >= need.height)
        images[static_cast<size_t>(j)] = image;
    } catch (const InputError&) {
    }
  });
  images.erase(
      std::remove_if(images.begin(), images.end(), [](const cv::Mat& m) { return m.empty(); }),
      images.end());
  describer.Learn(images);
  return static_cast<int>(images.size());
}

DescribedSequence DescribeSequence(const FrameSource& source, const FrameDescriber& describer,
                                   const DescribeOptions& options,
                                   const std::function<void(int, int)>& progress) {
  return std::move(
      DescribeSequences(source, {&describer}, {options.cache}, options, progress).front());
}

std::vector<DescribedSequence> DescribeSequences(
    const FrameSource& source, const std::vector<const FrameDescriber*>& describers,
    const std::vector<RowCache*>& caches, const DescribeOptions& options,
    const std::function<void(int, int)>& progress) {
  if (describers.empty() || caches.size() != describers.size())
    throw std::logic_error("DescribeSequences: one cache (or nullptr) per descriptor");
  const int n = source.Size();
  const int kinds = static_cast<int>(describers.size());
  const std::string prefix = options.key.empty() ? "" : options.key + ": ";
  std::vector<cv::Mat> rows;
  for (const FrameDescriber* d : describers)
    rows.emplace_back(n, d->RowWidth(), d->RowType(), cv::Scalar(0));
  std::vector<char> ok(n, 0);
  std::vector<std::string> read_errors(n);
  const bool use_caches = !options.show_images;

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

  // Records the first frame size; a frame of another size is a failure (false).
  auto check_size = [&](int i, cv::Size size) {
    std::lock_guard<std::mutex> lock(mutex);
    if (!first_size) first_size = size, first_size_frame = source.FrameName(i);
    if (size != *first_size) {
      const std::string message = "image \"" + source.FrameName(i) + "\" is " + SizeText(size) +
                                  " but \"" + first_size_frame + "\" is " + SizeText(*first_size) +
                                  " (expected the frames of one sequence to have one size)";
      if (i < error_index) error_index = i, error_message = message;
      return false;
    }
    return true;
  };
  // Describes frame i once it is in memory with the descriptors whose rows are not cached
  // (`needed`); records a size mismatch as a failure. The frame is converted once for all of
  // them: grey (or Eq. 6) for every descriptor, grey + disparity (a stereo frame) for D-LDB.
  // Descriptors that run on batches (a network): each frame's patches wait in `pending` until
  // `flush` describes those of many frames in one call.
  bool any_batched = false;
  for (const FrameDescriber* d : describers) any_batched = any_batched || d->Batched();
  std::vector<std::vector<std::vector<cv::Mat>>> pending(
      static_cast<size_t>(kinds), std::vector<std::vector<cv::Mat>>(any_batched ? n : 0));
  std::vector<cv::Size> read_sizes(any_batched ? n : 0);
  auto describe = [&](int i, const cv::Mat& frame, const std::vector<char>& needed) {
    if (!check_size(i, frame.size())) return;
    // [0]: grey or Eq. 6, then side-window fusion; [1]: grey + disparity; [2]: colour (BGR)
    cv::Mat images[3];
    for (int k = 0; k < kinds; ++k) {
      if (!needed[static_cast<size_t>(k)]) continue;
      const FrameDescriber& describer = *describers[static_cast<size_t>(k)];
      const int kind = KindOf(describer);
      cv::Mat& image = images[kind];
      if (image.empty()) {
        try {
          image = ConvertFrame(frame, kind, i, options);
        } catch (const InputError& e) {
          fail(i, "image " + Quoted(source.FrameName(i)) + ": " + e.what());
          return;
        }
      }
      const cv::Size need = describer.MinimumFrame();
      if (image.cols < need.width || image.rows < need.height) {
        fail(i, "image " + Quoted(source.FrameName(i)) + " is " + SizeText(image.size()) +
                    "; the grid and sub-panoramas need at least " + SizeText(need) +
                    " (Grid_x x Panoramas by Grid_y pixels)");
        return;
      }
      if (describer.Batched()) {
        pending[static_cast<size_t>(k)][static_cast<size_t>(i)] = describer.Patches(image);
        read_sizes[static_cast<size_t>(i)] = frame.size();
        continue;
      }
      describer.Describe(image, rows[static_cast<size_t>(k)].row(i));
      if (caches[static_cast<size_t>(k)] != nullptr && use_caches)
        caches[static_cast<size_t>(k)]->Store(source, i, rows[static_cast<size_t>(k)].row(i),
                                              frame.size());
    }
    ok[i] = 1;
  };
  // The waiting patches of frames [first, last) described, batch by batch, then cached.
  auto flush = [&](int first, int last) {
    for (int k = 0; k < kinds; ++k) {
      const FrameDescriber& describer = *describers[static_cast<size_t>(k)];
      if (!describer.Batched()) continue;
      std::vector<int> frames;
      std::vector<cv::Mat> patches;
      for (int i = first; i < last; ++i) {
        std::vector<cv::Mat>& p = pending[static_cast<size_t>(k)][static_cast<size_t>(i)];
        if (p.empty()) continue;
        frames.push_back(i);
        for (cv::Mat& m : p) patches.push_back(std::move(m));
        p.clear();
      }
      if (frames.empty()) continue;
      cv::Mat described(static_cast<int>(frames.size()), describer.RowWidth(), describer.RowType());
      describer.DescribePatches(patches, described);
      for (size_t r = 0; r < frames.size(); ++r) {
        const int i = frames[r];
        described.row(static_cast<int>(r)).copyTo(rows[static_cast<size_t>(k)].row(i));
        if (caches[static_cast<size_t>(k)] != nullptr && use_caches)
          caches[static_cast<size_t>(k)]->Store(source, i, rows[static_cast<size_t>(k)].row(i),
                                                read_sizes[static_cast<size_t>(i)]);
      }
    }
  };
  const std::vector<char> all_needed(static_cast<size_t>(kinds), 1);
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
        describe(frames[k].first, frames[k].second, all_needed);
        report();
      });
      if (any_batched && !stopped()) flush(start, std::min(n, start + batch));
    }
  } else {
    // With a network, frames in chunks: each chunk's frames read and cut in parallel, then
    // their patches described in batches (the network uses every core itself).
    int chunk = n;
    if (any_batched) {
      chunk = std::max(1, threads * 8);
      for (const FrameDescriber* d : describers)
        if (d->Batched()) chunk = std::max(chunk, d->PreferredBatchOfFrames());
    }
    for (int start = 0; start < n && !stopped(); start += chunk) {
      const int end = std::min(n, start + chunk);
      ParallelFor(end - start, threads, [&](int j) {
        const int i = start + j;
        if (stopped()) return;
        // Rows of the caches first; the frame is read only when a descriptor still needs it.
        std::vector<char> needed(static_cast<size_t>(kinds), 1);
        bool any_needed = false, sizes_agree = true;
        for (int k = 0; k < kinds; ++k) {
          RowCache* cache = caches[static_cast<size_t>(k)];
          cv::Size cached_size;
          if (cache != nullptr && use_caches &&
              cache->Lookup(source, i, rows[static_cast<size_t>(k)].row(i), &cached_size)) {
            needed[static_cast<size_t>(k)] = 0;
            sizes_agree &= check_size(i, cached_size);
          } else {
            any_needed = true;
          }
        }
        if (!sizes_agree) {
          report();
          return;
        }
        if (!any_needed) {
          ok[i] = 1;
        } else if (auto f = read(i)) {
          describe(i, *f, needed);
        }
        report();
      });
      if (any_batched && !stopped()) flush(start, end);
    }
  }

  if (error_index < n) throw InputError(prefix + error_message);

  DescribedSequence kept;
  for (int i = 0; i < n; ++i) {
    if (ok[i]) {
      kept.kept.push_back(i);
    } else {
      kept.skipped.push_back(read_errors[i]);
    }
  }
  if (kept.kept.empty() && !options.share)
    throw InputError(prefix + "none of the " + std::to_string(n) +
                     " frames could be read (first failure: " +
                     (kept.skipped.empty() ? std::string("none") : kept.skipped.front()) + ")");
  kept.frame_size = first_size.value_or(cv::Size());
  std::vector<DescribedSequence> out(static_cast<size_t>(kinds), kept);
  for (int k = 0; k < kinds; ++k) {
    const cv::Mat& all = rows[static_cast<size_t>(k)];
    cv::Mat& into = out[static_cast<size_t>(k)].rows;
    if (kept.kept.size() == static_cast<size_t>(n)) {
      into = all;
    } else {
      into.create(static_cast<int>(kept.kept.size()), all.cols, all.type());
      for (size_t r = 0; r < kept.kept.size(); ++r) all.row(kept.kept[r]).copyTo(into.row(r));
    }
  }
  return out;
}

}  // namespace openable
