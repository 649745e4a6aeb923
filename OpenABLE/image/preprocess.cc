#include "OpenABLE/image/preprocess.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <stdexcept>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/option_checks.h"
#include "OpenABLE/base/strings.h"

namespace openable {

namespace {

// An image a program gives: not empty, of one of the types GreyOfImage and ColourOfImage take.
void CheckProgramImage(const cv::Mat& image, const std::string& what) {
  if (image.empty()) throw InputError(what + " is empty (expected an image)");
  const int depth = image.depth(), channels = image.channels();
  if ((depth != CV_8U && depth != CV_32F) || (channels != 1 && channels != 3))
    throw InputError(what + " has OpenCV type " + cv::typeToString(image.type()) +
                     " (expected CV_8UC1, CV_8UC3 (BGR), CV_32FC1 or CV_32FC3 in [0, 1])");
}

}  // namespace

cv::Mat1b GreyOfImage(const cv::Mat& image, const std::string& what) {
  CheckProgramImage(image, what);
  const int depth = image.depth(), channels = image.channels();
  if (depth == CV_32F) return ToGray8(image);
  // 8-bit grey is already what ToGray8 would give back (x / 255 x 255 rounds to x).
  if (channels == 1) return image;
  cv::Mat scaled;
  image.convertTo(scaled, CV_32F, 1.0 / 255.0);
  return ToGray8(scaled);
}

cv::Mat ColourOfImage(const cv::Mat& image, const std::string& what) {
  CheckProgramImage(image, what);
  if (image.depth() == CV_32F) return ToColour8(image);
  if (image.channels() == 3) return image;
  cv::Mat colour;
  cv::cvtColor(image, colour, cv::COLOR_GRAY2BGR);
  return colour;
}

cv::Mat1b ToGray8(const cv::Mat& frame) {
  if (frame.depth() != CV_32F || frame.channels() > 3)
    throw std::logic_error("ToGray8: expected a CV_32FC1, CV_32FC2 or CV_32FC3 frame");
  cv::Mat gray;
  if (frame.channels() == 3)
    cv::cvtColor(frame, gray, cv::COLOR_BGR2GRAY);
  else if (frame.channels() == 2)
    cv::extractChannel(frame, gray, 0);
  else
    gray = frame;
  cv::Mat1b out;
  gray.convertTo(out, CV_8U, 255.0);  // saturating and rounding
  return out;
}

cv::Mat ToColour8(const cv::Mat& frame) {
  if (frame.depth() != CV_32F || frame.channels() > 3)
    throw std::logic_error("ToColour8: expected a CV_32FC1, CV_32FC2 or CV_32FC3 frame");
  cv::Mat colour;
  if (frame.channels() == 3) {
    colour = frame;
  } else {
    cv::Mat grey = frame;
    if (frame.channels() == 2) cv::extractChannel(frame, grey, 0);
    cv::cvtColor(grey, colour, cv::COLOR_GRAY2BGR);
  }
  cv::Mat out;
  colour.convertTo(out, CV_8U, 255.0);  // saturating and rounding
  return out;
}

cv::Mat1b IlluminationInvariant(const cv::Mat& frame, double alpha) {
  if (frame.depth() != CV_32F)
    throw std::logic_error("IlluminationInvariant: expected a CV_32F frame");
  if (frame.channels() != 3)
    throw InputError(
        "the frame has " + std::to_string(frame.channels()) +
        " channel(s); Illumination_invariance 1 (Eq. 6) needs colour frames (R, G, B)");
  constexpr float kFloor = 1.0f / 510.0f;
  cv::Mat1b out(frame.size());
  bool grey = true;
  const float a = static_cast<float>(alpha), b = 1.0f - static_cast<float>(alpha);
  for (int y = 0; y < frame.rows; ++y) {
    const cv::Vec3f* in = frame.ptr<cv::Vec3f>(y);
    std::uint8_t* o = out.ptr<std::uint8_t>(y);
    for (int x = 0; x < frame.cols; ++x) {
      const cv::Vec3f& p = in[x];  // B, G, R
      grey = grey && p[0] == p[1] && p[1] == p[2];
      const float lb = std::log(std::max(p[0], kFloor));
      const float lg = std::log(std::max(p[1], kFloor));
      const float lr = std::log(std::max(p[2], kFloor));
      const float i = lg - a * lb - b * lr;
      o[x] = cv::saturate_cast<std::uint8_t>(255.0f * (0.5f + 0.5f * i));
    }
  }
  if (grey)
    throw InputError(
        "the frame is grey (R = G = B in every pixel); Illumination_invariance 1 "
        "(Eq. 6) gives a constant image for it: expected colour frames");
  return out;
}

double AlphaFromPeakResponses(double red_nm, double green_nm, double blue_nm) {
  if (!(blue_nm > 0 && blue_nm < green_nm && green_nm < red_nm) || !std::isfinite(red_nm)) {
    std::ostringstream s;
    s << "Lambda_red, Lambda_green, Lambda_blue: " << red_nm << ", " << green_nm << ", " << blue_nm
      << " nm are not valid peak spectral responses; expected 0 < blue < green < red "
      << "(e.g. 610, 535, 470 for KITTI's PointGrey Flea2)";
    throw InputError(s.str());
  }
  return (blue_nm / green_nm - blue_nm / red_nm) / (1.0 - blue_nm / red_nm);
}

cv::Mat ToGrayDisparity8(const cv::Mat& frame) {
  if (frame.type() != CV_32FC2)
    throw std::logic_error("ToGrayDisparity8: expected a CV_32FC2 stereo frame (grey, disparity)");
  cv::Mat out;
  frame.convertTo(out, CV_8U, 255.0);  // saturating and rounding, per channel
  return out;
}

std::vector<int> ParseSideWindowRadii(const std::string& text) {
  auto fail = [&](const std::string& why) {
    throw InputError("Side_window_radii: " + Quoted(text) + " is not valid (" + why +
                     "); expected radii in [1, 50] separated by commas, 1 to 16 layers, "
                     "e.g. \"1,2,3\"");
  };
  std::vector<int> radii;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    item = Trim(item);
    if (item.empty()) fail("empty item");
    char* end = nullptr;
    errno = 0;
    const long v = std::strtol(item.c_str(), &end, 10);
    if (end != item.c_str() + item.size() || errno == ERANGE)
      fail(Quoted(item) + " is not an integer");
    if (v < 1 || v > 50) fail(item + " is out of range");
    radii.push_back(static_cast<int>(v));
  }
  if (!text.empty() && text.back() == ',') fail("empty item");
  if (radii.empty()) fail("no radius");
  if (radii.size() > 16) fail(std::to_string(radii.size()) + " layers");
  return radii;
}

