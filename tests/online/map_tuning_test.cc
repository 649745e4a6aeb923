// A map's search at the batch run's quality: queries whose sequence sums are the batch run's
// matrix (Sequence_partial scale) cell by cell, the online confirmation by earlier independent
// queries against its definition written here, maps of several descriptors, and the settings a
// map chooses from two of its sessions (OnlineDetector::Tune) against the auto mode's choice
// on the same frames, kept in the map, and refused trust on unrelated traversals. The bundled
// Nordland sample (300 summer and 300 winter frames) and, when present, the shared Nordland
// seasons.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/progress.h"
#include "OpenABLE/io/frame_source.h"
#include "OpenABLE/online/online.h"
#include "OpenABLE/run/pipeline.h"
#include "OpenABLE/tuning/auto.h"
#include "config/config.h"
#include "matching/distances.h"
#include "matching/sequence.h"
#include "tests/test_support.h"

namespace openable {
namespace {

using testing::ExpectInputError;

std::string SeasonDir(const std::string& season) { return testing::SampleDir() + "/" + season; }

// The frames of a folder as openable_map reads them (ReadImageFile), `first` to `last`.
std::vector<cv::Mat> ReadFolder(const std::string& folder, int first = 0, int last = -1) {
  const std::vector<std::string> files = ListImages(folder, "");
  if (last < 0) last = static_cast<int>(files.size());
  std::vector<cv::Mat> out;
  for (int i = first; i < last; ++i) out.push_back(ReadImageFile(files[static_cast<size_t>(i)]));
  return out;
}

// A map of two sessions, `reference` then `query` frames.
std::unique_ptr<OnlineDetector> TwoSessions(const OnlineOptions& options,
                                            const std::vector<cv::Mat>& reference,
                                            const std::vector<cv::Mat>& query) {
  auto d = std::make_unique<OnlineDetector>(options);
  d->StartSession("summer", "2026-11-29T00:00:00Z");
  d->AddImagesToMap(reference);
  d->StartSession("winter", "2026-11-29T01:00:00Z");
  d->AddImagesToMap(query);
  return d;
}

// Rows [first, first + n) of a matrix.
cv::Mat Rows(const cv::Mat& m, int first, int n) { return m.rowRange(first, first + n).clone(); }

// The sequence distances of the batch run of two traversals, reference first (Test_OpenABLE's
// dense path: every pair compared, sums along diagonals with Sequence_partial scale), in the
// query-reference block, before Eq. 5.
cv::Mat1f BatchBlock(const cv::Mat& reference, const cv::Mat& query, int L, Metric metric) {
  cv::Mat rows;
  cv::vconcat(reference, query, rows);
  cv::Mat1f single = Distances(rows, rows, metric);
  const int r = reference.rows;
  SequenceDistancesInPlace(single, L, {0, r}, {0, r}, SequenceDirection::kForward, 0,
                           SequencePartial::kScale);
  return single(cv::Rect(0, r, r, query.rows)).clone();
}

void ExpectSameBlock(const cv::Mat1f& got, const cv::Mat1f& want, double relative,
                     const std::string& what) {
  ASSERT_EQ(got.size(), want.size()) << what;
  int best_differs = 0;
  for (int i = 0; i < want.rows; ++i) {
    for (int j = 0; j < want.cols; ++j)
      ASSERT_NEAR(got(i, j), want(i, j), relative * std::max(1.0f, std::fabs(want(i, j))))
          << what << " cell " << i << ", " << j;
    const float* a = got.ptr<float>(i);
    const float* b = want.ptr<float>(i);
    best_differs += std::min_element(a, a + got.cols) - a != std::min_element(b, b + want.cols) - b;
  }
  EXPECT_EQ(best_differs, 0) << what << ": rows whose best column differs";
}

// A query of one session scans it exactly and sums sequences as the frames come: its matrix is
// the batch run's block, cell by cell, for binary (exact) and float (within float rounding)
// rows, whatever L.
TEST(MapSearch, QueryGivesTheBatchScaleMatrixCellByCell) {
  const std::vector<cv::Mat> summer = ReadFolder(SeasonDir("summer"));
  const std::vector<cv::Mat> winter = ReadFolder(SeasonDir("winter"));
  for (const std::string descriptor : {"LDB", "HOG"}) {
    for (const int L : {1, 10, 40}) {
      OnlineOptions o;
      o.descriptor.name = descriptor;
      o.sequence_length = L;
      const auto d = TwoSessions(o, summer, winter);
      const cv::Mat rows = d->Descriptors();
      const int r = static_cast<int>(summer.size()), q = static_cast<int>(winter.size());
      OnlineDetector::QueryMatrix matrix;
      const std::vector<OnlineResult> results = d->Query(Rows(rows, r, q), {"summer"}, {}, &matrix);
      ASSERT_EQ(matrix.frames.size(), static_cast<size_t>(r));
      EXPECT_EQ(matrix.frames.front(), 0);
      const Metric metric = descriptor == "LDB" ? Metric::kHamming : Metric::kL2;
      const cv::Mat1f want = BatchBlock(Rows(rows, 0, r), Rows(rows, r, q), L, metric);
      ExpectSameBlock(matrix.sums, want, descriptor == "LDB" ? 0.0 : 2e-6,
                      descriptor + " L=" + std::to_string(L));
      for (int i = 0; i < q; ++i) {
        ASSERT_FALSE(results[static_cast<size_t>(i)].candidates.empty());
        const LoopCandidate& c = results[static_cast<size_t>(i)].candidates[0];
        EXPECT_EQ(c.session, 0);
        EXPECT_FLOAT_EQ(static_cast<float>(c.distance), matrix.sums(i, c.frame));
      }
    }
  }
}

// The shared Nordland seasons, HOG with L = 40: the map's best matches are the batch run's.
TEST(MapSearch, NordlandSeasonsGiveTheBatchRunsBestMatches) {
  const std::string root = testing::DatasetsDir() + "/nordland_trimmed";
  OPENABLE_REQUIRE_PATH(root);
  const std::vector<cv::Mat> summer = ReadFolder(root + "/summer");
  const std::vector<cv::Mat> winter = ReadFolder(root + "/winter");
  OnlineOptions o;
  o.descriptor.name = "HOG";
  o.sequence_length = 40;
  const auto d = TwoSessions(o, summer, winter);
  const int r = static_cast<int>(summer.size()), q = static_cast<int>(winter.size());
  const cv::Mat rows = d->Descriptors();
  OnlineDetector::QueryMatrix matrix;
  d->Query(Rows(rows, r, q), {"summer"}, {}, &matrix);
  ExpectSameBlock(matrix.sums, BatchBlock(Rows(rows, 0, r), Rows(rows, r, q), 40, Metric::kL2),
                  2e-6, "Nordland HOG L=40");
}

// The definition of the online confirmation, written out: query q's partner is the query
// max(L, 10) frames back (its sequence of L frames then shares none with q's), the next
// partner that one's, and so on; each best candidate must lie as many frames back in the same
// session as its query, within max(3, round(gap / 10)) frames.
std::vector<bool> ConfirmedByDefinition(const std::vector<int>& best,
                                        const std::vector<int>& session_of_best, int L,
                                        int partners) {
  const int gap = std::max(L, 10), tolerance = std::max(3, (gap + 5) / 10);
  std::vector<bool> out(best.size(), false);
  for (int q = 0; q < static_cast<int>(best.size()); ++q) {
    int from = q, found = 0;
    while (found < partners && from - gap >= 0) {
      const int p = from - gap;
      if (best[p] < 0 || best[from] < 0 || session_of_best[p] != session_of_best[from] ||
          std::abs((best[from] - best[p]) - (from - p)) > tolerance)
        break;
      ++found;
      from = p;
    }
    out[static_cast<size_t>(q)] = best[static_cast<size_t>(q)] >= 0 && found == partners;
  }
  return out;
}

TEST(MapSearch, OnlineConfirmationIsItsDefinition) {
  const std::vector<cv::Mat> summer = ReadFolder(SeasonDir("summer"));
  const std::vector<cv::Mat> winter = ReadFolder(SeasonDir("winter"));
  for (const int partners : {1, 2}) {
    for (const int L : {5, 20}) {
      OnlineOptions o;
      o.sequence_length = L;
      o.score.kind = MatchScore::kRatio;
      o.consistency = partners;
      const auto d = TwoSessions(o, summer, winter);
      const int r = static_cast<int>(summer.size()), q = static_cast<int>(winter.size());
      const std::vector<OnlineResult> results = d->Query(Rows(d->Descriptors(), r, q));
      std::vector<int> best, session;
      for (const OnlineResult& res : results) {
        best.push_back(res.candidates.empty() ? -1 : res.candidates[0].frame);
        session.push_back(res.candidates.empty() ? -1 : res.candidates[0].session);
      }
      const std::vector<bool> want = ConfirmedByDefinition(best, session, L, partners);
      int confirmed = 0;
      for (int i = 0; i < q; ++i) {
        const LoopCandidate& c = results[static_cast<size_t>(i)].candidates[0];
        EXPECT_EQ(c.confirmed, want[static_cast<size_t>(i)]) << "query " << i << " L " << L;
        EXPECT_EQ(c.accepted, c.confirmed && c.score <= o.Threshold()) << "query " << i;
        confirmed += c.confirmed;
      }
      // The sample's seasons follow one route: most answers are confirmed, none of the first.
      EXPECT_GT(confirmed, q / 3) << "L " << L;
      for (int i = 0; i < std::max(L, 10) * partners && i < q; ++i)
        EXPECT_FALSE(results[static_cast<size_t>(i)].candidates[0].confirmed) << "query " << i;
    }
  }
}

// Frames added one by one (AddFrame, a SLAM system's loop) are confirmed by the same rule
// within their session.
TEST(MapSearch, FramesAddedOneByOneAreConfirmedAlike) {
  const std::vector<cv::Mat> summer = ReadFolder(SeasonDir("summer"));
  const std::vector<cv::Mat> winter = ReadFolder(SeasonDir("winter"));
  OnlineOptions o;
  o.sequence_length = 10;
  o.score.kind = MatchScore::kRatio;
  o.consistency = 1;
  OnlineDetector d(o);
  d.StartSession("summer");
  d.AddImagesToMap(summer);
  d.StartSession("winter");
  std::vector<OnlineResult> results;
  for (const cv::Mat& frame : winter) results.push_back(d.AddFrame(frame));
  std::vector<int> best, session;
  for (const OnlineResult& res : results) {
    best.push_back(res.candidates.empty() ? -1 : res.candidates[0].frame);
    session.push_back(res.candidates.empty() ? -1 : res.candidates[0].session);
  }
  const std::vector<bool> want = ConfirmedByDefinition(best, session, 10, 1);
  for (size_t i = 0; i < results.size(); ++i) {
    if (results[i].candidates.empty()) continue;
    EXPECT_EQ(results[i].candidates[0].confirmed, want[i]) << "frame " << i;
  }
}

// The auto mode's configuration of the sample's two seasons (the defaults, Auto 1).
Config SampleAutoConfig() {
  Config c;
  ApplyOverride(c, "Images_path=" + SeasonDir("summer"), "test");
  ApplyOverride(c, "Images_path_2=" + SeasonDir("winter"), "test");
  ApplyOverride(c, "Auto=1", "test");
  return c;
}

// A map that keeps the rows of every descriptor of the auto mode's candidates chooses, from
// its two sessions, what the auto mode chooses from the same frames, with the same figures;
// its queries then give the chosen candidate's matrix of the batch run.
TEST(MapTuning, ChoosesWhatTheAutoModeChoosesFromTheSameFrames) {
  const std::vector<cv::Mat> summer = ReadFolder(SeasonDir("summer"));
  const std::vector<cv::Mat> winter = ReadFolder(SeasonDir("winter"));
  OnlineOptions o;
  o.descriptor.name = "HOG";
  o.kept_descriptors = "SIFT+LDB+SAD";
  const auto d = TwoSessions(o, summer, winter);
  EXPECT_EQ(d->Channels(), (std::vector<std::string>{"HOG", "SIFT", "LDB", "SAD"}));
  const MapTuning tuning = d->Tune({});
  EXPECT_TRUE(tuning.tuned);
  EXPECT_TRUE(d->UsesTuning());
  EXPECT_EQ(tuning.reference, "summer");
  EXPECT_EQ(tuning.query, "winter");

  const Config config = SampleAutoConfig();
  ProgressReporter quiet(std::cerr, false, false);
  SingleFrameStore store;
  const AutoChoice choice = ChooseSettings(config, quiet, store, {});
  const AutoCandidate& chosen = choice.candidates[static_cast<size_t>(choice.chosen)];
  EXPECT_EQ(tuning.chosen, AutoSettingsText(chosen.settings));
  EXPECT_EQ(tuning.reliable, choice.reliable);
  EXPECT_NEAR(tuning.consistency, chosen.figures.consistency, 1e-12);
  EXPECT_NEAR(tuning.distinctiveness, chosen.figures.distinctiveness, 1e-6);
  // The search now is the chosen candidate's, with the presets' acceptance.
  const OnlineOptions& s = d->Options();
  EXPECT_EQ(s.sequence_length, choice.config.matching.sequence_length);
  EXPECT_EQ(s.contrast.enabled, choice.config.matching.contrast.enabled);
  EXPECT_EQ(s.score.kind, MatchScore::kRatio);
  EXPECT_DOUBLE_EQ(s.Threshold(), 0.9);
  EXPECT_EQ(s.consistency, 1);

  // The winter session queried against the summer one: the chosen candidate's block of the
  // batch run (its fusion, contrast enhancement and shift), cell by cell.
  const int r = static_cast<int>(summer.size()), q = static_cast<int>(winter.size());
  OnlineDetector::QueryMatrix matrix;
  d->Query(Rows(d->Descriptors(), r, q), {"summer"}, {}, &matrix);
  cv::Mat1f want = SingleFrameMatrix(choice.config, store, {0, r})(cv::Rect(0, r, r, q)).clone();
  SequenceDistancesInPlace(want, s.sequence_length, {}, {}, SequenceDirection::kForward, 0,
                           SequencePartial::kScale);
  ExpectSameBlock(matrix.sums, want, 2e-5, "tuned " + tuning.chosen);
}

// Fused descriptors: each descriptor's distances divided by its largest over the two
// sessions (the units Tune keeps) and weighted, as the batch run fuses them; computed here
// by hand from the rows.
TEST(MapTuning, FusedSearchIsTheWeightedSumOfEachDescriptorOverItsLargest) {
  const std::vector<cv::Mat> summer = ReadFolder(SeasonDir("summer"), 0, 120);
  const std::vector<cv::Mat> winter = ReadFolder(SeasonDir("winter"), 0, 120);
  OnlineOptions o;
  o.descriptor.name = "HOG+LDB";
  const auto d = TwoSessions(o, summer, winter);
  OnlineDetector::TuneOptions t;
  // Values that hold commas are separated by semicolons.
  t.candidates = "Image_descriptor=HOG+LDB Image_sequences=5 Fusion_weights=2,1;1,3";
  d->Tune(t);
  const std::vector<double> w = d->Options().fusion_weights;
  ASSERT_TRUE(w == (std::vector<double>{2, 1}) || w == (std::vector<double>{1, 3}));
  const int n = 120;
  OnlineOptions hog, ldb;
  hog.descriptor.name = "HOG";
  const cv::Mat hog_rows = DescribeImages(summer, hog), ldb_rows = DescribeImages(summer, ldb);
  cv::Mat hog_all, ldb_all;
  cv::vconcat(hog_rows, DescribeImages(winter, hog), hog_all);
  cv::vconcat(ldb_rows, DescribeImages(winter, ldb), ldb_all);
  const cv::Mat1f dh = Distances(hog_all, hog_all, Metric::kL2);
  const cv::Mat1f dl = Distances(ldb_all, ldb_all, Metric::kHamming);
  double mh = 0, ml = 0;
  cv::minMaxLoc(dh, nullptr, &mh);
  cv::minMaxLoc(dl, nullptr, &ml);
  cv::Mat1f fused = w[0] * dh / mh + w[1] * dl / ml;
  cv::Mat1f want = fused(cv::Rect(0, n, n, n)).clone();
  SequenceDistancesInPlace(want, 5, {}, {}, SequenceDirection::kForward, 0,
                           SequencePartial::kScale);
  // The packed rows of the map: HOG's floats then LDB's bytes, frame by frame.
  const cv::Mat packed = d->Descriptors();
  ASSERT_EQ(packed.cols, 1764 * 4 + 32);
  OnlineDetector::QueryMatrix matrix;
  d->Query(Rows(packed, n, n), {"summer"}, {}, &matrix);
  ExpectSameBlock(matrix.sums, want, 2e-5, "HOG+LDB weights " + std::to_string(w[0]));
}

// Two stretches of the route that do not overlap: no candidate's best matches agree, the map
// says so and accepts nothing while it searches with them, also once saved and loaded.
TEST(MapTuning, UnrelatedTraversalsAreUnreliableAndAcceptNothing) {
  const auto d = TwoSessions(OnlineOptions(), ReadFolder(SeasonDir("summer"), 0, 150),
                             ReadFolder(SeasonDir("winter"), 150, 300));
  OnlineDetector::TuneOptions t;
  t.candidates = "Image_sequences=5,10,20";
  const MapTuning tuning = d->Tune(t);
  EXPECT_TRUE(tuning.tuned);
  EXPECT_FALSE(tuning.reliable);
  EXPECT_LT(tuning.consistency, 0.5);
  const cv::Mat rows = d->Descriptors();
  const auto accepted = [](const std::vector<OnlineResult>& results) {
    int n = 0;
    for (const OnlineResult& r : results)
      for (const LoopCandidate& c : r.candidates) n += c.accepted;
    return n;
  };
  EXPECT_EQ(accepted(d->Query(Rows(rows, 150, 150), {"summer"})), 0);
  const std::string path = testing::TempDir() + "/unrelated.map";
  d->SaveMap(path);
  OnlineDetector loaded(MapOptions(path));
  loaded.LoadMap(path);
  EXPECT_TRUE(loaded.Tuning().tuned);
  EXPECT_FALSE(loaded.Tuning().reliable);
  EXPECT_TRUE(loaded.UsesTuning());
  EXPECT_EQ(loaded.Tuning().chosen, tuning.chosen);
  EXPECT_EQ(accepted(loaded.Query(Rows(rows, 150, 150), {"summer"})), 0);
  // Told otherwise (another threshold), the search is not the one judged: the verdict does
  // not apply, and the threshold accepts.
  OnlineOptions other = MapOptions(path);
  other.threshold = 1.0;
  other.consistency = 0;
  OnlineDetector told(other);
  told.LoadMap(path);
  EXPECT_FALSE(told.UsesTuning());
  EXPECT_GT(accepted(told.Query(Rows(rows, 150, 150), {"summer"})), 0);
}

// A tuned map saved and loaded searches as before: the same settings, the same answers.
TEST(MapTuning, TunedMapsKeepTheirSettings) {
  OnlineOptions o;
  o.descriptor.name = "LDB";
  o.kept_descriptors = "SAD";
  const auto d = TwoSessions(o, ReadFolder(SeasonDir("summer"), 0, 200),
                             ReadFolder(SeasonDir("winter"), 0, 200));
  OnlineDetector::TuneOptions t;
  t.candidates =
      "Image_descriptor=SAD Contrast_enhancement=1 Image_sequences=10,20 | "
      "Image_descriptor=LDB Image_sequences=10";
  const MapTuning tuning = d->Tune(t);
  const std::string path = testing::TempDir() + "/tuned.map";
  d->SaveMap(path);
  const OnlineOptions options = MapOptions(path);
  EXPECT_EQ(options.descriptor.name, d->Options().descriptor.name);
  EXPECT_EQ(options.sequence_length, d->Options().sequence_length);
  EXPECT_EQ(options.contrast.enabled, d->Options().contrast.enabled);
  EXPECT_EQ(options.kept_descriptors.empty(), false);
  OnlineDetector loaded(options);
  loaded.LoadMap(path);
  EXPECT_TRUE(loaded.UsesTuning());
  EXPECT_EQ(loaded.Channels(), d->Channels());
  EXPECT_EQ(loaded.Tuning().candidates_json, tuning.candidates_json);
  EXPECT_EQ(loaded.Tuning().units, tuning.units);
  EXPECT_EQ(loaded.Tuning().shift, tuning.shift);
  const cv::Mat rows = Rows(d->Descriptors(), 200, 200);
  const std::vector<OnlineResult> a = d->Query(rows, {"summer"});
  const std::vector<OnlineResult> b = loaded.Query(rows, {"summer"});
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a[i].candidates.size(), b[i].candidates.size());
    for (size_t k = 0; k < a[i].candidates.size(); ++k) {
      EXPECT_EQ(a[i].candidates[k].frame, b[i].candidates[k].frame);
      EXPECT_EQ(a[i].candidates[k].distance, b[i].candidates[k].distance);
      EXPECT_EQ(a[i].candidates[k].accepted, b[i].candidates[k].accepted);
    }
  }
}

