// The ONNX descriptor against PyTorch: three small networks of the families users bring
// (NetVLAD, GeM, a linear projection; random weights of a fixed seed), exported by
// tests/data/onnx/make_models.py with PyTorch's outputs on the first 16 frames of the bundled
// Nordland sample. OpenCV's DNN module must give the same vectors from the same frames read and
// prepared by the descriptor (RGB, scaled to [0, 1], ImageNet's mean and deviation).
#include "descriptors/onnx.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "OpenABLE/base/error.h"
#include "OpenABLE/io/npy.h"
#include "descriptors/frame_describer.h"
#include "descriptors/registry.h"
#include "tests/test_support.h"

namespace openable {
namespace {

std::string DataDir() { return testing::SourceDir() + "/tests/data/onnx"; }

std::string ReadBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// The 16 frames PyTorch described, as OpenCV reads them (BGR, 64 x 32).
std::vector<cv::Mat> Frames() {
  std::vector<cv::Mat> frames;
  std::ifstream list(DataDir() + "/frames.txt");
  for (std::string name; std::getline(list, name);)
    if (!name.empty())
      frames.push_back(
          cv::imread(testing::SourceDir() + "/examples/data/nordland_sample/summer/" + name));
  return frames;
}

DescriptorOptions Model(const std::string& name) {
  DescriptorOptions o;
  o.name = "ONNX";
  o.model_path = DataDir() + "/" + name + ".onnx";
  o.model_input_size = "64x32";
  return o;
}

std::string ErrorOf(const DescriptorOptions& o) {
  try {
    OnnxDescriptor d(o);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// The outputs agree to 1e-5 (observed: 4e-8 to 8e-8, the rounding of float sums taken in
// another order by OpenCV's convolutions than by PyTorch's); the vectors' entries are of order
// 0.01 to 0.4, so a wrong layer, channel order or normalisation differs by far more.
constexpr double kTolerance = 1e-5;

TEST(OnnxDescriptor, GivesPyTorchsVectorsOnTheBundledFrames) {
  const std::vector<cv::Mat> frames = Frames();
  ASSERT_EQ(frames.size(), 16u);
  for (const char* name : {"netvlad", "gem", "projection"}) {
    DescriptorOptions o = Model(name);
    // The projection network's output is not normalised; the others normalise their own.
    o.model_normalize = false;
    const std::unique_ptr<Descriptor> d = CreateDescriptor(o);
    const cv::Mat1f expected =
        DecodeNpyMatrix(ReadBytes(DataDir() + "/" + name + "_outputs.npy"), name);
    ASSERT_EQ(d->Width(), expected.cols) << name;
    EXPECT_EQ(d->Kind(), DescriptorKind::kFloat);
    EXPECT_EQ(d->Channels(), 3);
    EXPECT_EQ(d->InputSize(), cv::Size(64, 32));
    cv::Mat rows(16, d->Width(), CV_32F);
    d->DescribeBatch(frames, rows);
    EXPECT_LE(cv::norm(rows, expected, cv::NORM_INF), kTolerance) << name;
    // One at a time, the same vectors.
    for (int i = 0; i < 16; ++i) {
      cv::Mat row(1, d->Width(), CV_32F);
      d->Describe(frames[static_cast<size_t>(i)], row);
      EXPECT_LE(cv::norm(row, expected.row(i), cv::NORM_INF), kTolerance) << name << " " << i;
    }
  }
}

TEST(OnnxDescriptor, NormalisesRowsWhenAsked) {
  const std::vector<cv::Mat> frames = Frames();
  const cv::Mat1f raw = DecodeNpyMatrix(ReadBytes(DataDir() + "/projection_outputs.npy"), "p");
  const std::unique_ptr<Descriptor> d = CreateDescriptor(Model("projection"));  // normalise: on
  cv::Mat rows(16, d->Width(), CV_32F);
  d->DescribeBatch(frames, rows);
  for (int i = 0; i < 16; ++i) {
    EXPECT_NEAR(cv::norm(rows.row(i)), 1.0, 1e-6);
    EXPECT_LE(cv::norm(rows.row(i), raw.row(i) / cv::norm(raw.row(i)), cv::NORM_INF), kTolerance);
  }
}

// A frame described as a run describes it: the frame resized to the network's input, in
// batches of Model_batch, cells and sub-panoramas as for any descriptor.
TEST(OnnxDescriptor, FrameDescriberBatchesAndCutsCells) {
  const std::vector<cv::Mat> frames = Frames();
  DescriptorOptions o = Model("gem");
  o.model_batch = 5;  // batches of 5 patches: 16 frames in batches of 5, 5, 5 and 1
  const std::unique_ptr<Descriptor> d = CreateDescriptor(o);
  EXPECT_EQ(d->PreferredBatch(), 5);
  const FrameDescriber whole(*d, DescriptionType::kGlobal);
  ASSERT_TRUE(whole.Batched());
  std::vector<cv::Mat> patches;
  for (const cv::Mat& f : frames)
    for (cv::Mat& p : whole.Patches(f)) patches.push_back(p);
  cv::Mat rows(16, whole.RowWidth(), CV_32F);
  whole.DescribePatches(patches, rows);
  const cv::Mat1f expected = DecodeNpyMatrix(ReadBytes(DataDir() + "/gem_outputs.npy"), "g");
  EXPECT_LE(cv::norm(rows, expected, cv::NORM_INF), kTolerance);
  // A 2 x 1 grid of a frame twice as wide: each half is one of the frames, unresized.
  cv::Mat wide;
  cv::hconcat(frames[0], frames[1], wide);
  const FrameDescriber grid(*d, DescriptionType::kGrid, 2, 1);
  cv::Mat row(1, grid.RowWidth(), CV_32F);
  grid.Describe(wide, row);
  EXPECT_LE(cv::norm(row.colRange(0, d->Width()), expected.row(0), cv::NORM_INF), kTolerance);
  EXPECT_LE(cv::norm(row.colRange(d->Width(), 2 * d->Width()), expected.row(1), cv::NORM_INF),
            kTolerance);
}

TEST(OnnxDescriptor, WeightsAreInTheFingerprint) {
  const std::unique_ptr<Descriptor> gem = CreateDescriptor(Model("gem"));
  const std::unique_ptr<Descriptor> again = CreateDescriptor(Model("gem"));
  const std::unique_ptr<Descriptor> other = CreateDescriptor(Model("projection"));
  EXPECT_FALSE(gem->Fingerprint().empty());
  EXPECT_EQ(gem->Fingerprint(), again->Fingerprint());
  EXPECT_NE(gem->Fingerprint(), other->Fingerprint());
}

// Bad models and settings: one line naming the key and the value, with what was expected.
TEST(OnnxDescriptor, BadModelsAndSettingsAreOneLine) {
  const std::string dir = testing::TempDir();
  const auto expect = [](const std::string& error, const std::string& part) {
    EXPECT_NE(error.find(part), std::string::npos) << error;
    EXPECT_EQ(error.find('\n'), std::string::npos) << error;
  };
  DescriptorOptions o = Model("gem");
  o.model_path = "";
  expect(ErrorOf(o), "Model_path: empty; expected the .onnx file");
  o.model_path = dir + "/absent.onnx";
  expect(ErrorOf(o), "absent.onnx");
  // A file that is not ONNX: an image, a PyTorch checkpoint (a ZIP archive).
  o.model_path = testing::SourceDir() + "/examples/data/nordland_sample/summer/images-00010.png";
  expect(ErrorOf(o), "not an ONNX network");
  std::ofstream(dir + "/model.pt", std::ios::binary) << "PK\x03\x04 not a network";
  o.model_path = dir + "/model.pt";
  expect(ErrorOf(o), "export it with torch.onnx.export");
  // A damaged network: OpenCV's reason, on one line.
  const std::string bytes = ReadBytes(DataDir() + "/gem.onnx");
  std::ofstream(dir + "/truncated.onnx", std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  o.model_path = dir + "/truncated.onnx";
  expect(ErrorOf(o), "cannot import it: ");
  // An input size the network refuses (it takes 8 x 8 images only).
  o = Model("fixed_input");
  expect(ErrorOf(o), "the network does not run on a 64x32 colour image");
  o.model_input_size = "8x8";
  EXPECT_EQ(ErrorOf(o), "");
  // An output that is a map per image, not a vector.
  expect(ErrorOf(Model("feature_map")),
         "its output is 1 x 4 x 32 x 64 for 1 image, not one "
         "vector per image");
  // Channels the network does not take.
  o = Model("gem");
  o.model_channels = "grey";
  o.model_mean = "0.5";
  o.model_std = "0.25";
  expect(ErrorOf(o), "does not run on a 64x32 grey image");
  // Settings.
  o = Model("gem");
  o.model_input_size = "64";
  expect(ErrorOf(o), "Model_input_size: \"64\" is not valid; expected the network's input as WxH");
  o = Model("gem");
  o.model_input_size = "";
  expect(ErrorOf(o), "Model_input_size: \"\" is empty");
  o = Model("gem");
  o.model_channels = "yuv";
  expect(ErrorOf(o), "Model_channels: \"yuv\" is not valid; expected rgb, bgr or grey");
  o = Model("gem");
  o.model_mean = "0.4,0.5";
  expect(ErrorOf(o), "Model_mean: \"0.4,0.5\" has 2 values; expected 3");
  o = Model("gem");
  o.model_std = "0.2,0,0.2";
  expect(ErrorOf(o), "Model_std: \"0.2,0,0.2\" has \"0\"; expected positive numbers");
}

}  // namespace
}  // namespace openable
