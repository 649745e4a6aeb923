// The descriptor cache (OpenABLE/run/descriptor_cache.h): its hash, which keys change the
// cache key, hits and misses, damaged files repaired, rows identical bit for bit.
#include "OpenABLE/run/descriptor_cache.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <set>

#include "OpenABLE/base/error.h"
#include "OpenABLE/describe/describe.h"
#include "OpenABLE/io/frame_source.h"
#include "config/config.h"
#include "descriptors/registry.h"
#include "tests/test_support.h"

namespace openable {
namespace {

namespace fs = std::filesystem;

std::string ReadAll(const std::string& path) { return testing::ReadBytes(path); }

// --- The descriptor cache --------------------------------------------------------------------

TEST(Fnv1a64, SpecificationVectors) {
  // From the FNV reference (Fowler, Noll, Vo) test suite.
  EXPECT_EQ(Fnv1a64("", 0), 0xcbf29ce484222325ull);
  EXPECT_EQ(Fnv1a64("a", 1), 0xaf63dc4c8601ec8cull);
  EXPECT_EQ(Fnv1a64("foobar", 6), 0x85944171f73967e8ull);
  // Continuation equals one pass.
  EXPECT_EQ(Fnv1a64("bar", 3, Fnv1a64("foo", 3)), Fnv1a64("foobar", 6));
}

// Keys that do not change a frame's row (inputs, outputs, matching, evaluation, tools). A key
// added to the configuration table must be put here or in DescriptionKeys(): otherwise this
// test fails, so a setting that changes rows cannot be left out of the cache key silently.
const std::set<std::string> kNotDescription = {"Frame_mode",
                                               "Images_path",
                                               "Images_path_2",
                                               "Images_path_left",
                                               "Images_path_right",
                                               "Calibration_path",
                                               "Images_format",
                                               "Video_path_1",
                                               "Video_path_2",
                                               "Initial_image",
                                               "Final_image",
                                               "Skip_unreadable",
                                               "Txt_name",
                                               "Npy_name",
                                               "Png_name",
                                               "Png_threshold_name",
                                               "Matrix_color",
                                               "Show_images",
                                               "Panorama_matching",
                                               "Image_sequences",
                                               "Threshold",
                                               "Threads",
                                               "Sequence_direction",
                                               "Matrix_mode",
                                               "Memory_limit",
                                               "Best_matches",
                                               "Band_width",
                                               "Matches_name",
                                               "Approximate_search",
                                               "Approximate_engine",
                                               "Approximate_checks",
                                               "Approximate_ef_search",
                                               "Approximate_nprobe",
                                               "Descriptor_cache",
                                               "Sequence_partial",
                                               "Match_score",
                                               "Match_score_window",
                                               "Match_threshold",
                                               "Match_consistency",
                                               "Auto",
                                               "Auto_candidates",
                                               "Auto_min_consistency",
                                               "Contrast_enhancement",
                                               "Contrast_window",
                                               "Fusion_weights",
                                               "Loops_name",
                                               "Bag_path",
                                               "Bag_topic",
                                               "Bag_topic_right",
                                               "Bag_path_2",
                                               "Bag_topic_2",
                                               "Timestamps_name",
                                               "Descriptors_path",
                                               "Descriptors_path_2"};

bool Perturb(Config& c, const std::string& key) {
  const std::string v = ConfigValueText(c, key);
  std::vector<std::string> candidates;
  if (!v.empty() && v.front() == '"') {
    candidates = {"HOG", "LDB", "other"};
  } else {
    const double x = std::stod(v);
    candidates = {std::to_string(x + 1), std::to_string(x - 1), std::to_string(x + 0.25),
                  std::to_string(x / 2)};
  }
  for (const std::string& cand : candidates) {
    Config copy = c;
    try {
      ApplyOverride(copy, key + "=" + cand);
    } catch (const InputError&) {
      continue;
    }
    if (ConfigValueText(copy, key) != v) {
      c = copy;
      return true;
    }
  }
  return false;
}

TEST(DescriptorCacheKey, TheDescriptionKeysAreTheRowStructsKeysInTheTablesOrder) {
  // The keys, in this order, make the settings text whose hash names a cache file: the same
  // list as when it was written by hand, and the network's keys (Model_*), which enter the
  // text of a network's rows only, so the caches of earlier runs stay valid.
  EXPECT_EQ(DescriptionKeys(), (std::vector<std::string>{"Camera_type",
                                                         "Description_type",
                                                         "Patch_size",
                                                         "Grid_x",
                                                         "Grid_y",
                                                         "Panoramas",
                                                         "Illumination_invariance",
                                                         "Alpha",
                                                         "Lambda_red",
                                                         "Lambda_green",
                                                         "Lambda_blue",
                                                         "Image_descriptor",
                                                         "Ldb_bits",
                                                         "Sad_patch",
                                                         "Model_path",
                                                         "Model_input_size",
                                                         "Model_channels",
                                                         "Model_mean",
                                                         "Model_std",
                                                         "Model_normalize",
                                                         "Model_batch",
                                                         "Side_window",
                                                         "Side_window_radii",
                                                         "Noise_gaussian",
                                                         "Noise_salt_pepper",
                                                         "Noise_overexposure",
                                                         "Noise_seed"}));
  // The text of a hand-crafted descriptor's rows is what it was before networks.
  const std::string ldb = DescriptionSettingsText(Config(), "LDB", 32, CV_8U);
  EXPECT_EQ(ldb.find("Model_"), std::string::npos) << ldb;
  EXPECT_NE(
      DescriptionSettingsText(Config(), "ONNX (weights 0123:10)", 32, CV_32F).find("Model_path: "),
      std::string::npos);
}

TEST(DescriptorCacheKey, EveryKeyIsClassifiedAndEveryDescriptionKeyChangesTheKey) {
  const std::set<std::string> described(DescriptionKeys().begin(), DescriptionKeys().end());
  const Config base;
  const std::string base_text = DescriptionSettingsText(base, "LDB", 32, CV_8U);
  for (const std::string& key : ConfigKeyNames()) {
    if (key.rfind("Snaps_", 0) == 0 || key.rfind("Odometry_", 0) == 0 ||
        key.rfind("Ground_truth", 0) == 0 || key.rfind("Verification", 0) == 0 ||
        kNotDescription.count(key))
      continue;
    if (key == "Tolerance" || key == "Exclusion" || key == "Vicinity" ||
        key.rfind("Evaluation_", 0) == 0 || key.rfind("Report_", 0) == 0)
      continue;  // evaluation keys
    ASSERT_TRUE(described.count(key))
        << key
        << " is new: add it to DescriptionKeys() (descriptor_cache.cc) if it changes "
           "descriptor rows, else to kNotDescription here";
    Config changed = base;
    ASSERT_TRUE(Perturb(changed, key)) << key;
    if (key.rfind("Model_", 0) == 0) {  // a network's keys: in the text of its rows only
      EXPECT_NE(DescriptionSettingsText(changed, "ONNX", 32, CV_32F),
                DescriptionSettingsText(base, "ONNX", 32, CV_32F))
          << key;
      continue;
    }
    EXPECT_NE(DescriptionSettingsText(changed, "LDB", 32, CV_8U), base_text) << key;
  }
  for (const std::string& key : DescriptionKeys())
    EXPECT_NE(std::find(ConfigKeyNames().begin(), ConfigKeyNames().end(), key),
              ConfigKeyNames().end())
        << key;
  // The descriptor's own name and row shape are part of the key too.
  EXPECT_NE(DescriptionSettingsText(base, "LDB", 64, CV_8U), base_text);
  EXPECT_NE(DescriptionSettingsText(base, "HOG", 32, CV_8U), base_text);
  EXPECT_NE(DescriptionSettingsText(base, "LDB", 32, CV_32F), base_text);
}

struct Fixture {
  std::string images, cache;
  std::unique_ptr<Descriptor> descriptor;
  std::unique_ptr<FrameDescriber> describer;
};

Fixture MakeFixture(int frames) {
  Fixture f;
  const std::string dir = testing::TempDir();
  f.images = dir + "/images";
  f.cache = dir + "/cache";
  fs::create_directories(f.images);
  cv::RNG rng(7);
  for (int i = 0; i < frames; ++i) {
    cv::Mat1b img(48, 64);
    rng.fill(img, cv::RNG::UNIFORM, 0, 256);
    cv::imwrite(f.images + "/f" + std::to_string(i) + ".png", img);
  }
  DescriptorOptions o;
  f.descriptor = CreateDescriptor("LDB", o);
  f.describer = std::make_unique<FrameDescriber>(*f.descriptor, DescriptionType::kGrid, 2, 2);
  return f;
}

DescribedSequence Describe(const Fixture& f, DescriptorCache* cache) {
  const auto source = OpenImageFolder(f.images, "", 0, -1);
  DescribeOptions o;
  o.cache = cache;
  return DescribeSequence(*source, *f.describer, o);
}

std::unique_ptr<DescriptorCache> OpenCache(const Fixture& f, std::vector<std::string>& w) {
  return DescriptorCache::Open(f.cache, "settings", f.describer->RowWidth(), f.describer->RowType(),
                               w);
}

bool SameBytes(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() &&
         std::equal(a.datastart, a.dataend, b.datastart);
}

TEST(DescriptorCache, MissThenHitGivesTheSameRows) {
  const Fixture f = MakeFixture(12);
  const DescribedSequence clean = Describe(f, nullptr);
  std::vector<std::string> w;
  {
    auto c = OpenCache(f, w);
    const DescribedSequence cold = Describe(f, c.get());
    EXPECT_EQ(c->Hits(), 0);
    EXPECT_EQ(c->Stored(), 12);
    EXPECT_TRUE(SameBytes(cold.rows, clean.rows));
  }
  {
    auto c = OpenCache(f, w);
    const DescribedSequence warm = Describe(f, c.get());
    EXPECT_EQ(c->Hits(), 12);
    EXPECT_EQ(c->Stored(), 0);
    EXPECT_TRUE(SameBytes(warm.rows, clean.rows));
    EXPECT_EQ(warm.frame_size, clean.frame_size);
  }
  EXPECT_TRUE(w.empty()) << w.front();
  // Other settings: another file, all misses.
  {
    auto c = DescriptorCache::Open(f.cache, "other settings", f.describer->RowWidth(),
                                   f.describer->RowType(), w);
    Describe(f, c.get());
    EXPECT_EQ(c->Hits(), 0);
  }
  // A changed image is a miss (content, not name, is the key).
  cv::Mat1b changed(48, 64, static_cast<std::uint8_t>(90));
  cv::imwrite(f.images + "/f3.png", changed);
  auto c = OpenCache(f, w);
  const DescribedSequence after = Describe(f, c.get());
  EXPECT_EQ(c->Hits(), 11);
  EXPECT_EQ(c->Stored(), 1);
  EXPECT_TRUE(SameBytes(after.rows, Describe(f, nullptr).rows));
}

// Opens the cache of `f` again, describes its frames with it and closes it: expects one warning
// on the way, holding `warning`, `hits` rows read from the cache, `stored` rows stored in it, and
// the rows of `clean`.
void ExpectOneWarningAndTheCleanRows(const Fixture& f, const DescribedSequence& clean,
                                     const std::string& warning, int hits, int stored) {
  std::vector<std::string> w;
  auto c = OpenCache(f, w);
  const DescribedSequence r = Describe(f, c.get());
  ASSERT_EQ(w.size(), 1u);
  EXPECT_NE(w[0].find(warning), std::string::npos) << w[0];
  EXPECT_EQ(c->Hits(), hits);
  EXPECT_EQ(c->Stored(), stored);
  EXPECT_TRUE(SameBytes(r.rows, clean.rows));
}

TEST(DescriptorCache, TruncatedOrDamagedFileIsRepairedWithAWarningNeverAWrongRow) {
  const Fixture f = MakeFixture(10);
  const DescribedSequence clean = Describe(f, nullptr);
  std::vector<std::string> w;
  std::string path;
  {
    auto c = OpenCache(f, w);
    Describe(f, c.get());
    path = c->Path();
  }
  const std::string full = ReadAll(path);
  // A run killed while writing: half a record at the end.
  const size_t record = 24 + static_cast<size_t>(f.describer->RowWidth()) + 8;
  fs::resize_file(path, full.size() - 3 * record - record / 2);
  ExpectOneWarningAndTheCleanRows(f, clean, "Descriptor_cache", 6, 4);
  EXPECT_EQ(ReadAll(path).size(), full.size());  // repaired: whole records only
  // A flipped bit inside a row: that record and the ones after it are dropped, not used.
  std::string bytes = ReadAll(path);
  bytes[bytes.size() - 5 * record + 30] ^= 0x10;
  testing::WriteBytes(path, bytes);
  ExpectOneWarningAndTheCleanRows(f, clean, "", 5, 5);
  // Garbage instead of a header: started afresh.
  testing::WriteBytes(path, "not a cache file at all");
  ExpectOneWarningAndTheCleanRows(f, clean, "bad header", 0, 10);
}

}  // namespace
}  // namespace openable
