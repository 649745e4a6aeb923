#include "descriptors/densevlad.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/hash.h"

namespace openable {

const std::vector<double>& DenseVladDescriptor::Scales() {
  // OpenCV's SIFT spreads its 4 x 4 bins over 6 x kSize pixels: windows of 12 pixels of the
  // shrunk frame, and of 18 and 24 pixels at the coarser scales, about Torii et al.'s 16 to 40
  // pixels of frames twice as wide. A larger window costs SIFT the square of its side, so the
  // coarser scales describe a smaller image with the same window rather than this one with a
  // larger window (4 times faster, the same regions).
  static const std::vector<double> scales = {1.0, 2.0 / 3.0, 0.5};
  return scales;
}

DenseVladDescriptor::DenseVladDescriptor(const DescriptorOptions& options) : Descriptor(options) {}

cv::Mat DenseVladDescriptor::DenseRootSift(const cv::Mat& patch) {
  CV_Assert(patch.type() == CV_8UC1 && !patch.empty());
  cv::Mat image = patch;
  if (patch.cols > kWidth) {
    const int height = std::max(
        16, static_cast<int>(std::lround(static_cast<double>(patch.rows) * kWidth / patch.cols)));
    cv::resize(patch, image, cv::Size(kWidth, height), 0, 0, cv::INTER_AREA);
  }
  // A SIFT object per call: cheap to build, and calls from several threads share nothing.
  cv::Ptr<cv::SIFT> sift = cv::SIFT::create();
  cv::Mat sift_rows;
  for (const double scale : Scales()) {
    cv::Mat scaled = image;
    if (scale != 1.0)
      cv::resize(image, scaled,
                 cv::Size(std::max(1, static_cast<int>(std::lround(image.cols * scale))),
                          std::max(1, static_cast<int>(std::lround(image.rows * scale)))),
                 0, 0, cv::INTER_AREA);
    std::vector<cv::KeyPoint> keypoints;
    for (int y = kStep / 2; y < scaled.rows; y += kStep)
      for (int x = kStep / 2; x < scaled.cols; x += kStep)
        keypoints.emplace_back(static_cast<float>(x), static_cast<float>(y), kSize);
    if (keypoints.empty()) continue;
    cv::Mat some;
    sift->compute(scaled, keypoints, some);
    sift_rows.push_back(some);
  }
  cv::Mat1f rows;
  sift_rows.convertTo(rows, CV_32F);
  // RootSIFT: L1-normalised, then the square root of each element (whose L2 norm is then 1),
  // so that comparing rows by L2 compares the histograms by the Hellinger kernel.
  for (int r = 0; r < rows.rows; ++r) {
    float* p = rows.ptr<float>(r);
    double l1 = 0;
    for (int c = 0; c < rows.cols; ++c) l1 += std::abs(p[c]);
    const float scale = l1 > 0 ? static_cast<float>(1.0 / l1) : 0.0f;
    for (int c = 0; c < rows.cols; ++c) p[c] = std::sqrt(std::abs(p[c]) * scale);
  }
  return std::move(rows);
}

cv::Mat1f DenseVladDescriptor::Vlad(const cv::Mat1f& local, const cv::Mat1f& centres) {
  const int k = centres.rows, d = centres.cols;
  cv::Mat1f out = cv::Mat1f::zeros(1, k * d);
  if (local.empty()) return out;
  CV_Assert(local.cols == d);
  // Nearest word of each row: the smallest |c|^2 - 2 x.c (|x|^2 is the same for every word).
  cv::Mat1f dots;
  cv::gemm(local, centres, 1.0, cv::noArray(), 0.0, dots, cv::GEMM_2_T);
  std::vector<float> norms(static_cast<size_t>(k));
  for (int j = 0; j < k; ++j)
    norms[static_cast<size_t>(j)] = static_cast<float>(centres.row(j).dot(centres.row(j)));
  float* v = out.ptr<float>(0);
  for (int i = 0; i < local.rows; ++i) {
    const float* s = dots.ptr<float>(i);
    int best = 0;
    float best_value = norms[0] - 2 * s[0];
    for (int j = 1; j < k; ++j) {
      const float value = norms[static_cast<size_t>(j)] - 2 * s[j];
      if (value < best_value) best_value = value, best = j;
    }
    const float* x = local.ptr<float>(i);
    const float* c = centres.ptr<float>(best);
    float* w = v + static_cast<size_t>(best) * static_cast<size_t>(d);
    for (int e = 0; e < d; ++e) w[e] += x[e] - c[e];
  }
  // Intra-normalisation: each word's sum to unit length, so that a few words holding many
  // descriptors (repeated structures, "bursts") do not outweigh the others; then the whole.
  for (int j = 0; j < k; ++j) {
    cv::Mat1f word = out.colRange(j * d, (j + 1) * d);
    const double n = cv::norm(word);
    if (n > 0) word /= n;
  }
  const double n = cv::norm(out);
  if (n > 0) out /= n;
  return out;
}

void DenseVladDescriptor::Learn(const std::vector<cv::Mat>& patches) const {
  std::vector<cv::Mat1f> per_patch(patches.size());
  cv::parallel_for_(cv::Range(0, static_cast<int>(patches.size())), [&](const cv::Range& r) {
    for (int i = r.start; i < r.end; ++i) {
      const cv::Mat1f all = DenseRootSift(patches[static_cast<size_t>(i)]);
      // kLearnPerFrame rows evenly spread over the patch's grid and scales.
      const int kept = std::min(all.rows, kLearnPerFrame);
      cv::Mat1f some(kept, all.cols);
      for (int j = 0; j < kept; ++j)
        all.row(static_cast<int>(static_cast<long long>(j) * all.rows / kept)).copyTo(some.row(j));
      per_patch[static_cast<size_t>(i)] = some;
    }
  });
  cv::Mat1f samples;
  for (const cv::Mat1f& m : per_patch)
    if (!m.empty()) samples.push_back(m);
  if (samples.rows < 4 * kCentres)
    throw InputError("Image_descriptor: DenseVLAD learns " + std::to_string(kCentres) +
                     " visual words from the reference traversal, but its frames gave " +
                     std::to_string(samples.rows) + " local descriptors; expected at least " +
                     std::to_string(4 * kCentres) + " (more or larger frames)");
  // k-means++ draws from OpenCV's random generator of this thread: seeded here (and restored)
  // so that the same frames give the same vocabulary, hence the same rows.
  cv::RNG& rng = cv::theRNG();
  const std::uint64_t saved = rng.state;
  rng.state = 0x44656e7365564c41ULL;
  cv::Mat labels;
  cv::Mat1f centres;
  cv::kmeans(samples, kCentres, labels,
             cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 30, 1e-4), 1,
             cv::KMEANS_PP_CENTERS, centres);
  rng.state = saved;
  centres_ = centres;
  char digest[17];
  std::snprintf(digest, sizeof digest, "%016llx",
                static_cast<unsigned long long>(
                    Fnv1a64(centres_.data, centres_.total() * centres_.elemSize())));
  fingerprint_ = "vocabulary " + std::string(digest);
}

void DenseVladDescriptor::DescribePatch(const cv::Mat& patch, cv::Mat row) const {
  if (centres_.empty())
    throw InputError(
        "Image_descriptor: DenseVLAD describes frames with a vocabulary learnt "
        "from a reference traversal first; expected Test_OpenABLE (which learns "
        "it from Images_path) or describe_images in Python (from the images given)");
  Vlad(DenseRootSift(patch), centres_).copyTo(row);
}

}  // namespace openable
