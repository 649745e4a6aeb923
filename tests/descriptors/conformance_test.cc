// One conformance suite run over every registered descriptor.
// Adding a descriptor: one line in ExpectedFor64() below.

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <map>
#include <memory>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "descriptors/descriptor.h"
#include "descriptors/registry.h"
#include "tests/descriptors/descriptor_test_util.h"
#include "tests/test_support.h"

namespace openable {
namespace {

using testing_util::Describe;
using testing_util::Options;
using testing_util::TexturedPatch;

// What each registered descriptor must declare for a 64 x 64 patch.
struct Expected {
  int width;
  DescriptorKind kind;
};
const std::map<std::string, Expected>& ExpectedFor64() {
  static const std::map<std::string, Expected> table = {
      {"LDB", {32, DescriptorKind::kBinary}},    // 256 bits
      {"D-LDB", {64, DescriptorKind::kBinary}},  // 256 bits of grey ++ 256 bits of disparity
      {"ORB", {32, DescriptorKind::kBinary}},    // 256 bits
      {"BRISK", {64, DescriptorKind::kBinary}},  // 512 bits
      {"SIFT", {128, DescriptorKind::kFloat}},   // 4 x 4 cells x 8 bins
      {"HOG", {1764, DescriptorKind::kFloat}},   // 7 x 7 blocks x 4 cells x 9 bins
      {"BRIEF", {32, DescriptorKind::kBinary}},  // 256 tests
      {"FREAK", {64, DescriptorKind::kBinary}},  // 512 pairs
      {"SAD", {2048, DescriptorKind::kBytes}},   // 64 x 32 thumbnail
      // the test network with GeM pooling (tests/data/onnx/gem.onnx): 32 channels pooled
      {"ONNX", {32, DescriptorKind::kFloat}},
      {"DENSEVLAD", {64 * 128, DescriptorKind::kFloat}},  // 64 words x 128 (RootSIFT)
  };
  return table;
}

// Hamming distance counted bit by bit, L1 as a direct sum of absolute byte differences, or L2
// norm as a direct sum of squares.
double Distance(const Descriptor& d, const cv::Mat& a, const cv::Mat& b) {
  if (d.Distance() == DistanceKind::kL1) {
    double sum = 0.0;
    for (int i = 0; i < a.cols; ++i)
      sum += std::abs(a.at<std::uint8_t>(0, i) - b.at<std::uint8_t>(0, i));
    return sum;
  }
  if (d.Distance() == DistanceKind::kHamming) {
    int bits = 0;
    for (int i = 0; i < a.cols; ++i) {
      const unsigned x = a.at<std::uint8_t>(0, i) ^ b.at<std::uint8_t>(0, i);
      for (int k = 0; k < 8; ++k) bits += static_cast<int>((x >> k) & 1u);
    }
    return bits;
  }
  double sum = 0.0;
  for (int i = 0; i < a.cols; ++i) {
    const double diff = static_cast<double>(a.at<float>(0, i)) - b.at<float>(0, i);
    sum += diff * diff;
  }
  return std::sqrt(sum);
}

// A patch of the descriptor's channel count: the textured grey patch, and for a 2-channel
// descriptor (D-LDB: grey, disparity) or a 3-channel one (ONNX: colour) independent textured
// patches as the other channels.
cv::Mat PatchFor(const Descriptor& d, int size, std::uint64_t seed) {
  if (d.Channels() == 1) return TexturedPatch(size, seed);
  std::vector<cv::Mat> channels;
  for (int c = 0; c < d.Channels(); ++c) channels.push_back(TexturedPatch(size, seed + 7919 * c));
  cv::Mat out;
  cv::merge(channels, out);
  return out;
}

bool SameBytes(const cv::Mat& a, const cv::Mat& b) {
  return a.type() == b.type() && a.size() == b.size() &&
         std::memcmp(a.ptr(0), b.ptr(0), a.cols * a.elemSize()) == 0;
}

class DescriptorConformance : public ::testing::TestWithParam<std::string> {
 protected:
  std::unique_ptr<Descriptor> Make(int patch_size = 64) const {
    DescriptorOptions options;
    options.patch_size = patch_size;
    // A network: the test network with GeM pooling, which takes any input size; its input is
    // the square patch here.
    options.model_path = testing::SourceDir() + "/tests/data/onnx/gem.onnx";
    options.model_input_size = std::to_string(patch_size) + "x" + std::to_string(patch_size);
    std::unique_ptr<Descriptor> d = CreateDescriptor(GetParam(), options);
    // A descriptor that learns (DenseVLAD's vocabulary) learns from textured patches first
    // (of at least 64 pixels: 16 x 16 patches hold too few of its local descriptors).
    if (d->Learns()) {
      std::vector<cv::Mat> patches;
      for (std::uint64_t seed = 500; seed < 508; ++seed)
        patches.push_back(TexturedPatch(std::max(patch_size, 64), seed));
      d->Learn(patches);
    }
    return d;
  }
};

TEST_P(DescriptorConformance, DeclaresWidthAndRowType) {
  const auto it = ExpectedFor64().find(GetParam());
  ASSERT_NE(it, ExpectedFor64().end()) << "add " << GetParam() << " to ExpectedFor64()";
  const auto d = Make();
  EXPECT_EQ(d->Name(), GetParam());
  EXPECT_EQ(d->PatchSize(), 64);
  EXPECT_EQ(d->Width(), it->second.width);
  EXPECT_EQ(d->Kind(), it->second.kind);
  EXPECT_EQ(d->Distance(), it->second.kind == DescriptorKind::kBinary  ? DistanceKind::kHamming
                           : it->second.kind == DescriptorKind::kFloat ? DistanceKind::kL2
                                                                       : DistanceKind::kL1);
  EXPECT_EQ(RowType(*d), it->second.kind == DescriptorKind::kFloat ? CV_32F : CV_8U);

  const cv::Mat row = Describe(*d, PatchFor(*d, 64, 1));
  EXPECT_EQ(row.rows, 1);
  EXPECT_EQ(row.cols, it->second.width);
  EXPECT_EQ(row.type(), RowType(*d));
  EXPECT_GT(cv::countNonZero(row), 0) << "an all-zero descriptor of a textured patch";
  if (d->Kind() == DescriptorKind::kFloat) {
    EXPECT_TRUE(cv::checkRange(row)) << "NaN or infinity in the descriptor";
  }
}

TEST_P(DescriptorConformance, WritesIntoARowOfALargerBlock) {
  // The pipeline describes straight into row i of an N x Width block.
  const auto d = Make();
  const cv::Mat patch = PatchFor(*d, 64, 2);
  cv::Mat block(3, d->Width(), RowType(*d), cv::Scalar::all(7));
  d->Describe(patch, block.row(1));
  EXPECT_TRUE(SameBytes(block.row(1), Describe(*d, patch)));
  const cv::Mat untouched(1, d->Width(), RowType(*d), cv::Scalar::all(7));
  EXPECT_TRUE(SameBytes(block.row(0), untouched));
  EXPECT_TRUE(SameBytes(block.row(2), untouched));
}

TEST_P(DescriptorConformance, IsDeterministic) {
  const auto d = Make();
  const cv::Mat patch = PatchFor(*d, 64, 3);
  const cv::Mat first = Describe(*d, patch);
  EXPECT_TRUE(SameBytes(first, Describe(*d, patch)));
  EXPECT_TRUE(SameBytes(first, Describe(*Make(), patch))) << "a second instance differs";
}

TEST_P(DescriptorConformance, IsDeterministicAcrossThreads) {
  const auto d = Make();
  std::vector<cv::Mat> patches;
  std::vector<cv::Mat> expected;
  for (int i = 0; i < 6; ++i) {
    patches.push_back(PatchFor(*d, 64, 10 + i));
    expected.push_back(Describe(*d, patches.back()));
  }
  constexpr int kThreads = 4;
  std::vector<std::vector<cv::Mat>> results(kThreads);
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&, t] {
      for (int repeat = 0; repeat < 3; ++repeat) {
        for (const cv::Mat& p : patches) results[t].push_back(Describe(*d, p));
      }
    });
  }
  for (std::thread& t : threads) t.join();
  for (int t = 0; t < kThreads; ++t) {
    ASSERT_EQ(results[t].size(), 3 * patches.size());
    for (std::size_t i = 0; i < results[t].size(); ++i) {
      EXPECT_TRUE(SameBytes(results[t][i], expected[i % patches.size()]))
          << "thread " << t << ", call " << i;
    }
  }
}

