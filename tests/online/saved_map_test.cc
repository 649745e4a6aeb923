// Saved maps of the online detector (OnlineDetector::SaveMap / LoadMap): a detector that
// loads yesterday's map gives every later frame the candidates the detector that saved it
// gives, on real KITTI 00 frames, with each index engine; the file is checked on loading.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <functional>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <tuple>
#include <vector>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/hash.h"
#include "OpenABLE/base/output_batch.h"
#include "OpenABLE/online/map_file.h"
#include "OpenABLE/online/online.h"
#include "tests/fuzz/map_detectors.h"
#include "tests/online/index_engines.h"
#include "tests/test_frames.h"
#include "tests/test_support.h"

namespace openable {
namespace {

using testing::ExpectInputError;
using testing::Q;

using testing::Kitti00LeftDir;
using testing::ReadKitti00Frames;

// Options whose index blocks start early: 850 frames give blocks of 64 x 2^m rows.
OnlineOptions BlockOptions(const std::string& engine) {
  OnlineOptions o;
  o.exclusion = 50;
  o.candidates = 3;
  o.exact_limit = 100;
  o.block_frames = 64;
  o.background_merges = false;  // the same blocks at the same frames in every detector
  o.approximate.engine = engine;
  return o;
}

void ExpectSameCandidates(const OnlineResult& a, const OnlineResult& b) {
  ASSERT_EQ(a.frame, b.frame);
  EXPECT_EQ(a.approximate, b.approximate) << "frame " << a.frame;
  ASSERT_EQ(a.candidates.size(), b.candidates.size()) << "frame " << a.frame;
  for (size_t i = 0; i < a.candidates.size(); ++i) {
    EXPECT_EQ(a.candidates[i].frame, b.candidates[i].frame) << "frame " << a.frame;
    EXPECT_EQ(a.candidates[i].distance, b.candidates[i].distance) << "frame " << a.frame;
    EXPECT_EQ(a.candidates[i].normalized, b.candidates[i].normalized) << "frame " << a.frame;
    EXPECT_EQ(a.candidates[i].accepted, b.candidates[i].accepted) << "frame " << a.frame;
  }
}

bool SameBytes(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() &&
         std::memcmp(a.data, b.data, a.total() * a.elemSize()) == 0;
}

// The detector that saved its map after `saved` frames and the one that loaded it are fed the
// remaining frames: every candidate is the same, with each index engine.
class SavedMapEngine : public online_test::KittiEngineTest {};

TEST_P(SavedMapEngine, GivesTheSameCandidatesAfterLoading) {
  const std::string engine = GetParam();
  const OnlineOptions options = BlockOptions(engine);
  const cv::Mat rows = DescribeImages(ReadKitti00Frames(2, 1699), options);  // 850 frames
  const int saved = 600;
  OnlineDetector yesterday(options);
  for (int q = 0; q < saved; ++q) yesterday.AddDescriptor(rows.row(q));
  const std::string path = testing::TempDir() + "/kitti.map";
  yesterday.SaveMap(path);

  OnlineDetector today(options);
  const OnlineDetector::LoadedMap loaded = today.LoadMap(path);
  EXPECT_EQ(loaded.frames, saved);
  EXPECT_FALSE(loaded.rebuilt) << loaded.reason;
  // 600 - 50 = 550 searchable rows: 8 full blocks of 64 = one block of 512.
  EXPECT_EQ(yesterday.Blocks(), 1);
  EXPECT_EQ(today.Blocks(), yesterday.Blocks());
  EXPECT_EQ(loaded.blocks, yesterday.Blocks());
  EXPECT_EQ(today.Size(), saved);
  EXPECT_TRUE(SameBytes(today.Descriptors(), yesterday.Descriptors()));

  int approximate = 0;
  for (int q = saved; q < rows.rows; ++q) {
    const OnlineResult a = yesterday.AddDescriptor(rows.row(q));
    const OnlineResult b = today.AddDescriptor(rows.row(q));
    ExpectSameCandidates(a, b);
    approximate += b.approximate;
  }
  EXPECT_EQ(approximate, rows.rows - saved);
  EXPECT_EQ(today.Blocks(), yesterday.Blocks());
}

INSTANTIATE_TEST_SUITE_P(Index, SavedMapEngine, online_test::IndexEngines(),
                         online_test::EngineName);

// Another block size: the saved blocks are set aside and the index built from the rows, as a
// detector with that block size given the same rows by AddToMap builds it.
TEST(SavedMap, OtherIndexSettingsRebuildTheBlocks) {
  OPENABLE_REQUIRE_PATH(Kitti00LeftDir());
  const OnlineOptions options = BlockOptions("flann");
  const cv::Mat rows = DescribeImages(ReadKitti00Frames(2, 1699), options);
  const int saved = 600;
  OnlineDetector yesterday(options);
  for (int q = 0; q < saved; ++q) yesterday.AddDescriptor(rows.row(q));
  const std::string path = testing::TempDir() + "/kitti.map";
  yesterday.SaveMap(path);

  OnlineOptions other = options;
  other.block_frames = 128;
  OnlineDetector today(other), reference(other);
  const OnlineDetector::LoadedMap loaded = today.LoadMap(path);
  EXPECT_TRUE(loaded.rebuilt);
  EXPECT_NE(loaded.reason.find("block_frames = 64"), std::string::npos) << loaded.reason;
  reference.AddToMap(rows.rowRange(0, saved));
  // 550 searchable rows: 4 full blocks of 128 = one block of 512.
  EXPECT_EQ(today.Blocks(), 1);
  EXPECT_EQ(reference.Blocks(), 1);
  for (int q = saved; q < rows.rows; ++q)
    ExpectSameCandidates(reference.AddDescriptor(rows.row(q)), today.AddDescriptor(rows.row(q)));
}

// Float rows (HOG, exact search): the rows and the normalising unit (the largest single-frame
// distance so far) come back exactly, so the candidates and their normalised distances are
// those of the detector that saved the map, within float rounding: L2 distances come from a
// matrix product (matching/distances.h) whose last bits depend on how many rows it multiplies
// at once, and the loaded detector starts its running sequence sums from the L - 1 frames before
// its first one, where the other had them already.
TEST(SavedMap, FloatMapKeepsItsNormalisation) {
  OPENABLE_REQUIRE_PATH(Kitti00LeftDir());
  OnlineOptions options;
  options.descriptor.name = "HOG";
  options.sequence_length = 3;
  options.exclusion = 5;
  const cv::Mat rows = DescribeImages(ReadKitti00Frames(20, 1699), options);  // 85 frames
  OnlineDetector yesterday(options);
  for (int q = 0; q < 60; ++q) yesterday.AddDescriptor(rows.row(q));
  const std::string path = testing::TempDir() + "/hog.map";
  yesterday.SaveMap(path);
  OnlineDetector today(options);
  EXPECT_EQ(today.LoadMap(path).frames, 60);
  EXPECT_TRUE(SameBytes(today.Descriptors(), yesterday.Descriptors()));
  for (int q = 60; q < rows.rows; ++q) {
    const OnlineResult a = yesterday.AddDescriptor(rows.row(q));
    const OnlineResult b = today.AddDescriptor(rows.row(q));
    ASSERT_EQ(a.candidates.size(), b.candidates.size()) << "frame " << q;
    for (size_t i = 0; i < a.candidates.size(); ++i) {
      EXPECT_EQ(a.candidates[i].frame, b.candidates[i].frame) << "frame " << q;
      EXPECT_NEAR(a.candidates[i].distance, b.candidates[i].distance,
                  1e-6 * a.candidates[i].distance)
          << "frame " << q;
      EXPECT_NEAR(a.candidates[i].normalized, b.candidates[i].normalized,
                  1e-6 * a.candidates[i].normalized)
          << "frame " << q;
    }
  }
}

// With verification, every frame's local features are saved: the loaded frames are verified
// against later frames with the same features (the matches and inliers are equal).
TEST(SavedMap, VerificationFeaturesAreSavedWithTheMap) {
  OPENABLE_REQUIRE_PATH(Kitti00LeftDir());
  const std::vector<cv::Mat> frames = ReadKitti00Frames(10, 1699);  // 170 frames
  OnlineOptions options;
  options.exclusion = 50;
  options.verification.enabled = true;
  options.verification.candidates = 3;
  OnlineDetector yesterday(options);
  const int saved = 120;
  for (int q = 0; q < saved; ++q) yesterday.AddFrame(frames[q]);
  const std::string path = testing::TempDir() + "/verified.map";
  yesterday.SaveMap(path);
  OnlineDetector today(options);
  EXPECT_EQ(today.LoadMap(path).frames, saved);
  int verified = 0;
  for (int q = saved; q < static_cast<int>(frames.size()); ++q) {
    const OnlineResult a = yesterday.AddFrame(frames[q]);
    const OnlineResult b = today.AddFrame(frames[q]);
    ASSERT_EQ(a.candidates.size(), b.candidates.size());
    for (size_t i = 0; i < a.candidates.size(); ++i) {
      EXPECT_EQ(a.candidates[i].frame, b.candidates[i].frame);
      EXPECT_EQ(a.candidates[i].distance, b.candidates[i].distance);
      EXPECT_EQ(a.candidates[i].matches, b.candidates[i].matches) << "frame " << q;
      EXPECT_EQ(a.candidates[i].inliers, b.candidates[i].inliers) << "frame " << q;
      EXPECT_EQ(a.candidates[i].geometric, b.candidates[i].geometric) << "frame " << q;
      verified += b.candidates[i].geometric;
    }
  }
  // KITTI 00 revisits its start from about frame 1570 (every 10th: 157 on): some loops there.
  EXPECT_GT(verified, 0);

  // A detector without verification loads the rows and ignores the features; a map without
  // features cannot serve a detector that verifies.
  OnlineOptions plain = options;
  plain.verification.enabled = false;
  OnlineDetector rows_only(plain);
  EXPECT_EQ(rows_only.LoadMap(path).frames, saved);
  const std::string plain_path = testing::TempDir() + "/plain.map";
  rows_only.SaveMap(plain_path);
  OnlineDetector verifying(options);
  ExpectInputError([&] { verifying.LoadMap(plain_path); },
                   {plain_path, "features = none", "features = ORB", "same verification"});
}

// Every defect of a map file is one line naming the file, and leaves the detector empty.
// Where the settings, the first section of a saved map, begin: the u64 at byte 32, in the
// first entry of the table after the 16-byte signature, the version and the section count
// (map_file.h).
std::size_t FirstSectionOffset(const std::string& map) {
  std::uint64_t offset = 0;
  for (int i = 0; i < 8; ++i)
    offset |= static_cast<std::uint64_t>(static_cast<unsigned char>(map[32 + i])) << (8 * i);
  return static_cast<std::size_t>(offset);
}

TEST(SavedMap, DefectsAreOneLineErrors) {
  OnlineOptions options;
  options.exclusion = 5;
  OnlineDetector yesterday(options);
  cv::Mat rows(40, 32, CV_8U);
  cv::randu(rows, 0, 256);
  for (int q = 0; q < rows.rows; ++q) yesterday.AddDescriptor(rows.row(q));
  const std::string dir = testing::TempDir();
  const std::string path = dir + "/good.map";
  yesterday.SaveMap(path);
  const std::string good = testing::ReadBytes(path);
  ASSERT_GT(good.size(), 40u * 32u);
  EXPECT_EQ(good.compare(0, 12, "OpenABLE-map"), 0);

  auto load = [&](const std::string& p) {
    OnlineDetector d(options);
    try {
      d.LoadMap(p);
    } catch (...) {
      EXPECT_EQ(d.Size(), 0);
      throw;
    }
  };
  ExpectInputError([&] { load(dir + "/absent.map"); },
                   {"no map at " + Q(dir + "/absent.map"), "create one with openable_map add"});
  // A folder and a FIFO are named before a byte is read (a FIFO with no writer would block).
  std::filesystem::create_directories(dir + "/folder.map");
  ExpectInputError([&] { load(dir + "/folder.map"); },
                   {"map " + Q(dir + "/folder.map") + " is a folder, not a regular file"});
  std::filesystem::remove(dir + "/fifo.map");
  ASSERT_EQ(::mkfifo((dir + "/fifo.map").c_str(), 0600), 0);
  ExpectInputError([&] { load(dir + "/fifo.map"); },
                   {"map " + Q(dir + "/fifo.map") + " is a FIFO (named pipe), not a regular file"});
  testing::WriteBytes(dir + "/text.map", "frames 40\n");
  ExpectInputError([&] { load(dir + "/text.map"); }, {"text.map", "not an OpenABLE map"});
  std::string newer = good;
  newer[16] = 4;  // the format version, little-endian
  testing::WriteBytes(dir + "/newer.map", newer);
  ExpectInputError([&] { load(dir + "/newer.map"); },
                   {"newer.map", "map format version 4", "reads versions 1 to 3",
                    "written by a newer OpenABLE"});
  // A bit flipped in the rows, which a mapped map uses in place: found before LoadMap returns
  // when asked, else by the background check, which CheckMap, the next search and a save
  // report; the damaged map is never written out again.
  std::string flipped = good;
  flipped[good.size() / 2] ^= 0x10;
  testing::WriteBytes(dir + "/flipped.map", flipped);
  ExpectInputError(
      [&] {
        OnlineDetector d(options);
        d.LoadMap(dir + "/flipped.map", {true, /*check_in_background=*/false});
      },
      {"flipped.map", "damaged", "descriptor rows"});
  {
    OnlineDetector d(options);
    d.LoadMap(dir + "/flipped.map");
    ExpectInputError([&] { d.CheckMap(); }, {"flipped.map", "damaged", "descriptor rows"});
    ExpectInputError([&] { d.AddDescriptor(rows.row(0)); }, {"flipped.map", "damaged"});
    ExpectInputError([&] { d.Query(rows.rowRange(0, 2)); }, {"flipped.map", "damaged"});
    ExpectInputError([&] { d.SaveMap(dir + "/copy.map"); }, {"flipped.map", "damaged"});
    EXPECT_FALSE(std::filesystem::exists(dir + "/copy.map"));
  }
  // A bit flipped in the settings, or in the table of sections: found on opening.
  std::string header = good;
  ASSERT_EQ(FirstSectionOffset(good) % 64, 0u);
  ASSERT_EQ(good.compare(FirstSectionOffset(good), 9, "openable "), 0);
  header[FirstSectionOffset(good) + 2] ^= 0x01;
  testing::WriteBytes(dir + "/header.map", header);
  ExpectInputError([&] { load(dir + "/header.map"); }, {"header.map", "damaged", "settings"});
  std::string table = good;
  table[30] ^= 0x01;
  testing::WriteBytes(dir + "/table.map", table);
  ExpectInputError([&] { load(dir + "/table.map"); }, {"table.map", "damaged", "table"});
  testing::WriteBytes(dir + "/short.map", good.substr(0, good.size() - 100));
  ExpectInputError([&] { load(dir + "/short.map"); }, {"short.map", "truncated"});
  testing::WriteBytes(dir + "/tiny.map", good.substr(0, 18));
  ExpectInputError([&] { load(dir + "/tiny.map"); }, {"tiny.map", "truncated"});

  OnlineOptions wider = options;
  wider.descriptor.ldb_bits = 512;
  OnlineDetector other(wider);
  ExpectInputError([&] { other.LoadMap(path); },
                   {path, "ldb_bits = 256", "this detector has ldb_bits = 512"});
  EXPECT_EQ(other.Size(), 0);
  ExpectInputError([&] { yesterday.LoadMap(path); },
                   {"holds 40 frames", "expected an empty detector"});

  // Saving: a folder that cannot be made, then a save cut short (no space left): the earlier
  // map is kept whole and no temporary file is left beside it.
  testing::WriteBytes(dir + "/file", "x");
  ExpectInputError([&] { yesterday.SaveMap(dir + "/file/sub.map"); }, {"file/sub.map"});
  yesterday.AddDescriptor(rows.row(0));
  FailStagedWritesAfterForTesting(100, ENOSPC);
  ExpectInputError([&] { yesterday.SaveMap(path); }, {path, "No space left on device"});
  FailStagedWritesAfterForTesting(-1, 0);
  EXPECT_EQ(testing::ReadBytes(path), good);
  int files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir))
    files += entry.path().filename().string().find(".tmp-") != std::string::npos;
  EXPECT_EQ(files, 0);
}

