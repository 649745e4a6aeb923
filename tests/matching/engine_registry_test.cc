// Every engine of the registry (matching/search/engine_registry.cc) keeps the contract of
// ApproximateIndex on both kinds of rows, whatever engines the table lists: exact distances in
// order, the same candidates from an index read back from its Serialize(), a memory estimate,
// and a refusal naming the key when the build lacks what it needs.
#include "matching/search/engine_registry.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "OpenABLE/base/error.h"
#include "matching/distances.h"
#include "matching/search/approximate.h"
#include "matching/search/approximate_engine.h"

namespace openable {
namespace {

cv::Mat RandomRows(int rows, int cols, int depth, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> normal(0.0f, 1.0f);
  cv::Mat m(rows, cols, depth);
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < cols; ++j) {
      if (depth == CV_8U)
        m.at<std::uint8_t>(i, j) = static_cast<std::uint8_t>(rng());
      else
        m.at<float>(i, j) = normal(rng);
    }
  return m;
}

TEST(EngineRegistry, NamesAreDistinctAndAutoIsLast) {
  const std::vector<std::string> names = ApproximateEngineNames();
  ASSERT_GE(names.size(), 2u);
  for (std::size_t i = 0; i < names.size(); ++i)
    for (std::size_t j = i + 1; j < names.size(); ++j) EXPECT_NE(names[i], names[j]);
  EXPECT_EQ(names.back(), kAutoApproximateEngine);
  EXPECT_EQ(ApproximateOptions().engine, kAutoApproximateEngine);
  std::string choices;
  for (std::size_t i = 0; i < names.size(); ++i)
    choices += (i == 0 ? "" : i + 1 == names.size() ? " or " : ", ") + names[i];
  EXPECT_EQ(ApproximateEngineChoices(), choices);
  // An unknown name: one line naming the key and every name.
  try {
    ParseApproximateEngine("annoy", "Approximate_engine");
    ADD_FAILURE() << "annoy accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              "Approximate_engine: \"annoy\" is not valid; expected " + choices);
  }
  EXPECT_FALSE(IsApproximateEngine("annoy"));
  EXPECT_THROW(ResolvedEngine("annoy", CV_8U), InputError);
}

TEST(EngineRegistry, EveryEngineSearchesBothKindsOfRowsAndReadsItselfBack) {
  for (const std::string& name : ApproximateEngineNames()) {
    for (const int depth : {CV_8U, CV_32F}) {
      SCOPED_TRACE(name + (depth == CV_8U ? " binary" : " float"));
      const ApproximateEngineEntry& entry = FindApproximateEngine(name, depth);
      EXPECT_EQ(entry.name, ResolvedEngine(name, depth));
      EXPECT_GT(std::string(entry.summary).size(), 0u);
      ApproximateOptions options;
      options.engine = name;
      options.k = 5;
      EXPECT_GT(entry.bytes_per_row(options, depth, 32), 0);
      const cv::Mat refs = RandomRows(600, 32, depth, 7);
      const cv::Mat queries = RandomRows(40, 32, depth, 8);
      if (!ApproximateEngineAvailable(name)) {
        EXPECT_THROW(ApproximateIndex(refs, options), InputError);
        try {
          CheckEngineAvailable(name, "Approximate_engine");
          ADD_FAILURE() << "accepted without FAISS";
        } catch (const InputError& e) {
          EXPECT_EQ(std::string(e.what()).rfind("Approximate_engine: " + name + " needs FAISS", 0),
                    0u)
              << e.what();
        }
        continue;
      }
      if (entry.binary_only && depth != CV_8U) {
        EXPECT_THROW(ApproximateIndex(refs, options), std::invalid_argument);
        continue;
      }
      const ApproximateIndex index(refs, options);
      EXPECT_EQ(index.Options().engine, entry.name);
      const CandidateLists lists = index.Search(queries);
      ASSERT_EQ(lists.size(), 40u);
      for (int q = 0; q < queries.rows; ++q) {
        const std::vector<Candidate>& list = lists[static_cast<size_t>(q)];
        EXPECT_LE(list.size(), 5u);
        for (std::size_t i = 0; i < list.size(); ++i) {
          EXPECT_EQ(list[i].distance, RowDistance(refs, list[i].reference, queries, q));
          if (i > 0) {
            EXPECT_TRUE(CandidateBefore(list[i - 1], list[i]));
          }
        }
      }
      // An index made from the bytes of Serialize() (read, or built again when they are empty)
      // gives the same candidates.
      const ApproximateIndex again(refs, options, index.Serialize());
      const CandidateLists read = again.Search(queries);
      ASSERT_EQ(read.size(), lists.size());
      for (std::size_t q = 0; q < lists.size(); ++q) {
        ASSERT_EQ(read[q].size(), lists[q].size()) << q;
        for (std::size_t i = 0; i < lists[q].size(); ++i)
          EXPECT_EQ(read[q][i].reference, lists[q][i].reference) << q << " " << i;
      }
      EXPECT_TRUE(index.Search(cv::Mat(0, 32, depth)).empty());
    }
  }
}

}  // namespace
}  // namespace openable
