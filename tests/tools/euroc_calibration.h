// Test helper: converts an EuRoC / Kalibr camera pair (sensorLeft.yaml, sensorRight.yaml) into
// OpenABLE's stereo calibration file (OpenABLE/stereo/calibration.h).
//
// EuRoC sensor files hold, per camera:
//   T_BS        4x4 (rows, cols, data) pose of the sensor in the body frame: it maps a point
//               from the sensor's frame to the body frame, p_B = T_BS p_S
//   intrinsics  [fu, fv, cu, cv] (pinhole)
//   distortion_coefficients  [k1, k2, p1, p2] (radial-tangential)
// The calibration file wants R, T with x_right = R x_left + T (cv::stereoRectify's
// convention), so
//   T_right_from_left = inverse(T_BS_right) * T_BS_left,  R = its 3x3 block, T = its last column;
//   ML = [fu 0 cu; 0 fv cv; 0 0 1] of the left file, MR of the right file;
//   DL, DR = [k1 k2 p1 p2 0] (no k3 in EuRoC's model).
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace openable::testing {

struct EurocCamera {
  cv::Matx44d body_from_sensor;  // T_BS
  double fu = 0, fv = 0, cu = 0, cv = 0;
  cv::Vec4d distortion;  // k1 k2 p1 p2
};

// Reads one EuRoC sensor file; returns false when it cannot be read.
inline bool ReadEurocCamera(const std::string& path, EurocCamera& out) {
  cv::FileStorage fs(path, cv::FileStorage::READ);
  if (!fs.isOpened()) return false;
  std::vector<double> t, k, d;
  fs["T_BS"]["data"] >> t;
  fs["intrinsics"] >> k;
  fs["distortion_coefficients"] >> d;
  if (t.size() != 16 || k.size() != 4 || d.size() != 4) return false;
  out.body_from_sensor = cv::Matx44d(t.data());
  out.fu = k[0], out.fv = k[1], out.cu = k[2], out.cv = k[3];
  out.distortion = cv::Vec4d(d[0], d[1], d[2], d[3]);
  return true;
}

struct ConvertedCalibration {
  cv::Matx33d ml, mr, r;
  cv::Vec<double, 5> dl, dr;
  cv::Vec3d t;
};

inline ConvertedCalibration ConvertEuroc(const EurocCamera& left, const EurocCamera& right) {
  ConvertedCalibration c;
  const cv::Matx44d right_from_left = right.body_from_sensor.inv() * left.body_from_sensor;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) c.r(i, j) = right_from_left(i, j);
    c.t(i) = right_from_left(i, 3);
  }
  c.ml = cv::Matx33d(left.fu, 0, left.cu, 0, left.fv, left.cv, 0, 0, 1);
  c.mr = cv::Matx33d(right.fu, 0, right.cu, 0, right.fv, right.cv, 0, 0, 1);
  c.dl = cv::Vec<double, 5>(left.distortion[0], left.distortion[1], left.distortion[2],
                            left.distortion[3], 0.0);
  c.dr = cv::Vec<double, 5>(right.distortion[0], right.distortion[1], right.distortion[2],
                            right.distortion[3], 0.0);
  return c;
}

// Writes `c` as a calibration file (OpenCV FileStorage YAML: %YAML:1.0, opencv-matrix nodes;
// DL, DR 5x1, T 3x1).
inline void WriteCalibrationFile(const ConvertedCalibration& c, const std::string& path) {
  cv::FileStorage fs(path, cv::FileStorage::WRITE | cv::FileStorage::FORMAT_YAML);
  fs << "ML" << cv::Mat(c.ml) << "MR" << cv::Mat(c.mr);
  fs << "DL" << cv::Mat(c.dl) << "DR" << cv::Mat(c.dr);
  fs << "R" << cv::Mat(c.r) << "T" << cv::Mat(c.t);
  fs << "colormap" << 2 << "use_log" << 0;
}

// ../shared/datasets/euroc_stereo_pairs converted into `path`; false when absent.
inline bool WriteEurocCalibration(const std::string& dataset, const std::string& path) {
  EurocCamera left, right;
  if (!ReadEurocCamera(dataset + "/sensorLeft.yaml", left) ||
      !ReadEurocCamera(dataset + "/sensorRight.yaml", right))
    return false;
  WriteCalibrationFile(ConvertEuroc(left, right), path);
  return true;
}

}  // namespace openable::testing