// A detector that has no frame yet saves an empty map, which loads into an empty detector
// (saving it threw a cv::Exception: the rows of an empty index were a range of no buffer).
TEST(SavedMap, EmptyDetectorSavesAndLoads) {
  const OnlineOptions options = fuzz::MapDetectorOptions(fuzz::MapKind::kRows);
  OnlineDetector empty(options);
  EXPECT_EQ(empty.Descriptors().rows, 0);
  EXPECT_EQ(empty.Descriptors().cols, empty.RowWidth());
  const std::string path = testing::TempDir() + "/empty.map";
  empty.SaveMap(path);
  OnlineDetector today(options);
  EXPECT_EQ(today.LoadMap(path).frames, 0);
  EXPECT_EQ(today.Size(), 0);
  EXPECT_EQ(today.AddDescriptor(cv::Mat::zeros(1, today.RowWidth(), CV_8U)).frame, 0);
}

// The maps of the map fuzzer's corpus (tests/fuzz/corpus/map/, written by
// tests/fuzz/write_seeds.cc and tests/fuzz/map_fuzzer.cc's findings).
std::string MapSeed(const std::string& name) {
  return testing::SourceDir() + "/tests/fuzz/corpus/map/" + name;
}

// `bytes` with the checksum of a map file (the FNV-1a 64 of all but its last 8 bytes) in its
// last 8 bytes, written to `path`: a file that passes the checksum and is checked further.
void WriteWithChecksum(const std::string& path, std::string bytes) {
  std::uint64_t sum = Fnv1a64(bytes.data(), bytes.size() - 8);
  for (size_t i = 0; i < 8; ++i, sum >>= 8)
    bytes[bytes.size() - 8 + i] = static_cast<char>(sum & 0xFF);
  testing::WriteBytes(path, bytes);
}

