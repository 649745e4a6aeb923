#include "OpenABLE/stereo/stereo_source.h"

#include <opencv2/imgproc.hpp>
#include <utility>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/strings.h"

namespace openable {
namespace {

// A frame of a FrameSource (CV_32FC1/3 in [0, 1]) as 8-bit grey, luma weights as ToGray8.
cv::Mat Gray8(const cv::Mat& frame) {
  cv::Mat gray = frame, out;
  if (frame.channels() == 3) cv::cvtColor(frame, gray, cv::COLOR_BGR2GRAY);
  gray.convertTo(out, CV_8U, 255.0);
  return out;
}

class StereoFolderSource final : public FrameSource {
 public:
  StereoFolderSource(std::unique_ptr<FrameSource> left, std::unique_ptr<FrameSource> right,
                     const StereoCalibration& calibration, const cv::Size& size,
                     const StereoSourceOptions& options, std::string left_key,
                     std::string right_key)
      : left_(std::move(left)),
        right_(std::move(right)),
        left_key_(std::move(left_key)),
        right_key_(std::move(right_key)),
        size_(size),
        rectifier_(calibration, size, options.alpha),
        disparity_(DisparityOptions::ForWidth(size.width)),
        compute_disparity_(options.compute_disparity) {}

  int Size() const override { return left_->Size(); }
  std::string FrameName(int i) const override { return left_->FrameName(i); }
  bool ParallelReads() const override { return left_->ParallelReads() && right_->ParallelReads(); }
  double Timestamp(int i) const override { return left_->Timestamp(i); }

  cv::Mat Read(int i) const override {
    const cv::Mat left = WithKey(left_key_, [&] { return Gray8(left_->Read(i)); });
    const cv::Mat right = WithKey(right_key_, [&] { return Gray8(right_->Read(i)); });
    if (left.size() != right.size())
      throw InputError(left_key_ + "/" + right_key_ + ": stereo pair " + std::to_string(i) +
                       ": left image " + Quoted(left_->FrameName(i)) + " is " +
                       SizeText(left.size()) + " but right image " + Quoted(right_->FrameName(i)) +
                       " is " + SizeText(right.size()) +
                       " (expected both images of a pair to have one size)");
    if (left.size() != size_)
      throw InputError(left_key_ + ": image " + Quoted(left_->FrameName(i)) + " is " +
                       SizeText(left.size()) + " but " + Quoted(left_->FrameName(0)) + " is " +
                       SizeText(size_) +
                       " (expected one size for every stereo pair: the rectification is "
                       "computed once)");
    cv::Mat channels[2];
    if (compute_disparity_) {
      const StereoPair pair = ProcessStereoPair(rectifier_, disparity_, left, right);
      pair.left_rectified.convertTo(channels[0], CV_32F, 1.0 / 255.0);
      channels[1] = NormalizeDisparity(pair.disparity, disparity_);
    } else {
      cv::Mat left_rectified, right_rectified;
      rectifier_.Rectify(left, cv::Mat(), left_rectified, right_rectified);
      left_rectified.convertTo(channels[0], CV_32F, 1.0 / 255.0);
      channels[1] = cv::Mat::zeros(left_rectified.size(), CV_32F);
    }
    cv::Mat frame;
    cv::merge(channels, 2, frame);
    return frame;
  }

 private:
  std::unique_ptr<FrameSource> left_, right_;
  std::string left_key_, right_key_;
  cv::Size size_;
  StereoRectifier rectifier_;
  DisparityOptions disparity_;
  bool compute_disparity_;
};

}  // namespace

StereoPair ProcessStereoPair(const StereoRectifier& rectifier, const DisparityOptions& options,
                             const cv::Mat& left, const cv::Mat& right) {
  StereoPair pair;
  rectifier.Rectify(left, right, pair.left_rectified, pair.right_rectified);
  pair.disparity = ComputeDisparity(pair.left_rectified, pair.right_rectified, options);
  return pair;
}

std::unique_ptr<FrameSource> OpenStereoFolders(const std::string& left, const std::string& right,
                                               const std::string& extension, int first, int last,
                                               const StereoCalibration& calibration,
                                               const StereoSourceOptions& options) {
  const auto left_paths = WithKey("Images_path_left", [&] { return ListImages(left, extension); });
  const auto right_paths =
      WithKey("Images_path_right", [&] { return ListImages(right, extension); });
  if (left_paths.size() != right_paths.size())
    throw InputError("Images_path_left/Images_path_right: folder " + Quoted(left) + " holds " +
                     std::to_string(left_paths.size()) + " images but folder " + Quoted(right) +
                     " holds " + std::to_string(right_paths.size()) +
                     " (expected one right image per left image: pairs are matched by position "
                     "in natural order)");
  auto left_source =
      WithKey("Images_path_left", [&] { return OpenImageFolder(left, extension, first, last); });
  auto right_source =
      WithKey("Images_path_right", [&] { return OpenImageFolder(right, extension, first, last); });
  return OpenStereoSources(std::move(left_source), std::move(right_source), calibration, options,
                           "Images_path_left", "Images_path_right");
}

std::unique_ptr<FrameSource> OpenStereoSources(std::unique_ptr<FrameSource> left,
                                               std::unique_ptr<FrameSource> right,
                                               const StereoCalibration& calibration,
                                               const StereoSourceOptions& options,
                                               const std::string& left_key,
                                               const std::string& right_key) {
  if (left->Size() != right->Size())
    throw InputError(left_key + "/" + right_key + ": " + std::to_string(left->Size()) +
                     " left images but " + std::to_string(right->Size()) +
                     " right images (expected one right image per left image: pairs are "
                     "matched by position)");
  const cv::Mat first_left = WithKey(left_key, [&] { return left->Read(0); });
  WithKey("Calibration_path", [&] {
    CheckCalibrationFits(calibration, first_left.size(), left->FrameName(0));
    return 0;
  });
  return std::make_unique<StereoFolderSource>(std::move(left), std::move(right), calibration,
                                              first_left.size(), options, left_key, right_key);
}

}  // namespace openable