TEST(MapTuning, RefusesWhatItCannotJudge) {
  const std::vector<cv::Mat> frames = ReadFolder(SeasonDir("summer"), 0, 60);
  OnlineDetector one((OnlineOptions()));
  one.StartSession("only");
  one.AddImagesToMap(frames);
  ExpectInputError([&] { one.Tune({}); }, {"tune", "1 session", "expected two traversals"});
  const auto d = TwoSessions(OnlineOptions(), frames, frames);
  OnlineDetector::TuneOptions t;
  t.reference = "summer";
  t.query = "spring";
  ExpectInputError([&] { d->Tune(t); }, {"query session \"spring\"", "summer, winter"});
  t = {};
  t.candidates = "Patch_size=32,64";
  ExpectInputError([&] { d->Tune(t); }, {"Patch_size", "described already"});
  t.candidates = "Image_descriptor=HOG Image_sequences=10";
  ExpectInputError([&] { d->Tune(t); }, {"Image_descriptor=HOG", "holds LDB"});
  t.candidates = "";
  t.min_consistency = 2;
  ExpectInputError([&] { d->Tune(t); }, {"min_consistency", "[0, 1]"});
  EXPECT_FALSE(d->Tuning().tuned);  // nothing changed by the refusals
}

// Several descriptors' rows given and taken side by side: the rows of each, in the order of
// Channels(), refused at another width.
TEST(MapSearch, RowsOfSeveralDescriptorsGoSideBySide) {
  const std::vector<cv::Mat> frames = ReadFolder(SeasonDir("summer"), 0, 30);
  OnlineOptions o;
  o.descriptor.name = "LDB";
  o.kept_descriptors = "SAD";
  OnlineDetector d(o);
  d.AddImagesToMap(frames);
  EXPECT_EQ(d.RowType(), CV_8U);
  EXPECT_EQ(d.RowWidth(), 32 + 2048);
  const cv::Mat packed = d.Descriptors();
  OnlineOptions ldb;
  const cv::Mat ldb_rows = DescribeImages(frames, ldb);
  OnlineOptions sad;
  sad.descriptor.name = "SAD";
  const cv::Mat sad_rows = DescribeImages(frames, sad);
  EXPECT_EQ(cv::norm(packed.colRange(0, 32), ldb_rows, cv::NORM_INF), 0);
  EXPECT_EQ(cv::norm(packed.colRange(32, 32 + 2048), sad_rows, cv::NORM_INF), 0);
  OnlineDetector again(o);
  again.AddToMap(packed);
  EXPECT_EQ(cv::norm(again.Descriptors(), packed, cv::NORM_INF), 0);
  ExpectInputError([&] { again.AddToMap(ldb_rows); },
                   {"map rows of 30x32", "expected nx2080 CV_8UC1", "LDB, SAD side by side"});
}

}  // namespace
}  // namespace openable
