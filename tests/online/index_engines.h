// The index engines that the online detector's tests run with, one test of a TEST_P each.
#pragma once

#include <filesystem>
#include <ostream>
#include <string>

#include <gtest/gtest.h>

#include "OpenABLE/base/enum_names.h"
#include "matching/approximate.h"
#include "tests/test_frames.h"

namespace openable {

// An engine in a test's description: its name.
inline void PrintTo(ApproximateEngine engine, std::ostream* os) { *os << EnumName(engine); }

namespace online_test {

// The engines' values, for INSTANTIATE_TEST_SUITE_P.
inline auto IndexEngines() {
  return ::testing::Values(ApproximateEngine::kFlann, ApproximateEngine::kHnsw,
                           ApproximateEngine::kIvf);
}

// A test's name: its engine's ("flann", "hnsw", "ivf").
inline std::string EngineName(const ::testing::TestParamInfo<ApproximateEngine>& info) {
  return EnumName(info.param);
}

// A test of one index engine (the parameter) on KITTI 00's frames: skipped when they are
// absent, or for a FAISS engine in a build without FAISS.
class KittiEngineTest : public ::testing::TestWithParam<ApproximateEngine> {
 protected:
  void SetUp() override {
    OPENABLE_REQUIRE_PATH(testing::Kitti00LeftDir());
    if (GetParam() != ApproximateEngine::kFlann && !FaissAvailable())
      GTEST_SKIP() << "this build has no FAISS (libfaiss-dev)";
  }
};

}  // namespace online_test
}  // namespace openable