// Found by tests/fuzz/map_fuzzer.cc: a frame's feature count of 0xffffff.. was allocated (as
// points, 34 GB) before the bytes behind it were counted: an abort under AddressSanitizer,
// std::bad_alloc or a machine out of memory otherwise. Every size read from a map is now
// checked against the bytes that follow before anything of that size is allocated: the rows
// that frames x row_width announce too.
TEST(SavedMap, SizesAreCheckedBeforeAllocating) {
  const std::string path = MapSeed("huge_point_count.map");
  ExpectInputError([&] { ReadMapFile(path); },
                   {path, "the map is truncated", "for a frame's feature points"});

  // Signature, version 1, the settings, the rows' length, (no rows), the checksum.
  auto put64 = [](std::string& out, std::uint64_t v) {
    for (int i = 0; i < 8; ++i) out.push_back(static_cast<char>((v >> (8 * i)) & 0xFF));
  };
  std::string huge("OpenABLE-map\r\n\x1a\n\x01\0\0\0", 20);
  const std::string settings = "frames 100000\nrow_width 100000\nrow_type CV_32F\n";
  put64(huge, settings.size());
  huge += settings;
  put64(huge, 40000000000);  // 100000 x 100000 floats
  huge += std::string(8, '\0');
  const std::string rows_path = testing::TempDir() + "/huge_rows.map";
  WriteWithChecksum(rows_path, huge);
  ExpectInputError([&] { ReadMapFile(rows_path); },
                   {rows_path, "the map is truncated", "for the rows, expected 40000000000"});
}

