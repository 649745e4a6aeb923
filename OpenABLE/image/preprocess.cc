#include "OpenABLE/image/preprocess.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "OpenABLE/base/error.h"

namespace openable {

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

cv::Mat1b IlluminationInvariant(const cv::Mat& frame, double alpha) {
  if (frame.depth() != CV_32F)
    throw std::logic_error("IlluminationInvariant: expected a CV_32F frame");
  if (frame.channels() != 3)
    throw InputError("the frame has " + std::to_string(frame.channels()) +
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
    throw InputError("the frame is grey (R = G = B in every pixel); Illumination_invariance 1 "
                     "(Eq. 6) gives a constant image for it: expected colour frames");
  return out;
}

double AlphaFromPeakResponses(double red_nm, double green_nm, double blue_nm) {
  if (!(blue_nm > 0 && blue_nm < green_nm && green_nm < red_nm) || !std::isfinite(red_nm)) {
    std::ostringstream s;
    s << "Lambda_red, Lambda_green, Lambda_blue: " << red_nm << ", " << green_nm << ", "
      << blue_nm << " nm are not valid peak spectral responses; expected 0 < blue < green < red "
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

}  // namespace openable
