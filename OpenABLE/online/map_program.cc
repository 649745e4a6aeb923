#include "OpenABLE/online/map_program.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <limits>
#include <memory>
#include <mutex>
#include <sstream>
#include <string>
#include <vector>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/interrupt.h"
#include "OpenABLE/base/output_batch.h"
#include "OpenABLE/base/progress.h"
#include "OpenABLE/base/strings.h"
#include "OpenABLE/base/threading.h"
#include "OpenABLE/evaluation/report.h"
#include "OpenABLE/io/frame_source.h"
#include "OpenABLE/io/json.h"
#include "OpenABLE/online/map_file.h"
#include "OpenABLE/online/online.h"
#include "OpenABLE/reports/evaluation_files.h"
#include "OpenABLE/reports/html_report.h"
#include "OpenABLE/run/evaluate.h"
#include "OpenABLE/run/given_rows.h"
#include "OpenABLE/tuning/auto.h"
#include "config/config.h"
#include "descriptors/registry.h"

namespace openable {
namespace {

const char* const kUsageText =
    "Usage: openable_map add MAP --images FOLDER --session NAME [--time T] [--config FILE]\n"
    "                        [--set Key=Value ...] [--threshold X] [--descriptors FILE.npy]\n"
    "       openable_map tune MAP [--session REFERENCE --session QUERY] [--frames N]\n"
    "                         [--threshold X] [--config FILE] [--set Key=Value ...] [--json]\n"
    "       openable_map info MAP [--json]\n"
    "       openable_map merge A B -o C\n"
    "       openable_map query MAP --images FOLDER [--session NAME ...] [--config FILE]\n"
    "                          [--set Key=Value ...] [--threshold X] [--json]\n"
    "                          [--output PREFIX] [--descriptors FILE.npy]\n"
    "\n"
    "A map holds the places of one or more sessions (traversals of a route): each frame's\n"
    "descriptor rows and the index that finds them again (docs/library.md, \"Maps that grow\").\n"
    "\n"
    "  add    describes the images of FOLDER and appends them to MAP as session NAME (a new\n"
    "         name), creating MAP when it does not exist. A new map takes its description and\n"
    "         index settings from --config FILE (a Config.txt) and --set, else the defaults\n"
    "         (LDB 256 bits, global), and keeps the search they give (L, score, threshold,\n"
    "         confirmation) for its queries. With the auto preset (--config "
    "config/presets/auto.txt,\n"
    "         Auto 1) the map keeps the rows of every descriptor of its candidates, so that\n"
    "         tune can choose among them. An existing map keeps its own settings, and a\n"
    "         --config that describes otherwise is refused. The frames must be of the map's\n"
    "         size. MAP is replaced whole when the new one is written (an interrupted add leaves\n"
    "         it as it was). --descriptors FILE.npy adds rows computed elsewhere (one per\n"
    "         frame, float32 matched by L2 or uint8 bits by Hamming, as a run's\n"
    "         Descriptors_path) instead of describing images; --images then only names the\n"
    "         frames (one image per row) and may be left out. A map made so takes only such\n"
    "         rows, of the same width and type, in add and query.\n"
    "  tune   chooses the map's search settings from its data, with no ground truth, as\n"
    "         Test_OpenABLE's auto mode does (docs/evaluation.md, \"Without ground truth\"): the\n"
    "         frames of the second session (or the QUERY one) are matched against those of the\n"
    "         first (REFERENCE) with every candidate of Auto_candidates that the map's\n"
    "         descriptors allow, the best by agreement is kept in MAP with its verdict, and\n"
    "         query then uses it: the ratio score <= 0.9 (--threshold X), confirmed by an\n"
    "         earlier independent query (Match_consistency 1). When no candidate can be trusted\n"
    "         (consistency below Auto_min_consistency) the map is UNRELIABLE and accepts\n"
    "         nothing. --frames N judges on the first N frames of each session.\n"
    "  info   prints the map's settings, sessions (name, time, frames), tuned settings and\n"
    "         verdict, index blocks and size, after verifying every checksum.\n"
    "  merge  writes C: the sessions of A, then those of B (same description settings and\n"
    "         frame size, distinct session names), indexed with A's index settings.\n"
    "  query  describes the images of FOLDER (a traversal of its own) and finds each one's best\n"
    "         match in MAP, in every session or only those named by --session, with the map's\n"
    "         tuned settings unless --config or --set say otherwise. Sequences (L) run over\n"
    "         the query frames before each one. Prints a table, or with --json one object whose\n"
    "         \"queries\" list holds, for each image, \"query\" (its file name), \"session\",\n"
    "         \"frame\" (within the session; null when nothing was found), \"map_frame\",\n"
    "         \"score\", \"distance\", \"accepted\" and \"confirmed\". --output PREFIX writes\n"
    "         PREFIX.csv and PREFIX.json (the same), and PREFIX.html: a page with the matrix\n"
    "         to explore and the accepted matches' frames side by side; with Ground_truth_type\n"
    "         (one session searched) the evaluation Test_OpenABLE gives too\n"
    "         (PREFIX_eval.json, ...).\n"
    "\n"
    "Keys read from --config/--set: the description (Image_descriptor, Patch_size, Ldb_bits,\n"
    "Sad_patch, Description_type, Grid_x, Grid_y; Auto and Auto_candidates for add), the index\n"
    "(Exclusion, Approximate_*), the search (Image_descriptor among the map's descriptors,\n"
    "Fusion_weights, Image_sequences, Contrast_enhancement, Contrast_window, Match_score,\n"
    "Match_score_window, Match_threshold, Match_consistency), tune's Auto_candidates and\n"
    "Auto_min_consistency, and query's evaluation keys (Ground_truth_type, Ground_truth,\n"
    "Tolerance, ...). --threshold X: a best match is accepted when its score is <= X (default:\n"
    "the score's, 0.9 for the ratio, 0.13 for the distance; Match_threshold -1 means that\n"
    "default). By default an accepted match is also confirmed by the best match of an earlier\n"
    "query of the traversal, one sequence apart (Match_consistency 1; 0: the score alone).\n"
    "\n"
    "Example (two seasons of one route as sessions of one map, the settings chosen from them):\n"
    "  openable_map add route.map --images nordland/summer --session summer \\\n"
    "      --config config/presets/auto.txt\n"
    "  openable_map add route.map --images nordland/winter --session winter\n"
    "  openable_map tune route.map\n"
    "  openable_map info route.map\n"
    "  openable_map query route.map --images nordland/spring --session summer --output spring\n"
    "\n"
    "Exit status: 0 success, 1 bad input (one line on stderr, the map unchanged), 2 bad\n"
    "command line, 3 internal error.\n";

using Arguments = MapCommandLine;

// One line naming the bad argument, or "".
std::string Parse(int argc, const char* const* argv, Arguments& a) {
  const std::vector<std::string> with_value = {
      "--images", "--session", "--time",      "--config", "--set",
      "-o",       "--output",  "--threshold", "--frames", "--descriptors"};
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
      if (arg == "--images")
        a.images = value;
      else if (arg == "--session")
        a.sessions.push_back(value);
      else if (arg == "--time")
        a.time = value;
      else if (arg == "--config")
        a.config = value;
      else if (arg == "--set")
        a.sets.push_back(value);
      else if (arg == "--threshold")
        a.threshold = value;
      else if (arg == "--frames")
        a.frames = value;
      else if (arg == "--descriptors")
        a.descriptors = value;
      else
        a.output = value;
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
  const std::vector<std::string> commands = {"add", "tune", "info", "merge", "query"};
  if (a.command.empty()) return "a command is needed: add, tune, info, merge or query";
  if (std::find(commands.begin(), commands.end(), a.command) == commands.end())
    return "unknown command " + Quoted(a.command) + "; expected add, tune, info, merge or query";
  const std::size_t maps = a.command == "merge" ? 2 : 1;
  if (a.positional.size() != maps)
    return a.command + " takes " + (maps == 1 ? "one map" : "two maps (A B)") + ", got " +
           std::to_string(a.positional.size()) + " paths";
  if ((a.command == "add" || a.command == "query") && a.images.empty() && a.descriptors.empty())
    return a.command + " needs --images FOLDER (or --descriptors FILE.npy)";
  if (a.command == "add" && a.sessions.size() != 1)
    return "add needs one --session NAME (the new session's name)";
  if (a.command == "merge" && a.output.empty()) return "merge needs -o C (the merged map)";
  if (a.command == "tune" && a.sessions.size() != 0 && a.sessions.size() != 2)
    return "tune takes two --session (the reference, then the query) or none (the first two)";
  // Options that only one command reads are refused elsewhere rather than ignored.
  const auto only = [&](bool given, const char* option, std::vector<std::string> takers) {
    if (given && std::find(takers.begin(), takers.end(), a.command) == takers.end())
      return std::string(option) + " is not an option of " + a.command;
    return std::string();
  };
  for (const std::string& problem :
       {only(!a.images.empty(), "--images", {"add", "query"}),
        only(!a.descriptors.empty(), "--descriptors", {"add", "query"}),
        only(!a.time.empty(), "--time", {"add"}), only(!a.frames.empty(), "--frames", {"tune"}),
        only(!a.threshold.empty(), "--threshold", {"add", "tune", "query"}),
        only(!a.config.empty() || !a.sets.empty(), "--config/--set", {"add", "tune", "query"}),
        only(!a.output.empty() && a.command != "merge", "--output", {"query"}),
        only(!a.sessions.empty(), "--session", {"add", "tune", "query"})})
    if (!problem.empty()) return problem;
  return "";
}

// The configuration of --config and --set: the defaults, the file, then each --set.
Config ConfigOf(const Arguments& a) {
  Config c = a.config.empty() ? Config() : LoadConfig(a.config);
  for (const std::string& s : a.sets) ApplyOverride(c, s, "--set");
  return c;
}

// The keys of the search (the settings Tune chooses and a query may set otherwise).
const std::vector<std::string>& SearchKeys() {
  static const std::vector<std::string> keys = {
      "Image_descriptor",     "Fusion_weights",  "Image_sequences",
      "Contrast_enhancement", "Contrast_window", "Match_score",
      "Match_score_window",   "Match_threshold", "Match_consistency"};
  return keys;
}

// The search keys the command line sets: all with --config, else those of --set.
std::vector<std::string> SearchKeysGiven(const Arguments& a) {
  if (!a.config.empty()) return SearchKeys();
  std::vector<std::string> out;
  for (const std::string& assignment : a.sets) {
    const std::string key = Lower(Trim(assignment.substr(0, assignment.find('='))));
    for (const std::string& k : SearchKeys())
      if (Lower(k) == key) out.push_back(k);
  }
  return out;
}

// The value of search key `key` of `c` onto `o`.
void SetSearchKey(const Config& c, const std::string& key, OnlineOptions& o) {
  const MatchingOptions& m = c.matching;
  if (key == "Image_descriptor") {
    // Another search among the map's descriptors: the others stay kept.
    std::vector<std::string> all;
    for (const std::string& list : {o.descriptor.name, o.kept_descriptors})
      for (const std::string& n : list.empty() ? std::vector<std::string>{} : DescriptorList(list))
        if (std::find(all.begin(), all.end(), Upper(n)) == all.end()) all.push_back(Upper(n));
    o.descriptor.name = c.descriptor.name;
    std::vector<std::string> searched;
    for (const std::string& n : DescriptorList(o.descriptor.name)) searched.push_back(Upper(n));
    std::string kept;
    for (const std::string& n : all)
      if (std::find(searched.begin(), searched.end(), n) == searched.end())
        kept += (kept.empty() ? "" : "+") + n;
    o.kept_descriptors = kept;
    if (o.fusion_weights.size() != searched.size()) o.fusion_weights.clear();
  } else if (key == "Fusion_weights") {
    const int names = static_cast<int>(DescriptorList(o.descriptor.name).size());
    o.fusion_weights =
        m.fusion_weights.empty() || names < 2 ? std::vector<double>{} : m.FusionWeights(names);
  } else if (key == "Image_sequences") {
    o.sequence_length = m.sequence_length;
  } else if (key == "Contrast_enhancement") {
    o.contrast.enabled = m.contrast.enabled;
  } else if (key == "Contrast_window") {
    o.contrast.window = m.contrast.window;
  } else if (key == "Match_score") {
    o.score.kind = m.score.kind;
  } else if (key == "Match_score_window") {
    o.score.window = m.score.window;
  } else if (key == "Match_threshold") {
    o.threshold = m.match_threshold;  // -1: the score's default
  } else if (key == "Match_consistency") {
    o.consistency = m.match_consistency;
  }
}

// --threshold X onto `o`.
void SetThreshold(const Arguments& a, OnlineOptions& o) {
  if (a.threshold.empty()) return;
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

// Whether the registered descriptor `name` learns from a reference traversal (a network is
// not created here: it learns nothing).
bool LearnsFromReference(const std::string& name) {
  if (Upper(name) == "ONNX") return false;
  return CreateDescriptor(name, DescriptorOptions())->Learns();
}

// The options of a new map from a Config.txt and --set: description, index, and the search
// keys `search` (those the command line gives; the others keep the detector's defaults). With
// Auto 1 (the auto preset) the map keeps the rows of every descriptor of its candidates but
// those that learn from a reference traversal (DenseVLAD: a map's sessions would each learn
// another vocabulary), which tune then leaves out.
OnlineOptions OptionsOfConfig(const Config& c, const std::vector<std::string>& search) {
  OnlineOptions o;
  o.descriptor = c.descriptor;
  o.description = c.description.type;
  if (o.description == DescriptionType::kGrid) {
    o.grid_x = c.description.grid_x;
    o.grid_y = c.description.grid_y;
  }
  for (const std::string& key : search) SetSearchKey(c, key, o);
  o.exclusion = c.evaluation.protocol.exclusion;
  o.approximate = c.scale.approximate;
  o.approximate.k = std::max(o.approximate.k, o.candidates);
  if (c.automatic.enabled) {
    std::vector<std::string> kept;
    for (const AutoSettings& candidate : ParseAutoCandidates(c.automatic.candidates))
      for (const auto& [key, value] : candidate)
        if (key == "Image_descriptor")
          for (const std::string& name : DescriptorList(value))
            if (std::find(kept.begin(), kept.end(), Upper(name)) == kept.end() &&
                !LearnsFromReference(name))
              kept.push_back(Upper(name));
    std::string text;
    for (const std::string& name : kept) text += (text.empty() ? "" : "+") + name;
    o.kept_descriptors = text;
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
  // At most 512 images at a time, and at most about 256 MB of them (the size of the first
  // decoded image sets the count): large frames never sit in memory by the hundred.
  std::size_t chunk = 512;
  for (std::size_t first = 0; first < files.size(); first += chunk) {
    if (first == 0 && !files.empty()) {
      const cv::Mat probe = ReadImageFile(files.front());
      const double bytes =
          std::max<double>(1.0, static_cast<double>(probe.total() * probe.elemSize()));
      const std::size_t threads = static_cast<std::size_t>(EffectiveThreads(0));
      chunk = std::clamp<std::size_t>(static_cast<std::size_t>(256e6 / bytes), threads, 512);
    }
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
        if (static_cast<std::size_t>(i) < error_at)
          error_at = static_cast<std::size_t>(i), error = e.what();
      }
    });
    if (error_at < n) throw InputError(error);
    body(images, names);
    progress.Update(static_cast<std::int64_t>(first + n));
  }
  progress.End();
}

std::string JoinedChannels(const OnlineDetector& d) { return JoinStrings(d.Channels(), "+"); }

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
    throw InputError(path + ": the map holds " + features +
                     " features for verified loops, "
                     "which openable_map does not keep; expected a map saved without "
                     "verification (add to this one with OnlineDetector::AddFrame and "
                     "verification on)");
}