// Found by tests/fuzz/map_fuzzer.cc: a setting whose value held a carriage return (the fuzzer
// had pasted the map's signature into row_type) gave a message of two lines. Settings are text:
// a line with a control character is refused, and named escaped (the first such line of the
// committed input holds bytes 0x17).
TEST(SavedMap, SettingsWithControlCharactersAreRefused) {
  const std::string path = MapSeed("setting_control_character.map");
  ExpectInputError([&] { ReadMapFile(path); },
                   {path, "setting line \"openable\\x17", "control character"});
}

// Found by tests/fuzz/map_fuzzer.cc on its seed verifying.map: with 5 inliers required, a
// candidate with 6 matches threw a cv::Exception from the fundamental matrix's estimator
// (tests/verification has the unit test). The frame is now verified.
TEST(SavedMap, FuzzerSeedWithVerificationSearchesAndVerifies) {
  OnlineDetector detector(fuzz::MapDetectorOptions(fuzz::MapKind::kVerifying));
  EXPECT_EQ(detector.LoadMap(MapSeed("verifying.map")).frames, 3);
  const OnlineResult r = detector.AddFrame(fuzz::MapFrame(0));
  ASSERT_EQ(r.candidates.size(), 1u);   // the three frames are one place (score_window 10)
  EXPECT_EQ(r.candidates[0].frame, 0);  // the same image
  // 6 of its 10 features pass the ratio test: too few for the fundamental matrix, the
  // homography fits them.
  EXPECT_EQ(r.candidates[0].matches, 6);
  EXPECT_EQ(r.candidates[0].model, GeometricModel::kHomography);
  EXPECT_TRUE(r.candidates[0].geometric);
}

