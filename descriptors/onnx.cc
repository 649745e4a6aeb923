#include "descriptors/onnx.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/hash.h"
#include "OpenABLE/base/input_file.h"
#include "OpenABLE/base/module_loader.h"
#include "OpenABLE/base/strings.h"

namespace openable {
namespace {

using OpenableDnnLoad = void (*)(const std::string&, std::unique_ptr<OnnxNetwork>&);

// OpenCV's message on one line: its lines joined, runs of spaces made one, at most 400
// characters (its messages quote the failed assertion and the node, over several lines).
std::string OneLine(const std::string& text) {
  std::string out;
  for (const char c : text) {
    const char d = std::isspace(static_cast<unsigned char>(c)) ? ' ' : c;
    if (d == ' ' && (out.empty() || out.back() == ' ')) continue;
    out += d;
  }
  while (!out.empty() && out.back() == ' ') out.pop_back();
  if (out.size() > 400) out = out.substr(0, 397) + "...";
  return out;
}

cv::Size ParseInputSize(const std::string& text) {
  const std::string t = Lower(Trim(text));
  const std::size_t x = t.find('x');
  int w = 0, h = 0;
  const auto whole = [](const std::string& s, int& v) {
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    return ec == std::errc() && end == s.data() + s.size() && !s.empty();
  };
  if (x == std::string::npos || !whole(t.substr(0, x), w) || !whole(t.substr(x + 1), h) || w < 1 ||
      h < 1 || w > 4096 || h > 4096)
    throw InputError("Model_input_size: " + Quoted(text) +
                     (t.empty() ? " is empty" : " is not valid") +
                     "; expected the network's input as WxH in pixels, each in [1, 4096] (e.g. "
                     "224x224; docs/descriptors.md lists what common networks take)");
  return cv::Size(w, h);
}

std::vector<float> ParseValues(const char* key, const std::string& text, int channels,
                               bool positive) {
  std::vector<float> values;
  for (const std::string& item : SplitTrimmed(text, ',')) {
    double v = 0;
    const auto [end, ec] = std::from_chars(item.data(), item.data() + item.size(), v);
    if (item.empty() || ec != std::errc() || end != item.data() + item.size() ||
        !std::isfinite(v) || (positive && v <= 0))
      throw InputError(std::string(key) + ": " + Quoted(text) + " has " + Quoted(item) +
                       "; expected " + (positive ? "positive " : "") +
                       "numbers separated by commas, one per channel");
    values.push_back(static_cast<float>(v));
  }
  if (values.size() == 1) values.assign(static_cast<std::size_t>(channels), values.front());
  if (static_cast<int>(values.size()) != channels)
    throw InputError(std::string(key) + ": " + Quoted(text) + " has " +
                     std::to_string(values.size()) + " values; expected " +
                     std::to_string(channels) + " (one per channel of Model_channels) or one");
  return values;
}

}  // namespace

OnnxDescriptor::OnnxDescriptor(const DescriptorOptions& options)
    : Descriptor(options), path_(options.model_path), normalize_(options.model_normalize) {
  if (Trim(path_).empty())
    throw InputError(
        "Model_path: empty; expected the .onnx file of the network "
        "(Image_descriptor ONNX)");
  const std::string channels = Lower(Trim(options.model_channels));
  if (channels == "rgb") {
    order_ = Order::kRgb;
  } else if (channels == "bgr") {
    order_ = Order::kBgr;
  } else if (channels == "grey" || channels == "gray") {
    order_ = Order::kGrey;
  } else {
    throw InputError("Model_channels: " + Quoted(options.model_channels) +
                     " is not valid; expected rgb, bgr or grey (the channels the network takes, "
                     "in order)");
  }
  const int c = order_ == Order::kGrey ? 1 : 3;
  mean_ = ParseValues("Model_mean", options.model_mean, c, false);
  std_ = ParseValues("Model_std", options.model_std, c, true);
  input_ = ParseInputSize(options.model_input_size);

  // The file: read once for its digest (the descriptor cache keys rows by the weights too) and
  // checked to be a file before OpenCV sees it.
  const std::string name = "Model_path " + Quoted(path_);
  const std::string bytes = ReadInputFile(path_, name, "expected an ONNX network (.onnx)");
  char digest[17];
  std::snprintf(digest, sizeof digest, "%016llx",
                static_cast<unsigned long long>(Fnv1a64(bytes.data(), bytes.size())));
  fingerprint_ = std::string(digest) + ":" + std::to_string(bytes.size());
  // An ONNX file is a protobuf ModelProto, whose first field written is ir_version (field 1,
  // varint: the byte 0x08). Anything else (an image, a text file, a PyTorch checkpoint, which
  // is a ZIP archive) is told apart here with a clearer line than the importer's.
  if (bytes.empty() || static_cast<unsigned char>(bytes[0]) != 0x08)
    throw InputError(name + ": not an ONNX network (an ONNX file begins with its ir_version; " +
                     (bytes.compare(0, 2, "PK") == 0
                          ? std::string("this is a ZIP archive, as PyTorch's .pt checkpoints "
                                        "are: export it with torch.onnx.export")
                          : std::string("this file does not")) +
                     "); expected a .onnx file");
  try {
    reinterpret_cast<OpenableDnnLoad>(ModuleSymbol("dnn", "openable_dnn_load"))(path_, network_);
  } catch (const cv::Exception& e) {
    throw InputError(name + ": OpenCV " CV_VERSION " cannot import it: " + OneLine(e.what()) +
                     " (docs/descriptors.md lists the operators it reads)");
  }
  // Once on blank images: the output's width, and whether the network takes batches (an
  // export without a dynamic batch axis takes one image at a time).
  const cv::Mat blank(input_, CV_8UC3, cv::Scalar::all(128));
  const auto width_of = [&](int n, std::string* why) {
    cv::Mat out;
    try {
      out = network_->Forward(Blob(std::vector<cv::Mat>(static_cast<std::size_t>(n), blank)));
    } catch (const cv::Exception& e) {
      *why = OneLine(e.what());
      return -1;
    }
    const std::size_t total = out.total();
    const bool one_vector_each =
        out.dims >= 2 && out.size[0] == n && total % static_cast<std::size_t>(n) == 0 && [&] {
          // N x D, or N x D x 1 x 1 (a pooled convolution): one axis beyond N of size > 1.
          int wide = 0;
          for (int d = 1; d < out.dims; ++d) wide += out.size[d] > 1 ? 1 : 0;
          return wide <= 1;
        }();
    if (!one_vector_each) {
      std::string shape;
      for (int d = 0; d < out.dims; ++d) shape += (d ? " x " : "") + std::to_string(out.size[d]);
      *why = "its output is " + shape + " for " + std::to_string(n) + " image" +
             (n == 1 ? "" : "s") + ", not one vector per image";
      return 0;
    }
    return static_cast<int>(total / static_cast<std::size_t>(n));
  };
  std::string why;
  const int wanted = options.model_batch;
  int width = wanted > 1 ? width_of(2, &why) : -1;
  batch_ = wanted;
  if (width <= 0) {  // a network of fixed batch 1, or an output that is not one vector each
    std::string why_one;
    width = width_of(1, &why_one);
    batch_ = 1;
    if (width <= 0)
      throw InputError(
          name + ": " +
          (width == 0 ? why_one
                      : "the network does not run on a " + std::to_string(input_.width) + "x" +
                            std::to_string(input_.height) + " " + (c == 1 ? "grey" : "colour") +
                            " image (Model_input_size, Model_channels): " + why_one) +
          "; expected a network whose output is one vector per image");
  }
  width_ = width;
}

cv::Mat OnnxDescriptor::Blob(const std::vector<cv::Mat>& patches) const {
  const int c = order_ == Order::kGrey ? 1 : 3;
  const int sizes[] = {static_cast<int>(patches.size()), c, input_.height, input_.width};
  cv::Mat blob(4, sizes, CV_32F);
  const std::size_t plane = static_cast<std::size_t>(input_.area());
  cv::Mat grey;
  for (std::size_t n = 0; n < patches.size(); ++n) {
    const cv::Mat& p = patches[n];
    if (p.type() != CV_8UC3 || p.size() != input_)
      throw std::logic_error("ONNX: expected a " + std::to_string(input_.width) + "x" +
                             std::to_string(input_.height) + " CV_8UC3 patch");
    float* out = blob.ptr<float>() + n * static_cast<std::size_t>(c) * plane;
    if (order_ == Order::kGrey) cv::cvtColor(p, grey, cv::COLOR_BGR2GRAY);
    for (int y = 0; y < input_.height; ++y) {
      const unsigned char* in =
          order_ == Order::kGrey ? grey.ptr<unsigned char>(y) : p.ptr<unsigned char>(y);
      for (int x = 0; x < input_.width; ++x) {
        const std::size_t at = static_cast<std::size_t>(y) * input_.width + x;
        for (int k = 0; k < c; ++k) {
          // OpenCV holds BGR: channel k of an RGB network is the pixel's byte 2 - k.
          const int byte = order_ == Order::kGrey ? x : 3 * x + (order_ == Order::kRgb ? 2 - k : k);
          out[static_cast<std::size_t>(k) * plane + at] =
              (static_cast<float>(in[byte]) / 255.0f - mean_[static_cast<std::size_t>(k)]) /
              std_[static_cast<std::size_t>(k)];
        }
      }
    }
  }
  return blob;
}

void OnnxDescriptor::Run(const std::vector<cv::Mat>& patches, cv::Mat rows) const {
  const cv::Mat blob = Blob(patches);
  cv::Mat out;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    try {
      out = network_->Forward(blob);
    } catch (const cv::Exception& e) {
      throw InputError("Model_path " + Quoted(path_) + ": the network failed on a batch of " +
                       std::to_string(patches.size()) + ": " + OneLine(e.what()));
    }
  }
  const int n = static_cast<int>(patches.size());
  if (out.dims < 2 || out.size[0] != n || out.total() != static_cast<std::size_t>(n) * width_)
    throw InputError("Model_path " + Quoted(path_) + ": the network gave " +
                     std::to_string(out.total()) + " values for " + std::to_string(n) +
                     " images; expected " + std::to_string(width_) + " each, as on its first run");
  const cv::Mat flat(n, width_, CV_32F, out.ptr<float>());
  for (int i = 0; i < n; ++i) {
    cv::Mat row = rows.row(i);
    flat.row(i).copyTo(row);
    if (normalize_) {
      const double norm = cv::norm(row, cv::NORM_L2);
      if (norm > 0) row *= 1.0 / norm;
    }
  }
}

void OnnxDescriptor::DescribeBatch(const std::vector<cv::Mat>& patches, cv::Mat rows) const {
  if (rows.rows != static_cast<int>(patches.size()) || rows.cols != width_ || rows.type() != CV_32F)
    throw std::logic_error("ONNX: rows of another shape than the patches");
  for (std::size_t at = 0; at < patches.size(); at += static_cast<std::size_t>(batch_)) {
    const std::size_t end = std::min(patches.size(), at + static_cast<std::size_t>(batch_));
    Run(std::vector<cv::Mat>(patches.begin() + static_cast<std::ptrdiff_t>(at),
                             patches.begin() + static_cast<std::ptrdiff_t>(end)),
        rows.rowRange(static_cast<int>(at), static_cast<int>(end)));
  }
}

void OnnxDescriptor::DescribePatch(const cv::Mat& patch, cv::Mat row) const { Run({patch}, row); }

}  // namespace openable
