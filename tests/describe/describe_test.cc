#include "OpenABLE/describe/describe.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <atomic>

#include "OpenABLE/base/error.h"

namespace openable {
namespace {

// A descriptor whose one float is the mean grey value of the patch: it makes the global and
// grid geometry checkable by hand.
class MeanDescriptor : public Descriptor {
 public:
  explicit MeanDescriptor(int patch) : Descriptor(OptionsOf(patch)) {}
  std::string Name() const override { return "MEAN"; }
  int Width() const override { return 1; }
  DescriptorKind Kind() const override { return DescriptorKind::kFloat; }

 private:
  static DescriptorOptions OptionsOf(int patch) {
    DescriptorOptions o;
    o.patch_size = patch;
    return o;
  }
  void DescribePatch(const cv::Mat& patch, cv::Mat row) const override {
    if (patch.rows != PatchSize() || patch.cols != PatchSize() || patch.type() != CV_8UC1)
      throw std::logic_error("bad patch");
    row.at<float>(0, 0) = static_cast<float>(cv::mean(patch)[0]);
  }
};

// Frames in memory; frames listed in `broken` throw InputError like an unreadable file.
class MemorySource : public FrameSource {
 public:
  MemorySource(std::vector<cv::Mat> frames, std::vector<int> broken, bool parallel)
      : frames_(std::move(frames)), broken_(std::move(broken)), parallel_(parallel) {}
  int Size() const override { return static_cast<int>(frames_.size()); }
  std::string FrameName(int i) const override { return "frame" + std::to_string(i); }
  cv::Mat Read(int i) const override {
    for (int b : broken_)
      if (b == i) throw InputError("image \"frame" + std::to_string(i) + "\" cannot be decoded");
    return frames_[i];
  }
  bool ParallelReads() const override { return parallel_; }

 private:
  std::vector<cv::Mat> frames_;
  std::vector<int> broken_;
  bool parallel_;
};

cv::Mat Constant(int rows, int cols, float v) {
  return cv::Mat(rows, cols, CV_32FC1, cv::Scalar(v));
}

TEST(FrameDescriber, GridCellsInRowMajorOrder) {
  // A 40x60 frame whose quadrants are 0.0, 0.2 / 0.4, 0.6 (x 255 after grey conversion).
  cv::Mat1b frame(40, 60);
  for (int y = 0; y < 40; ++y)
    for (int x = 0; x < 60; ++x) frame(y, x) = static_cast<uchar>(10 * ((y >= 20) * 2 + (x >= 30)));
  MeanDescriptor mean(16);
  const FrameDescriber grid(mean, DescriptionType::kGrid, 2, 2);
  ASSERT_EQ(grid.RowWidth(), 4);
  cv::Mat row(1, 4, CV_32F);
  grid.Describe(frame, row);
  for (int c = 0; c < 4; ++c) EXPECT_NEAR(row.at<float>(0, c), 10.f * c, 1e-4) << c;

  const FrameDescriber global(mean, DescriptionType::kGlobal, 2, 2);  // grid ignored
  ASSERT_EQ(global.RowWidth(), 1);
  cv::Mat one(1, 1, CV_32F);
  global.Describe(frame, one);
  EXPECT_NEAR(one.at<float>(0, 0), 15.f, 0.5f);
}

TEST(DescribeSequence, ParallelAndSerialAgreeAndKeepOrder) {
  std::vector<cv::Mat> frames;
  for (int i = 0; i < 37; ++i) frames.push_back(Constant(12, 20, (3 * i + 0.25f) / 255.f));
  MeanDescriptor mean(16);
  const FrameDescriber d(mean, DescriptionType::kGlobal);
  for (bool parallel : {true, false}) {
    MemorySource src(frames, {}, parallel);
    DescribeOptions opt;
    opt.threads = 3;
    int last = 0;
    const DescribedSequence seq = DescribeSequence(src, d, opt, [&](int done, int total) {
      EXPECT_EQ(total, 37);
      EXPECT_EQ(done, last + 1);
      last = done;
    });
    EXPECT_EQ(last, 37);
    ASSERT_EQ(seq.rows.rows, 37);
    EXPECT_EQ(seq.frame_size, cv::Size(20, 12));
    for (int i = 0; i < 37; ++i)
      EXPECT_NEAR(seq.rows.at<float>(i, 0), 3 * i, 1e-4) << i;  // grey level 3i + 0.25 rounds to 3i
  }
}

TEST(DescribeSequence, UnreadableFrameStopsAndIsNamed) {
  std::vector<cv::Mat> frames(10, Constant(8, 8, 0.5f));
  MeanDescriptor mean(16);
  const FrameDescriber d(mean, DescriptionType::kGlobal);
  MemorySource src(frames, {6, 3}, true);
  DescribeOptions opt;
  opt.key = "Images_path";
  try {
    DescribeSequence(src, d, opt);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    // The lowest failing frame is reported, whatever thread saw it first.
    EXPECT_EQ(std::string(e.what()), "Images_path: image \"frame3\" cannot be decoded");
  }
}

TEST(DescribeSequence, SkipModeDropsUnreadableFrames) {
  std::vector<cv::Mat> frames;
  for (int i = 0; i < 6; ++i) frames.push_back(Constant(8, 8, i / 10.f));
  MeanDescriptor mean(16);
  const FrameDescriber d(mean, DescriptionType::kGlobal);
  MemorySource src(frames, {1, 4}, false);
  DescribeOptions opt;
  opt.skip_unreadable = true;
  const DescribedSequence seq = DescribeSequence(src, d, opt);
  EXPECT_EQ(seq.kept, (std::vector<int>{0, 2, 3, 5}));
  ASSERT_EQ(seq.skipped.size(), 2u);
  EXPECT_NE(seq.skipped[0].find("frame1"), std::string::npos);
  EXPECT_NEAR(seq.rows.at<float>(1, 0), std::round(0.2f * 255), 1e-4);

  MemorySource all_bad(frames, {0, 1, 2, 3, 4, 5}, true);
  EXPECT_THROW(DescribeSequence(all_bad, d, opt), InputError);
}

// Counts the reads of each frame (from several threads).
class CountingSource : public MemorySource {
 public:
  using MemorySource::MemorySource;
  cv::Mat Read(int i) const override {
    ++reads_[static_cast<size_t>(i)];
    return MemorySource::Read(i);
  }
  int Reads(int i) const { return reads_[static_cast<size_t>(i)].load(); }