TEST_P(DescriptorConformance, IdenticalImagesAreAtDistanceZero) {
  const auto d = Make();
  const cv::Mat patch = PatchFor(*d, 64, 4);
  const cv::Mat copy = patch.clone();
  EXPECT_EQ(Distance(*d, Describe(*d, patch), Describe(*d, copy)), 0.0);
}

TEST_P(DescriptorConformance, ViewIntoALargerImageIsDescribedFromItsOwnPixels) {
  // The same pixels as a 64 x 64 view inside a larger, different image and as a standalone
  // copy: the descriptor must not read pixels around the view.
  const auto d = Make();
  cv::Mat big = PatchFor(*d, 128, 5);
  const cv::Mat view = big(cv::Rect(30, 40, 64, 64));
  ASSERT_TRUE(view.isSubmatrix());
  EXPECT_EQ(Distance(*d, Describe(*d, view), Describe(*d, view.clone())), 0.0);
}

TEST_P(DescriptorConformance, HandlesUniformPatches) {
  const auto d = Make();
  for (const int value : {0, 255}) {
    const cv::Mat patch(64, 64, CV_8UC(d->Channels()), cv::Scalar::all(value));
    cv::Mat row;
    EXPECT_NO_THROW(row = Describe(*d, patch)) << "uniform patch " << value;
    if (d->Kind() == DescriptorKind::kFloat && !row.empty()) {
      EXPECT_TRUE(cv::checkRange(row)) << "uniform patch " << value;
    }
  }
}

