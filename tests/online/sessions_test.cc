// Sessions of one map (OnlineDetector::StartSession, Query, AppendMap, LoadMap in place): the
// Nordland seasons of the bundled sample as two traversals of one route. A session appended to
// a saved map gives the loops of the map built in one go; queries equal a brute-force search
// written here from the definition of the sequence distance; merges and appends refuse what
// does not fit, leaving the maps as they were.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/hash.h"
#include "OpenABLE/online/map_file.h"
#include "OpenABLE/online/online.h"
#include "tests/test_support.h"

namespace openable {
namespace {

using testing::ExpectInputError;

std::vector<cv::Mat> ReadSeason(const std::string& season) {
  std::vector<std::string> names;
  for (const auto& e : std::filesystem::directory_iterator(testing::SampleDir() + "/" + season))
    if (e.path().extension() == ".png") names.push_back(e.path().string());
  std::sort(names.begin(), names.end());
  std::vector<cv::Mat> frames;
  for (const std::string& n : names) frames.push_back(cv::imread(n, cv::IMREAD_GRAYSCALE));
  return frames;
}

// Blocks from 64 searchable frames on, merged in AddFrame (repeatable), over the engine given.
OnlineOptions SessionOptions(const std::string& engine) {
  OnlineOptions o;
  o.sequence_length = 3;
  o.exclusion = 20;
  o.candidates = 3;
  o.exact_limit = 64;
  o.block_frames = 16;
  o.background_merges = false;
  o.approximate.engine = engine;
  o.approximate.k = 8;
  o.approximate.nprobe = 4;
  return o;
}

int Bits(const cv::Mat& a, int i, const cv::Mat& b, int j) {
  int bits = 0;
  for (int k = 0; k < a.cols; ++k)
    bits += __builtin_popcount(
        static_cast<unsigned>(a.at<std::uint8_t>(i, k) ^ b.at<std::uint8_t>(j, k)));
  return bits;
}

// The sequence distance of the definition: the L frames ending at query i and at reference j,
// as many as both traversals hold since their starts, scaled to L terms.
double SequenceBits(const cv::Mat& q, int i, const cv::Mat& r, int j, int first_j, int L) {
  const int terms = std::min({L, i + 1, j - first_j + 1});
  double sum = 0;
  for (int k = 0; k < terms; ++k) sum += Bits(q, i - k, r, j - k);
  return static_cast<float>(sum * L / terms);
}

void ExpectSameCandidates(const OnlineResult& a, const OnlineResult& b, const std::string& what) {
  ASSERT_EQ(a.candidates.size(), b.candidates.size()) << what;
  for (std::size_t c = 0; c < a.candidates.size(); ++c) {
    EXPECT_EQ(a.candidates[c].frame, b.candidates[c].frame) << what << " candidate " << c;
    EXPECT_EQ(a.candidates[c].distance, b.candidates[c].distance) << what << " candidate " << c;
    EXPECT_EQ(a.candidates[c].session, b.candidates[c].session) << what << " candidate " << c;
  }
}

class Sessions : public ::testing::TestWithParam<std::string> {};

// Summer saved as a map; winter appended after loading it; the loops winter finds equal those
// of one detector fed both seasons, and the reloaded two-session map answers queries like it.
TEST_P(Sessions, AppendedSessionFindsTheLoopsOfTheMapBuiltAtOnce) {
  const std::vector<cv::Mat> summer = ReadSeason("summer"), winter = ReadSeason("winter");
  ASSERT_GT(summer.size(), 200u);
  ASSERT_EQ(summer.size(), winter.size());
  const OnlineOptions options = SessionOptions(GetParam());
  const std::string dir = testing::TempDir();

  OnlineDetector once(options);
  once.StartSession("summer", "2026-07-01T10:00:00Z");
  for (const cv::Mat& f : summer) once.AddFrame(f);
  once.StartSession("winter", "2027-01-15T10:00:00Z");
  std::vector<OnlineResult> expected;
  for (const cv::Mat& f : winter) expected.push_back(once.AddFrame(f));

  {
    OnlineDetector first(options);
    first.StartSession("summer", "2026-07-01T10:00:00Z");
    for (const cv::Mat& f : summer) first.AddFrame(f);
    first.SaveMap(dir + "/route.map");
  }
  OnlineDetector later(options);
  const OnlineDetector::LoadedMap loaded = later.LoadMap(dir + "/route.map");
  EXPECT_FALSE(loaded.rebuilt);
  EXPECT_GT(loaded.blocks, 0);
  later.CheckMap();
  ASSERT_EQ(later.Sessions().size(), 1u);
  EXPECT_EQ(later.Sessions()[0].name, "summer");
  EXPECT_EQ(later.Sessions()[0].time, "2026-07-01T10:00:00Z");
  EXPECT_EQ(later.FrameSize(), "64x32");
  later.StartSession("winter", "2027-01-15T10:00:00Z");
  int right = 0;
  for (std::size_t i = 0; i < winter.size(); ++i) {
    const OnlineResult r = later.AddFrame(winter[i]);
    EXPECT_EQ(r.session, 1);
    ExpectSameCandidates(r, expected[i], "winter frame " + std::to_string(i));
    // Frame-aligned seasons: winter frame i is summer frame i (+-2 frames).
    if (!r.candidates.empty() && r.candidates[0].session == 0 &&
        std::abs(r.candidates[0].session_frame - static_cast<int>(i)) <= 2)
      ++right;
  }
  // The seasons are hard at 64 x 32 pixels with LDB (and LSH's buckets miss many); the point
  // here is that summer is searched at all: a map that lost it finds none, chance about 5 in
  // 300.
  EXPECT_GT(right, static_cast<int>(winter.size()) / 10) << right << " of " << winter.size();
  later.SaveMap(dir + "/route.map");

  // Reloaded: two sessions, and queries across them equal to those of the map built at once.
  OnlineDetector reloaded(options);
  reloaded.LoadMap(dir + "/route.map");
  ASSERT_EQ(reloaded.Sessions().size(), 2u);
  EXPECT_EQ(reloaded.Sessions()[1].name, "winter");
  EXPECT_EQ(reloaded.Sessions()[1].first, static_cast<int>(summer.size()));
  EXPECT_EQ(reloaded.Sessions()[1].count, static_cast<int>(winter.size()));
  const cv::Mat queries = DescribeImages(winter, options);
  const std::vector<OnlineResult> a = reloaded.Query(queries);
  const std::vector<OnlineResult> b = once.Query(queries);
  for (std::size_t i = 0; i < a.size(); ++i) ExpectSameCandidates(a[i], b[i], "query");
}

INSTANTIATE_TEST_SUITE_P(Engines, Sessions, ::testing::Values("binary_ivf", "flann"));

// Exact search (no blocks): candidates within a session only `exclusion` frames back, every
// frame of earlier sessions, sequences cut at each session's start; queries restricted to a
// session. All against the brute force of the definition.
TEST(SessionRules, CandidatesAndSequencesFollowTheSessions) {
  OnlineOptions o;
  o.sequence_length = 4;
  o.exclusion = 10;
  o.candidates = 1000;
  o.approximate.k = 1000;
  cv::Mat rows(90, 32, CV_8U);
  cv::RNG rng(7);
  rng.fill(rows, cv::RNG::UNIFORM, 0, 256);
  OnlineDetector d(o);
  d.StartSession("a");
  for (int i = 0; i < 50; ++i) d.AddDescriptor(rows.row(i));
  d.StartSession("b");
  for (int i = 50; i < 90; ++i) {
    const OnlineResult r = d.AddDescriptor(rows.row(i));
    // Every frame of "a", and the frames of "b" up to i - 10.
    const int expected_count = 50 + std::max(0, i - 10 - 50 + 1);
    ASSERT_EQ(static_cast<int>(r.candidates.size()), expected_count) << i;
    for (const LoopCandidate& c : r.candidates) {
      const int first_j = c.frame < 50 ? 0 : 50;
      const double want = SequenceBits(rows.rowRange(50, 90), i - 50, rows, c.frame, first_j, 4);
      EXPECT_EQ(c.distance, want) << i << " vs " << c.frame;
      EXPECT_EQ(c.session, c.frame < 50 ? 0 : 1);
      EXPECT_EQ(c.session_frame, c.frame - first_j);
    }
  }
  // Queries: a traversal of its own, against session "a" only, then every session.
  const cv::Mat q = rows.rowRange(20, 35).clone();
  const std::vector<OnlineResult> only_a = d.Query(q, {"a"});
  for (int i = 0; i < q.rows; ++i) {
    ASSERT_EQ(only_a[i].candidates.size(), 50u);
    for (const LoopCandidate& c : only_a[i].candidates)
      EXPECT_EQ(c.distance, SequenceBits(q, i, rows, c.frame, 0, 4));
    // Query i is row 20 + i of "a": itself at distance 0 once the sequence is whole.
    if (i >= 3) {
      EXPECT_EQ(only_a[i].candidates[0].frame, 20 + i);
      EXPECT_EQ(only_a[i].candidates[0].distance, 0);
    }
  }
  EXPECT_EQ(d.Query(q)[0].candidates.size(), 90u);
  ExpectInputError([&] { d.Query(q, {"c"}); }, {"session \"c\" is not in the map", "a, b"});
  ExpectInputError([&] { d.StartSession("a"); }, {"already has a session named \"a\""});
  ExpectInputError([&] { d.StartSession("x\ty"); }, {"session name", "printable"});
  ExpectInputError([&] { d.StartSession(""); }, {"session name"});
}

// Two maps of one route merged (AppendMap) equal the map built in one go; merges that do not
// fit are refused with one line, the maps unchanged.
TEST(MapMerge, AppendedMapEqualsOneMapAndMisfitsAreRefused) {
  const std::vector<cv::Mat> summer = ReadSeason("summer"), winter = ReadSeason("winter");
  const OnlineOptions options = SessionOptions("binary_ivf");
  const std::string dir = testing::TempDir();
  OnlineDetector s(options), w(options), both(options);
  s.StartSession("summer");
  w.StartSession("winter");
  both.StartSession("summer");
  for (const cv::Mat& f : summer) s.AddFrame(f), both.AddFrame(f);
  both.StartSession("winter");
  for (const cv::Mat& f : winter) w.AddFrame(f), both.AddFrame(f);
  s.SaveMap(dir + "/summer.map");
  w.SaveMap(dir + "/winter.map");
  const std::string winter_bytes = testing::ReadBytes(dir + "/winter.map");

  OnlineDetector merged(options);
  merged.LoadMap(dir + "/summer.map");
  merged.AppendMap(dir + "/winter.map");
  ASSERT_EQ(merged.Size(), both.Size());
  ASSERT_EQ(merged.Sessions().size(), 2u);
  EXPECT_EQ(merged.Sessions()[1].first, static_cast<int>(summer.size()));
  EXPECT_EQ(cv::norm(merged.Descriptors(), both.Descriptors(), cv::NORM_INF), 0);
  const cv::Mat queries = DescribeImages(winter, options);
  const std::vector<OnlineResult> a = merged.Query(queries, {"summer"});
  const std::vector<OnlineResult> b = both.Query(queries, {"summer"});
  for (std::size_t i = 0; i < a.size(); ++i) {
    ExpectSameCandidates(a[i], b[i], "merged query");
    for (const LoopCandidate& c : a[i].candidates) EXPECT_EQ(c.session, 0);
  }

  // The same sessions twice; other description settings; frames of another size.
  ExpectInputError([&] { merged.AppendMap(dir + "/winter.map"); },
                   {"winter.map", "both maps have a session named \"winter\""});
  OnlineOptions wider = options;
  wider.descriptor.ldb_bits = 512;
  OnlineDetector other(wider);
  other.StartSession("other");
  for (int i = 0; i < 30; ++i) other.AddFrame(summer[static_cast<std::size_t>(i)]);
  other.SaveMap(dir + "/wider.map");
  const int before = merged.Size();
  ExpectInputError([&] { merged.AppendMap(dir + "/wider.map"); },
                   {"wider.map", "ldb_bits = 512", "this detector has ldb_bits = 256"});
  OnlineDetector big(options);
  big.StartSession("big");
  cv::Mat large;
  cv::resize(summer[0], large, cv::Size(128, 64));
  for (int i = 0; i < 30; ++i) big.AddFrame(large);
  big.SaveMap(dir + "/big.map");
  ExpectInputError([&] { merged.AppendMap(dir + "/big.map"); },
                   {"big.map", "frames are 128x64", "this map's are 64x32"});
  ExpectInputError([&] { merged.AddFrame(large); }, {"is 128x64", "the map's frames are 64x32"});
  EXPECT_EQ(merged.Size(), before);
  EXPECT_EQ(merged.Sessions().size(), 2u);
  EXPECT_EQ(testing::ReadBytes(dir + "/winter.map"), winter_bytes);
}

// A map opened in place (mapped, checked in the background) gives the candidates of the same
// map read into memory and checked first.
TEST(MappedMap, InPlaceEqualsReadIntoMemory) {
  const std::vector<cv::Mat> summer = ReadSeason("summer"), winter = ReadSeason("winter");
  const OnlineOptions options = SessionOptions("binary_ivf");
  const std::string dir = testing::TempDir();
  {
    OnlineDetector d(options);
    for (const cv::Mat& f : summer) d.AddFrame(f);
    d.SaveMap(dir + "/summer.map");
    EXPECT_EQ(d.Sessions().size(), 1u);
    EXPECT_EQ(d.Sessions()[0].name, "default");
  }
  OnlineDetector mapped(options), copied(options);
  mapped.LoadMap(dir + "/summer.map");
  copied.LoadMap(dir + "/summer.map", {/*in_place=*/false, /*check_in_background=*/false});
  const cv::Mat queries = DescribeImages(winter, options);
  const std::vector<OnlineResult> a = mapped.Query(queries), b = copied.Query(queries);
  for (std::size_t i = 0; i < a.size(); ++i) ExpectSameCandidates(a[i], b[i], "query");
  mapped.CheckMap();
  // Frames added after loading in place join the map like any other.
  for (std::size_t i = 0; i < 40; ++i) {
    const OnlineResult x = mapped.AddFrame(winter[i]), y = copied.AddFrame(winter[i]);
    ExpectSameCandidates(x, y, "frame added after loading");
  }
}

// A map of the first format version (one session, one FNV-1a checksum, written here byte by
// byte as map_file.h describes it) is read as one session named "default".
TEST(MappedMap, FirstVersionIsOneSession) {
  OnlineOptions o;
  cv::Mat rows(12, 32, CV_8U);
  cv::RNG rng(3);
  rng.fill(rows, cv::RNG::UNIFORM, 0, 256);
  const auto file = [&](const std::string& extra) {
    std::string f("OpenABLE-map\r\n\x1a\n", 16);
    auto put = [&](std::uint64_t v, int bytes) {
      for (int i = 0; i < bytes; ++i) f.push_back(static_cast<char>((v >> (8 * i)) & 0xFF));
    };
    put(1, 4);
    const std::string settings =
        "openable 0\nframes 12\nrow_width 32\nrow_type CV_8U\nunit 256\ndescriptor LDB\n"
        "description global\npatch_size 64\nldb_bits 256\ngrid_x 1\ngrid_y 1\n" +
        extra;
    put(settings.size(), 8);
    f += settings;
    put(rows.total(), 8);
    f.append(reinterpret_cast<const char*>(rows.data), rows.total());
    put(0, 4);  // blocks
    put(0, 4);  // features
    put(Fnv1a64(f.data(), f.size()), 8);
    return f;
  };
  const std::string path = testing::TempDir() + "/v1.map";
  testing::WriteBytes(path, file(""));
  // A frame size that is not WxH is refused by name.
  testing::WriteBytes(path + "2", file("frame_size 2\n"));
  ExpectInputError([&] { OnlineDetector(o).LoadMap(path + "2"); },
                   {"v1.map2", "setting \"frame_size\" of the map is \"2\"", "expected WxH"});
  OnlineDetector d(o);
  EXPECT_EQ(d.LoadMap(path).frames, 12);
  ASSERT_EQ(d.Sessions().size(), 1u);
  EXPECT_EQ(d.Sessions()[0].name, "default");
  EXPECT_EQ(d.Sessions()[0].count, 12);
  EXPECT_EQ(cv::norm(d.Descriptors(), rows, cv::NORM_INF), 0);
}

// Session times: ISO 8601 UTC with real dates (leap years by the Gregorian rule).
TEST(SessionTimes, AreIsoUtcTimesOfRealDates) {
  for (const std::string good :
       {"2026-11-29T09:30:00Z", "2024-02-29T00:00:00Z", "2000-02-29T23:59:59Z",
        "2026-12-31T23:59:60Z", "2026-01-01T00:00:00.125Z"})
    EXPECT_NO_THROW(CheckSessionTime(good, "time")) << good;
  for (const std::string& bad : std::vector<std::string>{
           "", "yesterday", "2026-11-29", "2026-11-29T09:30:00", "2026-11-29 09:30:00Z",
           "2023-02-29T00:00:00Z", "1900-02-29T00:00:00Z", "2026-04-31T00:00:00Z",
           "2026-13-01T00:00:00Z", "2026-00-10T00:00:00Z", "2026-11-29T24:00:00Z",
           "2026-11-29T09:60:00Z", "2026-11-29T09:30:00.Z", "2026-11-29T09:30:00+01:00",
           "+2026-11-29T09:30:00Z", std::string(100000, '1')})
    ExpectInputError([&] { CheckSessionTime(bad, "--time"); }, {"--time", "YYYY-MM-DDTHH:MM:SSZ"});
  OnlineDetector d((OnlineOptions()));
  ExpectInputError([&] { d.StartSession("s", "tomorrow"); }, {"session time", "tomorrow"});
  EXPECT_TRUE(d.Sessions().empty());
}

}  // namespace
}  // namespace openable
