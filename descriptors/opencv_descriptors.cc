#include "descriptors/opencv_descriptors.h"

#include <algorithm>
#include <cmath>
#include <mutex>
#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "OpenABLE/base/error.h"

namespace openable {
namespace {

std::string MatShape(const cv::Mat& m) {
  return std::to_string(m.rows) + " x " + std::to_string(m.cols) + " " + cv::typeToString(m.type());
}

// Pixels added on each side of the patch; see the header.
int Padding(int patch_size) { return patch_size / 2 + 1; }

cv::Mat PadPatch(const cv::Mat& patch) {
  const int pad = Padding(patch.rows);
  cv::Mat padded;
  // BORDER_ISOLATED: a patch that is a view into a larger image is padded from its own pixels.
  cv::copyMakeBorder(patch, padded, pad, pad, pad, pad,
                     cv::BORDER_REFLECT_101 | cv::BORDER_ISOLATED);
  return padded;
}

// The patch centre in the padded image.
cv::Point2f Centre(int patch_size) {
  const float c =
      static_cast<float>(Padding(patch_size)) + 0.5f * static_cast<float>(patch_size - 1);
  return {c, c};
}

// Runs compute() on one keypoint and copies the single descriptor row into `row`.
void ComputeOne(const std::string& name, cv::Feature2D& feature, const cv::Mat& padded,
                cv::KeyPoint keypoint, cv::Mat row) {
  std::vector<cv::KeyPoint> keypoints{keypoint};
  cv::Mat descriptors;
  feature.compute(padded, keypoints, descriptors);
  if (keypoints.size() != 1 || descriptors.rows != 1 || descriptors.cols != row.cols ||
      descriptors.type() != row.type()) {
    throw std::logic_error(name + ": OpenCV returned " + std::to_string(keypoints.size()) +
                           " keypoint(s) and a " + MatShape(descriptors) +
                           " descriptor block for the central keypoint; expected 1 and 1 x " +
                           std::to_string(row.cols) + " " + cv::typeToString(row.type()));
  }
  descriptors.copyTo(row);
}

// BRISK's standard pattern, as in the paper and OpenCV's default (patternScale 1): ring radii
// 0, 2.9, 4.9, 7.4, 10.8 times 0.85 pixels at scale 1, with 1, 10, 14, 15, 20 points.
constexpr double kBriskRingScale = 0.85;
constexpr float kBriskOuterRadius = static_cast<float>(kBriskRingScale * 10.8);
constexpr float kBriskDMax = 5.85f;
// Larger than any distance between two points of the pattern at scale 1 (at most 18.4 px):
// no long pairs, hence no orientation estimate.
constexpr float kBriskDMinNoOrientation = 1000.0f;
// OpenCV's BRISK scale discretisation: 64 scales over a range of 30, keypoint size 7.2 (0.6 x
// the basic size 12) at scale 1.
constexpr int kBriskScales = 64;
constexpr double kBriskScaleRange = 30.0;
constexpr double kBriskSizeAtScaleOne = 7.2;

float BriskKeypointSize(int patch_size) {
  const double wanted = 0.5 * patch_size / kBriskOuterRadius;  // outer ring on radius S / 2
  const double index = std::round(kBriskScales * std::log(wanted) / std::log(kBriskScaleRange));
  const double clamped = std::clamp(index, 0.0, static_cast<double>(kBriskScales - 1));
  return static_cast<float>(kBriskSizeAtScaleOne *
                            std::pow(kBriskScaleRange, clamped / kBriskScales));
}

cv::Ptr<cv::BRISK> MakeBrisk() {
  const std::vector<float> radii = {0.0f, static_cast<float>(kBriskRingScale * 2.9),
                                    static_cast<float>(kBriskRingScale * 4.9),
                                    static_cast<float>(kBriskRingScale * 7.4), kBriskOuterRadius};
  const std::vector<int> points = {1, 10, 14, 15, 20};
  return cv::BRISK::create(/*thresh=*/30, /*octaves=*/0, radii, points, kBriskDMax,
                           kBriskDMinNoOrientation);
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// ORB

OrbDescriptor::OrbDescriptor(const DescriptorOptions& options) : Descriptor(options) {}

void OrbDescriptor::DescribePatch(const cv::Mat& patch, cv::Mat row) const {
  // cv::ORB is cheap to build (its pattern is made in compute()); one per call is thread-safe.
  cv::Ptr<cv::ORB> orb = cv::ORB::create(/*nfeatures=*/500, /*scaleFactor=*/1.2f, /*nlevels=*/1,
                                         /*edgeThreshold=*/PatchSize(), /*firstLevel=*/0,
                                         /*WTA_K=*/2, cv::ORB::HARRIS_SCORE,
                                         /*patchSize=*/PatchSize());
  const cv::KeyPoint keypoint(Centre(PatchSize()), static_cast<float>(PatchSize()),
                              /*angle=*/0.0f, /*response=*/0.0f, /*octave=*/0);
  ComputeOne("ORB", *orb, PadPatch(patch), keypoint, row);
}

// ---------------------------------------------------------------------------------------------
// BRISK

struct BriskDescriptor::Pool {
  std::mutex mutex;
  std::vector<cv::Ptr<cv::BRISK>> idle;
};

BriskDescriptor::BriskDescriptor(const DescriptorOptions& options)
    : Descriptor(options), pool_(std::make_unique<Pool>()) {
  keypoint_size_ = BriskKeypointSize(PatchSize());
  pool_->idle.push_back(MakeBrisk());
}

BriskDescriptor::~BriskDescriptor() = default;

void BriskDescriptor::DescribePatch(const cv::Mat& patch, cv::Mat row) const {
  cv::Ptr<cv::BRISK> brisk;
  {
    std::lock_guard<std::mutex> lock(pool_->mutex);
    if (!pool_->idle.empty()) {
      brisk = pool_->idle.back();
      pool_->idle.pop_back();
    }
  }
  if (!brisk) {
    brisk = MakeBrisk();
  }
  // Returns the instance to the pool on every exit, including exceptions.
  struct Release {
    Pool& pool;
    cv::Ptr<cv::BRISK>& brisk;
    ~Release() {
      std::lock_guard<std::mutex> lock(pool.mutex);
      pool.idle.push_back(brisk);
    }
  } release{*pool_, brisk};

  std::vector<cv::KeyPoint> keypoints{
      cv::KeyPoint(Centre(PatchSize()), keypoint_size_, /*angle=*/0.0f)};
  cv::Mat descriptors;
  brisk->compute(PadPatch(patch), keypoints, descriptors);
  if (keypoints.size() != 1 || keypoints[0].angle != 0.0f || descriptors.rows != 1 ||
      descriptors.cols != Width() || descriptors.type() != CV_8UC1) {
    throw std::logic_error(
        "BRISK: OpenCV returned " + std::to_string(keypoints.size()) + " keypoint(s)" +
        (keypoints.empty() ? std::string() : " at angle " + std::to_string(keypoints[0].angle)) +
        " and a " + MatShape(descriptors) +
        " descriptor block; expected 1 keypoint at angle 0 and 1 x 64 CV_8UC1");
  }
  descriptors.copyTo(row);
}

// ---------------------------------------------------------------------------------------------
// SIFT

SiftDescriptor::SiftDescriptor(const DescriptorOptions& options) : Descriptor(options) {}

void SiftDescriptor::DescribePatch(const cv::Mat& patch, cv::Mat row) const {
  // cv::SIFT is cheap to build; one per call is thread-safe.
  cv::Ptr<cv::SIFT> sift = cv::SIFT::create();
  const cv::KeyPoint keypoint(Centre(PatchSize()), static_cast<float>(PatchSize()) / 6.0f,
                              /*angle=*/0.0f, /*response=*/0.0f, /*octave=*/0);
  ComputeOne("SIFT", *sift, PadPatch(patch), keypoint, row);
}

}  // namespace openable
