// The table of keys (config/option_table.h) and its agreement with the option structs it
// binds: the range a key shows users is exactly what the owning struct's Check() accepts.
#include "config/option_table.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "OpenABLE/base/error.h"
#include "OpenABLE/evaluation/ground_truth.h"
#include "config/config.h"
#include "tests/test_support.h"

namespace openable {
namespace {

// The InputError `check` throws, or "" when it throws none.
std::string ErrorOf(const std::function<void()>& check) {
  try {
    check();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// A message names `key` when it starts with "Key:" or "Key (" (the key and the struct's field).
bool Names(const std::string& message, const std::string& key) {
  return message.rfind(key + ":", 0) == 0 || message.rfind(key + " (", 0) == 0;
}

// A configuration that every struct's Check() accepts as it is.
Config Baseline() {
  Config c;
  c.input.images_path = "frames";
  return c;
}

// Walks every numeric key: its bounds (or, for an open range, a large value) pass the owning
// struct's Check() without an error about that key, and the values just outside them are
// refused by that Check() with an error naming the key. Sets the field directly, past the
// table's own reading, so the Check() is what decides.
TEST(ConfigTable, EveryNumericRangeIsWhatItsCheckAccepts) {
  Config names_only;
  int walked = 0;
  for (const OptionBinding& b : ConfigTable(names_only).Bindings()) {
    ASSERT_TRUE(b.check) << b.key;
    const bool integer = b.kind == OptionBinding::Kind::kInt;
    if (!integer && b.kind != OptionBinding::Kind::kDouble) continue;
    ++walked;
    const double step = integer ? 1.0 : std::max(1e-3, std::fabs(b.min) * 1e-3);
    std::vector<double> inside = {b.min_excluded ? b.min + step : b.min,
                                  std::isinf(b.max) ? b.min + 1e6 : b.max};
    std::vector<double> outside = {b.min_excluded ? b.min : b.min - step};
    if (!std::isinf(b.max)) outside.push_back(b.max + step);
    // The error of the owner's Check() with the field set to `v`, past the table's reading.
    const auto check_at = [&](double v) {
      Config c = Baseline();
      const OptionTable table = ConfigTable(c);
      const OptionBinding& bound = *table.Find(b.key);
      bound.set_number(v);
      return ErrorOf(bound.check);
    };
    for (const double v : inside)
      EXPECT_FALSE(Names(check_at(v), b.key))
          << b.key << " = " << v << " is inside " << b.RangeText() << " but: " << check_at(v);
    for (const double v : outside)
      EXPECT_TRUE(Names(check_at(v), b.key))
          << b.key << " = " << v << " is outside " << b.RangeText()
          << " but its Check() says: " << check_at(v);
  }
  EXPECT_EQ(walked, 73);  // every int and double key
}

// The odometry's own limits, which the configuration once showed wider (disparities up to
// 1024, refused above 256 by the stereo odometry naming a field instead of the key).
TEST(ConfigTable, OdometryKeysShowTheOdometrysLimits) {
  Config c;
  const OptionTable table = ConfigTable(c);
  EXPECT_EQ(table.Find("Odometry_num_disparities")->RangeText(), "integer in [16, 256]");
  testing::ExpectInputError(
      [&] { ApplyOverride(c, "Odometry_num_disparities=512"); },
      {"--set: Odometry_num_disparities: value \"512\"", "integer in [16, 256]"});
  c.odometry.num_disparities = 40;  // in range, not a multiple of 16
  testing::ExpectInputError(
      [&] { c.odometry.Check(); },
      {"Odometry_num_disparities (StereoOdometryOptions.disparity.num_disparities)",
       "a multiple of 16"});
}

// Ground_truth_type's help describes every format of the registry (ground_truth.h).
TEST(ConfigTable, GroundTruthTypeHelpDescribesEveryRegisteredFormat) {
  Config c;
  const OptionTable table = ConfigTable(c);
  const std::string& help = table.Find("Ground_truth_type")->meaning;
  for (const GroundTruthFormat& f : GroundTruthFormats())
    EXPECT_NE(help.find(std::string(f.name) + ": " + f.summary), std::string::npos) << f.name;
  ApplyOverride(c, "Ground_truth_type=positions");
  EXPECT_EQ(c.evaluation.truth.type, GroundTruthType::kPositions);
}

// The kinds of binding read and write their fields as Config.txt holds them.
TEST(OptionTable, BindsNumbersFlagsEnumsAndText) {
  struct Owner {
    int count = 3;
    double weight = 1;
    bool flag = false;
    SequenceDirection direction = SequenceDirection::kForward;
    snaps::Corrector corrector = snaps::Corrector::kBoth;
    std::string name = "a";
    void Check() const {}
  } o;
  OptionTable t;
  t.Add("Count", "G", o, o.count, 1, 5, "count");
  t.Add("Weight", "G", o, o.weight, 0, kNoLimit, "weight", true, /*min_excluded=*/true);
  t.Add("Flag", "G", o, o.flag, "flag");
  t.AddEnumNumber("Direction", "G", o, o.direction, "direction");
  t.AddEnumName("Corrector", "G", o, o.corrector, "corrector");
  t.Add("Name", "G", o, o.name, "name");
  ParseOptionText(t,
                  "Count: 5\nWeight: 0.5\nFlag: 1\nDirection: 2\nCorrector: Pose-Graph\n"
                  "Name: 'b c'\n",
                  "cfg");
  EXPECT_EQ(o.count, 5);
  EXPECT_EQ(o.weight, 0.5);
  EXPECT_TRUE(o.flag);
  EXPECT_EQ(o.direction, SequenceDirection::kBoth);
  EXPECT_EQ(o.corrector, snaps::Corrector::kPoseGraph);
  EXPECT_EQ(o.name, "b c");
  EXPECT_NE(FormatOptionText(t).find("Corrector: \"pose-graph\"\n"), std::string::npos);
  EXPECT_NE(FormatOptionText(t).find("Direction: 2\n"), std::string::npos);
  EXPECT_EQ(t.Find("Direction")->RangeText(), "integer in [0, 2]");
  EXPECT_EQ(t.Find("Weight")->RangeText(), "number >= 0 (0 excluded)");
  testing::ExpectInputError([&] { ApplyOptionOverride(t, "Weight=0"); },
                            {"--set: Weight: value \"0\" is not valid; expected number >= 0 "
                             "(0 excluded)"});
  testing::ExpectInputError([&] { ApplyOptionOverride(t, "Direction=3"); },
                            {"Direction: value \"3\"", "integer in [0, 2]"});
  testing::ExpectInputError([&] { ParseOptionText(t, "Corrector: both-ways\n", "cfg"); },
                            {"cfg:1: Corrector: \"both-ways\" is not valid; expected "
                             "discounted, pose-graph or both"});
  testing::ExpectInputError([&] { ApplyOptionOverride(t, "Flag=2"); }, {"integer in [0, 1]"});
}

}  // namespace
}  // namespace openable
