// The keys of approximate search agree with the library they are bound onto: the defaults,
// ranges and engine names that Test_OpenABLE --help, docs/configuration.md and Config.txt show
// are those of ApproximateOptions and of the engine registry (matching/search/engine_registry.h),
// and every engine of the registry reads back through the key.
#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/strings.h"
#include "config/config.h"
#include "matching/search/engine_registry.h"
#include "matching/search/incremental_index.h"

namespace openable {
namespace {

// Every field of two ApproximateOptions is equal.
void ExpectSameOptions(const ApproximateOptions& a, const ApproximateOptions& b) {
  EXPECT_EQ(a.engine, b.engine);
  EXPECT_EQ(a.k, b.k);
  EXPECT_EQ(a.checks, b.checks);
  EXPECT_EQ(a.lsh_tables, b.lsh_tables);
  EXPECT_EQ(a.lsh_key_bits, b.lsh_key_bits);
  EXPECT_EQ(a.lsh_probe_level, b.lsh_probe_level);
  EXPECT_EQ(a.kd_trees, b.kd_trees);
  EXPECT_EQ(a.hnsw_m, b.hnsw_m);
  EXPECT_EQ(a.hnsw_ef_construction, b.hnsw_ef_construction);
  EXPECT_EQ(a.ef_search, b.ef_search);
  EXPECT_EQ(a.ivf_lists, b.ivf_lists);
  EXPECT_EQ(a.nprobe, b.nprobe);
  EXPECT_EQ(a.threads, b.threads);
  EXPECT_EQ(a.seed, b.seed);
}

// The keys bound onto ApproximateOptions' integer fields, with the field and its range.
struct IntKey {
  const char* key;
  int ApproximateOptions::*field;
  ApproximateRange range;
};
const IntKey kIntKeys[] = {
    {"Approximate_checks", &ApproximateOptions::checks, ApproximateOptions::kChecksRange},
    {"Approximate_ef_search", &ApproximateOptions::ef_search, ApproximateOptions::kEfSearchRange},
    {"Approximate_nprobe", &ApproximateOptions::nprobe, ApproximateOptions::kNprobeRange},
};

TEST(ApproximateKeys, DefaultsAreTheLibrarys) {
  const ApproximateOptions library;
  ExpectSameOptions(ScaleOptions().approximate, library);
  ExpectSameOptions(Config().scale.approximate, library);
  ExpectSameOptions(IncrementalIndexOptions().approximate, library);
  // What --help, the reference and Config.txt show as the default.
  const Config defaults;
  EXPECT_EQ(ConfigValueText(defaults, "Approximate_engine"), "\"" + library.engine + "\"");
  for (const IntKey& k : kIntKeys)
    EXPECT_EQ(ConfigValueText(defaults, k.key), std::to_string(library.*k.field)) << k.key;
}

TEST(ApproximateKeys, RangesAreTheLibrarys) {
  Config c;
  const OptionTable table = ConfigTable(c);
  for (const IntKey& k : kIntKeys) {
    SCOPED_TRACE(k.key);
    const OptionBinding* b = table.Find(k.key);
    ASSERT_NE(b, nullptr);
    EXPECT_EQ(b->min, k.range.min);
    EXPECT_EQ(b->max, k.range.max);
    // ApproximateOptions::Check() takes the same bounds: in at both ends, out just beyond.
    for (const int v : {k.range.min, k.range.max}) {
      ApproximateOptions o;
      o.*k.field = v;
      EXPECT_NO_THROW(o.Check()) << v;
    }
    for (const int v : {k.range.min - 1, k.range.max + 1}) {
      ApproximateOptions o;
      o.*k.field = v;
      EXPECT_THROW(o.Check(), std::invalid_argument) << v;
    }
  }
}

// A field no key sets, set by a program, is checked with the rest of the configuration.
TEST(ApproximateKeys, FieldsWithoutKeysAreCheckedToo) {
  Config c;
  c.input.images_path = "x";
  CheckConfig(c);
  c.scale.approximate.lsh_tables = 0;
  try {
    CheckConfig(c);
    ADD_FAILURE() << "lsh_tables = 0 accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              "ScaleOptions.approximate: ApproximateOptions::lsh_tables = 0, expected 1..64");
  }
}

TEST(ApproximateKeys, EveryEngineOfTheRegistryReadsBackAndIsInTheHelp) {
  const std::vector<std::string> names = ApproximateEngineNames();
  ASSERT_GE(names.size(), 2u);
  EXPECT_EQ(names.back(), kAutoApproximateEngine);
  Config c;
  const std::string meaning = ConfigTable(c).Find("Approximate_engine")->meaning;
  const std::string reference = ConfigMarkdownReference();
  for (const std::string& name : names) {
    SCOPED_TRACE(name);
    EXPECT_EQ(name, Lower(name));
    // Read through the key (any case) and written back as Config.txt holds it.
    ApplyOverride(c, "Approximate_engine=" + Upper(name));
    EXPECT_EQ(c.scale.approximate.engine, name);
    EXPECT_EQ(ConfigValueText(c, "Approximate_engine"), "\"" + name + "\"");
    EXPECT_TRUE(IsApproximateEngine(name));
    EXPECT_EQ(ParseApproximateEngine(name, "k"), name);
    // Named, with its meaning ("name, what it is" or "name (the default), ..."), in the key's
    // help and so in the reference.
    EXPECT_TRUE(meaning.find(name + ", ") != std::string::npos ||
                meaning.find(name + " (") != std::string::npos)
        << meaning;
    // Its engine for each kind of rows is an engine of the table, which the library accepts.
    for (const int depth : {CV_8U, CV_32F}) {
      const std::string resolved = ResolvedEngine(name, depth);
      EXPECT_NE(resolved, kAutoApproximateEngine);
      EXPECT_TRUE(IsApproximateEngine(resolved));
      if (name != kAutoApproximateEngine) {
        EXPECT_EQ(resolved, name);
      }
    }
    ApproximateOptions o;
    o.engine = name;
    EXPECT_NO_THROW(o.Check());
    // The key is refused only for want of FAISS, as the library says.
    c.input.images_path = "x";
    c.scale.matches_name = "m.csv";
    c.scale.approximate_search = true;
    if (ApproximateEngineAvailable(name)) {
      EXPECT_NO_THROW(CheckConfig(c));
    } else {
      EXPECT_THROW(CheckConfig(c), InputError);
    }
    c.scale.approximate_search = false;
  }
  EXPECT_NE(reference.find(ApproximateEngineHelp()), std::string::npos);
  // The names of a refused value are the registry's, from the key and from the library.
  try {
    ApplyOverride(c, "Approximate_engine=annoy");
    ADD_FAILURE() << "annoy accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("expected " + ApproximateEngineChoices()),
              std::string::npos)
        << e.what();
  }
  c.scale.approximate.engine = "annoy";  // past the key's reading: the owner's Check() refuses it
  try {
    CheckConfig(c);
    ADD_FAILURE() << "annoy accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("Approximate_engine: \"annoy\" is not valid; expected " +
                                              ApproximateEngineChoices(),
                                          0),
              0u)
        << e.what();
  }
}

}  // namespace
}  // namespace openable
