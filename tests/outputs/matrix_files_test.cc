#include "OpenABLE/outputs/matrix_files.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <thread>
#include <vector>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/output_batch.h"
#include "OpenABLE/io/npy.h"
#include "OpenABLE/reports/figures.h"
#include "tests/test_support.h"

namespace openable {
namespace {

namespace fs = std::filesystem;

std::string ReadAll(const std::string& path) { return testing::ReadBytes(path); }

TEST(ColorMaps, MatchTheOriginalTable) {
  // (b, g, r) of s = 0.25 for each of the 12 maps, worked out by hand from the original's
  // table (docs/output_formats.md).
  const float s = 0.25f;
  const cv::Vec3f expected[12] = {
      {s, s, s},         {0, 0, s},         {0, s, 0}, {s, 0, 0},     {0.75f, 0.75f, s},
      {0.75f, s, 0.75f}, {s, 0.75f, 0.75f}, {0, s, 1}, {1, 0.75f, s}, {0.4980f * s, 0.7804f * s, s},
      {0.75f, s, 1},     {0, 0.625f, s}};
  for (int map = 0; map < 12; ++map)
    for (int k = 0; k < 3; ++k) EXPECT_FLOAT_EQ(ColorOf(s, map)[k], expected[map][k]) << map;
  EXPECT_THROW(ColorOf(s, 12), std::logic_error);
}

TEST(ColorMaps, ColorizeScalesTo8Bit) {
  const cv::Mat1f m = (cv::Mat1f(1, 3) << 0.f, 0.5f, 1.f);
  const cv::Mat3b grey = ColorizeMatrix(m, 0);
  EXPECT_EQ(grey(0, 0), cv::Vec3b(0, 0, 0));
  EXPECT_EQ(grey(0, 1), cv::Vec3b(128, 128, 128));  // 127.5 rounds to 128
  EXPECT_EQ(grey(0, 2), cv::Vec3b(255, 255, 255));
  const cv::Mat3b red = ColorizeMatrix(m, 1);
  EXPECT_EQ(red(0, 2), cv::Vec3b(0, 0, 255));
}

TEST(Npy, HeaderAndDataFollowTheFormat) {
  cv::Mat1f m(3, 5);
  for (int k = 0; k < 15; ++k) m(k / 5, k % 5) = 0.5f * k - 1.f;
  const std::string bytes = EncodeNpy(m);
  ASSERT_GE(bytes.size(), 10u);
  EXPECT_EQ(bytes.substr(0, 6), std::string("\x93NUMPY", 6));
  EXPECT_EQ(bytes[6], 1);
  EXPECT_EQ(bytes[7], 0);
  const size_t header_len =
      static_cast<unsigned char>(bytes[8]) | (static_cast<unsigned char>(bytes[9]) << 8);
  EXPECT_EQ((10 + header_len) % 64, 0u);
  const std::string header = bytes.substr(10, header_len);
  EXPECT_EQ(header.back(), '\n');
  EXPECT_NE(header.find("'descr': '<f4'"), std::string::npos) << header;
  EXPECT_NE(header.find("'fortran_order': False"), std::string::npos);
  EXPECT_NE(header.find("'shape': (3, 5)"), std::string::npos);
  ASSERT_EQ(bytes.size(), 10 + header_len + 15 * 4);
  for (int k = 0; k < 15; ++k) {
    float v;
    std::memcpy(&v, bytes.data() + 10 + header_len + 4 * k, 4);
    EXPECT_EQ(v, 0.5f * k - 1.f);
  }
}

TEST(Npy, NumpyReadsIt) {
  const char* python = "/usr/bin/python3";
  if (!fs::exists(python) || std::system("/usr/bin/python3 -c 'import numpy' 2>/dev/null") != 0)
    GTEST_SKIP() << "python3 with numpy absent (apt-get install python3-numpy)";
  cv::Mat1f m(4, 2);
  for (int k = 0; k < 8; ++k) m(k / 2, k % 2) = static_cast<float>(k) / 8.f;
  const std::string path = testing::TempDir() + "/m.npy";
  std::ofstream(path, std::ios::binary) << EncodeNpy(m);
  const std::string cmd = std::string(python) + " -c \"import numpy as n; a=n.load('" + path +
                          "'); assert a.dtype==n.float32 and a.shape==(4,2) and "
                          "abs(a[3,1]-7/8)<1e-7 and abs(a[1,0]-2/8)<1e-7\"";
  EXPECT_EQ(std::system(cmd.c_str()), 0) << cmd;
}

TEST(Text, SpaceSeparatedRows) {
  const cv::Mat1f m = (cv::Mat1f(2, 3) << 0.f, 0.5f, 1.f, 0.123456789f, 1e-7f, 0.25f);
  EXPECT_EQ(EncodeText(m), "0 0.5 1\n0.123457 1e-07 0.25\n");
  const cv::Mat1b t = (cv::Mat1b(2, 2) << 0, 1, 1, 0);
  EXPECT_EQ(EncodeText(t), "0 1\n1 0\n");
}

TEST(Png, DecodesToTheSamePixels) {
  cv::Mat3b img(4, 6, cv::Vec3b(10, 20, 30));
  img(1, 2) = cv::Vec3b(255, 0, 7);
  const std::string bytes = EncodePng(img);
  const cv::Mat back =
      cv::imdecode(std::vector<uchar>(bytes.begin(), bytes.end()), cv::IMREAD_COLOR);
  ASSERT_EQ(back.size(), img.size());
  EXPECT_EQ(cv::norm(back, img, cv::NORM_INF), 0.0);
}

TEST(OutputBatch, NothingVisibleUntilCommit) {
  const std::string dir = testing::TempDir();
  {
    OutputBatch batch;
    batch.Stage("Txt_name", dir + "/a.txt", "hello");
    batch.Stage("Npy_name", dir + "/sub/b.npy", "bytes");  // folder created on demand
    EXPECT_FALSE(fs::exists(dir + "/a.txt"));
    batch.Commit();
  }
  EXPECT_EQ(ReadAll(dir + "/a.txt"), "hello");
  EXPECT_EQ(ReadAll(dir + "/sub/b.npy"), "bytes");
}

// Two outputs of one batch at the same file (also through "." or a link) are refused, naming both
// keys, and nothing is left behind.
TEST(OutputBatch, TwoOutputsAtOneFileAreRefused) {
  const std::string dir = testing::TempDir();
  fs::create_directories(dir + "/real");
  fs::create_directory_symlink(dir + "/real", dir + "/link");
  const std::pair<std::string, std::string> clashes[] = {
      {dir + "/m.txt", dir + "/m.txt"},
      {dir + "/m.txt", dir + "/./sub/../m.txt"},
      {dir + "/real/m.png", dir + "/link/m.png"},
  };
  for (const auto& [first, second] : clashes) {
    {
      OutputBatch batch;
      batch.Stage("Txt_name", first, "a");
      try {
        batch.Stage("Npy_name", second, "b");
        FAIL() << "expected an InputError for " << second;
      } catch (const InputError& e) {
        const std::string m = e.what();
        EXPECT_NE(m.find("Npy_name"), std::string::npos) << m;
        EXPECT_NE(m.find("Txt_name"), std::string::npos) << m;
        EXPECT_EQ(m.find('\n'), std::string::npos) << m;
      }
    }
    EXPECT_FALSE(fs::exists(first));
  }
  EXPECT_NO_THROW(
      CheckDistinctOutputs({{"Txt_name", dir + "/a.txt"}, {"Npy_name", dir + "/a.npy"}}));
  EXPECT_THROW(CheckDistinctOutputs({{"Txt_name", dir + "/a"}, {"Npy_name", dir + "/./a"}}),
               InputError);
}

// A prefix that is a folder would write hidden files (".json") in it.
TEST(OutputBatch, PrefixThatIsAFolderIsRefused) {
  const std::string dir = testing::TempDir();
  testing::ExpectInputError([&] { CheckOutputPrefix("Evaluation_name", dir); },
                            {"Evaluation_name", "is a folder", "eval"});
  testing::ExpectInputError([&] { CheckOutputPrefix("--output", "results/"); },
                            {"--output", "results/", "results/eval"});
  EXPECT_NO_THROW(CheckOutputPrefix("Evaluation_name", dir + "/eval"));
  EXPECT_NO_THROW(CheckOutputPrefix("Evaluation_name", ""));
}

// Runs that create the same missing output folder at once all succeed: a folder created by
// another is what each needs.
TEST(OutputBatch, ConcurrentBatchesCreatingOneFolderAllSucceed) {
  const std::string dir = testing::TempDir();
  for (int round = 0; round < 20; ++round) {
    const std::string folder = dir + "/r" + std::to_string(round) + "/a/b/c";
    std::vector<std::thread> threads;
    std::atomic<int> failures{0};
    for (int t = 0; t < 8; ++t)
      threads.emplace_back([&, t] {
        try {
          OutputBatch batch;
          batch.Stage("Npy_name", folder + "/m" + std::to_string(t) + ".npy", "x");
          batch.Commit();
        } catch (const InputError&) {
          ++failures;
        }
      });
    for (auto& th : threads) th.join();
    EXPECT_EQ(failures.load(), 0) << "round " << round;
  }
}

// Two batches committing the same outputs at once leave one batch's whole set, never a mix
// (the commit's lock on the folder).
TEST(OutputBatch, ConcurrentCommitsOfTheSameOutputsNeverMix) {
  const std::string dir = testing::TempDir();
  const std::vector<std::string> names = {"m.txt", "m.npy", "m.png", "e.json", "e_pr.png"};
  for (int round = 0; round < 30; ++round) {
    std::vector<std::thread> threads;
    for (const std::string run : {"A", "B"})
      threads.emplace_back([&, run] {
        OutputBatch batch;
        for (const std::string& n : names) batch.Stage("Txt_name", dir + "/" + n, run);
        batch.Commit();
      });
    for (auto& th : threads) th.join();
    const std::string first = ReadAll(dir + "/" + names[0]);
    for (const std::string& n : names) EXPECT_EQ(ReadAll(dir + "/" + n), first) << round << n;
  }
}

TEST(OutputBatch, FailureLeavesNoFile) {
  const std::string dir = testing::TempDir();
  fs::create_directories(dir + "/is_a_folder.png");
  {
    OutputBatch batch;
    batch.Stage("Txt_name", dir + "/a.txt", "hello");
    try {
      batch.Stage("Png_name", dir + "/is_a_folder.png", "x");
      FAIL() << "expected an InputError";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("Png_name"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("is_a_folder.png"), std::string::npos) << e.what();
    }
  }  // destroyed without commit
  EXPECT_FALSE(fs::exists(dir + "/a.txt"));
  for (const auto& entry : fs::directory_iterator(dir))
    EXPECT_EQ(entry.path().filename(), "is_a_folder.png") << "left behind: " << entry.path();
}

}  // namespace
}  // namespace openable

