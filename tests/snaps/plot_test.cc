// Top view of trajectories: size, colours where the trajectories are, equal aspect.
#include "OpenABLE/snaps/plot.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "tests/test_support.h"

namespace openable::snaps {
namespace {

Trajectory Circle(double radius, double y_offset) {
  Trajectory t;
  for (int k = 0; k <= 200; ++k) {
    Eigen::Isometry3d p = Eigen::Isometry3d::Identity();
    const double a = 2 * M_PI * k / 200 + M_PI / 4;  // the start dot at 45 degrees
    p.translation() = Eigen::Vector3d(radius * std::cos(a), y_offset, radius * std::sin(a));
    t.poses.push_back(p);
    t.frame_ids.push_back(k);
  }
  return t;
}

int CountColour(const cv::Mat3b& img, const cv::Vec3b& colour) {
  int n = 0;
  for (int y = 0; y < img.rows; ++y)
    for (int x = 0; x < img.cols; ++x) n += img(y, x) == colour ? 1 : 0;
  return n;
}

TEST(RenderTrajectories, DrawsEachTrajectoryInItsColourWithEqualAspect) {
  const Trajectory truth = Circle(100, 0);
  const Trajectory input = Circle(80, 0);
  const Trajectory corrected = Circle(95, 0);
  TrajectoryPlot plot;
  plot.truth = &truth;
  plot.input = &input;
  plot.corrected = &corrected;
  plot.loops = {{200, 0, 1.0}, {150, 50, 1.0}};
  plot.title = "circles";
  const cv::Mat3b img = RenderTrajectories(plot);
  ASSERT_EQ(img.rows, 1000);
  ASSERT_EQ(img.cols, 1000);
  // Solid pixels of the three colours (black truth, vermillion input, blue corrected).
  EXPECT_GT(CountColour(img, cv::Vec3b(0, 94, 213)), 300);
  EXPECT_GT(CountColour(img, cv::Vec3b(178, 114, 0)), 300);
  if (std::getenv("OPENABLE_KEEP_TEST_FILES") != nullptr) {
    cv::imwrite(openable::testing::TempDir() + "/circles.png", img);
  }
}

TEST(RenderTrajectories, EqualAspect) {
  // A lone circle (the legend is small and sits in a corner the circle leaves empty) spans as
  // many pixels across as up and down, in both ground planes.
  Trajectory input = Circle(80, 0);
  TrajectoryPlot plot;
  plot.input = &input;
  const cv::Mat3b img = RenderTrajectories(plot);
  // Extents within a band through the plot area's centre (an 880 px square from x = 90,
  // y = 50): away from the legend's line samples.
  const int cx = 90 + 440, cy = 50 + 440;
  int left = img.cols, right = 0, top = img.rows, bottom = 0;
  const cv::Vec3b vermillion(0, 94, 213);
  for (int y = 0; y < img.rows; ++y) {
    for (int x = 0; x < img.cols; ++x) {
      if (img(y, x) != vermillion) continue;
      if (std::abs(y - cy) < 60) {
        left = std::min(left, x);
        right = std::max(right, x);
      }
      if (std::abs(x - cx) < 60) {
        top = std::min(top, y);
        bottom = std::max(bottom, y);
      }
    }
  }
  EXPECT_NEAR(right - left, bottom - top, 4);
  EXPECT_GT(right - left, 700);
}

TEST(RenderTrajectories, RejectsBadArguments) {
  const Trajectory input = Circle(10, 0);
  TrajectoryPlot plot;
  EXPECT_THROW(RenderTrajectories(plot), std::logic_error);
  plot.input = &input;
  plot.axes = "yz";
  EXPECT_THROW(RenderTrajectories(plot), std::logic_error);
  plot.axes = "xy";
  plot.loops = {{201, 0, 1.0}};
  EXPECT_THROW(RenderTrajectories(plot), std::logic_error);
  plot.loops.clear();
  EXPECT_EQ(RenderTrajectories(plot).rows, 1000);
}

}  // namespace
}  // namespace openable::snaps
