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
  const char* help;  // what it is and how its rows are compared, for Image_descriptor's help
};

// The one table of descriptors, in the order shown to users.
const Entry kDescriptors[] = {
    {"LDB", &Make<LdbDescriptor>, "binary, Hamming distance"},  // descriptors/ldb.h
    {"D-LDB", &Make<DldbDescriptor>,                            // descriptors/dldb.h
     "LDB of the grey and of the disparity image; binary, Hamming distance; needs Camera_type 1"},
    {"ORB", &Make<OrbDescriptor>, "binary, Hamming distance"},  // opencv_descriptors.h
    {"BRISK", &Make<BriskDescriptor>, "binary, Hamming distance"},
    {"BRIEF", &Make<BriefDescriptor>, "binary, Hamming distance"},  // descriptors/brief.h
    {"FREAK", &Make<FreakDescriptor>, "binary, Hamming distance"},  // descriptors/freak.h
    {"SIFT", &Make<SiftDescriptor>, "float rows, L2 distance"},     // opencv_descriptors.h
    {"HOG", &Make<HogDescriptor>, "float rows, L2 distance"},       // descriptors/hog.h
    {"SAD", &Make<SadDescriptor>,                                   // descriptors/sad.h
     "SeqSLAM's patch-normalised thumbnail, sum of absolute differences; Sad_patch"},
    {"DENSEVLAD", &Make<DenseVladDescriptor>,  // descriptors/densevlad.h
     "dense RootSIFT aggregated by VLAD over a vocabulary learnt from the frames of "
     "Images_path, no ground truth; robust to a change of viewpoint and of light; float rows, "
     "L2 distance; not in maps or the online detector"},
    {"ONNX", &Make<OnnxDescriptor>,  // descriptors/onnx.h
     "a network of the user's, Model_path; float rows, L2 distance"},
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

std::string DescriptorHelp() {
  std::string text;
  for (const Entry& e : kDescriptors)
    text += (text.empty() ? "" : ", ") + std::string(e.name) + " (" + e.help + ")";
  for (const Unavailable& u : kUnavailable)
    text += ". " + std::string(u.name) + " is not available: " + u.reason;
  return text;
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
