// The rooms of the source tree and what each may use (docs/architecture.md, "What each room may
// include"), read from the sources' #include lines and from the CMake link lists: every use must
// be one the room's list allows, none may break a "never" rule, and no header includes itself
// through others.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "tests/test_support.h"

namespace openable {
namespace {

namespace fs = std::filesystem;

// Each room and the rooms it may use, from the ground up (a room always uses itself).
const std::vector<std::pair<std::string, std::set<std::string>>> kRooms = {
    {"OpenABLE/base", {}},
    {"OpenABLE/io", {"OpenABLE/base"}},
    {"descriptors", {"OpenABLE/base"}},
    {"matching", {"OpenABLE/base"}},
    {"OpenABLE/image", {"OpenABLE/base"}},
    {"OpenABLE/stereo", {"OpenABLE/base", "OpenABLE/io"}},
    {"OpenABLE/describe",
     {"OpenABLE/base", "OpenABLE/io", "descriptors", "matching", "OpenABLE/image"}},
    {"OpenABLE/evaluation", {"OpenABLE/base", "OpenABLE/io", "matching"}},
    {"OpenABLE/cluster",
     {"OpenABLE/base", "OpenABLE/io", "descriptors", "matching", "OpenABLE/describe"}},
    {"OpenABLE/snaps", {"OpenABLE/base", "OpenABLE/io", "OpenABLE/image", "OpenABLE/evaluation"}},
    {"OpenABLE/odometry", {"OpenABLE/base", "OpenABLE/stereo"}},
    {"OpenABLE/verification",
     {"OpenABLE/base", "OpenABLE/image", "OpenABLE/stereo", "OpenABLE/odometry"}},
    {"config",
     {"OpenABLE/base", "descriptors", "matching", "OpenABLE/image", "OpenABLE/evaluation",
      "OpenABLE/snaps", "OpenABLE/odometry", "OpenABLE/verification"}},
    {"OpenABLE/run",
     {"OpenABLE/base", "OpenABLE/io", "descriptors", "matching", "OpenABLE/image",
      "OpenABLE/stereo", "OpenABLE/describe", "OpenABLE/evaluation", "OpenABLE/cluster",
      "OpenABLE/verification", "config"}},
    {"OpenABLE/reports",
     {"OpenABLE/base", "OpenABLE/io", "OpenABLE/evaluation", "config", "OpenABLE/run"}},
    {"OpenABLE/tuning",
     {"OpenABLE/base", "OpenABLE/io", "descriptors", "matching", "OpenABLE/evaluation",
      "OpenABLE/cluster", "config", "OpenABLE/run", "OpenABLE/reports"}},
    {"OpenABLE/outputs",
     {"OpenABLE/base", "OpenABLE/io", "matching", "OpenABLE/evaluation", "config", "OpenABLE/run",
      "OpenABLE/reports", "OpenABLE/tuning"}},
    {"OpenABLE/app",
     {"OpenABLE/base", "OpenABLE/io", "OpenABLE/image", "OpenABLE/stereo", "OpenABLE/evaluation",
      "OpenABLE/cluster", "OpenABLE/snaps", "OpenABLE/odometry", "config", "OpenABLE/run",
      "OpenABLE/reports", "OpenABLE/tuning", "OpenABLE/outputs"}},
    {"OpenABLE/online",
     {"OpenABLE/base", "OpenABLE/io", "descriptors", "matching", "OpenABLE/image",
      "OpenABLE/describe", "OpenABLE/evaluation", "OpenABLE/verification", "config", "OpenABLE/run",
      "OpenABLE/reports", "OpenABLE/tuning", "OpenABLE/app"}},
    {"OpenABLE/python",
     {"OpenABLE/base", "OpenABLE/io", "descriptors", "matching", "OpenABLE/image",
      "OpenABLE/evaluation", "OpenABLE/snaps", "config", "OpenABLE/run", "OpenABLE/tuning",
      "OpenABLE/app", "OpenABLE/online"}},
};

// The rules docs/architecture.md states as "never": a use from `from` (a room, or a file of it
// when `files` is not empty) to `to` breaks it. They hold even if a room's list grows.
struct NeverRule {
  std::string name, from, to;
  std::set<std::string> files;  // empty: every file of `from`
};
const std::vector<NeverRule> kNever = {
    {"the ground floor uses no room", "OpenABLE/base", "*", {}},
    {"frame sources stand on base alone", "OpenABLE/io", "*OpenABLE/base", {}},
    {"descriptors read no files (frames come decoded)", "descriptors", "OpenABLE/io", {}},
    {"matching reads no files (rows come described)", "matching", "OpenABLE/io", {}},
    {"evaluation never sees a run", "OpenABLE/evaluation", "OpenABLE/run", {}},
    {"a run writes no files of its own (outputs/ does)", "OpenABLE/run", "OpenABLE/outputs", {}},
    {"a run neither reports nor tunes", "OpenABLE/run", "OpenABLE/reports|OpenABLE/tuning", {}},
    {"the online detector needs no pipeline (the map fuzzer builds it alone)",
     "OpenABLE/online",
     "OpenABLE/run|OpenABLE/tuning|OpenABLE/app|OpenABLE/outputs",
     {"OpenABLE/online/online.h", "OpenABLE/online/online.cc", "OpenABLE/online/map_file.h",
      "OpenABLE/online/map_file.cc"}},
};

// The room of a path ("matching/score.h" -> "matching"); empty when it belongs to none.
std::string RoomOf(const std::string& path) {
  for (const auto& [room, uses] : kRooms)
    if (path.rfind(room + "/", 0) == 0) return room;
  return "";
}

bool Allowed(const std::string& from, const std::string& to) {
  if (from == to) return true;
  for (const auto& [room, uses] : kRooms)
    if (room == from) return uses.count(to) > 0;
  return false;
}

bool Breaks(const NeverRule& rule, const std::string& file, const std::string& from,
            const std::string& to) {
  if (from != rule.from || from == to) return false;
  if (!rule.files.empty() && rule.files.count(file) == 0) return false;
  if (rule.to == "*") return true;
  if (rule.to[0] == '*') return to != rule.to.substr(1);  // anything but
  std::stringstream targets(rule.to);
  std::string t;
  while (std::getline(targets, t, '|'))
    if (t == to) return true;
  return false;
}

// One use of a room by another: from a file's #include, or from a target's link list (`file`
// is then the CMakeLists.txt and `what` the linked target).
struct Use {
  std::string file, what, from, to;
};

// Every broken rule among `uses`, one line each.
std::vector<std::string> Violations(const std::vector<Use>& uses) {
  std::vector<std::string> out;
  for (const Use& u : uses) {
    for (const NeverRule& rule : kNever)
      if (Breaks(rule, u.file, u.from, u.to))
        out.push_back(u.file + " uses " + u.what + ": never (" + rule.name + ")");
    if (!Allowed(u.from, u.to))
      out.push_back(u.file + " uses " + u.what + " (" + u.to + "), not in the list of " + u.from);
  }
  return out;
}

std::vector<std::string> SourceFiles() {
  std::vector<std::string> out;
  for (const auto& [room, uses] : kRooms)
    for (const auto& entry : fs::recursive_directory_iterator(testing::SourceDir() + "/" + room)) {
      const std::string ext = entry.path().extension().string();
      if (ext == ".h" || ext == ".cc")
        out.push_back(fs::relative(entry.path(), testing::SourceDir()).string());
    }
  return out;
}

// Every project include ("folder/file.h") of every source file of the rooms.
std::map<std::string, std::vector<std::string>> Includes() {
  std::map<std::string, std::vector<std::string>> out;
  const std::regex include("^#include \"([^\"]+)\"");
  for (const std::string& file : SourceFiles()) {
    std::ifstream in(testing::SourceDir() + "/" + file);
    std::string line;
    std::smatch m;
    auto& list = out[file];
    while (std::getline(in, line))
      if (std::regex_search(line, m, include)) list.push_back(m[1]);
  }
  return out;
}

std::vector<Use> IncludeUses() {
  std::vector<Use> uses;
  for (const auto& [file, list] : Includes())
    for (const std::string& target : list) {
      const std::string to = RoomOf(target);
      if (!to.empty()) uses.push_back({file, target, RoomOf(file), to});
    }
  return uses;
}

// The room of a CMake target of the project; empty for a target of another project.
std::string RoomOfTarget(const std::string& target) {
  static const std::map<std::string, std::string> kTargets = {
      {"openable_base", "OpenABLE/base"},
      {"openable_io", "OpenABLE/io"},
      {"openable_oiio", "OpenABLE/io"},
      {"openable_video", "OpenABLE/io"},
      {"openable_gui", "OpenABLE/io"},
      {"openable_codecs", "OpenABLE/io"},
      {"openable_rosbag", "OpenABLE/io"},
      {"openable_mpi", "OpenABLE/io"},
      {"openable_descriptors", "descriptors"},
      {"openable_dnn", "descriptors"},
      {"openable_matching", "matching"},
      {"openable_faiss", "matching"},
      {"openable_image", "OpenABLE/image"},
      {"openable_stereo", "OpenABLE/stereo"},
      {"openable_describe", "OpenABLE/describe"},
      {"openable_evaluation", "OpenABLE/evaluation"},
      {"openable_cluster", "OpenABLE/cluster"},
      {"openable_snaps_core", "OpenABLE/snaps"},
      {"openable_odometry", "OpenABLE/odometry"},
      {"openable_verification", "OpenABLE/verification"},
      {"openable_config", "config"},
      {"openable_run", "OpenABLE/run"},
      {"openable_reports", "OpenABLE/reports"},
      {"openable_tuning", "OpenABLE/tuning"},
      {"openable_outputs", "OpenABLE/outputs"},
      {"openable_app", "OpenABLE/app"},
      {"OpenABLE", "OpenABLE/online"},
      {"OpenABLE::OpenABLE", "OpenABLE/online"},
      {"openable_python", "OpenABLE/python"},
  };
  const auto it = kTargets.find(target);
  return it == kTargets.end() ? "" : it->second;
}

// The project targets each target_link_libraries(...) of `cmake_text` links.
std::vector<Use> LinkUses(const std::string& file, const std::string& cmake_text) {
  std::vector<Use> uses;
  const std::regex call(R"(target_link_libraries\(\s*([A-Za-z_:]+)([^)]*)\))");
  for (auto it = std::sregex_iterator(cmake_text.begin(), cmake_text.end(), call);
       it != std::sregex_iterator(); ++it) {
    const std::string from = RoomOfTarget((*it)[1]);
    std::stringstream items((*it)[2].str());
    std::string item;
    while (items >> item) {
      const std::string to = RoomOfTarget(item);
      if (!from.empty() && !to.empty()) uses.push_back({file, item, from, to});
    }
  }
  return uses;
}

std::vector<Use> ProjectLinkUses() {
  std::vector<Use> uses;
  for (const std::string& file :
       {"OpenABLE/CMakeLists.txt", "OpenABLE/base/CMakeLists.txt", "OpenABLE/python/CMakeLists.txt",
        "descriptors/CMakeLists.txt", "matching/CMakeLists.txt", "config/CMakeLists.txt"}) {
    std::ifstream in(testing::SourceDir() + "/" + file);
    std::stringstream text;
    text << in.rdbuf();
    const std::vector<Use> more = LinkUses(file, text.str());
    uses.insert(uses.end(), more.begin(), more.end());
  }
  return uses;
}

TEST(Layering, EveryIncludeIsAllowedAndBreaksNoNeverRule) {
  const std::vector<Use> uses = IncludeUses();
  ASSERT_GT(uses.size(), 500u) << "sources not found under " << testing::SourceDir();
  for (const std::string& v : Violations(uses)) ADD_FAILURE() << v;
  // Every source file belongs to a room; a quoted include outside them is the umbrella header,
  // which only the Python module includes.
  for (const auto& [file, list] : Includes())
    for (const std::string& target : list)
      if (RoomOf(target).empty())
        EXPECT_TRUE(target == "OpenABLE/OpenABLE.h" && RoomOf(file) == "OpenABLE/python")
            << file << " includes " << target << ", which belongs to no room";
}

TEST(Layering, EveryLinkIsAllowedAndBreaksNoNeverRule) {
  const std::vector<Use> uses = ProjectLinkUses();
  ASSERT_GT(uses.size(), 40u) << "link lists not found under " << testing::SourceDir();
  for (const std::string& v : Violations(uses)) ADD_FAILURE() << v;
}

// The rooms' lists form no circle: a room may not use, through others, a room that uses it.
TEST(Layering, TheRoomsListsHaveNoCircle) {
  for (std::size_t i = 0; i < kRooms.size(); ++i)
    for (const std::string& used : kRooms[i].second) {
      const auto at = std::find_if(kRooms.begin(), kRooms.end(),
                                   [&](const auto& r) { return r.first == used; });
      ASSERT_NE(at, kRooms.end()) << kRooms[i].first << " lists the unknown room " << used;
      EXPECT_LT(at - kRooms.begin(), static_cast<std::ptrdiff_t>(i))
          << kRooms[i].first << " uses " << used << ", listed after it";
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

// The checks fail on uses that break the rules: includes and links written here, each caught
// with the rule it breaks.
TEST(Layering, UsesThatBreakTheRulesAreCaught) {
  const auto caught = [](const std::vector<Use>& uses, const std::string& words) {
    const std::vector<std::string> v = Violations(uses);
    return std::any_of(v.begin(), v.end(),
                       [&](const std::string& s) { return s.find(words) != std::string::npos; });
  };
  EXPECT_TRUE(caught({{"matching/x.cc", "OpenABLE/io/npy.h", "matching", "OpenABLE/io"}},
                     "matching reads no files"));
  EXPECT_TRUE(caught(
      {{"OpenABLE/online/online.cc", "OpenABLE/run/pipeline.h", "OpenABLE/online", "OpenABLE/run"}},
      "the online detector needs no pipeline"));
  // The same include from the detector's tuning, which runs candidates, is allowed.
  EXPECT_TRUE(Violations({{"OpenABLE/online/map_tuning.cc", "OpenABLE/run/pipeline.h",
                           "OpenABLE/online", "OpenABLE/run"}})
                  .empty());
  EXPECT_TRUE(caught({{"OpenABLE/base/x.h", "OpenABLE/io/npy.h", "OpenABLE/base", "OpenABLE/io"}},
                     "the ground floor uses no room"));
  EXPECT_TRUE(caught(LinkUses("matching/CMakeLists.txt",
                              "target_link_libraries(openable_matching\n  PUBLIC openable_base\n"
                              "  PRIVATE Eigen3::Eigen openable_io)"),
                     "matching reads no files"));
  EXPECT_TRUE(caught(LinkUses("OpenABLE/CMakeLists.txt",
                              "target_link_libraries(openable_run PUBLIC openable_outputs)"),
                     "a run writes no files of its own"));
  // A use outside a room's list that no never rule names is caught by the list.
  EXPECT_TRUE(caught(LinkUses("OpenABLE/CMakeLists.txt",
                              "target_link_libraries(openable_image PRIVATE openable_stereo)"),
                     "not in the list of OpenABLE/image"));
  EXPECT_TRUE(LinkUses("x", "target_link_libraries(openable_image PRIVATE opencv_core)").empty());
}

}  // namespace
}  // namespace openable