 private:
  mutable std::array<std::atomic<int>, 64> reads_{};
};

// A cache in memory holding the rows of the frames listed.
class MemoryCache : public RowCache {
 public:
  MemoryCache(const cv::Mat& rows, std::vector<int> held) : rows_(rows), held_(std::move(held)) {}
  bool Lookup(const FrameSource&, int i, cv::Mat row, cv::Size* size) override {
    if (std::find(held_.begin(), held_.end(), i) == held_.end()) return false;
    rows_.row(i).copyTo(row);
    *size = cv::Size(40, 24);
    return true;
  }
  void Store(const FrameSource&, int, const cv::Mat&, cv::Size) override { ++stored; }
  std::atomic<int> stored{0};

 private:
  cv::Mat rows_;
  std::vector<int> held_;
};

// Several descriptors of one source: each frame read once for all of them, each descriptor's
// rows those it gets alone; with a cache holding some rows of one descriptor, the frames are
// still read for the other, and rows come from the cache where it has them.
TEST(DescribeSequences, ReadEachFrameOnceAndGiveEachDescriptorsOwnRows) {
  std::vector<cv::Mat> frames;
  for (int i = 0; i < 30; ++i) frames.push_back(Constant(24, 40, (5 * i + 0.25f) / 255.f));
  MeanDescriptor small(16), large(32);
  const FrameDescriber global(large, DescriptionType::kGlobal);
  const FrameDescriber grid(small, DescriptionType::kGrid, 2, 1);
  for (const bool parallel : {true, false}) {
    CountingSource src(frames, {}, parallel);
    DescribeOptions opt;
    opt.threads = 3;
    const std::vector<DescribedSequence> both =
        DescribeSequences(src, {&global, &grid}, {nullptr, nullptr}, opt);
    for (int i = 0; i < 30; ++i) EXPECT_EQ(src.Reads(i), 1) << i;
    ASSERT_EQ(both.size(), 2u);
    MemorySource plain(frames, {}, parallel);
    EXPECT_EQ(cv::norm(both[0].rows, DescribeSequence(plain, global, opt).rows, cv::NORM_INF), 0);
    EXPECT_EQ(cv::norm(both[1].rows, DescribeSequence(plain, grid, opt).rows, cv::NORM_INF), 0);
    EXPECT_EQ(both[1].rows.cols, 2);
    EXPECT_EQ(both[0].kept, both[1].kept);
  }
  // The cache of the first descriptor holds frames 0-9 with other values (-1): they are kept.
  CountingSource src(frames, {}, true);
  MemoryCache cache(cv::Mat(30, 1, CV_32F, cv::Scalar(-1)), {0, 1, 2, 3, 4, 5, 6, 7, 8, 9});
  DescribeOptions opt;
  const std::vector<DescribedSequence> both =
      DescribeSequences(src, {&global, &grid}, {&cache, nullptr}, opt);
  for (int i = 0; i < 30; ++i) EXPECT_EQ(src.Reads(i), 1) << i;  // the grid needs every frame
  EXPECT_EQ(both[0].rows.at<float>(3, 0), -1.0f);
  EXPECT_NEAR(both[0].rows.at<float>(12, 0), 60.0f, 1e-4);
  EXPECT_EQ(cache.stored.load(), 20);  // the rows it lacked
  // Both descriptors cached for every frame: nothing is read.
  std::vector<int> every(30);
  for (int i = 0; i < 30; ++i) every[static_cast<size_t>(i)] = i;
  MemoryCache first(cv::Mat(30, 1, CV_32F, cv::Scalar(7)), every);
  MemoryCache second(cv::Mat(30, 2, CV_32F, cv::Scalar(8)), every);
  CountingSource unread(frames, {}, true);
  const std::vector<DescribedSequence> cached =
      DescribeSequences(unread, {&global, &grid}, {&first, &second}, opt);
  for (int i = 0; i < 30; ++i) EXPECT_EQ(unread.Reads(i), 0) << i;
  EXPECT_EQ(cached[1].rows.at<float>(29, 1), 8.0f);
}

TEST(DescribeSequence, FramesOfDifferentSizesAreAnError) {
  std::vector<cv::Mat> frames = {Constant(8, 8, 0), Constant(8, 8, 0), Constant(9, 8, 0)};
  MeanDescriptor mean(16);
  const FrameDescriber d(mean, DescriptionType::kGlobal);
  MemorySource src(frames, {}, true);
  try {
    DescribeSequence(src, d, DescribeOptions());
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("\"frame2\" is 8x9"), std::string::npos) << msg;
    EXPECT_NE(msg.find("is 8x8"), std::string::npos) << msg;
  }
}

}  // namespace
}  // namespace openable