// Local features that verification could not use are refused on loading: a descriptor row
// count other than the points', a point that is not finite, descriptors of another width or
// type than the detector's features.
TEST(SavedMap, InconsistentFeaturesAreRefused) {
  const OnlineOptions options = fuzz::MapDetectorOptions(fuzz::MapKind::kVerifying);
  const std::string good = MapSeed("verifying.map");
  const MapFile map = ReadMapFile(good);
  ASSERT_EQ(map.features.size(), 3u);
  ASSERT_GT(map.features[1].points.size(), 1u);
  const std::string dir = testing::TempDir();
  auto written = [&](const std::string& name, const std::function<void(MapFile&)>& change) {
    MapFile m = map;
    for (FrameFeatures& f : m.features) f.descriptors = f.descriptors.clone();
    change(m);
    WriteMapFile(dir + "/" + name, m);
    return dir + "/" + name;
  };
  const std::string fewer =
      written("fewer.map", [](MapFile& m) { m.features[1].points.pop_back(); });
  ExpectInputError([&] { ReadMapFile(fewer); }, {fewer, "feature descriptors", "row per point"});
  const std::string nan = written("nan.map", [](MapFile& m) {
    m.features[2].points[0].x = std::numeric_limits<float>::quiet_NaN();
  });
  ExpectInputError([&] { ReadMapFile(nan); }, {nan, "feature point is (nan", "pixel coordinates"});
  const std::string narrow = written("narrow.map", [](MapFile& m) {
    m.features[1].descriptors = m.features[1].descriptors.colRange(0, 16).clone();
  });
  EXPECT_NO_THROW(ReadMapFile(narrow));
  OnlineDetector detector(options);
  ExpectInputError([&] { detector.LoadMap(narrow); },
                   {narrow, "frame 1", "descriptors of 16 CV_8UC1", "expected 32 CV_8UC1 (ORB)"});
  EXPECT_EQ(detector.Size(), 0);
}

