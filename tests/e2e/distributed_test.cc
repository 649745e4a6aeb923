// Runs spread over processes with mpirun (OpenABLE/cluster/cluster.h, docs/distributed.md): every
// output equals the single-process run's, byte for byte for Hamming distances and within
// 1e-5 for L2 (whose matrix products sum in another order when the rows are split), in the
// dense and the bounded mode, for one and two traversals, L = 1 and L = 10, with 1, 2 and 3
// processes; a process that fails ends the run with one line naming it and leaves no output.
// Skipped, saying why, when mpirun or the MPI module is absent.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <ostream>
#include <sstream>
#include <string>
#include <vector>

#include "OpenABLE/io/npy.h"
#include "tests/e2e/e2e_support.h"
#include "tests/test_support.h"

namespace openable {
namespace {

using namespace e2e;  // NOLINT: the e2e helpers are this file's vocabulary

namespace fs = std::filesystem;

// Why the tests cannot run here, or empty.
std::string MissingMpi() {
  if (std::system("command -v mpirun > /dev/null 2>&1") != 0)
    return "mpirun is not installed (Debian: openmpi-bin)";
  const fs::path module = fs::path(testing::TestOpenableExe()).parent_path().parent_path() /
                          "modules" / "libopenable_mpi.so";
  if (!fs::exists(module))
    return "this build has no MPI module (" + module.string() +
           "; configure with libopenmpi-dev installed)";
  return "";
}

// `program` run by mpirun with `processes` processes (0: run directly, one process).
Outcome RunSpread(int processes, const std::string& program, const std::vector<std::string>& args,
                  const std::string& dir) {
  if (processes == 0) return RunProgram(program, args, dir);
  // Root may run mpirun in containers and CI; --quiet keeps mpirun's own summary of a failed
  // run out of the output, so that what is left is the program's.
  std::vector<std::string> all = {"OMPI_ALLOW_RUN_AS_ROOT=1",
                                  "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1",
                                  "OMPI_MCA_rmaps_base_oversubscribe=1",
                                  "mpirun",
                                  "--quiet",
                                  "-np",
                                  std::to_string(processes),
                                  program};
  all.insert(all.end(), args.begin(), args.end());
  return RunProgram("/usr/bin/env", all, dir);
}

struct Case {
  const char* name;
  const char* descriptor;  // LDB: Hamming, HOG: L2
  bool bounded;
  bool two_traversals;
  int sequence_length;
};

// `images`: the first traversal's folder (empty: the sample's summer frames).
// Test names and failure messages show the case's name, not its bytes.
void PrintTo(const Case& c, std::ostream* os) { *os << c.name; }

std::string ConfigOf(const std::string& dir, const Case& c, const std::string& images = "") {
  const std::string path = dir + "/Config.txt";
  std::ofstream f(path);
  f << "%YAML:1.0\n"
    << "Images_path: \"" << (images.empty() ? testing::SampleDir() + "/summer" : images) << "\"\n"
    << "Images_path_2: \"" << (c.two_traversals ? testing::SampleDir() + "/winter" : "") << "\"\n"
    << "Image_descriptor: " << c.descriptor << "\n"
    << "Image_sequences: " << c.sequence_length << "\n"
    << "Matrix_mode: " << (c.bounded ? 2 : 1) << "\n"
    << "Best_matches: 5\n"
    << "Exclusion: 20\n"
    << "Threshold: 0.3\n"
    << "Matches_name: \"out/matches.csv\"\n";
  if (!c.bounded)
    f << "Txt_name: \"out/matrix.txt\"\nNpy_name: \"out/matrix.npy\"\n"
      << "Png_name: \"out/matrix.png\"\n";
  return path;
}

// Lines of a matches CSV split at commas.
std::vector<std::vector<std::string>> CsvRows(const std::string& path) {
  std::vector<std::vector<std::string>> rows;
  std::istringstream in(ReadAll(path));
  std::string line;
  while (std::getline(in, line)) {
    std::vector<std::string> cells;
    std::istringstream l(line);
    std::string cell;
    while (std::getline(l, cell, ',')) cells.push_back(cell);
    rows.push_back(cells);
  }
  return rows;
}

// The matches of two runs: equal, or (L2) equal frames and ranks with values within 1e-5.
// L2 distances come from |a|^2 + |b|^2 - 2 a.b in float32, and the bounded pipeline's blocks of
// 16 query rows start at each process's first row, so OpenBLAS may sum a.b with another kernel
// (the edge kernels of a partial block): a difference of a few units in the last place of a.b
// (HOG rows: |a|^2 near 49) is 1e-6 to 1e-5 of a normalised distance after the cancellation
// (1.5e-6 measured on an AMD EPYC with OpenBLAS's Zen kernels, 2e-7 on an Intel Xeon).
void ExpectSameMatches(const std::string& a, const std::string& b, bool exact) {
  if (exact) {
    EXPECT_EQ(ReadAll(a), ReadAll(b)) << a << " and " << b << " differ";
    return;
  }
  const auto ra = CsvRows(a), rb = CsvRows(b);
  ASSERT_EQ(ra.size(), rb.size());
  for (size_t i = 0; i < ra.size(); ++i) {
    ASSERT_EQ(ra[i].size(), rb[i].size()) << "line " << i;
    for (size_t k = 0; k < ra[i].size(); ++k) {
      if (i > 0 && ra[i][k].find('.') != std::string::npos) {
        EXPECT_NEAR(std::stod(ra[i][k]), std::stod(rb[i][k]), 1e-5) << "line " << i;
      } else {
        EXPECT_EQ(ra[i][k], rb[i][k]) << "line " << i;
      }
    }
  }
}

// Copies the sample's summer frames to <dir>/frames; returns the copies in order.
std::vector<std::string> CopySummerFrames(const std::string& dir) {
  fs::create_directories(dir + "/frames");
  std::vector<fs::path> images;
  for (const auto& e : fs::directory_iterator(testing::SampleDir() + "/summer"))
    images.push_back(e.path());
  std::sort(images.begin(), images.end());
  std::vector<std::string> copies;
  for (const fs::path& p : images) {
    copies.push_back(dir + "/frames/" + p.filename().string());
    fs::copy_file(p, copies.back());
  }
  return copies;
}

class Spread : public ::testing::TestWithParam<Case> {};

TEST_P(Spread, OneTwoAndThreeProcessesWriteTheSingleProcessOutputs) {
  const std::string missing = MissingMpi();
  if (!missing.empty()) GTEST_SKIP() << missing;
  const Case& c = GetParam();
  const bool hamming = std::string(c.descriptor) == "LDB";
  const std::string single = testing::TempDir();
  const Outcome one =
      RunProgram(testing::TestOpenableExe(), {ConfigOf(single, c), "--quiet"}, single);
  ASSERT_EQ(one.status, 0) << one.err;
  for (const int processes : {1, 2, 3}) {
    SCOPED_TRACE(std::to_string(processes) + " processes");
    const std::string dir = testing::TempDir();
    const Outcome o =
        RunSpread(processes, testing::TestOpenableExe(), {ConfigOf(dir, c), "--quiet"}, dir);
    ASSERT_EQ(o.status, 0) << o.err << o.out;
    if (processes > 1) {
      EXPECT_NE(o.out.find("processes: " + std::to_string(processes)), std::string::npos) << o.out;
    }
    ExpectSameMatches(single + "/out/matches.csv", dir + "/out/matches.csv", hamming);
    if (c.bounded) {
      EXPECT_FALSE(fs::exists(dir + "/out/matrix.npy"));
      continue;
    }
    const cv::Mat1f a = ReadNpy(single + "/out/matrix.npy");
    const cv::Mat1f b = ReadNpy(dir + "/out/matrix.npy");
    ASSERT_EQ(a.size(), b.size());
    ASSERT_FALSE(a.empty());
    if (hamming) {
      EXPECT_EQ(ReadAll(single + "/out/matrix.npy"), ReadAll(dir + "/out/matrix.npy"));
      EXPECT_EQ(ReadAll(single + "/out/matrix.txt"), ReadAll(dir + "/out/matrix.txt"));
      EXPECT_EQ(ReadAll(single + "/out/matrix.png"), ReadAll(dir + "/out/matrix.png"));
    } else {
      double worst = 0;
      for (int i = 0; i < a.rows; ++i)
        for (int j = 0; j < a.cols; ++j)
          worst = std::max(worst, static_cast<double>(std::abs(a(i, j) - b(i, j))));
      EXPECT_LE(worst, 1e-6);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Mpi, Spread,
                         ::testing::Values(Case{"LdbDenseOneL1", "LDB", false, false, 1},
                                           Case{"LdbDenseOneL10", "LDB", false, false, 10},
                                           Case{"LdbDenseTwoL1", "LDB", false, true, 1},
                                           Case{"LdbDenseTwoL10", "LDB", false, true, 10},
                                           Case{"LdbBoundedOneL1", "LDB", true, false, 1},
                                           Case{"LdbBoundedOneL10", "LDB", true, false, 10},
                                           Case{"LdbBoundedTwoL1", "LDB", true, true, 1},
                                           Case{"LdbBoundedTwoL10", "LDB", true, true, 10},
                                           Case{"HogDenseOneL1", "HOG", false, false, 1},
                                           Case{"HogDenseOneL10", "HOG", false, false, 10},
                                           Case{"HogDenseTwoL1", "HOG", false, true, 1},
                                           Case{"HogDenseTwoL10", "HOG", false, true, 10},
                                           Case{"HogBoundedOneL1", "HOG", true, false, 1},
                                           Case{"HogBoundedOneL10", "HOG", true, false, 10},
                                           Case{"HogBoundedTwoL1", "HOG", true, true, 1},
                                           Case{"HogBoundedTwoL10", "HOG", true, true, 10}),
                         [](const ::testing::TestParamInfo<Case>& info) {
                           return std::string(info.param.name);
                         });

// Descriptors users bring, spread over processes: a network (the GeM test network), DenseVLAD
// (each process learns the same vocabulary from the same frames) and rows computed elsewhere
// (Descriptors_path: every process reads the file, none describes), dense and bounded: two
// processes write the one-process outputs.
TEST(SpreadBrought, ANetworkDenseVladAndGivenRowsGiveTheOneProcessOutputs) {
  const std::string missing = MissingMpi();
  if (!missing.empty()) GTEST_SKIP() << missing;
  const std::string rows_dir = testing::TempDir();
  cv::Mat1f rows(300, 48);
  cv::RNG(11).fill(rows, cv::RNG::UNIFORM, 0.0, 1.0);
  std::ofstream(rows_dir + "/rows.npy", std::ios::binary) << EncodeNpy(rows);
  struct Brought {
    const char* name;
    const char* descriptor;
    std::vector<std::string> keys;
  };
  const std::vector<Brought> cases = {
      {"network",
       "ONNX",
       {"Model_path: \"" + testing::SourceDir() + "/tests/data/onnx/gem.onnx\"",
        "Model_input_size: \"64x32\""}},
      {"DenseVLAD", "DenseVLAD", {}},
      {"given rows", "HOG", {"Descriptors_path: \"" + rows_dir + "/rows.npy\""}},
      {"given rows, bounded", "HOG", {"Descriptors_path: \"" + rows_dir + "/rows.npy\""}}};
  for (const Brought& brought : cases) {
    const std::string name = brought.name;
    const std::vector<std::string>& keys = brought.keys;
    SCOPED_TRACE(name);
    const bool bounded = name.find("bounded") != std::string::npos;
    std::string outputs[2];
    for (const int processes : {0, 2}) {
      const std::string dir = testing::TempDir();
      const Case c{"", brought.descriptor, bounded, false, 5};
      const std::string config = ConfigOf(dir, c);
      {
        std::ofstream f(config, std::ios::app);
        for (const std::string& k : keys) f << k << "\n";
      }
      const Outcome o = RunSpread(processes, testing::TestOpenableExe(), {config, "--quiet"}, dir);
      ASSERT_EQ(o.status, 0) << o.err << o.out;
      outputs[processes == 0 ? 0 : 1] = dir;
    }
    ExpectSameMatches(outputs[0] + "/out/matches.csv", outputs[1] + "/out/matches.csv", false);
    if (bounded) continue;
    const cv::Mat1f a = ReadNpy(outputs[0] + "/out/matrix.npy");
    const cv::Mat1f b = ReadNpy(outputs[1] + "/out/matrix.npy");
    ASSERT_EQ(a.size(), b.size());
    ASSERT_EQ(a.rows, 300);
    double worst = 0;
    for (int i = 0; i < a.rows; ++i)
      for (int j = 0; j < a.cols; ++j)
        if (std::isfinite(a(i, j)) || std::isfinite(b(i, j)))
          worst = std::max(worst, static_cast<double>(std::abs(a(i, j) - b(i, j))));
    EXPECT_LE(worst, 1e-6);
  }
}

// A frame that only process 1 reads is damaged: the run ends on every process, process 0 says
// so in one line naming the frame and the process, and nothing is written.
TEST(SpreadFailure, AFrameOfOneShareEndsTheRunInOneLineWithNoOutput) {
  const std::string missing = MissingMpi();
  if (!missing.empty()) GTEST_SKIP() << missing;
  const std::string dir = testing::TempDir();
  const std::string damaged = CopySummerFrames(dir).back();
  std::ofstream(damaged, std::ios::trunc) << "not an image";
  const Case c{"", "LDB", false, false, 5};
  const std::string config = ConfigOf(dir, c, dir + "/frames");
  const Outcome o = RunSpread(2, testing::TestOpenableExe(), {config, "--quiet"}, dir);
  EXPECT_EQ(o.status, 1) << o.err;
  EXPECT_EQ(o.out, "");
  EXPECT_EQ(std::count(o.err.begin(), o.err.end(), '\n'), 1) << o.err;
  EXPECT_NE(o.err.find("Test_OpenABLE: error: Images_path: image \"" + damaged), std::string::npos)
      << o.err;
  EXPECT_NE(o.err.find("(process 1 of 2)"), std::string::npos) << o.err;
  EXPECT_FALSE(fs::exists(dir + "/out")) << "an output of the failed run was left";
}

// Ctrl-C on mpirun while the frames are described: mpirun ends every process with SIGTERM;
// the user reads at most one line (process 0's), never one per process, and no output is left.
// At most: Open MPI's mpirun (4.1) sends SIGCONT, waits a second, then SIGTERM and SIGKILL
// about 2 ms apart, so on a busy machine process 0 may be killed before its handler runs and
// the line is not printed (measured: 6 runs of 10 with the other core busy; docs/distributed.md).
// The other processes, silent by design, are also what mpirun ends when process 0 has already
// reported a failure (the case above), so this guards that one line too.
TEST(SpreadFailure, CtrlCOnMpirunPrintsAtMostOneLineAndLeavesNoOutput) {
  const std::string missing = MissingMpi();
  if (!missing.empty()) GTEST_SKIP() << missing;
  const std::string data = testing::DatasetsDir() + "/kitti00_first1700/image_0";
  OPENABLE_REQUIRE_PATH(data);
  const std::string dir = testing::TempDir();
  // The interrupt comes 300 ms after the progress line of the first traversal (KITTI 00's 1700
  // frames; the line is written when a traversal is described, stderr not being a terminal).
  // The second traversal lists every frame six times (links), six times as long to
  // describe as the first on any machine, so that the interrupt lands while it is described
  // and never after the run has written its output.
  const std::string repeated = dir + "/repeated";
  fs::create_directories(repeated);
  std::vector<fs::path> frames;
  for (const auto& e : fs::directory_iterator(data)) frames.push_back(e.path());
  std::sort(frames.begin(), frames.end());
  int link = 0;
  for (int copy = 0; copy < 6; ++copy)
    for (const fs::path& frame : frames) {
      char name[32];
      std::snprintf(name, sizeof name, "%06d.png", link++);
      fs::create_symlink(frame, repeated + "/" + name);
    }
  const std::string config = dir + "/Config.txt";
  std::ofstream(config) << "%YAML:1.0\nImages_path: \"" << data << "\"\nImages_path_2: \""
                        << repeated << "\"\nImage_descriptor: LDB\nThreads: 1\n"
                        << "Npy_name: \"out/matrix.npy\"\n";
  const std::string err = dir + "/stderr.log";
  const pid_t child = StartRunToInterrupt(
      dir, {"mpirun", "--quiet", "-np", "2", testing::TestOpenableExe(), config}, err,
      {"OMPI_ALLOW_RUN_AS_ROOT=1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1",
       "OMPI_MCA_rmaps_base_oversubscribe=1"},
      10000);
  ASSERT_GT(child, 0);
  int status = 0;
  if (::waitpid(child, &status, WNOHANG) == child)
    GTEST_SKIP() << "the run finished before it could be interrupted";
  ASSERT_EQ(::kill(child, SIGINT), 0);
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  EXPECT_FALSE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  const std::string e = ReadAll(err);
  const std::string line = "Test_OpenABLE: interrupted by SIGTERM (temporary files removed)\n";
  size_t count = 0;
  for (size_t at = e.find(line); at != std::string::npos; at = e.find(line, at + 1)) ++count;
  EXPECT_LE(count, 1u) << e;
  EXPECT_EQ(e.find("(process 1 of 2)"), std::string::npos) << e;
  EXPECT_FALSE(fs::exists(dir + "/out")) << "an output of the interrupted run was left";
}

// With Skip_unreadable, the damaged frame of the last share is skipped as in a single
// process: the same matrix, the same frame listed as skipped.
TEST(SpreadFailure, SkippedFramesOfAShareAreSkippedAsInOneProcess) {
  const std::string missing = MissingMpi();
  if (!missing.empty()) GTEST_SKIP() << missing;
  const std::string dir = testing::TempDir();
  const std::vector<std::string> frames = CopySummerFrames(dir);
  std::ofstream(frames.back(), std::ios::trunc) << "x";
  const Case c{"", "LDB", false, false, 5};
  const std::string config = ConfigOf(dir, c, dir + "/frames");
  std::ofstream(config, std::ios::app) << "Skip_unreadable: 1\n";
  const Outcome one = RunProgram(testing::TestOpenableExe(), {config, "--quiet"}, dir);
  ASSERT_EQ(one.status, 0) << one.err;
  const std::string single = ReadAll(dir + "/out/matrix.npy");
  fs::remove_all(dir + "/out");
  const Outcome o = RunSpread(3, testing::TestOpenableExe(), {config, "--quiet"}, dir);
  ASSERT_EQ(o.status, 0) << o.err;
  EXPECT_EQ(ReadAll(dir + "/out/matrix.npy"), single);
  EXPECT_NE(o.out.find("skipped: image \"" + frames.back()), std::string::npos) << o.out;
  EXPECT_NE(o.out.find(std::to_string(frames.size() - 1) + " frames of"), std::string::npos)
      << o.out;
}

// The other programs are not spread: under mpirun with several processes they say so.
TEST(SpreadFailure, ProgramsThatDoNotSpreadRefuseSeveralProcesses) {
  const std::string missing = MissingMpi();
  if (!missing.empty()) GTEST_SKIP() << missing;
  const std::string dir = testing::TempDir();
  const Case c{"", "LDB", false, false, 1};
  const Outcome o = RunSpread(2, testing::OpenableSweepExe(),
                              {ConfigOf(dir, c), "--vary", "Image_sequences=1,2"}, dir);
  EXPECT_EQ(o.status, 1) << o.err;
  EXPECT_EQ(o.err,
            "openable_sweep: error: openable_sweep runs as one process, but mpirun started 2; "
            "expected one (Test_OpenABLE spreads a run over processes)\n");
}

TEST(SpreadFailure, OpenableEvaluateRefusesSeveralProcesses) {
  const std::string missing = MissingMpi();
  if (!missing.empty()) GTEST_SKIP() << missing;
  const std::string dir = testing::TempDir();
  const Outcome o = RunSpread(2, testing::OpenableEvaluateExe(), {"--matrix", "m.npy"}, dir);
  EXPECT_EQ(o.status, 1) << o.err;
  EXPECT_EQ(o.err,
            "openable_evaluate: error: openable_evaluate runs as one process, but mpirun "
            "started 2; expected one (Test_OpenABLE spreads a run over processes)\n");
}

}  // namespace
}  // namespace openable
