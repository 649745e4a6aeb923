#include "descriptors/registry.h"

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/strings.h"
#include "descriptors/brief.h"
#include "descriptors/densevlad.h"
#include "descriptors/dldb.h"
#include "descriptors/freak.h"
#include "descriptors/hog.h"
#include "descriptors/ldb.h"
#include "descriptors/onnx.h"
#include "descriptors/opencv_descriptors.h"
#include "descriptors/sad.h"

namespace openable {
namespace {

using Factory = std::unique_ptr<Descriptor> (*)(const DescriptorOptions&);

template <typename T>
std::unique_ptr<Descriptor> Make(const DescriptorOptions& options) {
  return std::make_unique<T>(options);
}

struct Entry {
  const char* name;
  Factory create;
};

// The one table of descriptors, in the order shown to users.
const Entry kDescriptors[] = {
    {"LDB", &Make<LdbDescriptor>},      // descriptors/ldb.h
    {"D-LDB", &Make<DldbDescriptor>},   // descriptors/dldb.h (2-channel patch: grey, disparity)
    {"ORB", &Make<OrbDescriptor>},      // descriptors/opencv_descriptors.h
    {"BRISK", &Make<BriskDescriptor>},  // descriptors/opencv_descriptors.h
    {"BRIEF", &Make<BriefDescriptor>},  // descriptors/brief.h
    {"FREAK", &Make<FreakDescriptor>},  // descriptors/freak.h
    {"SIFT", &Make<SiftDescriptor>},    // descriptors/opencv_descriptors.h
    {"HOG", &Make<HogDescriptor>},      // descriptors/hog.h
    {"SAD", &Make<SadDescriptor>},      // descriptors/sad.h (SeqSLAM; byte values, L1 distance)
    // descriptors/densevlad.h (dense RootSIFT + VLAD, its vocabulary learnt from the reference)
    {"DENSEVLAD", &Make<DenseVladDescriptor>},
    {"ONNX", &Make<OnnxDescriptor>},  // descriptors/onnx.h (a network of the user's; Model_path)
};

struct Unavailable {
  const char* name;
  const char* reason;
};

const Unavailable kUnavailable[] = {
    {"SURF",
     "patented non-free code, absent from Debian's OpenCV build; use SIFT for a vector "
     "descriptor or LDB for a binary one"},
};

// "NPY": rows given by a file, not described (DescriptorOptions::given_width, given_binary).
// Not in the table: a user does not choose it (a run's given rows come from Descriptors_path,
// OpenABLE/run/given_rows.h), but a map of given rows names its channel so.
class RowsGivenDescriptor : public Descriptor {
 public:
  explicit RowsGivenDescriptor(const DescriptorOptions& options)
      : Descriptor(options), width_(options.given_width), binary_(options.given_binary) {
    if (width_ < 1)
      throw InputError(
          "Image_descriptor: NPY names rows given by a file (Descriptors_path, "
          "openable_map add --descriptors), not a descriptor to choose; expected "
          "one of the registered descriptors");
    // A bound for rows a map names (4 MB of floats a frame), far above any descriptor's.
    if (width_ > kMaxWidth)
      throw InputError("rows given of " + std::to_string(width_) +
                       " values a frame; expected at most " + std::to_string(kMaxWidth));
  }
  std::string Name() const override { return "NPY"; }
  int Width() const override { return width_; }
  DescriptorKind Kind() const override {
    return binary_ ? DescriptorKind::kBinary : DescriptorKind::kFloat;
  }

 protected:
  void DescribePatch(const cv::Mat&, cv::Mat) const override {
    throw InputError(
        "descriptor NPY: the rows were computed elsewhere and given; expected "
        "rows for these frames too (openable_map --descriptors FILE.npy)");
  }

 private:
  static constexpr int kMaxWidth = 1 << 20;
  int width_;
  bool binary_;
};

}  // namespace

std::vector<std::string> RegisteredDescriptorNames() {
  std::vector<std::string> names;
  for (const Entry& e : kDescriptors) {
    names.emplace_back(e.name);
  }
  return names;
}

std::vector<std::pair<std::string, std::string>> UnavailableDescriptors() {
  std::vector<std::pair<std::string, std::string>> out;
  for (const Unavailable& u : kUnavailable) {
    out.emplace_back(u.name, u.reason);
  }
  return out;
}

std::unique_ptr<Descriptor> CreateDescriptor(const std::string& name,
                                             const DescriptorOptions& options) {
  const std::string key = Upper(name);
  if (key == "NPY") return std::make_unique<RowsGivenDescriptor>(options);
  for (const Entry& e : kDescriptors) {
    if (key == e.name) {
      return e.create(options);
    }
  }
  for (const Unavailable& u : kUnavailable) {
    if (key == u.name) {
      throw InputError("Image_descriptor: \"" + name + "\" is not available: " + u.reason);
    }
  }
  std::string valid;
  for (const Entry& e : kDescriptors) {
    if (!valid.empty()) {
      valid += ", ";
    }
    valid += e.name;
  }
  throw InputError("Image_descriptor: unknown descriptor \"" + name + "\"; expected one of " +
                   valid);
}

std::unique_ptr<Descriptor> CreateDescriptor(const DescriptorOptions& options) {
  return CreateDescriptor(options.name, options);
}

std::vector<std::string> DescriptorList(const std::string& value) {
  std::vector<std::string> names;
  std::string item;
  const auto take = [&] {
    const std::string name = Upper(Trim(item));
    item.clear();
    if (name.empty())
      throw InputError("Image_descriptor: \"" + value +
                       "\" has an empty name; expected one "
                       "descriptor name, or several joined by + or , (e.g. HOG+LDB)");
    for (const std::string& seen : names)
      if (seen == name)
        throw InputError("Image_descriptor: \"" + value + "\" names " + name +
                         " twice; expected each fused descriptor once");
    bool known = name == "NPY";  // rows given (RowsGivenDescriptor)
    for (const Entry& e : kDescriptors) known = known || name == e.name;
    if (!known) CreateDescriptor(name, DescriptorOptions());  // throws the unknown-name error
    names.push_back(name);
  };
  for (const char ch : value) {
    if (ch == '+' || ch == ',') {
      take();
    } else {
      item += ch;
    }
  }
  take();
  return names;
}

}  // namespace openable
