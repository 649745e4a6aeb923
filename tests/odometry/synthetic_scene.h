// Test helper: images of a textured box-shaped room rendered by ray casting, for camera poses
// known exactly. Every pixel sees the nearest of five planes (back wall, floor, ceiling, left and
// right walls); each plane carries its own random texture (noise plus rectangles and discs of
// random grey, so that corners and blobs can be tracked), fixed to the plane, so that a point of
// the scene looks the same from every pose. Rendered at twice the resolution and averaged down
// (INTER_AREA) against aliasing.
#pragma once

#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "OpenABLE/odometry/calibration.h"

namespace openable::odometry_test {

class SyntheticRoom {
 public:
  static constexpr int kTile = 1024;             // texture pixels per plane side
  static constexpr double kPixelsPerMetre = 20;  // texture resolution

  explicit SyntheticRoom(std::uint64_t seed) {
    atlas_ = cv::Mat(kTile, kTile * 5, CV_8UC1);
    cv::RNG rng(seed);
    for (int p = 0; p < 5; ++p) {
      cv::Mat tile = atlas_.colRange(p * kTile, (p + 1) * kTile);
      cv::Mat noise(kTile, kTile, CV_32F);
      rng.fill(noise, cv::RNG::NORMAL, 0.0, 1.0);
      cv::GaussianBlur(noise, noise, cv::Size(0, 0), 8.0);
      cv::normalize(noise, noise, 60, 190, cv::NORM_MINMAX);
      noise.convertTo(tile, CV_8U);
      for (int k = 0; k < 2500; ++k) {
        const cv::Point c(rng.uniform(0, kTile), rng.uniform(0, kTile));
        const int size = rng.uniform(3, 16);
        const cv::Scalar grey(rng.uniform(0, 256));
        if (rng.uniform(0, 2) == 0) {
          cv::rectangle(tile, cv::Rect(c.x, c.y, size, rng.uniform(3, 16)), grey, cv::FILLED);
        } else {
          cv::circle(tile, c, size / 2 + 1, grey, cv::FILLED, cv::LINE_AA);
        }
      }
      cv::GaussianBlur(tile, tile, cv::Size(0, 0), 0.7);
    }
  }

  // The image seen by a camera with `intrinsics` at camera-to-world `pose` (OpenCV axes: x
  // right, y down, z forward; the room spans x in [-5, 5], y in [-4, 2], z up to 25 m).
  cv::Mat Render(const odometry::Intrinsics& intrinsics, const cv::Size& size,
                 const Eigen::Isometry3d& pose) const {
    const int s = 2;  // supersampling
    cv::Mat1f map_x(size.height * s, size.width * s), map_y(size.height * s, size.width * s);
    const Eigen::Vector3d origin = pose.translation();
    // Planes n . X = c, with the two world axes giving the texture coordinates.
    struct Plane {
      int axis;
      double c;
      int u_axis, v_axis;
    };
    const std::array<Plane, 5> planes = {
        {{2, 25.0, 0, 1}, {1, 2.0, 0, 2}, {1, -4.0, 0, 2}, {0, -5.0, 2, 1}, {0, 5.0, 2, 1}}};
    for (int y = 0; y < map_x.rows; ++y) {
      for (int x = 0; x < map_x.cols; ++x) {
        const double u = (x + 0.5) / s - 0.5, v = (y + 0.5) / s - 0.5;
        const Eigen::Vector3d ray =
            pose.linear() * Eigen::Vector3d((u - intrinsics.cx) / intrinsics.fx,
                                            (v - intrinsics.cy) / intrinsics.fy, 1.0);
        double best = 1e30;
        int hit = -1;
        for (int p = 0; p < 5; ++p) {
          const double denominator = ray[planes[p].axis];
          if (std::abs(denominator) < 1e-12) continue;
          const double t = (planes[p].c - origin[planes[p].axis]) / denominator;
          if (t > 0 && t < best) best = t, hit = p;
        }
        if (hit < 0) {
          map_x(y, x) = map_y(y, x) = -1;
          continue;
        }
        const Eigen::Vector3d point = origin + best * ray;
        map_x(y, x) = static_cast<float>(hit * kTile + kTile / 2 +
                                         kPixelsPerMetre * point[planes[hit].u_axis]);
        map_y(y, x) = static_cast<float>(kTile / 2 + kPixelsPerMetre * point[planes[hit].v_axis]);
      }
    }
    cv::Mat big, out;
    cv::remap(atlas_, big, map_x, map_y, cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(0));
    cv::resize(big, out, size, 0, 0, cv::INTER_AREA);
    return out;
  }

 private:
  cv::Mat atlas_;
};

// Camera-to-world pose: rotation of `degrees` about `axis`, then position `position`.
inline Eigen::Isometry3d Pose(double degrees, const Eigen::Vector3d& axis,
                              const Eigen::Vector3d& position) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::AngleAxisd(degrees * M_PI / 180.0, axis.normalized()).toRotationMatrix();
  pose.translation() = position;
  return pose;
}

inline double Degrees(double radians) { return radians * 180.0 / M_PI; }

// The camera that renders the room in the tests: 640 x 480 pixels, focal length 400 pixels, the
// principal point at the image centre.
inline const cv::Size kSize(640, 480);
inline const odometry::Intrinsics kIntrinsics{400, 400, 319.5, 239.5};

}  // namespace openable::odometry_test
