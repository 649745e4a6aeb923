// The registry of a run's outputs (OpenABLE/outputs/run_outputs.h): the files checked before a
// run (PlannedOutputs) are the files WriteOutputs writes, in its order; a bounded run notes the
// files it cannot write.
#include "OpenABLE/outputs/run_outputs.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "OpenABLE/run/result.h"
#include "config/config.h"
#include "matching/normalize.h"
#include "tests/test_support.h"

namespace openable {
namespace {

namespace fs = std::filesystem;

// A configuration that asks for every file a run without evaluation writes, in `dir`.
Config EveryOutput(const std::string& dir) {
  Config c;
  c.output.txt_name = dir + "/m.txt";
  c.output.npy_name = dir + "/m.npy";
  c.output.png_name = dir + "/m.png";
  c.matching.threshold = 0.5;  // and so the thresholded image beside m.png
  c.scale.matches_name = dir + "/matches.csv";
  return c;
}

RunResult SmallRun() {
  RunResult r;
  r.normalized = (cv::Mat1f(3, 3) << 0, 0.25f, 1, 0.25f, 0, 0.75f, 1, 0.75f, 0);
  r.thresholded = ThresholdMatrix(r.normalized, 0.5f);
  Traversal t;
  t.frames = 3;
  r.traversals = {t};
  Match m;
  m.query = 2;
  m.rank = 1;
  m.distance = m.score = 1.0f;
  r.matches = {m};
  return r;
}

std::vector<std::string> PathsOf(const std::vector<std::pair<std::string, std::string>>& files) {
  std::vector<std::string> paths;
  for (const auto& [key, path] : files) paths.push_back(path);
  return paths;
}

TEST(RunOutputs, ThePlannedFilesAreTheFilesWrittenInTheirOrder) {
  const std::string dir = testing::TempDir() + "/run_outputs_every";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const Config c = EveryOutput(dir);
  const auto planned = PlannedOutputs(c);
  // Written by hand from docs/output_formats.md: the matrix files, the settings beside them,
  // the images, the matches.
  EXPECT_EQ(PathsOf(planned),
            (std::vector<std::string>{dir + "/m.npy", dir + "/m.txt", dir + "/m.npy.json",
                                      dir + "/m.txt.json", dir + "/m.png",
                                      dir + "/m_thresholded.png", dir + "/matches.csv"}));
  EXPECT_EQ(planned[2].first, "Npy_name (settings)");
  EXPECT_EQ(planned[5].first, "Png_name (thresholded image)");
  RunResult r = SmallRun();
  const std::vector<std::string> written = WriteOutputs(c, r);
  EXPECT_EQ(written, PathsOf(planned));
  for (const std::string& path : written) EXPECT_TRUE(fs::is_regular_file(path)) << path;
  // The text holds the thresholded matrix (Eq. 9: 0 where M' < 0.5, 1 otherwise).
  EXPECT_EQ(testing::ReadBytes(dir + "/m.txt").substr(0, 6), "0 0 1\n");
}

TEST(RunOutputs, ABoundedRunNotesEachDenseFileItDoesNotWrite) {
  const Config c = EveryOutput(testing::TempDir());
  RunResult r = SmallRun();
  EXPECT_TRUE(UnwrittenOutputNotes(c, r).empty());  // dense: every file is written
  r.bounded = true;
  const std::vector<std::string> notes = UnwrittenOutputNotes(c, r);
  ASSERT_EQ(notes.size(), 4u);
  EXPECT_EQ(notes[0],
            "Npy_name: not written: the run is bounded and keeps no dense matrix (see "
            "Matches_name)");
  EXPECT_EQ(notes[1].substr(0, 9), "Txt_name:");
  EXPECT_EQ(notes[2].substr(0, 9), "Png_name:");
  EXPECT_EQ(notes[3].substr(0, 29), "Png_name (thresholded image):");
}

}  // namespace
}  // namespace openable
