#include "OpenABLE/app/command_line.h"

#include <gtest/gtest.h>

namespace openable {
namespace {

std::string Parse(std::vector<const char*> args, CommandLine& out) {
  args.insert(args.begin(), "prog");
  return ParseCommandLine(static_cast<int>(args.size()), args.data(), "prog", out);
}

TEST(CommandLine, FileOverridesAndFlags) {
  CommandLine cl;
  EXPECT_EQ(Parse({"c.txt", "--set", "A=1", "--set=B=2", "-q", "--print-config"}, cl), "");
  EXPECT_EQ(cl.config_path, "c.txt");
  EXPECT_EQ(cl.overrides, (std::vector<std::string>{"A=1", "B=2"}));
  EXPECT_TRUE(cl.quiet);
  EXPECT_TRUE(cl.print_config);
  EXPECT_FALSE(cl.help);
  EXPECT_FALSE(cl.json);
  CommandLine json;
  EXPECT_EQ(Parse({"c.txt", "--json"}, json), "");
  EXPECT_TRUE(json.json);
  EXPECT_FALSE(json.quiet);
}

TEST(CommandLine, OverridesAloneOrHelpAloneAreEnough) {
  CommandLine cl;
  EXPECT_EQ(Parse({"--set", "Threads=1"}, cl), "");
  EXPECT_EQ(Parse({"--help"}, cl), "");
  EXPECT_TRUE(cl.help);
  EXPECT_EQ(Parse({"--version"}, cl), "");
  EXPECT_TRUE(cl.version);
}

TEST(CommandLine, UsageErrorsAreOneLineNamingTheArgument) {
  CommandLine cl;
  EXPECT_EQ(
      Parse({}, cl),
      "prog: no configuration given; expected prog Config.txt or --set Key=Value (see --help)");
  EXPECT_EQ(Parse({"--bogus"}, cl), "prog: unknown option \"--bogus\" (see --help)");
  EXPECT_EQ(Parse({"a.txt", "b.txt"}, cl),
            "prog: more than one configuration file (\"a.txt\" and \"b.txt\"); expected one (see "
            "--help)");
  EXPECT_EQ(Parse({"--set"}, cl), "prog: --set needs Key=Value (see --help)");
}

TEST(CommandLine, ConfigOfAppliesOverridesInOrder) {
  CommandLine cl;
  cl.overrides = {"Threads=3", "Threads=5", "Snaps_corrector=pose-graph"};
  const Config c = ConfigOf(cl);
  EXPECT_EQ(c.matching.threads, 5);
  EXPECT_EQ(EnumName(c.snaps.corrector), "pose-graph");
}

}  // namespace
}  // namespace openable