TEST_P(DescriptorConformance, RejectsPatchOfWrongSizeOrType) {
  const auto d = Make();
  cv::Mat row(1, d->Width(), RowType(*d));
  const int c = d->Channels();
  // A descriptor of any input size (empty InputSize: DenseVLAD) refuses patches below 16 x 16.
  const bool any_size = d->InputSize().empty();
  const std::vector<cv::Mat> wrong = {
      cv::Mat(),
      cv::Mat(any_size ? 15 : 63, 64, CV_8UC(c), cv::Scalar::all(9)),
      cv::Mat(64, any_size ? 15 : 65, CV_8UC(c), cv::Scalar::all(9)),
      cv::Mat(any_size ? 8 : 32, any_size ? 8 : 32, CV_8UC(c), cv::Scalar::all(9)),
      cv::Mat(64, 64, CV_8UC(c == 1 ? 2 : 1), cv::Scalar::all(9)),  // the other channel count
      cv::Mat(64, 64, CV_8UC(c == 3 ? 4 : 3), cv::Scalar::all(9)),
      cv::Mat(64, 64, CV_32FC1, cv::Scalar(9)),
      cv::Mat(64, 64, CV_16UC1, cv::Scalar(9)),
  };
  for (const cv::Mat& patch : wrong) {
    EXPECT_THROW(d->Describe(patch, row), std::logic_error)
        << patch.rows << " x " << patch.cols << " type " << patch.type();
  }
  const cv::Mat patch = PatchFor(*d, 64, 6);
  const int other_type = RowType(*d) == CV_8U ? CV_32F : CV_8U;
  EXPECT_THROW(d->Describe(patch, cv::Mat(1, d->Width() - 1, RowType(*d))), std::logic_error);
  EXPECT_THROW(d->Describe(patch, cv::Mat(1, d->Width(), other_type)), std::logic_error);
  EXPECT_THROW(d->Describe(patch, cv::Mat()), std::logic_error);
}

TEST_P(DescriptorConformance, DifferentImagesAreAtNonZeroDistance) {
  const auto d = Make();
  std::vector<cv::Mat> rows;
  for (int i = 0; i < 5; ++i) rows.push_back(Describe(*d, PatchFor(*d, 64, 100 + i)));
  for (std::size_t i = 0; i < rows.size(); ++i) {
    for (std::size_t j = i + 1; j < rows.size(); ++j) {
      EXPECT_GT(Distance(*d, rows[i], rows[j]), 0.0) << "images " << i << " and " << j;
    }
  }
}

TEST_P(DescriptorConformance, WorksAtOtherPatchSizes) {
  for (const int size : {16, 24, 32, 48, 96}) {
    const auto d = Make(size);
    EXPECT_EQ(d->PatchSize(), size);
    const cv::Mat a = PatchFor(*d, size, 200 + size);
    const cv::Mat b = PatchFor(*d, size, 300 + size);
    cv::Mat row_a, row_b;
    ASSERT_NO_THROW(row_a = Describe(*d, a)) << "patch size " << size;
    ASSERT_NO_THROW(row_b = Describe(*d, b)) << "patch size " << size;
    EXPECT_EQ(Distance(*d, row_a, Describe(*d, a.clone())), 0.0) << "patch size " << size;
    EXPECT_GT(Distance(*d, row_a, row_b), 0.0) << "patch size " << size;
  }
}

INSTANTIATE_TEST_SUITE_P(AllRegistered, DescriptorConformance,
                         ::testing::ValuesIn(RegisteredDescriptorNames()),
                         [](const ::testing::TestParamInfo<std::string>& info) {
                           std::string name = info.param;  // "D-LDB" -> "D_LDB"
                           for (char& ch : name)
                             if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
                           return name;
                         });

// The table above covers exactly the registered names.
TEST(DescriptorConformanceTable, CoversEveryRegisteredName) {
  const std::vector<std::string> names = RegisteredDescriptorNames();
  EXPECT_EQ(names.size(), ExpectedFor64().size());
  for (const std::string& name : names) EXPECT_EQ(ExpectedFor64().count(name), 1u) << name;
}

}  // namespace
}  // namespace openable