double PreprocessOptions::Alpha() const {
  return lambda_red > 0 ? AlphaFromPeakResponses(lambda_red, lambda_green, lambda_blue) : alpha;
}

std::vector<int> PreprocessOptions::SideWindowRadii() const {
  return side_window ? ParseSideWindowRadii(side_window_radii) : std::vector<int>{};
}

void PreprocessOptions::Check() const {
  CheckNumberRange("Alpha", alpha, 0, 1);
  CheckNumberRange("Lambda_red", lambda_red, 0, 2000);
  CheckNumberRange("Lambda_green", lambda_green, 0, 2000);
  CheckNumberRange("Lambda_blue", lambda_blue, 0, 2000);
  const int given = (lambda_red > 0) + (lambda_green > 0) + (lambda_blue > 0);
  if (given != 0 && given != 3)
    throw InputError("Lambda_red, Lambda_green, Lambda_blue: " + FormatNumber(lambda_red) + ", " +
                     FormatNumber(lambda_green) + ", " + FormatNumber(lambda_blue) +
                     "; expected all three peak responses (nm) or none (0)");
  CheckNumberRange("Noise_gaussian", noise.gaussian, 0, 1);
  CheckNumberRange("Noise_salt_pepper", noise.salt_pepper, 0, 1);
  CheckNumberAtLeast("Noise_overexposure", noise.overexposure, 0);
  CheckIntRange("Noise_seed", noise.seed, 0, 1000000000);
  SideWindowRadii();
}

}  // namespace openable