// A detector holding the map at `path` with its own settings (its tuned search when tuned) and
// `base`'s others.
std::unique_ptr<OnlineDetector> Open(const std::string& path, const OnlineOptions& base) {
  auto d = std::make_unique<OnlineDetector>(MapOptions(path, base));
  d->LoadMap(path);
  return d;
}

// The description settings of `o` that a map must share, as one line.
std::string DescriptionOf(const OnlineOptions& o) {
  std::vector<std::string> names;
  for (const std::string& n : DescriptorList(o.descriptor.name)) names.push_back(Upper(n));
  if (!o.kept_descriptors.empty())
    for (const std::string& n : DescriptorList(o.kept_descriptors))
      if (std::find(names.begin(), names.end(), Upper(n)) == names.end()) names.push_back(Upper(n));
  std::sort(names.begin(), names.end());
  std::string list;
  for (const std::string& n : names) list += (list.empty() ? "" : "+") + n;
  std::string network;
  if (std::find(names.begin(), names.end(), "ONNX") != names.end())
    network = " (network input " + o.descriptor.model_input_size + " " +
              o.descriptor.model_channels + ", mean " + o.descriptor.model_mean + ", std " +
              o.descriptor.model_std + ", normalize " + (o.descriptor.model_normalize ? "1" : "0") +
              ")";
  return list + " " + std::to_string(o.descriptor.patch_size) + " " +
         std::to_string(o.descriptor.ldb_bits) + " " + EnumName(o.description) + " " +
         std::to_string(o.grid_x) + "x" + std::to_string(o.grid_y) + network;
}