namespace openable {
namespace {

// The fast colouring (one affine function per channel, rows in parallel) against ColorOf,
// pixel by pixel, for every map.
TEST(ColorizeMatrix, EqualsColorOfForEveryPixelAndMap) {
  cv::Mat1f m(37, 53);
  cv::RNG rng(5);
  rng.fill(m, cv::RNG::UNIFORM, -0.2, 1.2);  // out of [0, 1] is clamped
  m(0, 0) = 0.f;
  m(0, 1) = 1.f;
  for (int map = 0; map < 12; ++map) {
    const cv::Mat3b c = ColorizeMatrix(m, map);
    for (int i = 0; i < m.rows; ++i)
      for (int j = 0; j < m.cols; ++j) {
        const cv::Vec3f e = ColorOf(std::min(1.f, std::max(0.f, m(i, j))), map);
        for (int k = 0; k < 3; ++k)
          ASSERT_EQ(c(i, j)[k], cv::saturate_cast<std::uint8_t>(e[k] * 255.f))
              << "map " << map << " at " << i << "," << j;
      }
  }
}

// printf's "%.6g" of every cell, one row per line: the reference of the text writer.
std::string PrintfText(const cv::Mat1f& m) {
  std::string expected;
  char buf[64];
  for (int i = 0; i < m.rows; ++i) {
    for (int j = 0; j < m.cols; ++j) {
      std::snprintf(buf, sizeof buf, "%s%.6g", j ? " " : "", m(i, j));
      expected += buf;
    }
    expected += "\n";
  }
  return expected;
}

// The text writer against printf's "%.6g" on values of every magnitude.
TEST(EncodeText, MatchesPrintfOnRandomFloats) {
  cv::Mat1f m(130, 7);  // more rows than one parallel block
  cv::RNG rng(9);
  for (int i = 0; i < m.rows; ++i)
    for (int j = 0; j < m.cols; ++j)
      m(i, j) = static_cast<float>(rng.uniform(0.0, 1.0) * std::pow(10.0, rng.uniform(-9, 4)));
  EXPECT_EQ(EncodeText(m), PrintfText(m));
}

// A matrix as a Hamming run makes it (integer sums over their largest, few distinct values,
// each formatted once and then looked up) and many distinct values (more than the lookup
// holds: colliding entries are formatted again), over several pieces of TextChunks.
TEST(EncodeText, PiecesMatchPrintfWithRepeatedAndManyDistinctValues) {
  cv::Mat1f hamming(1100, 300), distinct(700, 60);
  cv::RNG rng(4);
  for (int i = 0; i < hamming.rows; ++i)
    for (int j = 0; j < hamming.cols; ++j)
      hamming(i, j) = static_cast<float>(rng.uniform(0, 7681)) / 7680.0f;  // L = 30, 256 bits
  for (int i = 0; i < distinct.rows; ++i)
    for (int j = 0; j < distinct.cols; ++j)
      distinct(i, j) = static_cast<float>(rng.uniform(0.0, 1.0));
  for (const cv::Mat1f* m : {&hamming, &distinct}) {
    TextChunks chunks(*m);
    std::string joined;
    int pieces = 0;
    for (std::string_view piece; chunks.Next(piece); ++pieces) joined += piece;
    EXPECT_GT(pieces, 1);
    EXPECT_EQ(joined, PrintfText(*m));
  }
}

// Every kind of float against printf's "%.6g": zeros of both signs, 1, the infinities and NaNs,
// subnormals, the extremes, values that round up at the sixth digit (to a new power of ten
// too) and those either side of the switch between fixed and scientific notation; then
// random bit patterns (every exponent) and every float near the values of a Hamming run.
TEST(EncodeText, MatchesPrintfOnSpecialAndBoundaryValues) {
  using limits = std::numeric_limits<float>;
  const float inf = limits::infinity(), nan = limits::quiet_NaN();
  const float tiny = limits::denorm_min(), normal = limits::min();
  const float below_normal = std::nextafter(normal, 0.f), big = limits::max();
  const float below_one = std::nextafter(1.f, 0.f), above_one = std::nextafter(1.f, 2.f);
  std::vector<float> values = {0.f, -0.f, 1.f, -1.f, inf, -inf, nan, -nan, tiny, -tiny};
  values.insert(values.end(), {below_normal, normal, big, -big, below_one, above_one});
  values.insert(values.end(), {0.1234565f, 0.1234575f, 9.999995f, 9.999994f, 99999.95f});
  values.insert(values.end(), {999999.4f, 999999.5f, 1e6f, 123456.5f, 1234567.f, 1e-5f});
  values.insert(values.end(), {0.0001f, 0.00009999995f, 0.00009999994f, 0.5f, 0.25f});
  values.insert(values.end(), {1.f / 3.f, 2.f / 3.f, 1e-7f, 1e-38f, 3e38f});
  // Either side of every number of the form d.ddddd5 x 10^e that the sixth digit rounds.
  cv::RNG rng(11);
  for (int i = 0; i < 2000; ++i) {
    const double half = (std::floor(rng.uniform(100000.0, 1000000.0)) + 0.5) *
                        std::pow(10.0, rng.uniform(-12, 8) - 5);
    const float near = static_cast<float>(half);
    values.insert(values.end(), {near, std::nextafter(near, 0.f), std::nextafter(near, inf)});
  }
  for (int i = 0; i < 20000; ++i) {  // any bit pattern: every exponent, subnormals, NaNs
    const std::uint32_t bits = static_cast<std::uint32_t>(rng.next());
    float v;
    std::memcpy(&v, &bits, sizeof v);
    values.push_back(v);
  }
  for (int k = 0; k <= 7680; ++k) {  // k / 7680 (L = 30, 256 bits) and its neighbours
    const float v = static_cast<float>(k) / 7680.0f;
    values.insert(values.end(), {v, std::nextafter(v, 0.f), std::nextafter(v, 2.f)});
  }
  values.resize(values.size() / 97 * 97);
  const cv::Mat1f m(static_cast<int>(values.size() / 97), 97, values.data());
  EXPECT_EQ(EncodeText(m), PrintfText(m));
  // One value a row and one row: the first and the last cell of a row are the same one.
  for (const float v : {0.f, -0.f, inf, -nan, 1e-7f, 0.1234565f})
    EXPECT_EQ(EncodeText(cv::Mat1f(1, 1, v)), PrintfText(cv::Mat1f(1, 1, v)));
}

// Thresholded matrices (CV_8U): every byte value, as printf's "%d", in one long row (longer than
// a piece's first buffer) and in many short ones.
TEST(EncodeText, BytesMatchPrintf) {
  cv::Mat1b long_row(1, 9000), rows(700, 3);
  cv::RNG rng(12);
  for (int j = 0; j < long_row.cols; ++j) long_row(0, j) = static_cast<std::uint8_t>(j % 256);
  rng.fill(rows, cv::RNG::UNIFORM, 0, 256);
  for (const cv::Mat1b* m : {&long_row, &rows}) {
    std::string expected;
    char buf[8];
    for (int i = 0; i < m->rows; ++i) {
      for (int j = 0; j < m->cols; ++j) {
        std::snprintf(buf, sizeof buf, "%s%d", j ? " " : "", (*m)(i, j));
        expected += buf;
      }
      expected += "\n";
    }
    EXPECT_EQ(EncodeText(*m), expected);
  }
}

// A row far wider than the others before it: the piece's buffer grows in the middle of a piece.
TEST(EncodeText, WideRowsGrowThePieceBuffer) {
  cv::Mat1f m(40, 20000);
  cv::RNG rng(13);
  rng.fill(m, cv::RNG::UNIFORM, -1e6, 1e6);
  TextChunks chunks(m);
  std::string joined;
  int pieces = 0;
  for (std::string_view piece; chunks.Next(piece); ++pieces) joined += piece;
  EXPECT_EQ(pieces, 2);  // rows 0-31 and 32-39
  EXPECT_EQ(joined, PrintfText(m));
}

TEST(EncodeMatches, NpyRecordsAndCsvText) {
  const std::vector<Match> m = {{1, 2, 0.5f, 1, 0.25f}, {3, 4, 0.25f, 0, 0.75f}};
  const std::string csv = EncodeMatches(m, true);
  EXPECT_EQ(csv,
            "query,reference,distance,rank,score,accepted,confirmed\n1,2,0.5,1,0.25,0,0\n"
            "3,4,0.25,0,0.75,0,0\n");
  const std::string npy = EncodeMatches(m, false);
  const size_t header = npy.size() - 44;  // 64-byte aligned header, 22-byte records
  EXPECT_EQ(header % 64, 0u);
  EXPECT_NE(npy.find("('distance', '<f4')"), std::string::npos);
  EXPECT_NE(npy.find("('score', '<f4'), ('accepted', '|u1'), ('confirmed', '|u1')"),
            std::string::npos);
  EXPECT_NE(npy.find("'shape': (2,)"), std::string::npos);
  int q = 0;
  float dist = 0, score = 0;
  std::memcpy(&q, npy.data() + header + 22, 4);
  std::memcpy(&dist, npy.data() + header + 22 + 8, 4);
  std::memcpy(&score, npy.data() + header + 22 + 16, 4);
  EXPECT_EQ(q, 3);
  EXPECT_EQ(dist, 0.25f);
  EXPECT_EQ(score, 0.75f);
  EXPECT_EQ(npy[header + 22 + 20], 0);
  EXPECT_EQ(npy[header + 22 + 21], 0);
}

// The verdicts of the matches file: per query, its rank-1 match accepted when its score is at
// most the threshold (read here from the records themselves) and confirmed when, besides,
// AcceptedMatches with the consistency keeps it; records of other ranks 0, in both encodings.
TEST(EncodeMatches, AcceptedAndConfirmedColumnsAreTheRankOneVerdicts) {
  // 40 queries: query q's best match is reference q + 5 (an answer that advances with the
  // queries), but for query 17 (reference 300: its partners disagree) and query 30 (score
  // 0.95, above the threshold); a second-rank match and a band cell for each.
  std::vector<Match> matches;
  for (int q = 0; q < 40; ++q) {
    const int best = q == 17 ? 300 : q + 5;
    const float score = q == 30 ? 0.95f : 0.5f + 0.01f * static_cast<float>(q % 7);
    matches.push_back({q, best, score, 1, score});
    matches.push_back({q, best + 50, 0.99f, 2, 0.99f});
    matches.push_back({q, q, 0.97f, 0, 0.99f});
  }
  const double threshold = 0.9;
  AgreementOptions agreement;
  agreement.sequence_length = 1;
  agreement.partial = SequencePartial::kScale;
  const MatchVerdicts alone = VerdictsOf(matches, threshold, nullptr, false);
  const MatchVerdicts confirmed = VerdictsOf(matches, threshold, &agreement, false);
  const std::vector<std::uint8_t> kept = AcceptedMatches(matches, 40, threshold, &agreement);
  for (int q = 0; q < 40; ++q) {
    EXPECT_EQ(alone.accepted[q], q == 30 ? 0 : 1) << q;
    EXPECT_EQ(alone.confirmed[q], alone.accepted[q]) << q;  // nothing to confirm
    EXPECT_EQ(confirmed.accepted[q], alone.accepted[q]) << q;
    EXPECT_EQ(confirmed.confirmed[q], kept[q]) << q;
  }
  // Query 17's wrong answer is refused, and so are the queries whose partner it is (27, and 7,
  // which looks 10 queries forward).
  for (int q : {7, 17, 27}) EXPECT_EQ(confirmed.confirmed[q], 0) << q;
  EXPECT_EQ(confirmed.confirmed[5], 1);
  EXPECT_TRUE(VerdictsOf(matches, threshold, &agreement, true).confirmed.empty());
  EXPECT_TRUE(VerdictsOf(matches, -1, nullptr, false).accepted.empty());

  const std::string csv = EncodeMatches(matches, true, confirmed);
  std::istringstream lines(csv);
  std::string line;
  std::getline(lines, line);
  EXPECT_EQ(line, "query,reference,distance,rank,score,accepted,confirmed");
  const std::string npy = EncodeMatches(matches, false, confirmed);
  const std::size_t data = npy.size() - 22 * matches.size();
  for (std::size_t i = 0; i < matches.size(); ++i) {
    ASSERT_TRUE(std::getline(lines, line));
    const Match& m = matches[i];
    const bool best = m.rank == 1;
    const int a = best ? confirmed.accepted[m.query] : 0;
    const int c = best ? confirmed.confirmed[m.query] : 0;
    const std::string end = "," + std::to_string(a) + "," + std::to_string(c);
    EXPECT_EQ(line.substr(line.size() - end.size()), end) << line;
    EXPECT_EQ(npy[data + 22 * i + 20], a) << i;
    EXPECT_EQ(npy[data + 22 * i + 21], c) << i;
  }
}

}  // namespace
}  // namespace openable
