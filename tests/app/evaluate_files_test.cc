// openable_evaluate's command line as a library call: flags become the keys they stand for, in
// the order given, labels belong to the matrix before them, and bad arguments are one line.
#include "OpenABLE/app/evaluate_files.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace openable {
namespace {

std::string Parse(std::vector<const char*> args, EvaluateCommandLine& out) {
  args.insert(args.begin(), "openable_evaluate");
  return ParseEvaluateCommandLine(static_cast<int>(args.size()), args.data(), out);
}

TEST(EvaluateCommandLine, FlagsAreKeysInOrderAndLabelsFollowTheirMatrix) {
  EvaluateCommandLine c;
  ASSERT_EQ(Parse({"--matrix", "a.npy", "--label", "A", "--gt-type", "aligned", "--set",
                   "Tolerance=3", "--tolerance", "4", "--matrix", "b.npy", "--reference-frames",
                   "12", "--output", "out/e", "--quiet"},
                  c),
            "");
  ASSERT_EQ(c.matrices.size(), 2u);
  EXPECT_EQ(c.matrices[0].path, "a.npy");
  EXPECT_EQ(c.matrices[0].label, "A");
  EXPECT_EQ(c.matrices[1].path, "b.npy");
  EXPECT_EQ(c.matrices[1].label, "");
  EXPECT_EQ(c.overrides, (std::vector<std::string>{"Ground_truth_type=aligned", "Tolerance=3",
                                                   "Tolerance=4", "Evaluation_name=out/e"}));
  EXPECT_EQ(c.reference_frames, 12);
  EXPECT_TRUE(c.quiet);
  EXPECT_FALSE(c.json);
}

TEST(EvaluateCommandLine, BadArgumentsAreOneLinePointingAtHelp) {
  const std::vector<std::pair<std::vector<const char*>, std::string>> cases = {
      {{"--label", "x"}, "--label must follow a --matrix"},
      {{"--matrix"}, "--matrix needs a value"},
      {{"--matrix", "a", "--reference-frames", "0"}, "\"0\" is not valid"},
      {{"--matrix", "a", "--reference-frames", "5x"}, "\"5x\" is not valid"},
      {{"--bogus"}, "unknown option \"--bogus\""},
      {{}, "no --matrix given"},
  };
  for (const auto& [args, part] : cases) {
    EvaluateCommandLine c;
    const std::string error = Parse(args, c);
    EXPECT_EQ(error.rfind("openable_evaluate: ", 0), 0u) << error;
    EXPECT_NE(error.find(part), std::string::npos) << error;
    EXPECT_NE(error.find("(see --help)"), std::string::npos) << error;
    EXPECT_EQ(error.find('\n'), std::string::npos) << error;
  }
}

TEST(EvaluateCommandLine, TheSharedCommandLineFormsWork) {
  // --name=value as the other programs take it, and the configuration as a file given alone.
  EvaluateCommandLine c;
  ASSERT_EQ(Parse({"--matrix=a.npy", "--radius=7", "base.txt", "--set=Tolerance=3"}, c), "");
  EXPECT_EQ(c.config_path, "base.txt");
  EXPECT_EQ(c.overrides, (std::vector<std::string>{"Ground_truth_radius=7", "Tolerance=3"}));
  EvaluateCommandLine twice;
  EXPECT_NE(Parse({"--matrix", "a", "base.txt", "--config", "other.txt"}, twice)
                .find("more than one configuration file (\"base.txt\" and \"other.txt\")"),
            std::string::npos);
}

TEST(EvaluateCommandLine, HelpAndVersionAreAnsweredWhateverFollows) {
  EvaluateCommandLine help, version;
  EXPECT_EQ(Parse({"--help", "--bogus"}, help), "");
  EXPECT_TRUE(help.help);
  EXPECT_EQ(Parse({"--version"}, version), "");
  EXPECT_TRUE(version.version);
}

}  // namespace
}  // namespace openable