// The search settings as a person reads them.
std::string SearchText(const OnlineOptions& o) {
  std::string text = o.descriptor.name;
  if (!o.fusion_weights.empty()) {
    text += " (weights";
    for (const double w : o.fusion_weights) text += " " + FormatNumber(w);
    text += ")";
  }
  if (o.contrast.enabled) text += ", contrast enhancement +-" + std::to_string(o.contrast.window);
  text += ", L = " + std::to_string(o.sequence_length) + ", " + EnumName(o.score.kind) + " score";
  if (o.score.kind == MatchScore::kRatio)
    text += " (window +-" + std::to_string(o.score.window) + ")";
  text += " <= " + FormatNumber(o.Threshold());
  if (o.consistency > 0)
    text += ", confirmed by " + std::to_string(o.consistency) + " earlier independent quer" +
            (o.consistency == 1 ? "y" : "ies");
  return text;
}

// The lock of the map at `path` for the read-change-save of a command (MapWriteLock), saying
// on stderr when another writer holds it; an interruption from now on says the map is unchanged.
std::unique_ptr<MapWriteLock> LockForWriting(const std::string& path, bool quiet) {
  auto lock = std::make_unique<MapWriteLock>(path, [&](const std::string& line) {
    if (!quiet) std::cerr << "openable_map: " << line << "\n";
  });
  SetInterruptNote(path + " unchanged");
  return lock;
}

