// The registry of ground-truth formats (GroundTruthFormats, ground_truth.h): every format
// parses from its name, is named in the messages, and is either a pose format or a
// loader; the lists users see are made from it.
#include <gtest/gtest.h>

#include <set>
#include <string>

#include "OpenABLE/evaluation/ground_truth.h"
#include "tests/test_support.h"

namespace openable {
namespace {

TEST(GroundTruthFormats, EachParsesFromItsNameAndIsOneKindOfFormat) {
  std::set<std::string> names;
  for (const GroundTruthFormat& f : GroundTruthFormats()) {
    EXPECT_TRUE(names.insert(f.name).second) << "two formats named " << f.name;
    const GroundTruthType type = ParseGroundTruthType(f.name);
    EXPECT_FALSE(type.IsNone());
    EXPECT_EQ(&type.Format(), &f);
    EXPECT_EQ(GroundTruthTypeName(type), f.name);
    // A pose format reads poses; any other loads its pairs itself.
    EXPECT_NE(f.read_poses == nullptr, f.load == nullptr) << f.name;
    EXPECT_TRUE(f.read_poses || (!f.orientations && !f.timestamps)) << f.name;
    // The list of the messages names it (the key's help: tests/config/option_table_test.cc).
    EXPECT_NE(GroundTruthFormatList().find(f.name), std::string::npos);
  }
  EXPECT_EQ(names, (std::set<std::string>{"matrix", "pairs", "aligned", "kitti", "tum", "positions",
                                          "vpr_bench", "vpr_tutorial"}));
}

TEST(GroundTruthFormats, NamedConstantsAreTheRegistrysEntries) {
  EXPECT_TRUE(GroundTruthType::kNone.IsNone());
  EXPECT_EQ(ParseGroundTruthType(""), GroundTruthType::kNone);
  EXPECT_EQ(ParseGroundTruthType("none"), GroundTruthType::kNone);
  EXPECT_EQ(ParseGroundTruthType("TUM"), GroundTruthType::kTum);
  EXPECT_STREQ(GroundTruthType::kPositions.Format().name, "positions");
  EXPECT_TRUE(GroundTruthType::kKitti.Format().orientations);
  EXPECT_FALSE(GroundTruthType::kPositions.Format().orientations);
  EXPECT_TRUE(GroundTruthType::kTum.Format().timestamps);
  EXPECT_FALSE(GroundTruthType::kAligned.Format().needs_file);
  // The formats that pair a query traversal with a reference one.
  std::set<std::string> two;
  for (const GroundTruthFormat& f : GroundTruthFormats())
    if (f.two_traversals) two.insert(f.name);
  EXPECT_EQ(two, (std::set<std::string>{"aligned", "vpr_bench", "vpr_tutorial"}));
  EXPECT_THROW(GroundTruthType::kNone.Format(), std::logic_error);
  EXPECT_THROW(GroundTruthType("gps").Format(), std::logic_error);
}

TEST(GroundTruthFormats, ListsAndMessagesComeFromTheRegistry) {
  EXPECT_EQ(GroundTruthFormatList(),
            "matrix, pairs, aligned, kitti, tum, positions, vpr_bench or vpr_tutorial");
  EXPECT_EQ(GroundTruthFormatList(", "),
            "matrix, pairs, aligned, kitti, tum, positions, vpr_bench, vpr_tutorial");
  testing::ExpectInputError([] { ParseGroundTruthType("gps"); },
                            {"Ground_truth_type: \"gps\" is not valid; expected matrix, pairs, "
                             "aligned, kitti, tum, positions, vpr_bench or vpr_tutorial (or "
                             "empty: no evaluation)"});
  // The heading limit names the formats that have orientations.
  GroundTruthOptions o;
  o.type = GroundTruthType::kPositions;
  o.path = "xy.txt";
  o.heading_limit = 30;
  testing::ExpectInputError([&] { o.Check(); },
                            {"positions have no orientation; expected -1 (no limit), or "
                             "Ground_truth_type kitti or tum"});
}

}  // namespace
}  // namespace openable
