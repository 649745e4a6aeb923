#include "OpenABLE/online/map_program.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/progress.h"
#include "OpenABLE/base/strings.h"
#include "OpenABLE/base/threading.h"
#include "OpenABLE/io/frame_source.h"
#include "OpenABLE/io/json.h"
#include "OpenABLE/online/map_file.h"
#include "OpenABLE/online/online.h"
#include "config/config.h"

namespace openable {
namespace {

const char* const kUsageText =
    "Usage: openable_map add MAP --images FOLDER --session NAME [--time T] [--config FILE]\n"
    "                        [--set Key=Value ...]\n"
    "       openable_map info MAP [--json]\n"
    "       openable_map merge A B -o C\n"
    "       openable_map query MAP --images FOLDER [--session NAME ...] [--config FILE]\n"
    "                          [--set Key=Value ...] [--threshold X] [--json]\n"
    "\n"
    "A map holds the places of one or more sessions (traversals of a route): each frame's\n"
    "descriptor row and the index that finds them again (docs/library.md, \"Maps that grow\").\n"
    "\n"
    "  add    describes the images of FOLDER and appends them to MAP as session NAME (a new\n"
    "         name), creating MAP when it does not exist. A new map takes its description and\n"
    "         index settings from --config FILE (a Config.txt) and --set, else the defaults\n"
    "         (LDB 256 bits, global); an existing map keeps its own, and a --config that\n"
    "         describes otherwise is refused. The frames must be of the map's size. MAP is\n"
    "         replaced whole when the new one is written (an interrupted add leaves it as it\n"
    "         was).\n"
    "  info   prints the map's settings, sessions (name, time, frames), index blocks and size,\n"
    "         after verifying every checksum.\n"
    "  merge  writes C: the sessions of A, then those of B (same description settings and\n"
    "         frame size, distinct session names), indexed with A's index settings.\n"
    "  query  describes the images of FOLDER (a traversal of its own) and finds each one's best\n"
    "         match in MAP, in every session or only those named by --session. Sequences\n"
    "         (Image_sequences) run over the query frames before each one. Prints a table, or\n"
    "         with --json one object whose \"queries\" list holds, for each image, \"query\"\n"
    "         (its file name), \"session\", \"frame\" (within the session; null when nothing\n"
    "         was found), \"map_frame\", \"score\", \"distance\" and \"accepted\".\n"
    "\n"
    "Keys read from --config/--set: Image_descriptor, Patch_size, Ldb_bits, Description_type,\n"
    "Grid_x, Grid_y (the description), Exclusion and Approximate_* (the index), and for query\n"
    "Image_sequences, Match_score, Score_window, Threads. --threshold X: a best match is\n"
    "accepted when its score is <= X (default 0.13: the mean fraction of differing bits).\n"
    "\n"
    "Example (two seasons of one route as sessions of one map):\n"
    "  openable_map add route.map --images nordland/summer --session summer\n"
    "  openable_map add route.map --images nordland/winter --session winter\n"
    "  openable_map info route.map\n"
    "  openable_map query route.map --images nordland/spring --session summer --json\n"
    "\n"
    "Exit status: 0 success, 1 bad input (one line on stderr, the map unchanged), 2 bad\n"
    "command line, 3 internal error.\n";

using Arguments = MapCommandLine;

// One line naming the bad argument, or "".
std::string Parse(int argc, const char* const* argv, Arguments& a) {
  const std::vector<std::string> with_value = {"--images", "--session", "--time", "--config",
                                               "--set",    "-o",        "--output",
                                               "--threshold"};
  for (int i = 1; i < argc; ++i) {
    std::string arg = argv[i], value;
    const std::size_t eq = arg.find('=');
    const bool joined = arg.rfind("--", 0) == 0 && eq != std::string::npos;
    if (joined) {
      value = arg.substr(eq + 1);
      arg = arg.substr(0, eq);
    }
    if (std::find(with_value.begin(), with_value.end(), arg) != with_value.end()) {
      if (!joined) {
        if (i + 1 >= argc) return arg + " needs a value";
        value = argv[++i];
      }
      if (arg == "--images") a.images = value;
      else if (arg == "--session") a.sessions.push_back(value);
      else if (arg == "--time") a.time = value;
      else if (arg == "--config") a.config = value;
      else if (arg == "--set") a.sets.push_back(value);
      else if (arg == "--threshold") a.threshold = value;
      else a.output = value;
    } else if (arg == "--json") {
      a.json = true;
    } else if (arg == "--quiet" || arg == "-q") {
      a.quiet = true;
    } else if (arg.size() > 1 && arg[0] == '-') {
      return "unknown option " + Quoted(arg);
    } else if (a.command.empty()) {
      a.command = arg;
    } else {
      a.positional.push_back(arg);
    }
  }
  const std::vector<std::string> commands = {"add", "info", "merge", "query"};
  if (a.command.empty()) return "a command is needed: add, info, merge or query";
  if (std::find(commands.begin(), commands.end(), a.command) == commands.end())
    return "unknown command " + Quoted(a.command) + "; expected add, info, merge or query";
  const std::size_t maps = a.command == "merge" ? 2 : 1;
  if (a.positional.size() != maps)
    return a.command + " takes " + (maps == 1 ? "one map" : "two maps (A B)") + ", got " +
           std::to_string(a.positional.size()) + " paths";
  if ((a.command == "add" || a.command == "query") && a.images.empty())
    return a.command + " needs --images FOLDER";
  if (a.command == "add" && a.sessions.size() != 1)
    return "add needs one --session NAME (the new session's name)";
  if (a.command == "merge" && a.output.empty()) return "merge needs -o C (the merged map)";
  return "";
}

// The options a Config.txt and --set give (description, index, sequences and score).
OnlineOptions OptionsOfConfig(const Arguments& a, bool* given) {
  *given = !a.config.empty() || !a.sets.empty();
  Config c = a.config.empty() ? Config() : LoadConfig(a.config);
  for (const std::string& s : a.sets) ApplyOverride(c, s, "--set");
  OnlineOptions o;
  o.descriptor = c.descriptor;
  o.description = c.description.type;
  if (o.description == DescriptionType::kGrid) {
    o.grid_x = c.description.grid_x;
    o.grid_y = c.description.grid_y;
  }
  o.sequence_length = c.matching.sequence_length;
  o.exclusion = c.evaluation.protocol.exclusion;
  o.score = c.matching.score;
  o.score_window = c.matching.score_window;
  o.approximate = c.scale.approximate;
  o.approximate.k = std::max(o.approximate.k, o.candidates);
  if (!a.threshold.empty()) {
    std::size_t used = 0;
    double t = -1;
    try {
      t = std::stod(a.threshold, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != a.threshold.size() || !std::isfinite(t) || t < 0)
      throw InputError("--threshold " + Quoted(a.threshold) + ": expected a number >= 0");
    o.threshold = t;
  }
  return o;
}

// The images of `folder` in natural order, read and added `chunk` at a time (reading spread
// over the cores), so that a long traversal never sits in memory whole.
template <typename Body>
void ForImagesOf(const std::string& folder, bool quiet, const char* what, Body body) {
  const std::vector<std::string> files = ListImages(folder, "");
  ProgressReporter progress(std::cerr, !quiet, isatty(STDERR_FILENO) != 0);
  progress.Begin(what, static_cast<std::int64_t>(files.size()), "frames");
  const std::size_t chunk = 512;
  for (std::size_t first = 0; first < files.size(); first += chunk) {
    const std::size_t n = std::min(chunk, files.size() - first);
    std::vector<cv::Mat> images(n);
    std::vector<std::string> names(files.begin() + static_cast<std::ptrdiff_t>(first),
                                   files.begin() + static_cast<std::ptrdiff_t>(first + n));
    std::mutex mutex;
    std::string error;
    std::size_t error_at = n;
    ParallelFor(static_cast<int>(n), 0, [&](int i) {
      try {
        images[static_cast<std::size_t>(i)] = ReadImageFile(names[static_cast<std::size_t>(i)]);
      } catch (const std::exception& e) {
        std::lock_guard<std::mutex> lock(mutex);
        if (static_cast<std::size_t>(i) < error_at) error_at = static_cast<std::size_t>(i), error = e.what();
      }
    });
    if (error_at < n) throw InputError(error);
    body(images, names);
    progress.Update(static_cast<std::int64_t>(first + n));
  }
  progress.End();
}

std::string FileName(const std::string& path) {
  return std::filesystem::path(path).filename().string();
}

// A map saved with verification holds each frame's local features, which this program (no
// verification) would not write back: adding to it or merging it is refused, not done while
// dropping them.
void RequireNoFeatures(const std::string& path) {
  MapReadOptions read;
  read.header_only = true;
  const std::string features = ReadMapFile(path, read).Setting("features");
  if (!features.empty() && features != "none")
    throw InputError(path + ": the map holds " + features + " features for verified loops, "
                     "which openable_map does not keep; expected a map saved without "
                     "verification (add to this one with OnlineDetector::AddFrame and "
                     "verification on)");
}

// A detector holding the map at `path`, with its own settings and `base`'s others.
std::unique_ptr<OnlineDetector> Open(const std::string& path, const OnlineOptions& base) {
  auto d = std::make_unique<OnlineDetector>(MapOptions(path, base));
  d->LoadMap(path);
  return d;
}

// The description settings of `o` that a map must share, as "key value" lines.
std::string DescriptionOf(const OnlineOptions& o) {
  return o.descriptor.name + " " + std::to_string(o.descriptor.patch_size) + " " +
         std::to_string(o.descriptor.ldb_bits) + " " + EnumName(o.description) + " " +
         std::to_string(o.grid_x) + "x" + std::to_string(o.grid_y);
}

int Add(const Arguments& a) {
  const std::string& path = a.positional[0];
  bool configured = false;
  const OnlineOptions wanted = OptionsOfConfig(a, &configured);
  std::unique_ptr<OnlineDetector> d;
  const bool exists = std::filesystem::exists(path);
  if (exists) {
    RequireNoFeatures(path);
    d = Open(path, wanted);
    const OnlineOptions& have = d->Options();
    if (configured && DescriptionOf(have) != DescriptionOf(wanted))
      throw InputError(path + ": the map describes frames with " + DescriptionOf(have) +
                       " (descriptor, patch, LDB bits, description, grid); --config/--set ask "
                       "for " + DescriptionOf(wanted) + " (expected the map's own settings)");
  } else {
    d = std::make_unique<OnlineDetector>(wanted);
  }
  d->StartSession(a.sessions[0], a.time);
  const int before = d->Size();
  ForImagesOf(a.images, a.quiet, "describing", [&](const std::vector<cv::Mat>& images,
                                                   const std::vector<std::string>& names) {
    d->AddImagesToMap(images, names);
  });
  d->SaveMap(path);
  if (!a.quiet)
    std::cout << (exists ? "Appended" : "Created") << " session " << Quoted(a.sessions[0])
              << ": " << d->Size() - before << " frames; " << path << " holds "
              << d->Size() << " frames in " << d->Sessions().size() << " session"
              << (d->Sessions().size() == 1 ? "" : "s") << ".\n";
  return 0;
}

int Info(const Arguments& a) {
  const std::string& path = a.positional[0];
  MapReadOptions read;
  read.check_in_background = false;  // info says the checksums match
  const MapFile map = ReadMapFile(path, read);
  std::uintmax_t bytes = std::filesystem::file_size(path);
  if (a.json) {
    Json settings = Json::object();
    for (const auto& [k, v] : map.settings) settings[k] = v;
    Json sessions = Json::array();
    for (const MapSession& s : map.sessions)
      sessions.push_back({{"name", s.name}, {"time", s.time}, {"first", s.first},
                          {"frames", s.count}});
    Json blocks = Json::array();
    for (const auto& b : map.blocks)
      blocks.push_back({{"first", b.first}, {"frames", b.count},
                        {"bytes", b.Bytes().size}});
    std::cout << json::Dump({{"map", path},
                                       {"format_version", map.version},
                                       {"frames", map.rows.rows},
                                       {"bytes", bytes},
                                       {"checksums", "ok"},
                                       {"settings", settings},
                                       {"sessions", sessions},
                                       {"blocks", blocks}});
    return 0;
  }
  std::cout << path << ": OpenABLE map, format version " << map.version << ", " << map.rows.rows
            << " frames, " << bytes << " bytes ("
            << cv::format("%.1f", map.rows.rows > 0 ? static_cast<double>(bytes) / map.rows.rows
                                                     : 0.0)
            << " a frame); checksums match\n";
  std::cout << "Description: " << map.Setting("descriptor") << ", patch "
            << map.Setting("patch_size") << ", " << map.Setting("ldb_bits") << " LDB bits, "
            << map.Setting("description") << " (grid " << map.Setting("grid_x") << "x"
            << map.Setting("grid_y") << "); frames "
            << (map.Setting("frame_size").empty() ? "of unknown size" : map.Setting("frame_size"))
            << "\n";
  std::cout << "Index: " << map.Setting("engine") << ", exact up to "
            << map.Setting("exact_limit") << " frames, blocks of " << map.Setting("block_frames")
            << " x 2^m frames (" << map.blocks.size() << " block"
            << (map.blocks.size() == 1 ? "" : "s") << "), exclusion "
            << map.Setting("exclusion") << "\n";
  std::cout << "Sessions:\n";
  for (const MapSession& s : map.sessions)
    std::cout << "  " << ToValidUtf8(s.name) << "  " << (s.time.empty() ? "-" : s.time)
              << "  frames " << s.first << "-" << s.first + s.count - 1 << " (" << s.count
              << ")\n";
  return 0;
}

int Merge(const Arguments& a) {
  for (const std::string& path : a.positional) RequireNoFeatures(path);
  std::unique_ptr<OnlineDetector> d = Open(a.positional[0], OnlineOptions());
  d->AppendMap(a.positional[1]);
  d->SaveMap(a.output);
  if (!a.quiet)
    std::cout << "Wrote " << a.output << ": " << d->Size() << " frames in "
              << d->Sessions().size() << " sessions.\n";
  return 0;
}

int Query(const Arguments& a) {
  const std::string& path = a.positional[0];
  bool configured = false;
  const OnlineOptions base = OptionsOfConfig(a, &configured);
  std::unique_ptr<OnlineDetector> d = Open(path, base);
  std::vector<cv::Mat> rows;
  std::vector<std::string> names;
  ForImagesOf(a.images, a.quiet || a.json, "describing queries",
              [&](const std::vector<cv::Mat>& images, const std::vector<std::string>& chunk) {
                rows.push_back(d->DescribeFrames(images, chunk));
                names.insert(names.end(), chunk.begin(), chunk.end());
              });
  cv::Mat all;
  cv::vconcat(rows, all);
  const std::vector<OnlineResult> results = d->Query(all, a.sessions);
  // Nothing is printed from a map whose checksums do not match.
  d->CheckMap();
  const auto& sessions = d->Sessions();
  if (a.json) {
    Json queries = Json::array();
    for (std::size_t i = 0; i < results.size(); ++i) {
      Json q = {{"query", FileName(names[i])}};
      if (results[i].candidates.empty()) {
        q["session"] = nullptr;
        q["frame"] = nullptr;
        q["map_frame"] = nullptr;
        q["score"] = nullptr;
        q["distance"] = nullptr;
        q["accepted"] = false;
      } else {
        const LoopCandidate& c = results[i].candidates[0];
        q["session"] = sessions[static_cast<std::size_t>(c.session)].name;
        q["frame"] = c.session_frame;
        q["map_frame"] = c.frame;
        q["score"] = json::Number(c.score);
        q["distance"] = json::Number(c.distance);
        q["accepted"] = c.accepted;
      }
      queries.push_back(std::move(q));
    }
    std::cout << json::Dump({{"map", path},
                                       {"sessions", json::Strings(a.sessions)},
                                       {"threshold", json::Number(d->Options().threshold)},
                                       {"queries", queries}});
    return 0;
  }
  int accepted = 0;
  std::cout << "query  session  frame  score  accepted\n";
  for (std::size_t i = 0; i < results.size(); ++i) {
    std::cout << ToValidUtf8(FileName(names[i])) << "  ";
    if (results[i].candidates.empty()) {
      std::cout << "-  -  -  no\n";
      continue;
    }
    const LoopCandidate& c = results[i].candidates[0];
    accepted += c.accepted;
    std::cout << ToValidUtf8(sessions[static_cast<std::size_t>(c.session)].name) << "  "
              << c.session_frame << "  " << cv::format("%.4f", c.score) << "  "
              << (c.accepted ? "yes" : "no") << "\n";
  }
  std::cout << accepted << " of " << results.size() << " queries accepted (score <= "
            << d->Options().threshold << ").\n";
  return 0;
}

}  // namespace

const char* const kMapUsage = kUsageText;

std::string ParseMapCommandLine(int argc, const char* const* argv, MapCommandLine& out) {
  return Parse(argc, argv, out);
}

int RunMapCommand(const MapCommandLine& a) {
  if (a.command == "add") return Add(a);
  if (a.command == "info") return Info(a);
  if (a.command == "merge") return Merge(a);
  return Query(a);
}

}  // namespace openable