// Rows computed elsewhere (--descriptors FILE.npy, read and checked as a run's
// Descriptors_path) and the names of their frames: the images of --images when given (one per
// row, in natural order of their names; only listed, not read), else none.
struct GivenRowsOfCommand {
  cv::Mat rows;
  std::vector<std::string> names;
};
GivenRowsOfCommand GivenRowsOf(const Arguments& a) {
  GivenRowsOfCommand out;
  out.rows = ReadGivenRows(a.descriptors, "--descriptors");
  if (!a.images.empty()) {
    out.names = ListImages(a.images, "");
    if (out.names.size() != static_cast<size_t>(out.rows.rows))
      throw InputError("--descriptors: " + Quoted(a.descriptors) + " holds " +
                       std::to_string(out.rows.rows) + " rows, but --images " + Quoted(a.images) +
                       " holds " + std::to_string(out.names.size()) +
                       " images; expected one row per image, in the natural order of their names");
  }
  return out;
}

// Whether the map at `path` holds rows given by a file (openable_map add --descriptors).
bool MapOfGivenRows(const std::string& path) {
  MapReadOptions read;
  read.header_only = true;
  return Upper(ReadMapFile(path, read).Setting("descriptor")) == "NPY";
}

// One line refusing --images without --descriptors for a map of given rows, or --descriptors
// for a map that describes its frames itself.
void CheckRowsFitMap(const Arguments& a, const std::string& path) {
  const bool given = MapOfGivenRows(path);
  if (given && a.descriptors.empty())
    throw InputError(path +
                     ": the map's rows were computed elsewhere (openable_map add "
                     "--descriptors); expected --descriptors FILE.npy with the rows of these "
                     "frames, computed the same way");
  if (!given && !a.descriptors.empty())
    throw InputError("--descriptors: " + Quoted(a.descriptors) + " given, but " + path +
                     " describes its frames itself; expected --images FOLDER, or a map made "
                     "with --descriptors");
}

int Add(const Arguments& a) {
  const std::string& path = a.positional[0];
  if (!a.time.empty()) CheckSessionTime(a.time, "--time");
  const bool configured = !a.config.empty() || !a.sets.empty();
  const auto lock = LockForWriting(path, a.quiet);
  OnlineOptions wanted = OptionsOfConfig(ConfigOf(a), SearchKeysGiven(a));
  SetThreshold(a, wanted);
  std::unique_ptr<OnlineDetector> d;
  const bool exists = std::filesystem::exists(path);
  GivenRowsOfCommand given;
  if (!a.descriptors.empty()) {
    given = GivenRowsOf(a);
    if (!exists) {
      // A new map of rows computed elsewhere: one channel, "NPY", of the rows' width and type.
      if (configured && !a.quiet &&
          (wanted.descriptor.name != OnlineOptions().descriptor.name ||
           !wanted.kept_descriptors.empty()))
        std::cerr << "note: Image_descriptor " << wanted.descriptor.name
                  << (wanted.kept_descriptors.empty() ? "" : " and Auto's candidates")
                  << " not used: the rows come from " << Quoted(a.descriptors) << "\n";
      wanted.descriptor.name = "NPY";
      wanted.description = DescriptionType::kGlobal;  // one row a frame
      wanted.grid_x = wanted.grid_y = 1;
      wanted.kept_descriptors.clear();
      wanted.fusion_weights.clear();
      wanted.descriptor.given_width = given.rows.cols;
      wanted.descriptor.given_binary = given.rows.type() == CV_8U;
    }
  }
  if (exists) {
    RequireNoFeatures(path);
    CheckRowsFitMap(a, path);
    d = Open(path, wanted);
    const OnlineOptions& have = d->Options();
    if (configured && DescriptionOf(have) != DescriptionOf(wanted))
      throw InputError(path + ": the map describes frames with " + DescriptionOf(have) +
                       " (descriptors, patch, LDB bits, description, grid); --config/--set ask "
                       "for " +
                       DescriptionOf(wanted) + " (expected the map's own settings)");
  } else {
    d = std::make_unique<OnlineDetector>(wanted);
  }
  d->StartSession(a.sessions[0], a.time);
  const int before = d->Size();
  if (!a.descriptors.empty()) {
    if (given.names.empty())
      d->AddToMap(given.rows);
    else
      d->AddToMap(given.rows, given.names);
  } else {
    ForImagesOf(a.images, a.quiet, "describing",
                [&](const std::vector<cv::Mat>& images, const std::vector<std::string>& names) {
                  d->AddImagesToMap(images, names);
                });
  }
  SetInterruptNoteOnCommit(path + " holds session " + Quoted(a.sessions[0]));
  d->SaveMap(path);
  if (!a.quiet) {
    std::cout << (exists ? "Appended" : "Created") << " session " << Quoted(a.sessions[0]) << ": "
              << d->Size() - before << " frames; " << path << " holds " << d->Size()
              << " frames in " << d->Sessions().size() << " session"
              << (d->Sessions().size() == 1 ? "" : "s") << " (descriptors " << JoinedChannels(*d)
              << ").\n";
    if (d->Sessions().size() >= 2 && !d->Tuning().tuned)
      std::cout << "Next: openable_map tune " << path
                << " chooses the search settings from its first two sessions.\n";
  }
  return 0;
}

// The candidates of a tuned map, ranked, as JSON (AutoJson's list).
Json TunedCandidates(const MapTuning& t) {
  if (t.candidates_json.empty()) return Json::array();
  return Json::parse(t.candidates_json);
}

