// The rooms of the source tree and what each may include (docs/architecture.md, "Modules"): a
// room includes only rooms on its floor or below, and no header includes itself through
// others. Read from the sources themselves, so an include that runs back up fails here.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include "tests/test_support.h"

namespace openable {
namespace {

namespace fs = std::filesystem;

// From the ground up; a room may include the rooms before it in this list, never after.
const std::vector<std::string> kRooms = {
    "OpenABLE/base",    "OpenABLE/io",     "descriptors",       "matching",
    "OpenABLE/image",   "OpenABLE/stereo", "OpenABLE/describe", "OpenABLE/evaluation",
    "OpenABLE/cluster", "OpenABLE/snaps",  "OpenABLE/odometry", "OpenABLE/verification",
    "config",           "OpenABLE/run",    "OpenABLE/reports",  "OpenABLE/tuning",
    "OpenABLE/outputs", "OpenABLE/app",    "OpenABLE/online",   "OpenABLE/python",
};

int FloorOf(const std::string& path) {
  for (std::size_t i = 0; i < kRooms.size(); ++i)
    if (path.rfind(kRooms[i] + "/", 0) == 0) return static_cast<int>(i);
  return -1;
}

// Every project include ("folder/file.h") of every source file of the rooms.
std::map<std::string, std::vector<std::string>> Includes() {
  std::map<std::string, std::vector<std::string>> out;
  const std::regex include("^#include \"([^\"]+)\"");
  for (const std::string& room : kRooms) {
    for (const auto& entry : fs::recursive_directory_iterator(testing::SourceDir() + "/" + room)) {
      const std::string ext = entry.path().extension().string();
      if (ext != ".h" && ext != ".cc") continue;
      const std::string file = fs::relative(entry.path(), testing::SourceDir()).string();
      std::ifstream in(entry.path());
      std::string line;
      std::smatch m;
      auto& list = out[file];
      while (std::getline(in, line))
        if (std::regex_search(line, m, include)) list.push_back(m[1]);
    }
  }
  return out;
}

TEST(Layering, EveryIncludeStaysOnItsFloorOrBelow) {
  const auto includes = Includes();
  ASSERT_GT(includes.size(), 100u) << "sources not found under " << testing::SourceDir();
  for (const auto& [file, list] : includes) {
    const int floor = FloorOf(file);
    ASSERT_GE(floor, 0) << file;
    for (const std::string& target : list) {
      const int to = FloorOf(target);
      if (to < 0) {
        // Outside the rooms: third-party headers written with quotes, or the umbrella header.
        EXPECT_TRUE(target == "OpenABLE/OpenABLE.h" && kRooms[floor] == "OpenABLE/python")
            << file << " includes " << target << ", which belongs to no room";
        continue;
      }
      EXPECT_LE(to, floor) << file << " (" << kRooms[floor] << ") includes " << target << " ("
                           << kRooms[to] << "), a room above it";
    }
  }
}

TEST(Layering, NoHeaderIncludesItselfThroughOthers) {
  const auto includes = Includes();
  // Depth-first search over the headers: a header met again while it is on the path is a cycle.
  std::map<std::string, int> state;  // 1 on the path, 2 done
  std::vector<std::string> path;
  std::function<void(const std::string&)> visit = [&](const std::string& header) {
    state[header] = 1;
    path.push_back(header);
    const auto it = includes.find(header);
    if (it != includes.end()) {
      for (const std::string& next : it->second) {
        if (state[next] == 1) {
          std::string cycle;
          for (auto p = std::find(path.begin(), path.end(), next); p != path.end(); ++p)
            cycle += *p + " -> ";
          ADD_FAILURE() << "include cycle: " << cycle << next;
        } else if (state[next] == 0) {
          visit(next);
        }
      }
    }
    path.pop_back();
    state[header] = 2;
  };
  for (const auto& [file, list] : includes)
    if (state[file] == 0) visit(file);
}

// The test can fail: an include from the ground floor up to the pipeline is caught.
TEST(Layering, AnIncludeRunningBackUpIsCaught) {
  EXPECT_GT(FloorOf("OpenABLE/run/pipeline.h"), FloorOf("OpenABLE/base/strings.h"));
  EXPECT_GT(FloorOf("OpenABLE/app/run.h"), FloorOf("OpenABLE/outputs/run_outputs.h"));
  EXPECT_EQ(FloorOf("OpenABLE/OpenABLE.h"), -1);
}

}  // namespace
}  // namespace openable