// A copy of the map at `good`, written to `path`, whose setting `key` is `value`.
void WriteWithSetting(const std::string& good, const std::string& key, const std::string& value,
                      const std::string& path) {
  MapFile map = ReadMapFile(good, {false, false});
  for (auto& [k, v] : map.settings)
    if (k == key) v = value;
  WriteMapFile(path, map);
}

// A map whose settings name a descriptor that does not exist (map fuzzer finding): one line
// naming the map, from LoadMap, MapOptions and AppendMap alike.
TEST(SavedMap, UnknownDescriptorsNameTheMap) {
  OnlineOptions options;
  OnlineDetector d(options);
  cv::Mat row(1, d.RowWidth(), d.RowType());
  cv::RNG rng(3);
  for (int i = 0; i < 5; ++i) {
    rng.fill(row, cv::RNG::UNIFORM, 0, 256);
    d.AddDescriptor(row);
  }
  const std::string good = testing::TempDir() + "/good.map";
  d.SaveMap(good);
  for (const std::string key : {"descriptor", "channels", "search_descriptor"}) {
    const std::string path = testing::TempDir() + "/bad_" + key + ".map";
    WriteWithSetting(good, key, "QQX", path);
    ExpectInputError([&] { OnlineDetector other(MapOptions(path)); }, {path, "QQX"});
    if (key != "channels") continue;  // the rows are LDB's: a detector of LDB loads them
    OnlineDetector fresh(options);
    ExpectInputError([&] { fresh.LoadMap(path); }, {path, "QQX"});
    EXPECT_EQ(fresh.Size(), 0);
    OnlineDetector appender(options);
    ExpectInputError([&] { appender.AppendMap(path); }, {path, "QQX"});
  }
}