Json TuningJson(const MapTuning& t) {
  if (!t.tuned) return Json();
  return {{"verdict", t.reliable ? "reliable" : "unreliable"},
          {"reference", t.reference},
          {"query", t.query},
          {"time", t.time},
          {"chosen", t.chosen},
          {"search", SearchText(t.search)},
          {"consistency", json::Number(t.consistency)},
          {"distinctiveness", json::Number(t.distinctiveness)},
          {"agreement", json::Number(t.agreement)},
          {"min_consistency", json::Number(t.min_consistency)},
          {"candidates", TunedCandidates(t)}};
}

// The lines a person reads of a map's tuning.
std::string TuningText(const MapTuning& t) {
  if (!t.tuned) return "";
  std::ostringstream o;
  o << "Tuned " << t.time << " on session " << Quoted(t.query) << " against " << Quoted(t.reference)
    << ": " << t.chosen << "\n  search: " << SearchText(t.search) << "\n  "
    << (t.reliable ? "reliable: " : "UNRELIABLE (accepts nothing): ")
    << FormatFixed(100.0 * t.consistency, 1)
    << " % of its best matches agree with an independent query's (Auto_min_consistency "
    << FormatNumber(t.min_consistency) << ")\n";
  return o.str();
}

int Info(const Arguments& a) {
  const std::string& path = a.positional[0];
  MapReadOptions read;
  read.check_in_background = false;  // info says the checksums match
  const MapFile map = ReadMapFile(path, read);
  std::unique_ptr<OnlineDetector> d = Open(path, OnlineOptions());
  const MapTuning& tuning = d->Tuning();
  std::uintmax_t bytes = std::filesystem::file_size(path);
  if (a.json) {
    Json settings = Json::object();
    for (const auto& [k, v] : map.settings)
      if (k != "tuned_candidates") settings[k] = v;
    Json sessions = Json::array();
    for (const MapSession& s : map.sessions)
      sessions.push_back(
          {{"name", s.name}, {"time", s.time}, {"first", s.first}, {"frames", s.count}});
    Json blocks = Json::array();
    for (const auto& b : map.blocks)
      blocks.push_back({{"first", b.first}, {"frames", b.count}, {"bytes", b.Bytes().size}});
    std::cout << json::Dump({{"map", path},
                             {"format_version", map.version},
                             {"frames", map.rows.rows},
                             {"bytes", bytes},
                             {"checksums", "ok"},
                             {"descriptors", json::Strings(d->Channels())},
                             {"settings", settings},
                             {"sessions", sessions},
                             {"tuning", TuningJson(tuning)},
                             {"blocks", blocks}});
    return 0;
  }
  std::cout << path << ": OpenABLE map, format version " << map.version << ", " << map.rows.rows
            << " frames, " << bytes << " bytes ("
            << cv::format("%.1f",
                          map.rows.rows > 0 ? static_cast<double>(bytes) / map.rows.rows : 0.0)
            << " a frame); checksums match\n";
  if (Upper(map.Setting("descriptor")) == "NPY")
    std::cout << "Descriptors: NPY, rows computed elsewhere (openable_map add --descriptors): "
              << map.Setting("row_width")
              << (map.Setting("row_type") == "CV_8U" ? " bytes of bits (Hamming)"
                                                     : " float32 values (L2)")
              << " a frame\n";
  else
    std::cout << "Descriptors: " << JoinedChannels(*d) << ", patch " << map.Setting("patch_size")
              << ", " << map.Setting("ldb_bits") << " LDB bits, " << map.Setting("description")
              << " (grid " << map.Setting("grid_x") << "x" << map.Setting("grid_y") << "); frames "
              << (map.Setting("frame_size").empty() ? "of unknown size" : map.Setting("frame_size"))
              << "\n";
  if (!map.Setting("model_weights").empty())
    std::cout << "Network: " << map.Setting("model_path") << " (weights "
              << map.Setting("model_weights") << "), input " << map.Setting("model_input_size")
              << " " << map.Setting("model_channels") << ", mean " << map.Setting("model_mean")
              << ", std " << map.Setting("model_std") << ", normalize "
              << map.Setting("model_normalize") << "\n";
  std::cout << "Search: " << SearchText(d->Options())
            << (tuning.tuned ? "" : " (not tuned: openable_map tune chooses it from the data)")
            << "\n";
  std::cout << TuningText(tuning);
  std::cout << "Index: " << map.Setting("engine") << ", exact up to " << map.Setting("exact_limit")
            << " frames, blocks of " << map.Setting("block_frames") << " x 2^m frames ("
            << map.blocks.size() << " block" << (map.blocks.size() == 1 ? "" : "s")
            << "), exclusion " << map.Setting("exclusion") << "\n";
  std::cout << "Sessions:\n";
  for (const MapSession& s : map.sessions)
    std::cout << "  " << ToValidUtf8(s.name) << "  " << (s.time.empty() ? "-" : s.time)
              << "  frames " << s.first << "-" << s.first + s.count - 1 << " (" << s.count << ")\n";
  return 0;
}

int Merge(const Arguments& a) {
  for (const std::string& path : a.positional) RequireNoFeatures(path);
  const auto lock = LockForWriting(a.output, a.quiet);
  std::unique_ptr<OnlineDetector> d = Open(a.positional[0], OnlineOptions());
  d->AppendMap(a.positional[1]);
  SetInterruptNoteOnCommit(a.output + " written");
  d->SaveMap(a.output);
  if (!a.quiet)
    std::cout << "Wrote " << a.output << ": " << d->Size() << " frames in " << d->Sessions().size()
              << " sessions.\n";
  return 0;
}

