// Frames of ../shared/datasets that several tests read.
#pragma once

#include <gtest/gtest.h>

#include <cstdio>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "tests/test_support.h"

namespace openable::testing {

// KITTI 00's first 1700 left frames: 000000.png to 001699.png.
inline std::string Kitti00LeftDir() { return DatasetsDir() + "/kitti00_first1700/image_0"; }

// Every `step`-th of those frames from 0 to `last`, as 8-bit grey images; a frame that cannot
// be read fails the test (and stays empty).
inline std::vector<cv::Mat> ReadKitti00Frames(int step, int last) {
  std::vector<cv::Mat> frames;
  for (int i = 0; i <= last; i += step) {
    char name[32];
    std::snprintf(name, sizeof name, "/%06d.png", i);
    frames.push_back(cv::imread(Kitti00LeftDir() + name, cv::IMREAD_GRAYSCALE));
    EXPECT_FALSE(frames.back().empty()) << name;
  }
  return frames;
}

}  // namespace openable::testing