// A map whose "indexed_channel" names no channel of it (map fuzzer finding: it was read out of
// bounds): one line naming the map and the setting, for -2 and for one past the last channel.
TEST(SavedMap, AnIndexedChannelBeyondTheMapsDescriptorsIsOneLine) {
  OnlineOptions options;
  options.kept_descriptors = "HOG";
  options.descriptor.patch_size = 16;
  OnlineDetector d(options);
  cv::Mat frame(48, 48, CV_8UC1);
  cv::RNG rng(5);
  for (int i = 0; i < 4; ++i) {
    rng.fill(frame, cv::RNG::UNIFORM, 0, 256);
    d.AddFrame(frame);
  }
  const std::string good = testing::TempDir() + "/two.map";
  d.SaveMap(good);
  for (const std::string value : {"2", "-2", "7"}) {
    const std::string path = testing::TempDir() + "/indexed_" + value + ".map";
    WriteWithSetting(good, "indexed_channel", value, path);
    // A detector whose channels are in another order rebuilds them on the map's.
    OnlineOptions reversed = options;
    reversed.descriptor.name = "HOG";
    reversed.kept_descriptors = "LDB";
    OnlineDetector other(reversed);
    ExpectInputError([&] { other.LoadMap(path); }, {path, "indexed_channel", value});
    EXPECT_EQ(other.Size(), 0);
  }
}

// A map of rows given by a file (descriptor NPY) whose settings name rows of absurd width, or a
// grid: one line naming the map, before anything is built for them.
TEST(SavedMap, MapsOfGivenRowsWithAbsurdSettingsAreOneLine) {
  OnlineOptions options;
  options.descriptor.name = "NPY";
  options.descriptor.given_width = 8;
  OnlineDetector d(options);
  cv::Mat1f rows(5, 8);
  cv::randu(rows, 0, 1);
  d.AddToMap(rows);
  const std::string good = testing::TempDir() + "/given.map";
  d.SaveMap(good);
  OnlineDetector reopened(MapOptions(good));
  EXPECT_EQ(reopened.Size(), 0);
  reopened.LoadMap(good);
  EXPECT_EQ(reopened.Size(), 5);
  EXPECT_EQ(reopened.RowWidth(), 8);
  for (const auto& [key, value, expected] :
       std::vector<std::tuple<std::string, std::string, std::string>>{
           {"row_width", "2000000000", "2000000000"}, {"description", "grid", "expected global"}}) {
    const std::string path = testing::TempDir() + "/given_" + key + ".map";
    WriteWithSetting(good, key, value, path);
    ExpectInputError([&] { OnlineDetector other(MapOptions(path)); }, {path, expected});
  }
}

}  // namespace
}  // namespace openable