int Tune(const Arguments& a) {
  const std::string& path = a.positional[0];
  RequireNoFeatures(path);
  const Config c = ConfigOf(a);
  const auto lock = LockForWriting(path, a.quiet || a.json);
  std::unique_ptr<OnlineDetector> d = Open(path, OnlineOptions());
  OnlineDetector::TuneOptions t;
  if (a.sessions.size() == 2) {
    t.reference = a.sessions[0];
    t.query = a.sessions[1];
  }
  // Auto_candidates when the command line sets it; else the defaults the map's rows allow.
  if (c.automatic.candidates != AutoOptions::kDefaultCandidates)
    t.candidates = c.automatic.candidates;
  t.min_consistency = c.automatic.min_consistency;
  OnlineOptions threshold;
  SetThreshold(a, threshold);
  t.threshold = threshold.threshold;
  if (!a.frames.empty()) {
    std::size_t used = 0;
    long long n = -1;
    try {
      n = std::stoll(a.frames, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != a.frames.size() || n < 1 || n > 100000000)
      throw InputError("--frames " + Quoted(a.frames) +
                       ": expected a whole number >= 1 (the "
                       "first frames of each session to judge on)");
    t.max_frames = static_cast<int>(n);
  }
  const bool log = !a.quiet && !a.json;
  const MapTuning tuning = d->Tune(t, [&](const std::string& line) {
    if (log) std::cerr << line << "\n";
  });
  SetInterruptNoteOnCommit(path + " holds the tuned settings");
  d->SaveMap(path);
  if (a.json) {
    std::cout << json::Dump({{"map", path}, {"tuning", TuningJson(tuning)}});
    return 0;
  }
  if (a.quiet) return 0;
  std::cout << "    rank  consistency  distinctiveness  agreement  settings\n";
  Json ranked = TunedCandidates(tuning);
  std::vector<Json> rows(ranked.begin(), ranked.end());
  std::stable_sort(rows.begin(), rows.end(), [](const Json& x, const Json& y) {
    return x["rank"].get<int>() < y["rank"].get<int>();
  });
  for (const Json& r : rows) {
    char line[96];
    std::snprintf(line, sizeof line, "    %4d  %11.3f  %15.3f  %9.3f  ", r["rank"].get<int>(),
                  r["consistency"].get<double>(), r["distinctiveness"].get<double>(),
                  r["agreement"].get<double>());
    const std::string settings = r["settings"].get<std::string>();
    std::cout << line << settings << (settings == tuning.chosen ? "  <- chosen" : "") << "\n";
  }
  std::cout << TuningText(tuning) << "Saved in " << path << ".\n";
  return 0;
}

// One query's best match as the outputs give it.
struct QueryRow {
  std::string query;  // file name
  const LoopCandidate* best = nullptr;
};

Json QueryJson(const QueryRow& row, const std::vector<MapSession>& sessions) {
  Json q = {{"query", row.query}};
  const LoopCandidate* c = row.best;
  q["session"] = c ? Json(sessions[static_cast<std::size_t>(c->session)].name) : Json();
  q["frame"] = c ? Json(c->session_frame) : Json();
  q["map_frame"] = c ? Json(c->frame) : Json();
  q["score"] = c ? json::Number(c->score) : Json();
  q["distance"] = c ? json::Number(c->distance) : Json();
  q["accepted"] = c != nullptr && c->accepted;
  q["confirmed"] = c != nullptr && c->confirmed;
  return q;
}

// A CSV field: quoted when it holds a comma, a quote or a line break (RFC 4180).
std::string CsvField(const std::string& text) {
  if (text.find_first_of(",\"\r\n") == std::string::npos) return text;
  std::string out = "\"";
  for (const char c : text) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

std::string EncodeQueryCsv(const Json& queries) {
  std::string csv = "query,session,frame,map_frame,distance,score,accepted,confirmed\n";
  for (const Json& q : queries) {
    const auto field = [&](const char* key) {
      const Json& v = q[key];
      if (v.is_null()) return std::string();
      if (v.is_string()) return CsvField(ToValidUtf8(v.get<std::string>()));
      if (v.is_boolean()) return std::string(v.get<bool>() ? "1" : "0");
      if (v.is_number_integer()) return std::to_string(v.get<long long>());
      return CsvNumber(v.get<double>());
    };
    csv += field("query") + "," + field("session") + "," + field("frame") + "," +
           field("map_frame") + "," + field("distance") + "," + field("score") + "," +
           field("accepted") + "," + field("confirmed") + "\n";
  }
  return csv;
}

// Frames for the page: rows are the query images, columns the map frames searched, read from
// the files the map names (a frame whose file is gone is shown grey and named so).
ReportFrames QueryFrames(const std::vector<std::string>& names, const OnlineDetector& d,
                         const std::vector<int>& columns) {
  ReportFrames frames;
  const std::vector<std::string>& files = d.FrameFiles();
  if (files.empty()) {
    frames.missing =
        "the map keeps no image file of its frames (a map saved before format 3, "
        "or frames added without names)";
    return frames;
  }
  const auto file = [&names, &files, columns](bool row, int index) {
    return row ? names[static_cast<std::size_t>(index)]
               : files[static_cast<std::size_t>(columns[static_cast<std::size_t>(index)])];
  };
  frames.read = [file](bool row, int index) {
    try {
      const std::string path = file(row, index);
      if (!path.empty()) return ReadImageFile(path);
    } catch (const InputError&) {
    }
    return cv::Mat(cv::Mat1b(48, 64, static_cast<unsigned char>(128)));
  };
  frames.name = [file](bool row, int index) {
    const std::string path = file(row, index);
    if (path.empty()) return std::string(row ? "query " : "map frame ") + std::to_string(index);
    std::error_code error;
    const bool there = std::filesystem::exists(path, error);
    return FileName(path) + (there ? "" : " (file not found)");
  };
  return frames;
}

// PREFIX.csv, PREFIX.json and PREFIX.html of a query, with ground truth the evaluation's files
// too, all or nothing. Returns the paths written.
std::vector<std::string> WriteQueryOutputs(const std::string& prefix, const Config& config,
                                           const OnlineDetector& d,
                                           const std::vector<std::string>& names,
                                           const std::vector<OnlineResult>& results,
                                           const OnlineDetector::QueryMatrix& matrix,
                                           const Json& document, const Arguments& a,
                                           ProgressReporter& progress) {
  CheckOutputPrefix("--output", prefix);
  const bool evaluated = EvaluationRequested(config);
  progress.Begin("writing", evaluated ? 4 : 3, "outputs");
  OutputBatch batch;
  batch.Stage("--output", prefix + ".csv", EncodeQueryCsv(document["queries"]));
  batch.Stage("--output", prefix + ".json", json::Dump(document));
  progress.Update(1);
  const OnlineOptions& o = d.Options();
  // The block searched, normalised by its largest value (Eq. 5) as a run's matrix.
  cv::Mat1f block;
  if (!matrix.sums.empty()) {
    block = matrix.sums.clone();
    double largest = 0;
    for (int i = 0; i < block.rows; ++i)
      for (int j = 0; j < block.cols; ++j)
        if (std::isfinite(block(i, j))) largest = std::max<double>(largest, block(i, j));
    if (largest > 0) block /= largest;
  }
  const EvaluationLayout layout = EvaluationLayout::QueryReference(block.rows, block.cols);
  const std::string label = "map " + o.descriptor.name + " L=" + std::to_string(o.sequence_length);
  ReportInput report;
  report.program = "openable_map query";
  const std::string queries = a.images.empty() ? a.descriptors : a.images;
  report.title =
      "OpenABLE map query: " + FileName(queries) + " against " + FileName(a.positional[0]);
  report.settings = {
      {"map", a.positional[0]},
      {"queries", queries},
      {"sessions searched", a.sessions.empty() ? "all" : json::Strings(a.sessions).dump()},
      {"search", SearchText(o)},
      {"tuned", d.Tuning().tuned ? (d.UsesTuning() ? "yes, used" : "yes, replaced") : "no"}};
  report.settings_note =
      "The map, the query's frames and the search it used (openable_map "
      "info gives the map's settings).";
  report.examples = config.evaluation.report_examples;
  Evaluation evaluation;
  if (EvaluationRequested(config)) {
    if (a.sessions.size() != 1)
      throw InputError("Ground_truth_type " +
                       Quoted(GroundTruthTypeName(config.evaluation.truth.type)) + " with " +
                       (a.sessions.empty() ? "every session" : "several sessions") +
                       " searched: expected one --session NAME, the reference traversal the "
                       "ground truth is of");
    if (block.empty())
      throw InputError(
          "Ground_truth_type: the query used the map's index (the session holds "
          "more than exact_limit frames), so there is no matrix to evaluate; "
          "expected a session of at most " +
          std::to_string(o.exact_limit) + " frames");
    Config c = config;
    c.matching.score = o.score;
    c.matching.score.window = o.score.window;
    c.matching.match_threshold = o.Threshold();
    c.matching.match_consistency = 0;
    evaluation.settings = EvaluationSettingsFrom(c);
    EvaluateMatrix(evaluation, block, layout, label, a.positional[0]);
    // The operating point is the map's own: its accepted answers (consistency online).
    PerQueryResult& p = evaluation.runs.front().per_query;
    const GroundTruth& truth = evaluation.truths.front();
    p.accepted.assign(static_cast<std::size_t>(block.rows), 0);
    CurvePoint& op = p.operating_point;
    op.tp = op.fp = 0;
    for (int q = 0; q < block.rows; ++q) {
      const LoopCandidate* c0 = results[static_cast<std::size_t>(q)].candidates.empty()
                                    ? nullptr
                                    : &results[static_cast<std::size_t>(q)].candidates[0];
      if (c0 == nullptr || !c0->accepted) continue;
      p.accepted[static_cast<std::size_t>(q)] = 1;
      const int column = c0->session_frame;
      bool right = false;
      for (const int t : truth.matches.at(static_cast<std::size_t>(q)))
        right = right || std::abs(t - column) <= evaluation.settings.options.tolerance;
      ++(right ? op.tp : op.fp);
    }
    op.precision = op.tp + op.fp > 0 ? static_cast<double>(op.tp) / (op.tp + op.fp) : 1.0;
    op.recall = p.positive_queries > 0 ? static_cast<double>(op.tp) / p.positive_queries : 0.0;
    op.f1 = op.precision + op.recall > 0 ? 2 * op.precision * op.recall / (op.precision + op.recall)
                                         : 0.0;
    p.has_operating_point = true;
    StageEvaluation(batch, "--output", prefix + "_eval", evaluation, {&block});
    report.evaluation = &evaluation;
    progress.Update(2);
  }
  if (!block.empty()) {
    report.matrices = {&block};
    report.frames = QueryFrames(names, d, matrix.frames);
    if (report.evaluation == nullptr) {
      // The map's own answers: its best match, score, and what it accepted (the score, then
      // the confirmation by earlier queries; none on an unreliable map).
      ReportAnswers answers;
      answers.label = label;
      answers.source = a.positional[0];
      answers.layout = layout;
      answers.score = o.score;
      answers.score.window = o.score.window;
      answers.threshold = o.Threshold();
      answers.consistency = o.consistency;
      answers.untrusted = d.UsesTuning() && !d.Tuning().reliable;
      QueryAnswers& q = answers.answers;
      const float none = std::numeric_limits<float>::infinity();
      q.best.assign(static_cast<std::size_t>(block.rows), -1);
      q.distance.assign(q.best.size(), none);
      q.score.assign(q.best.size(), none);
      q.accepted.assign(q.best.size(), 0);
      q.confirmed.assign(q.best.size(), 0);
      q.queries = block.rows;
      for (int i = 0; i < block.rows; ++i) {
        const auto& candidates = results[static_cast<std::size_t>(i)].candidates;
        if (candidates.empty()) continue;
        const LoopCandidate& c = candidates.front();
        const auto column = std::lower_bound(matrix.frames.begin(), matrix.frames.end(), c.frame);
        const int j = static_cast<int>(column - matrix.frames.begin());
        const std::size_t k = static_cast<std::size_t>(i);
        q.best[k] = j;
        q.distance[k] = block(i, j);
        q.score[k] = static_cast<float>(c.score);
        q.accepted[k] = c.score <= o.Threshold() && !answers.untrusted;
        q.confirmed[k] = c.accepted;
        ++q.answered;
      }
      report.answers = {answers};
      report.truth_advice =
          "Give the query's ground truth to openable_map query (--set Ground_truth_type=aligned, "
          "or a file: --set Ground_truth_type=pairs --set Ground_truth=FILE, with one --session)"
          " for R@1, AUC and the precision of the accepted matches.";
    }
    batch.Stage("--output", prefix + ".html", EncodeHtmlReport(report));
  }
  progress.Update(evaluated ? 3 : 2);
  const std::vector<std::string> paths = batch.Paths();
  batch.Commit();
  progress.Update(evaluated ? 4 : 3);
  progress.End();
  if (report.evaluation != nullptr && !a.quiet)
    std::cout << FormatEvaluationTable(evaluation.settings, evaluation.runs);
  return paths;
}

int Query(const Arguments& a) {
  const std::string& path = a.positional[0];
  const Config config = ConfigOf(a);
  OnlineOptions options = MapOptions(path, OptionsOfConfig(config, SearchKeysGiven(a)));
  // The map's search (tuned, or the one it was made with) unless the command line sets it.
  for (const std::string& key : SearchKeysGiven(a)) SetSearchKey(config, key, options);
  SetThreshold(a, options);
  if (a.json && !a.output.empty())
    throw InputError("--json and --output: expected one of them (--output writes " + a.output +
                     ".json)");
  CheckRowsFitMap(a, path);
  std::unique_ptr<OnlineDetector> d = std::make_unique<OnlineDetector>(options);
  d->LoadMap(path);
  const bool quiet = a.quiet || a.json;
  const MapTuning& tuning = d->Tuning();
  if (!quiet) {
    std::cerr << "search: " << SearchText(d->Options()) << "\n";
    if (!tuning.tuned)
      std::cerr << "note: the map's settings were not chosen from the data (openable_map tune "
                << path << " chooses them from two of its sessions)\n";
    else if (!d->UsesTuning())
      std::cerr << "note: --config/--set/--threshold replace the map's tuned settings ("
                << tuning.chosen << "); its verdict does not apply to them\n";
    else if (!tuning.reliable)
      std::cerr << "UNRELIABLE: the map's tuned settings could not be trusted (consistency "
                << FormatFixed(tuning.consistency, 3) << " below "
                << FormatNumber(tuning.min_consistency) << "): no match is accepted\n";
  }
  std::vector<cv::Mat> rows;
  std::vector<std::string> names;
  if (!a.descriptors.empty()) {
    // Rows computed elsewhere: named by their images when --images lists them, else "row i".
    GivenRowsOfCommand given = GivenRowsOf(a);
    rows.push_back(given.rows);
    names = given.names;
    for (int i = static_cast<int>(names.size()); i < given.rows.rows; ++i)
      names.push_back("row " + std::to_string(i));
  } else {
    ForImagesOf(a.images, quiet, "describing queries",
                [&](const std::vector<cv::Mat>& images, const std::vector<std::string>& chunk) {
                  rows.push_back(d->DescribeFrames(images, chunk));
                  names.insert(names.end(), chunk.begin(), chunk.end());
                });
  }
  cv::Mat all;
  cv::vconcat(rows, all);
  ProgressReporter progress(std::cerr, !quiet, isatty(STDERR_FILENO) != 0);
  progress.Begin("matching queries", all.rows, "frames");
  OnlineDetector::QueryMatrix out;
  const std::vector<OnlineResult> results = d->Query(
      all, a.sessions, [&](int done, int) { progress.Update(done); },
      a.output.empty() ? nullptr : &out);
  progress.End();
  // Nothing is printed from a map whose checksums do not match.
  d->CheckMap();
  const auto& sessions = d->Sessions();
  std::vector<QueryRow> table;
  for (std::size_t i = 0; i < results.size(); ++i)
    table.push_back(
        {FileName(names[i]), results[i].candidates.empty() ? nullptr : &results[i].candidates[0]});
  Json queries = Json::array();
  for (const QueryRow& row : table) queries.push_back(QueryJson(row, sessions));
  const Json document = {{"map", path},
                         {"sessions", json::Strings(a.sessions)},
                         {"search", SearchText(d->Options())},
                         {"threshold", json::Number(d->Options().Threshold())},
                         {"consistency", d->Options().consistency},
                         {"tuning", TuningJson(tuning)},
                         {"uses_tuning", d->UsesTuning()},
                         {"queries", queries}};
  if (a.json) {
    std::cout << json::Dump(document);
    return 0;
  }
  int accepted = 0, answered = 0;
  for (const QueryRow& row : table) {
    answered += row.best != nullptr;
    accepted += row.best != nullptr && row.best->accepted;
  }
  if (!a.output.empty()) {
    const std::vector<std::string> written =
        WriteQueryOutputs(a.output, config, *d, names, results, out, document, a, progress);
    if (!a.quiet) {
      std::cout << accepted << " of " << answered << " best matches accepted ("
                << SearchText(d->Options()) << ").\nWrote:\n";
      for (const std::string& w : written) std::cout << "  " << w << "\n";
    }
    return 0;
  }
  std::cout << "query  session  frame  score  accepted\n";
  for (const QueryRow& row : table) {
    std::cout << ToValidUtf8(row.query) << "  ";
    if (row.best == nullptr) {
      std::cout << "-  -  -  no\n";
      continue;
    }
    const LoopCandidate& c = *row.best;
    std::cout << ToValidUtf8(sessions[static_cast<std::size_t>(c.session)].name) << "  "
              << c.session_frame << "  " << cv::format("%.4f", c.score) << "  "
              << (c.accepted ? "yes" : "no") << "\n";
  }
  std::cout << accepted << " of " << answered << " best matches accepted ("
            << SearchText(d->Options()) << ").\n";
  return 0;
}
}  // namespace

const char* const kMapUsage = kUsageText;

std::string ParseMapCommandLine(int argc, const char* const* argv, MapCommandLine& out) {
  return Parse(argc, argv, out);
}

int RunMapCommand(const MapCommandLine& a) {
  if (a.command == "add") return Add(a);
  if (a.command == "tune") return Tune(a);
  if (a.command == "info") return Info(a);
  if (a.command == "merge") return Merge(a);
  return Query(a);
}

}  // namespace openable
