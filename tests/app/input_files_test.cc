// Every reader of an input file refuses a FIFO and a folder by name, in one line and at once:
// frames, saved maps, videos, bags, configurations, calibrations, ground truth, trajectories,
// frame times, matrices and their settings (base/input_file.h is the one way they open files).
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <functional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "OpenABLE/evaluation/matrix_file.h"
#include "OpenABLE/evaluation/pairs_file.h"
#include "OpenABLE/evaluation/pose_file.h"
#include "OpenABLE/io/frame_source.h"
#include "OpenABLE/odometry/calibration.h"
#include "OpenABLE/online/map_file.h"
#include "OpenABLE/outputs/matrix_settings.h"
#include "OpenABLE/snaps/loops.h"
#include "OpenABLE/stereo/calibration.h"
#include "OpenABLE/verification/verification.h"
#include "config/config.h"
#include "tests/test_support.h"

namespace openable {
namespace {

namespace fs = std::filesystem;
using testing::Q;
using testing::TempDir;

struct Reader {
  std::string name;
  std::function<void(const std::string&)> read;  // reads the file at the path given
};

std::vector<Reader> Readers() {
  return {
      {"image", [](const std::string& p) { ReadImageFile(p); }},
      {"map", [](const std::string& p) { ReadMapFile(p); }},
      {"video", [](const std::string& p) { OpenVideo(p, 0, -1); }},
      {"bag",
       [](const std::string& p) {
         OpenBag(p, "/cam0/image_raw", 0, -1, "Images_path", "Bag_topic");
       }},
      {"configuration", [](const std::string& p) { LoadConfig(p); }},
      {"pairs", [](const std::string& p) { ReadPairsFile(p, -1, "ground truth pairs"); }},
      {"poses",
       [](const std::string& p) { ReadPoseFile(p, PoseFileFormat::kKitti, "Ground_truth"); }},
      {"matrix", [](const std::string& p) { ReadMatrixFile(p); }},
      {"stereo calibration", [](const std::string& p) { LoadStereoCalibration(p); }},
      {"KITTI calibration", [](const std::string& p) { odometry::ReadKittiCalibration(p, 1.0); }},
      {"verification calibration",
       [](const std::string& p) {
         ReadVerificationCalibration(p, 1.0, "Verification_calibration");
       }},
      {"frame times", [](const std::string& p) { snaps::ReadFrameTimes(p, "Snaps_frame_times"); }},
  };
}

// The message of `read(path)`, with a writer opened on a FIFO after 3 s so that a reader that
// blocked on it ends (and fails on its message: an empty read, not the FIFO named) rather than
// hangs.
std::string MessageOf(const Reader& r, const std::string& path, bool fifo) {
  std::atomic<bool> done{false};
  std::thread unblock([&] {
    for (int i = 0; i < 30 && !done; ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    if (fifo && !done) {
      const int fd = ::open(path.c_str(), O_WRONLY | O_NONBLOCK);
      if (fd >= 0) ::close(fd);
    }
  });
  std::string message;
  try {
    r.read(path);
    message = "(no error)";
  } catch (const InputError& e) {
    message = e.what();
  } catch (const std::exception& e) {
    message = std::string("(not an InputError) ") + e.what();
  }
  done = true;
  unblock.join();
  return message;
}

TEST(InputFiles, EveryReaderRefusesAFifoByNameAtOnce) {
  const std::string dir = TempDir() + "/input_files_fifo";
  fs::remove_all(dir);
  fs::create_directories(dir);
  for (const Reader& r : Readers()) {
    // A name each reader accepts by its extension, so that the check of the file is what speaks.
    const std::string path = dir + "/input" +
                             (r.name == "image"    ? ".png"
                              : r.name == "video"  ? ".avi"
                              : r.name == "bag"    ? ".bag"
                              : r.name == "matrix" ? ".npy"
                                                   : ".txt");
    fs::remove(path);
    ASSERT_EQ(::mkfifo(path.c_str(), 0600), 0);
    const std::string message = MessageOf(r, path, true);
    SCOPED_TRACE(r.name + ": " + message);
    EXPECT_NE(message.find(Q(path) + " is a FIFO (named pipe), not a regular file"),
              std::string::npos);
    EXPECT_EQ(message.find('\n'), std::string::npos);
    fs::remove(path);
  }
  // The settings beside a matrix (<matrix>.json), read when the matrix is evaluated.
  const std::string matrix = dir + "/m.npy";
  ASSERT_EQ(::mkfifo((matrix + ".json").c_str(), 0600), 0);
  const std::string message =
      MessageOf({"settings", [](const std::string& p) { ReadMatrixSettings(p); }}, matrix, false);
  EXPECT_NE(message.find(Q(matrix + ".json") + " is a FIFO (named pipe), not a regular file"),
            std::string::npos)
      << message;
}

TEST(InputFiles, EveryReaderRefusesAFolderByName) {
  for (const Reader& r : Readers()) {
    const std::string dir =
        TempDir() + "/input_files_folder." + (r.name == "video" ? "avi" : "npy");
    fs::create_directories(dir);
    const std::string message = MessageOf(r, dir, false);
    SCOPED_TRACE(r.name + ": " + message);
    EXPECT_NE(message.find(Q(dir) + " is a folder, not a regular file"), std::string::npos);
    EXPECT_EQ(message.find("basic_filebuf"), std::string::npos);
    EXPECT_EQ(message.find('\n'), std::string::npos);
  }
}

}  // namespace
}  // namespace openable
