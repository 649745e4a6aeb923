#include "descriptors/registry.h"

#include <gtest/gtest.h>

#include <set>
#include <string>
#include <vector>

#include "OpenABLE/base/error.h"
#include "descriptors/brief.h"
#include "descriptors/freak.h"
#include "descriptors/hog.h"
#include "descriptors/ldb.h"
#include "descriptors/opencv_descriptors.h"
#include "tests/test_support.h"

namespace openable {
namespace {

using testing::InputErrorMessage;

bool Contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

DescriptorOptions Options(int patch_size, int ldb_bits = 256) {
  DescriptorOptions o;
  o.patch_size = patch_size;
  o.ldb_bits = ldb_bits;
  return o;
}

TEST(Registry, ListsTheBuiltDescriptorsInOrder) {
  EXPECT_EQ(RegisteredDescriptorNames(),
            (std::vector<std::string>{"LDB", "D-LDB", "ORB", "BRISK", "BRIEF", "FREAK", "SIFT",
                                      "HOG", "SAD", "DENSEVLAD", "ONNX"}));
}

TEST(Registry, ListsUnavailableDescriptorsWithReasons) {
  const auto unavailable = UnavailableDescriptors();
  std::set<std::string> names;
  for (const auto& [name, reason] : unavailable) {
    names.insert(name);
    EXPECT_FALSE(reason.empty()) << name;
  }
  EXPECT_EQ(names, (std::set<std::string>{"SURF"}));
  for (const std::string& name : RegisteredDescriptorNames()) EXPECT_EQ(names.count(name), 0u);
}

TEST(Registry, LookupIsCaseInsensitive) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"ldb", "LDB"},     {"d-Ldb", "D-LDB"}, {"Orb", "ORB"},
      {"bRiSk", "BRISK"}, {"brief", "BRIEF"}, {"Freak", "FREAK"},
      {"sift", "SIFT"},   {"Hog", "HOG"},     {"Sad", "SAD"}};
  for (const auto& [given, name] : cases) {
    const auto d = CreateDescriptor(given, Options(64));
    ASSERT_NE(d, nullptr) << given;
    EXPECT_EQ(d->Name(), name);
  }
}

TEST(Registry, UnknownNameNamesTheValueAndListsValidNames) {
  const std::string message = InputErrorMessage([] { CreateDescriptor("XYZ", Options(64)); });
  EXPECT_EQ(message,
            "Image_descriptor: unknown descriptor \"XYZ\"; expected one of LDB, D-LDB, ORB, BRISK, "
            "BRIEF, FREAK, SIFT, HOG, SAD, DENSEVLAD, ONNX");
  EXPECT_TRUE(Contains(InputErrorMessage([] { CreateDescriptor("", Options(64)); }), "\"\""));
}

TEST(Registry, UnavailableNamesGiveTheReason) {
  const std::string surf = InputErrorMessage([] { CreateDescriptor("SURF", Options(64)); });
  EXPECT_TRUE(Contains(surf, "Image_descriptor: \"SURF\" is not available: ")) << surf;
  EXPECT_TRUE(Contains(surf, "patented")) << surf;
  EXPECT_TRUE(Contains(surf, "use SIFT")) << surf;
  const std::string lower = InputErrorMessage([] { CreateDescriptor("surf", Options(64)); });
  EXPECT_TRUE(Contains(lower, "\"surf\" is not available")) << lower;
}

TEST(Registry, MessagesAreOneLine) {
  for (const std::string name : {"XYZ", "SURF", "surf"}) {
    const std::string m = InputErrorMessage([&] { CreateDescriptor(name, Options(64)); });
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
  }
}

TEST(Registry, RejectsSmallPatchForEveryDescriptor) {
  for (const std::string& name : RegisteredDescriptorNames()) {
    const std::string m = InputErrorMessage([&] { CreateDescriptor(name, Options(15)); });
    EXPECT_TRUE(Contains(m, "Patch_size")) << name << ": " << m;
    EXPECT_TRUE(Contains(m, "15")) << name << ": " << m;
  }
  EXPECT_NO_THROW(CreateDescriptor("LDB", Options(16)));
}

TEST(Registry, RejectsLdbBitsOutOfRange) {
  for (const int bits : {0, -3, 1387}) {
    const std::string m = InputErrorMessage([&] { CreateDescriptor("LDB", Options(64, bits)); });
    EXPECT_TRUE(Contains(m, "Ldb_bits")) << m;
    EXPECT_TRUE(Contains(m, std::to_string(bits))) << m;
  }
  EXPECT_EQ(CreateDescriptor("LDB", Options(64, 1))->Width(), 1);
  EXPECT_EQ(CreateDescriptor("LDB", Options(64, 1386))->Width(), 174);
}

TEST(Registry, RejectsHogPatchThatIsNotAMultipleOfEight) {
  const std::string m = InputErrorMessage([] { CreateDescriptor("HOG", Options(60)); });
  EXPECT_TRUE(Contains(m, "Patch_size")) << m;
  EXPECT_TRUE(Contains(m, "60")) << m;
  EXPECT_TRUE(Contains(m, "multiple of 8")) << m;
  EXPECT_NO_THROW(CreateDescriptor("LDB", Options(60)));
  EXPECT_NO_THROW(CreateDescriptor("ORB", Options(60)));
}

TEST(Registry, ConstructorsCheckTheirOwnOptions) {
  // Code that builds a descriptor directly gets the same one-line errors.
  EXPECT_TRUE(Contains(InputErrorMessage([] { LdbDescriptor d(Options(64, 0)); }), "Ldb_bits"));
  EXPECT_TRUE(Contains(InputErrorMessage([] { LdbDescriptor d(Options(8)); }), "Patch_size"));
  EXPECT_TRUE(Contains(InputErrorMessage([] { OrbDescriptor d(Options(8)); }), "Patch_size"));
  EXPECT_TRUE(Contains(InputErrorMessage([] { BriskDescriptor d(Options(8)); }), "Patch_size"));
  EXPECT_TRUE(Contains(InputErrorMessage([] { SiftDescriptor d(Options(8)); }), "Patch_size"));
  EXPECT_TRUE(Contains(InputErrorMessage([] { HogDescriptor d(Options(36)); }), "Patch_size"));
  EXPECT_TRUE(Contains(InputErrorMessage([] { BriefDescriptor d(Options(8)); }), "Patch_size"));
  EXPECT_TRUE(Contains(InputErrorMessage([] { FreakDescriptor d(Options(8)); }), "Patch_size"));
}

}  // namespace
}  // namespace openable

namespace openable {
namespace {

TEST(DescriptorOptions, CheckRejectsOutOfRangeValuesNamingTheKey) {
  EXPECT_NO_THROW(DescriptorOptions().Check());
  DescriptorOptions o;
  o.patch_size = 15;
  try {
    o.Check();
    FAIL() << "patch 15 accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("Patch_size: 15"), std::string::npos) << e.what();
  }
  o = DescriptorOptions();
  for (int bits : {0, 1387}) {
    o.ldb_bits = bits;
    EXPECT_THROW(o.Check(), InputError) << bits;
  }
  o.ldb_bits = 1386;
  EXPECT_NO_THROW(o.Check());
}

}  // namespace
}  // namespace openable
