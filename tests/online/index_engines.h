// The index engines that the online detector's tests run with, one test of a TEST_P each.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <ostream>
#include <string>

#include "matching/search/approximate.h"
#include "matching/search/engine_registry.h"
#include "tests/test_frames.h"

namespace openable {

namespace online_test {

// The engines' values, for INSTANTIATE_TEST_SUITE_P.
inline auto IndexEngines() { return ::testing::Values("flann", "hnsw", "ivf"); }

// A test's name: its engine's ("flann", "hnsw", "ivf").
inline std::string EngineName(const ::testing::TestParamInfo<std::string>& info) {
  return info.param;
}

// A test of one index engine (the parameter) on KITTI 00's frames: skipped when they are
// absent, or for a FAISS engine in a build without FAISS.
class KittiEngineTest : public ::testing::TestWithParam<std::string> {
 protected:
  void SetUp() override {
    OPENABLE_REQUIRE_PATH(testing::Kitti00LeftDir());
    if (!ApproximateEngineAvailable(GetParam()))
      GTEST_SKIP() << "this build has no FAISS (libfaiss-dev)";
  }
};

}  // namespace online_test
}  // namespace openable
