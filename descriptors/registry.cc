#include "descriptors/registry.h"

#include <cctype>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "OpenABLE/base/error.h"
#include "descriptors/brief.h"
#include "descriptors/freak.h"
#include "descriptors/dldb.h"
#include "descriptors/hog.h"
#include "descriptors/ldb.h"
#include "descriptors/opencv_descriptors.h"

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

std::string Upper(const std::string& s) {
  std::string out = s;
  for (char& c : out) {
    c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  }
  return out;
}

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
  for (const Entry& e : kDescriptors) {
    if (key == e.name) {
      options.Check();
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

void DescriptorOptions::Check() const {
  if (patch_size < 16) {
    throw InputError("Patch_size: " + std::to_string(patch_size) +
                     " is too small; expected an integer >= 16");
  }
  if (ldb_bits < 1 || ldb_bits > 1386) {
    throw InputError("Ldb_bits: " + std::to_string(ldb_bits) +
                     " is out of range; expected an integer in [1, 1386]");
  }
}

}  // namespace openable
