// The batch helpers and the online detector of OpenABLE/online/online.h: describe, describe_images,
// distance_matrix, OnlineDetector.
#include "OpenABLE/online/online.h"

#include <pybind11/stl.h>

#include <algorithm>
#include <cstdio>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <tuple>
#include <type_traits>
#include <utility>

#include "OpenABLE/python/common.h"
#include "matching/search/engine_registry.h"
#include "matching/sequence.h"

namespace openable::python {
namespace {

// The description part of OnlineOptions.
// The network's settings of describe and describe_images (Image_descriptor ONNX), as the
// Model_* keys: their defaults are the option table's.
struct ModelArgs {
  std::string path, input_size, channels, mean, std;
  bool normalize = true;
  int batch = 16;
};

#define OPENABLE_MODEL_ARGS                                            \
  py::arg("model_path") = TableDefault("Model_path"),                  \
  py::arg("model_input_size") = TableDefault("Model_input_size"),      \
  py::arg("model_channels") = TableDefault("Model_channels"),          \
  py::arg("model_mean") = TableDefault("Model_mean"),                  \
  py::arg("model_std") = TableDefault("Model_std"),                    \
  py::arg("model_normalize") = TableDefault("Model_normalize") == "1", \
  py::arg("model_batch") = std::stoi(TableDefault("Model_batch"))

// `text` with "@model_args@" replaced by the model_* keywords and their defaults, which are
// the option table's (as OPENABLE_MODEL_ARGS gives them).
std::string ModelDefaultsIn(const std::string& text) {
  const auto quoted = [](const char* key) { return "\"" + TableDefault(key) + "\""; };
  const std::pair<const char*, std::string> values[] = {
      {"@model_args@",
       "\n    model_path=" + quoted("Model_path") + ", model_input_size=" +
           quoted("Model_input_size") + ",\n    model_channels=" + quoted("Model_channels") +
           ", model_mean=" + quoted("Model_mean") + ",\n    model_std=" + quoted("Model_std") +
           ", model_normalize=" + (TableDefault("Model_normalize") == "1" ? "True" : "False") +
           ", model_batch=" + TableDefault("Model_batch")}};
  return FillPlaceholders(text, values);
}

OnlineOptions DescriptionOptions(const std::string& descriptor, const std::string& description,
                                 int patch_size, int ldb_bits, std::pair<int, int> grid,
                                 int sad_patch, const ModelArgs& model = {}) {
  OnlineOptions o;
  o.descriptor.model_path = model.path;
  o.descriptor.model_input_size = model.input_size;
  if (!model.channels.empty()) o.descriptor.model_channels = model.channels;
  if (!model.mean.empty()) o.descriptor.model_mean = model.mean;
  if (!model.std.empty()) o.descriptor.model_std = model.std;
  o.descriptor.model_normalize = model.normalize;
  o.descriptor.model_batch = model.batch;
  o.descriptor.name = descriptor;
  o.description = ParseEnum<DescriptionType>(description, "description");
  o.descriptor.patch_size = patch_size;
  o.descriptor.ldb_bits = ldb_bits;
  o.descriptor.sad_patch = sad_patch;
  o.grid_x = grid.first;
  o.grid_y = grid.second;
  return o;
}

cv::Mat Describe(const std::vector<MatView>& views, const OnlineOptions& options, int threads) {
  std::vector<cv::Mat> images;
  images.reserve(views.size());
  for (const MatView& v : views) images.push_back(v.mat);
  py::gil_scoped_release release;
  return DescribeImages(images, options, threads);
}

// The detector and a lock: AddFrame must not run twice at once, nor while its rows are read,
// and the GIL is released while it runs.
struct Detector {
  std::unique_ptr<OnlineDetector> detector;
  std::mutex mutex;
};

// A property that reads the detector under its lock: `getter` is a const member of
// OnlineDetector.
template <typename R>
auto Locked(R (OnlineDetector::*getter)() const) {
  return [getter](Detector& d) {
    std::lock_guard<std::mutex> lock(d.mutex);
    return ((*d.detector).*getter)();
  };
}

py::tuple ResultTuple(const OnlineResult& r, bool verification) {
  py::list candidates;
  for (const LoopCandidate& c : r.candidates) {
    if (!verification) {
      candidates.append(py::make_tuple(c.frame, c.distance, c.normalized, c.accepted, c.score));
      continue;
    }
    py::dict v;
    v["matches"] = c.matches;
    v["inliers"] = c.inliers;
    v["model"] = EnumName(c.model);
    v["geometric"] = c.geometric;
    v["streak"] = c.streak;
    v["verified"] = c.verified;
    candidates.append(py::make_tuple(c.frame, c.distance, c.normalized, c.accepted, c.score, v));
  }
  py::dict timings;
  timings["describe_seconds"] = r.describe_seconds;
  timings["search_seconds"] = r.search_seconds;
  if (verification) timings["verify_seconds"] = r.verify_seconds;
  timings["approximate"] = r.approximate;
  return py::make_tuple(r.frame, candidates, timings);
}

OnlineOptions OnlineOptionsOf(const py::kwargs& kwargs);

// A map's tuning as a dict, None when not tuned.
py::object TuningDict(const MapTuning& t) {
  if (!t.tuned) return py::none();
  py::dict d;
  d["verdict"] = t.reliable ? "reliable" : "unreliable";
  d["reliable"] = t.reliable;
  d["reference"] = t.reference;
  d["query"] = t.query;
  d["time"] = t.time;
  d["chosen"] = t.chosen;
  d["consistency"] = t.consistency;
  d["distinctiveness"] = t.distinctiveness;
  d["agreement"] = t.agreement;
  d["min_consistency"] = t.min_consistency;
  d["search"] = py::cast(t.search);
  d["candidates"] = py::module_::import("json").attr("loads")(
      t.candidates_json.empty() ? std::string("[]") : t.candidates_json);
  return d;
}

// The candidates of each query (OnlineDetector::Query) as lists of dicts, best first.
py::list QueryResults(const std::vector<OnlineResult>& results,
                      const std::vector<MapSession>& sessions) {
  py::list out;
  for (const OnlineResult& r : results) {
    py::list candidates;
    for (const LoopCandidate& c : r.candidates) {
      py::dict d;
      d["session"] = sessions[static_cast<std::size_t>(c.session)].name;
      d["frame"] = c.session_frame;
      d["map_frame"] = c.frame;
      d["distance"] = c.distance;
      d["normalized"] = c.normalized;
      d["score"] = c.score;
      d["accepted"] = c.accepted;
      d["confirmed"] = c.confirmed;
      candidates.append(d);
    }
    out.append(candidates);
  }
  return out;
}

std::vector<std::string> SessionNames(const py::object& sessions) {
  if (sessions.is_none()) return {};
  if (py::isinstance<py::str>(sessions)) return {sessions.cast<std::string>()};
  return sessions.cast<std::vector<std::string>>();
}

const char* const kQueryDoc = R"doc(
Returns:
    list[list[dict]]: for each query, its candidates best first, each {"session": the
    session's name, "frame": the frame within that session, "map_frame": the frame in the
    whole map, "distance": raw sequence distance, "normalized", "score", "confirmed": the best
    candidates of the earlier independent queries of the traversal agree with it (see the
    option consistency), "accepted": score <= threshold, and confirmed when consistency > 0,
    never on a map whose tuned settings are unreliable while they are used}; empty when the
    sessions searched hold no frame.

Raises:
    openable.InputError: rows of another width or dtype, an unknown session, images of another
    size than the map's frames, or a damaged loaded map.)doc";

// openable.OnlineOptions: OnlineOptions with one property per keyword argument of
// OnlineDetector, in the flat names of the Python API (grid as a pair, description by name,
// the approximate search's fields at the top level). The properties are the one list of options:
// the constructor's keywords, its signature, options["name"], keys() and to_dict() read it.
void BindOnlineOptions(py::module_& m) {
  using O = OnlineOptions;
  py::class_<O> c(m, "OnlineOptions", R"doc(OnlineOptions(**options)

The options of OnlineDetector (OpenABLE/online/online.h), with their defaults. Read like a
dict too: options["sequence_length"], options.keys(), options.to_dict().)doc");
  c.def(py::init([](const py::kwargs& kwargs) { return OnlineOptionsOf(kwargs); }),
        "__init__(**options)\n\nThe defaults, with the options given by keyword.")
      .def_property(
          "descriptor", [](const O& o) { return o.descriptor.name; },
          [](O& o, const std::string& name) { o.descriptor.name = name; },
          "A name of descriptor_names() but D-LDB (case-insensitive).")
      .def_property(
          "description", [](const O& o) { return EnumName(o.description); },
          [](O& o, const std::string& n) {
            o.description = ParseEnum<DescriptionType>(n, "description");
          },
          "\"global\" (the frame resized to the patch) or \"grid\" (grid cells).")
      .def_property(
          "patch_size", [](const O& o) { return o.descriptor.patch_size; },
          [](O& o, int v) { o.descriptor.patch_size = v; }, "Side of the square patch, pixels.")
      .def_property(
          "ldb_bits", [](const O& o) { return o.descriptor.ldb_bits; },
          [](O& o, int v) { o.descriptor.ldb_bits = v; }, "Bits of LDB rows (1..1386).")
      .def_property(
          "sad_patch", [](const O& o) { return o.descriptor.sad_patch; },
          [](O& o, int v) { o.descriptor.sad_patch = v; },
          "SAD: side of the normalised squares, pixels (2..64).")
      .def_readwrite("kept_descriptors", &O::kept_descriptors,
                     "Descriptors whose rows the map keeps besides those of descriptor "
                     "(\"HOG+SIFT+LDB+SAD\"), so that tune() can choose among them; \"\": none.")
      .def_readwrite("fusion_weights", &O::fusion_weights,
                     "One weight per name of a fused descriptor (\"HOG+LDB\"), > 0; []: equal "
                     "weights (Fusion_weights).")
      .def_property(
          "contrast_enhancement", [](const O& o) { return o.contrast.enabled; },
          [](O& o, bool on) { o.contrast.enabled = on; },
          "SeqSLAM's local contrast enhancement of each query's distances over "
          "+-contrast_window frames of a session; the map is then scanned exactly "
          "(Contrast_enhancement).")
      .def_property(
          "contrast_window", [](const O& o) { return o.contrast.window; },
          [](O& o, int w) { o.contrast.window = w; },
          "Frames on each side of the enhancement's window (>= 1).")
      .def_property(
          "grid", [](const O& o) { return std::make_pair(o.grid_x, o.grid_y); },
          [](O& o, std::pair<int, int> g) { std::tie(o.grid_x, o.grid_y) = g; },
          "(cells across, cells down) for description=\"grid\".")
      .def_readwrite("sequence_length", &O::sequence_length,
                     "L, frames summed along the diagonal (Image_sequences).")
      .def_readwrite("exclusion", &O::exclusion,
                     "Frame q's candidates are frames j <= q - exclusion (>= 1).")
      .def_readwrite("candidates", &O::candidates, "Candidates returned per frame (>= 1).")
      .def_property(
          "score", [](const O& o) { return EnumName(o.score.kind); },
          [](O& o, const std::string& n) { o.score.kind = ParseEnum<MatchScore>(n, "score"); },
          "\"distance\" (a candidate's normalised distance) or \"ratio\" (its distance over "
          "that of the best candidate more than score_window frames away; 1 without one): "
          "what threshold accepts (Match_score).")
      .def_property(
          "score_window", [](const O& o) { return o.score.window; },
          [](O& o, int w) { o.score.window = w; },
          "Frames on each side of a candidate that are not its rivals for the ratio "
          "score (>= 0; Match_score_window).")
      .def_readwrite("threshold", &O::threshold,
                     "A candidate is accepted when its score is <= threshold; < 0 (the "
                     "default): the score's own default, 0.13 for the distance, 0.9 for the "
                     "ratio. The distance score is the distance divided by L x the "
                     "descriptor's bit count for binary descriptors (the mean fraction of "
                     "differing bits), by L x the largest single-frame distance seen so far "
                     "for float descriptors, by L x the sum of the weights for fused ones: not "
                     "the scale of Config.txt's Threshold (docs/library.md).")
      .def_readwrite("consistency", &O::consistency,
                     "n (Match_consistency): an accepted candidate also needs the best "
                     "candidates of n earlier independent queries of its traversal to agree "
                     "with it along its diagonal; 0: the score alone. Online no later query "
                     "exists, so the first queries of a traversal are never accepted.")
      .def_readwrite("exact_limit", &O::exact_limit,
                     "Exact search while the searchable map holds at most this many frames.")
      .def_readwrite("block_frames", &O::block_frames, "Frames per index block beyond it.")
      .def_readwrite("background_merges", &O::background_merges,
                     "Build merges of two blocks on a background thread (no frame waits for a "
                     "large index build; candidates then depend on when a merge finishes); "
                     "False builds them inside add_frame, for repeatable results.");
  // Members of the nested option structs as top-level properties: the approximate search
  // (matching/search/approximate.h) and the verification (prefix verification_).
  const auto nested = [&c](const char* name, auto outer, auto member, const char* doc) {
    using T = std::remove_reference_t<decltype(std::declval<O&>().*outer.*member)>;
    c.def_property(
        name, [outer, member](const O& o) { return o.*outer.*member; },
        [outer, member](O& o, T v) { o.*outer.*member = v; }, doc);
  };
  const auto search = [&nested](const char* name, auto member, const char* doc) {
    nested(name, &O::approximate, member, doc);
  };
  // The engine's names and their meanings come from its registry
  // (matching/search/engine_registry.h).
  static const std::string engine_doc =
      "Index of the blocks beyond exact_limit: " + ApproximateEngineHelp();
  c.def_property(
      "engine", [](const O& o) { return o.approximate.engine; },
      [](O& o, const std::string& v) {
        o.approximate.engine = ParseApproximateEngine(v, "engine");
      },
      engine_doc.c_str());
  search("approximate_k", &ApproximateOptions::k, "Candidates per block (>= candidates).");
  search("ef_search", &ApproximateOptions::ef_search, "HNSW: candidate list while searching.");
  search("nprobe", &ApproximateOptions::nprobe, "IVF: cells scanned per query.");
  search("checks", &ApproximateOptions::checks, "k-d trees: references examined per query.");
  search("lsh_tables", &ApproximateOptions::lsh_tables, "LSH hash tables.");
  search("lsh_key_bits", &ApproximateOptions::lsh_key_bits, "Bits of an LSH key.");
  search("lsh_probe_level", &ApproximateOptions::lsh_probe_level, "LSH multi-probe level.");
  search("kd_trees", &ApproximateOptions::kd_trees, "Randomised k-d trees.");
  search("threads", &ApproximateOptions::threads, "Threads of a search; 0 = all cores.");
  search("seed", &ApproximateOptions::seed, "Seed of the index build.");
  // The network of descriptor "ONNX" (descriptors/onnx.h, the Model_* keys).
  const auto model = [&nested](const char* name, auto member, const char* doc) {
    nested(name, &O::descriptor, member, doc);
  };
  model("model_path", &DescriptorOptions::model_path, "descriptor ONNX: the .onnx file.");
  model("model_input_size", &DescriptorOptions::model_input_size,
        "descriptor ONNX: the network's input, \"WxH\".");
  model("model_channels", &DescriptorOptions::model_channels,
        "descriptor ONNX: \"rgb\", \"bgr\" or \"grey\".");
  model("model_mean", &DescriptorOptions::model_mean,
        "descriptor ONNX: per channel, after scaling to [0, 1].");
  model("model_std", &DescriptorOptions::model_std, "descriptor ONNX: per channel.");
  model("model_normalize", &DescriptorOptions::model_normalize,
        "descriptor ONNX: L2-normalise each row.");
  model("model_batch", &DescriptorOptions::model_batch, "descriptor ONNX: images per pass.");
  // Geometric verification (OpenABLE/verification/verification.h, the Verification_* keys).
  const auto verify = [&nested](const char* name, auto member, const char* doc) {
    nested(name, &O::verification, member, doc);
  };
  verify("verification", &VerificationOptions::enabled,
         "Check each frame's candidates geometrically and by temporal consistency; candidates "
         "then carry a sixth element, a dict (matches, inliers, model, geometric, streak, "
         "verified), and accepted means verified. Needs add_frame (images).");
  c.def_property(
      "verification_features", [](const O& o) { return EnumName(o.verification.features); },
      [](O& o, const std::string& v) {
        o.verification.features = ParseEnum<LocalFeatures>(v, "verification_features");
      },
      "Local features: \"ORB\" or \"SIFT\".");
  verify("verification_max_features", &VerificationOptions::max_features,
         "Features kept per frame (10..100000).");
  verify("verification_ratio", &VerificationOptions::ratio, "Lowe's ratio test, [0.1, 1].");
  verify("verification_min_inliers", &VerificationOptions::min_inliers,
         "Inliers a candidate needs to be verified (>= 5).");
  verify("verification_ransac_threshold", &VerificationOptions::ransac_threshold,
         "RANSAC inlier distance, pixels.");
  verify("verification_candidates", &VerificationOptions::candidates,
         "Candidates checked per frame: the best at distinct places (more than score_window "
         "frames apart).");
  verify("verification_consistency", &VerificationOptions::consistency,
         "Previous frames that must also have verified loops nearby (0: off).");
  verify("verification_tolerance", &VerificationOptions::tolerance,
         "Frames within which references are neighbours for the consistency.");
  verify("verification_calibration", &VerificationOptions::calibration,
         "KITTI calib.txt or OpenCV YAML stereo calibration: the essential matrix; empty: "
         "the fundamental matrix.");
  verify("verification_calibration_scale", &VerificationOptions::calibration_scale,
         "Multiplies the calibration's intrinsics (0.5 for half-size frames).");
  c.def(
       "__getitem__",
       [](const py::object& self, const std::string& name) -> py::object {
         const auto names = PropertyNames(py::type::of(self));
         if (std::find(names.begin(), names.end(), name) == names.end()) throw py::key_error(name);
         return self.attr(name.c_str());
       },
       "options[\"name\"]: the option `name`.")
      .def(
          "keys", [](const py::object& self) { return PropertyNames(py::type::of(self)); },
          "keys() -> list[str]\n\nThe names of the options.")
      .def(
          "to_dict", [](const py::object& self) { return PropertiesAsDict(self); },
          "to_dict() -> dict\n\nEvery option by name.")
      .def("__repr__", [](const py::object& self) {
        return "openable.OnlineOptions(**" + py::repr(PropertiesAsDict(self)).cast<std::string>() +
               ")";
      });
}

// OnlineOptions from the keyword arguments of OnlineDetector or OnlineOptions: the defaults,
// then each keyword set as the property of its name.
OnlineOptions OnlineOptionsOf(const py::kwargs& kwargs) {
  const std::vector<std::string> names = PropertyNames(py::type::of<OnlineOptions>());
  py::object options = py::cast(OnlineOptions());
  for (const auto item : kwargs) {
    const std::string name = item.first.cast<std::string>();
    if (std::find(names.begin(), names.end(), name) == names.end())
      throw py::type_error("unexpected keyword argument \"" + name + "\"; expected one of " +
                           py::str(py::cast(names)).cast<std::string>());
    options.attr(name.c_str()) = item.second;
  }
  return options.cast<OnlineOptions>();
}

const char* const kDescriptionArgs =
    R"doc(    descriptor (str): a name of descriptor_names() but D-LDB (case-insensitive).
    description (str): "global" (the frame resized to patch_size x patch_size and described
        at its centre) or "grid" (grid cells, each resized to the patch, rows concatenated in
        row-major cell order).
    patch_size (int): side of the square patch, pixels (>= 16; HOG: a multiple of 8).
    ldb_bits (int): bits of LDB rows (1..1386; 256 = 32 bytes).
    grid (tuple[int, int]): (cells across, cells down) for description="grid".
    sad_patch (int): SAD: side of the normalised squares of its Patch_size x Patch_size/2
        thumbnail, pixels (2..64).
    color_order (str): channel order of colour images, "bgr" (OpenCV's, as read_image()
        gives them by default) or "rgb" (as matplotlib, PIL and imageio give them).
    model_path, model_input_size, model_channels, model_mean, model_std, model_normalize,
        model_batch: descriptor "ONNX", a network of the user's, as the Model_* keys of
        Config.txt (docs/descriptors.md, "Bring your own descriptor"); the image is described
        in colour.)doc";

}  // namespace

namespace {

void RegisterOnlineHelpers(py::module_& m) {
  m.def("approximate_engines", &ApproximateEngineNames,
        (std::string(R"doc(approximate_engines() -> list[str]

Names of the approximate-search engines, the values of OnlineOptions.engine (any case), in
the order shown to users: )doc") +
         ApproximateEngineHelp())
            .c_str());

  m.def(
      "describe",
      [](const py::object& image, const std::string& descriptor, const std::string& description,
         int patch_size, int ldb_bits, std::pair<int, int> grid, int sad_patch,
         const std::string& color_order, const std::string& model_path,
         const std::string& model_input_size, const std::string& model_channels,
         const std::string& model_mean, const std::string& model_std, bool model_normalize,
         int model_batch) {
        const OnlineOptions o =
            DescriptionOptions(descriptor, description, patch_size, ldb_bits, grid, sad_patch,
                               {model_path, model_input_size, model_channels, model_mean, model_std,
                                model_normalize, model_batch});
        const cv::Mat rows = Describe({Image(image, "image", IsRgbOrder(color_order))}, o, 1);
        return ToNumpy(rows.row(0).clone(), true);
      },
      py::arg("image"), py::arg("descriptor") = "LDB", py::arg("description") = "global",
      py::arg("patch_size") = 64, py::arg("ldb_bits") = 256, py::arg("grid") = std::make_pair(1, 1),
      py::arg("sad_patch") = 8, py::arg("color_order") = "bgr", OPENABLE_MODEL_ARGS,
      ModelDefaultsIn(
          std::string(
              R"doc(describe(image, descriptor="LDB", description="global", patch_size=64,
    ldb_bits=256, grid=(1, 1), sad_patch=8, color_order="bgr",@model_args@) -> numpy.ndarray

The descriptor row of one image, as Test_OpenABLE describes a frame (grey conversion, then
global or grid description).

Args:
    image (numpy.ndarray): (H, W) grey or (H, W, 3) colour; uint8 (0-255) or float32 (0-1,
        as read_image() gives it). Read in place when contiguous (and BGR).
)doc") + kDescriptionArgs +
          R"doc(

Returns:
    numpy.ndarray: 1-D; uint8 bytes for binary descriptors and SAD, float32 for SIFT and HOG.

Raises:
    openable.InputError: unknown descriptor, bad options, or an image too small.)doc")
          .c_str());

  m.def(
      "describe_images",
      [](const py::object& images, const std::string& descriptor, const std::string& description,
         int patch_size, int ldb_bits, std::pair<int, int> grid, int sad_patch, int threads,
         const std::string& color_order, const std::string& model_path,
         const std::string& model_input_size, const std::string& model_channels,
         const std::string& model_mean, const std::string& model_std, bool model_normalize,
         int model_batch) {
        const OnlineOptions o =
            DescriptionOptions(descriptor, description, patch_size, ldb_bits, grid, sad_patch,
                               {model_path, model_input_size, model_channels, model_mean, model_std,
                                model_normalize, model_batch});
        return ToNumpy(Describe(Images(images, "images", IsRgbOrder(color_order)), o, threads));
      },
      py::arg("images"), py::arg("descriptor") = "LDB", py::arg("description") = "global",
      py::arg("patch_size") = 64, py::arg("ldb_bits") = 256, py::arg("grid") = std::make_pair(1, 1),
      py::arg("sad_patch") = 8, py::arg("threads") = 0, py::arg("color_order") = "bgr",
      OPENABLE_MODEL_ARGS,
      ModelDefaultsIn(
          std::string(
              R"doc(describe_images(images, descriptor="LDB", description="global", patch_size=64,
    ldb_bits=256, grid=(1, 1), sad_patch=8, threads=0, color_order="bgr",@model_args@) -> numpy.ndarray

One descriptor row per image, described in parallel (the GIL is released).

Args:
    images (list[numpy.ndarray] | numpy.ndarray): images as describe() takes them, or a stack
        (N, H, W) / (N, H, W, 3).
)doc") + kDescriptionArgs +
          R"doc(
    threads (int): threads; 0 = all cores.

Returns:
    numpy.ndarray: (N, W) uint8 (binary, SAD) or float32 (SIFT, HOG); no copy of the C++
    result.

Raises:
    openable.InputError: naming the image index.)doc")
          .c_str());

  m.def(
      "distance_matrix",
      [](const py::object& rows, int sequence_length, const std::string& direction,
         const py::object& traversal_starts, int threads, bool return_max, const py::object& metric,
         const std::string& partial) -> py::object {
        const MatView v = Matrix2D(rows, Elements::kUint8OrFloat32, "rows");
        const auto dir = ParseEnum<SequenceDirection>(direction, "direction");
        const auto part = ParseEnum<SequencePartial>(partial, "partial");
        std::optional<Metric> m;
        if (!metric.is_none()) m = ParseEnum<Metric>(metric.cast<std::string>(), "metric");
        std::vector<int> starts;
        if (!traversal_starts.is_none()) starts = traversal_starts.cast<std::vector<int>>();
        CheckTraversalStarts(starts, v.mat.rows, "traversal_starts");
        float max = 0;
        cv::Mat1f out;
        {
          py::gil_scoped_release release;
          out = DistanceMatrix(v.mat, sequence_length, dir, starts, threads, &max, m, part);
        }
        py::array a = ToNumpy(out);
        if (return_max) return py::make_tuple(a, max);
        return std::move(a);
      },
      py::arg("rows"), py::arg("sequence_length") = 1, py::arg("direction") = "forward",
      py::arg("traversal_starts") = py::none(), py::arg("threads") = 0,
      py::arg("return_max") = false, py::arg("metric") = py::none(), py::arg("partial") = "ahead",
      R"doc(distance_matrix(rows, sequence_length=1, direction="forward", traversal_starts=None,
    threads=0, return_max=False, metric=None, partial="ahead") -> numpy.ndarray

The normalised matrix M' of Test_OpenABLE over descriptor rows: distances between all rows
(Hamming for uint8 rows, L2 for float32, or `metric`), summed along sequences of L frames
(sequence_distances), divided by their largest value (Eq. 5).

Args:
    rows (numpy.ndarray): (N, W) descriptor rows, uint8 or float32 (read in place when their
        rows are contiguous).
    sequence_length (int): L >= 1 (Image_sequences).
    direction (str): "forward", "reverse" or "both" (Sequence_direction).
    traversal_starts (list[int] | None): first row of each traversal when several are
        concatenated (e.g. [0, N1]): sums never cross between them. None: one traversal.
    threads (int): threads; 0 = all cores.
    return_max (bool): also return the divisor max(M).
    metric (str | None): "hamming" or "l1" (uint8 rows; l1 for SAD's rows) or "l2" (float32
        rows); None: by the rows' type.
    partial (str): "ahead", "scale" or "skip" (Sequence_partial): cells with fewer than L
        frames before them take the L frames ahead of them on their diagonal, are scaled
        up, or hold +inf (never a best match).

Returns:
    numpy.ndarray: float32 (N, N) in [0, 1] (+inf for cells without a value), owning the C++ result
    (no copy); or (matrix, max) with return_max=True.)doc");
}

void BindDetectorMapAndState(py::class_<Detector>& c);

void RegisterDetector(py::module_& m) {
  BindOnlineOptions(m);
  // The signature of the constructor, from the defaults of the options' properties.
  const py::object defaults = py::cast(OnlineOptions());
  std::string signature = "OnlineDetector(*";
  for (const std::string& name : PropertyNames(m.attr("OnlineOptions")))
    signature += ", " + name + "=" + py::repr(defaults.attr(name.c_str())).cast<std::string>();
  signature += ")";
  const std::string class_doc = signature + R"doc(

Loop candidates frame by frame, for a SLAM system: each frame added is described, searched
among the earlier frames (exactly while the map holds at most exact_limit frames, then through
index blocks of the engine), and its best candidates are returned.

Args:
    **options: the properties of openable.OnlineOptions (help(openable.OnlineOptions) says
        what each means), by keyword.

Raises:
    openable.InputError (or ValueError): an option out of range, naming it; TypeError: an
    unknown option.

Calls from several threads are serialised by a lock.)doc";
  py::class_<Detector> c(m, "OnlineDetector", class_doc.c_str());
  c.def(py::init([](const py::kwargs& kwargs) {
          auto d = std::make_unique<Detector>();
          d->detector = std::make_unique<OnlineDetector>(OnlineOptionsOf(kwargs));
          return d;
        }),
        "__init__(**options)\n\nSee help(openable.OnlineDetector) for the options.")
      .def(
          "add_to_map",
          [](Detector& det, const py::object& rows) {
            const MatView v = Matrix2D(rows, Elements::kUint8OrFloat32, "rows");
            py::gil_scoped_release release;
            std::lock_guard<std::mutex> lock(det.mutex);
            det.detector->AddToMap(v.mat);
          },
          py::arg("rows"),
          R"doc(add_to_map(rows)

Appends descriptor rows (n x row_width, row_dtype; e.g. the `descriptors` of an earlier
detector, saved with numpy.save) as the next n frames without searching for them: a map from an
earlier run, which later frames find as candidates like any other frame.)doc")
      .def(
          "add_frame",
          [](Detector& d, const py::object& image, const std::string& color_order) {
            const MatView v = Image(image, "image", IsRgbOrder(color_order));
            OnlineResult r;
            {
              py::gil_scoped_release release;
              std::lock_guard<std::mutex> lock(d.mutex);
              r = d.detector->AddFrame(v.mat);
            }
            return ResultTuple(r, d.detector->Options().verification.enabled);
          },
          py::arg("image"), py::arg("color_order") = "bgr",
          R"doc(add_frame(image, color_order="bgr") -> tuple[int, list[tuple[int, float, float, bool, float]], dict]

Describes `image` and adds it as the next frame (the GIL is released meanwhile).

Args:
    image (numpy.ndarray): (H, W) grey or (H, W, 3) colour, uint8 or float32 in [0, 1].
    color_order (str): channel order of a colour image, "bgr" (OpenCV's) or "rgb".

Returns:
    (frame, candidates, timings): the index of the frame added (0, 1, ...); its candidates,
    best first (ties: earlier frame first), each (earlier frame, raw sequence distance,
    normalised distance, accepted, score: the normalised distance or the ratio, as the option
    score says; accepted is score <= threshold), empty while no frame is old enough; timings
    {"describe_seconds", "search_seconds", "approximate": whether index blocks were used}.

Raises:
    openable.InputError: an empty image, another type, or one smaller than the description
    needs.)doc")
      .def(
          "add_descriptor",
          [](Detector& d, const py::object& row) {
            const MatView v = Matrix2D(row, Elements::kUint8OrFloat32, "row");
            OnlineResult r;
            {
              py::gil_scoped_release release;
              std::lock_guard<std::mutex> lock(d.mutex);
              r = d.detector->AddDescriptor(v.mat);
            }
            return ResultTuple(r, d.detector->Options().verification.enabled);
          },
          py::arg("row"),
          R"doc(add_descriptor(row) -> tuple[int, list[tuple[int, float, float, bool, float]], dict]

Adds an already computed descriptor row (1-D, row_width elements of row_dtype, e.g. a row of
describe_images()) as the next frame; returns what add_frame() returns.)doc")
      .def(
          "save_map",
          [](Detector& det, const py::object& path_object) {
            const std::string path = FileSystemPath(path_object, "save_map: path");
            py::gil_scoped_release release;
            std::lock_guard<std::mutex> lock(det.mutex);
            det.detector->SaveMap(path);
          },
          py::arg("path"),
          R"doc(save_map(path)

Saves the map (the settings it was made with, every frame's descriptor row, the index blocks,
and with verification every frame's local features) to `path`, so that a later session starts
from it with load_map(). Versioned and checksummed; written through a temporary file renamed
into place when complete. Raises openable.InputError naming the path when it cannot be
written.)doc")
      .def(
          "add_images_to_map",
          [](Detector& det, const py::object& images, const std::string& color_order) {
            const std::vector<MatView> views = Images(images, "images", IsRgbOrder(color_order));
            std::vector<cv::Mat> mats;
            for (const MatView& v : views) mats.push_back(v.mat);
            py::gil_scoped_release release;
            std::lock_guard<std::mutex> lock(det.mutex);
            det.detector->AddImagesToMap(mats);
          },
          py::arg("images"), py::arg("color_order") = "bgr",
          R"doc(add_images_to_map(images, color_order="bgr")

Describes `images` (in parallel) and appends them as the next frames without searching for
them: a traversal added to a map in bulk (start_session() first names it). Every image must be
of the map's frame size (frame_size). Raises openable.InputError naming the first image that
does not fit, adding none.)doc")
      .def(
          "start_session",
          [](Detector& det, const std::string& name, const std::string& time) {
            std::lock_guard<std::mutex> lock(det.mutex);
            det.detector->StartSession(name, time);
          },
          py::arg("name"), py::arg("time") = "",
          R"doc(start_session(name, time="")

Begins a session (a traversal) at the next frame: its frames find every frame of the earlier
sessions, and those of their own session at least `exclusion` frames back; sequences never run
across a session's start. `time`: ISO 8601 UTC, by default now. Frames added before any
session belong to one named "default". Raises openable.InputError on a name already in the
map, empty, or not printable text.)doc")
      .def(
          "query",
          [](Detector& det, const py::object& rows, const py::object& sessions) {
            const MatView v = Matrix2D(rows, Elements::kUint8OrFloat32, "rows");
            const std::vector<std::string> names = SessionNames(sessions);
            std::vector<OnlineResult> results;
            {
              py::gil_scoped_release release;
              std::lock_guard<std::mutex> lock(det.mutex);
              results = det.detector->Query(v.mat, names);
            }
            return QueryResults(results, det.detector->Sessions());
          },
          py::arg("rows"), py::arg("sessions") = py::none(),
          (std::string(R"doc(query(rows, sessions=None) -> list[list[dict]]

Searches the map for each descriptor row of `rows` (a query traversal: row i is its frame i,
whose sequences use its own earlier rows) without adding them. Every frame of the map is a
candidate, or with `sessions` (a name or a list of names) only the frames of those sessions.

Args:
    rows (numpy.ndarray): (n, row_width) of row_dtype, e.g. describe_images()'s rows.
    sessions (str | list[str] | None): the sessions searched; None: all.
)doc") + kQueryDoc)
              .c_str())
      .def(
          "query_images",
          [](Detector& det, const py::object& images, const py::object& sessions,
             const std::string& color_order) {
            const std::vector<MatView> views = Images(images, "images", IsRgbOrder(color_order));
            std::vector<cv::Mat> mats;
            for (const MatView& v : views) mats.push_back(v.mat);
            const std::vector<std::string> names = SessionNames(sessions);
            std::vector<OnlineResult> results;
            {
              py::gil_scoped_release release;
              std::lock_guard<std::mutex> lock(det.mutex);
              results = det.detector->QueryImages(mats, names);
            }
            return QueryResults(results, det.detector->Sessions());
          },
          py::arg("images"), py::arg("sessions") = py::none(), py::arg("color_order") = "bgr",
          (std::string(
               R"doc(query_images(images, sessions=None, color_order="bgr") -> list[list[dict]]

Describes `images` (a query traversal, of the map's frame size) and queries them as query()
does.
)doc") + kQueryDoc)
              .c_str())
      .def(
          "append_map",
          [](Detector& det, const py::object& path_object) {
            const std::string path = FileSystemPath(path_object, "append_map: path");
            py::gil_scoped_release release;
            std::lock_guard<std::mutex> lock(det.mutex);
            det.detector->AppendMap(path);
          },
          py::arg("path"),
          R"doc(append_map(path)

Appends the sessions of the map saved at `path` after this detector's frames (the same
description options and frame size; session names not already here), indexed as
add_to_map() indexes rows: with load_map() and save_map(), the merge of two maps. Raises
openable.InputError naming the path and what differs, changing nothing.)doc")
      .def(
          "check_map",
          [](Detector& det) {
            py::gil_scoped_release release;
            std::lock_guard<std::mutex> lock(det.mutex);
            det.detector->CheckMap();
          },
          R"doc(check_map()

Waits for the background check of a loaded map's checksums; raises openable.InputError when
the map is damaged. Returns at once when no map was loaded or it was checked.)doc")
      .def_property_readonly(
          "sessions",
          [](Detector& d) {
            std::lock_guard<std::mutex> lock(d.mutex);
            py::list out;
            for (const MapSession& m : d.detector->Sessions()) {
              py::dict s;
              s["name"] = m.name;
              s["time"] = m.time;
              s["first"] = m.first;
              s["frames"] = m.count;
              out.append(s);
            }
            return out;
          },
          "The map's sessions in frame order, each {\"name\", \"time\" (ISO 8601 UTC), "
          "\"first\" (its first frame in the map), \"frames\"}.")
      .def(
          "session_of",
          [](Detector& d, int frame) {
            std::lock_guard<std::mutex> lock(d.mutex);
            const int s = d.detector->SessionOf(frame);
            const MapSession& m = d.detector->Sessions()[static_cast<std::size_t>(s)];
            return py::make_tuple(m.name, frame - m.first);
          },
          py::arg("frame"),
          "session_of(frame) -> tuple[str, int]\n\nThe session holding map frame `frame` and "
          "the frame's number within it.")
      .def_property_readonly("frame_size", Locked(&OnlineDetector::FrameSize),
                             "\"WxH\" of the map's frames (\"\" until the first image is added).");
  c.def_static(
      "open",
      [](const py::object& path_object, const py::kwargs& kwargs) {
        const std::string path = FileSystemPath(path_object, "OnlineDetector.open: path");
        // The map's own options (MapOptions), then each keyword given, as the constructor
        // sets them.
        const OnlineOptions base = OnlineOptionsOf(kwargs);
        OnlineOptions own;
        {
          py::gil_scoped_release release;
          own = MapOptions(path, base);
        }
        const std::vector<std::string> names = PropertyNames(py::type::of<OnlineOptions>());
        py::object options = py::cast(own);
        for (const auto item : kwargs) {
          const std::string name = item.first.cast<std::string>();
          if (std::find(names.begin(), names.end(), name) == names.end())
            throw py::type_error("unexpected keyword argument \"" + name + "\"; expected one of " +
                                 py::str(py::cast(names)).cast<std::string>());
          options.attr(name.c_str()) = item.second;
        }
        const OnlineOptions chosen = options.cast<OnlineOptions>();
        auto d = std::make_unique<Detector>();
        {
          py::gil_scoped_release release;
          d->detector = std::make_unique<OnlineDetector>(chosen);
          d->detector->LoadMap(path);
        }
        return d;
      },
      py::arg("path"),
      R"doc(OnlineDetector.open(path, **options) -> OnlineDetector

A detector holding the map saved at `path`, with the options the map keeps: the description
and index options it was made with, and its search (the one tune() chose, else the one it was
saved with: descriptor, sequence_length, score, threshold, consistency, ...); each keyword
given replaces the map's (a search of the keyword's, whose tuned verdict then does not apply;
description options other than the map's are refused on loading). The file is memory-mapped:
its rows and binary_ivf index blocks are used where they lie, and its checksums are verified in
the background (check_map()).)doc");
  BindDetectorMapAndState(c);
}

// The detector's loading of a saved map, finish_merges, and its state (the properties).
void BindDetectorMapAndState(py::class_<Detector>& c) {
  c.def(
       "load_map",
       [](Detector& det, const py::object& path_object, bool in_place, bool check_in_background) {
         const std::string path = FileSystemPath(path_object, "load_map: path");
         OnlineDetector::LoadedMap info;
         MapReadOptions read;
         read.in_place = in_place;
         read.check_in_background = check_in_background;
         {
           py::gil_scoped_release release;
           std::lock_guard<std::mutex> lock(det.mutex);
           info = det.detector->LoadMap(path, read);
         }
         py::dict out;
         out["frames"] = info.frames;
         out["blocks"] = info.blocks;
         out["rebuilt"] = info.rebuilt;
         out["reason"] = info.reason;
         return out;
       },
       py::arg("path"), py::arg("in_place") = true, py::arg("check_in_background") = true,
       R"doc(load_map(path, in_place=True, check_in_background=True) -> dict

Loads a map written by save_map() into this detector, which must be empty: its frames become
frames 0 .. frames - 1, and later frames find them as candidates; with the options of the
detector that saved it, every later frame gets the candidates that detector would give. The
description options (descriptor, description, patch_size, ldb_bits, grid) must be the map's.
When an index option differs (engine and its build settings, exact_limit, block_frames,
exclusion), the index is built from the rows instead of read. The sessions come with the map
(a map of the first format version is one session, "default").

in_place: memory-map the file and use its rows and binary_ivf blocks where they lie (a map of
ten million places opens in well under a second); False copies them. check_in_background:
verify the rows' and blocks' checksums on a background thread (check_map() waits for it; a
damaged map is reported by the next call that adds, queries or saves); False verifies them
before returning.

Returns:
    {"frames": frames loaded, "blocks": index blocks in use, "rebuilt": whether the blocks
    were built rather than read, "reason": the option that differed}.

Raises:
    openable.InputError: one line beginning with the path: unreadable, not a map, another
    format version, damaged or truncated, made with other description options, or the
    detector is not empty.)doc")
      .def(
          "finish_merges",
          [](Detector& det) {
            py::gil_scoped_release release;
            std::lock_guard<std::mutex> lock(det.mutex);
            det.detector->FinishMerges();
          },
          R"doc(finish_merges()

Waits for a merge of index blocks being built in the background (background_merges) and
installs its index.)doc")
      .def_property_readonly("size", Locked(&OnlineDetector::Size), "Frames added so far.")
      .def("__len__", Locked(&OnlineDetector::Size), "Frames added so far.")
      .def_property_readonly(
          "row_width", [](Detector& d) { return d.detector->RowWidth(); },
          "Elements per descriptor row.")
      .def_property_readonly(
          "row_dtype",
          [](Detector& d) {
            return d.detector->RowType() == CV_8U ? py::dtype::of<std::uint8_t>()
                                                  : py::dtype::of<float>();
          },
          "numpy.dtype of the rows: uint8 (Hamming) or float32 (L2).")
      .def_property_readonly(
          "descriptors",
          [](Detector& d) {
            cv::Mat rows;
            {
              std::lock_guard<std::mutex> lock(d.mutex);
              rows = d.detector->Descriptors();
            }
            py::array a = ToNumpy(rows);
            a.attr("setflags")(py::arg("write") = false);
            return a;
          },
          "Read-only (size, row_width) array of the stored rows: a view of the detector's "
          "memory when it can be shared (later frames are not added to it).")
      .def_property_readonly("memory_bytes", Locked(&OnlineDetector::MemoryBytes),
                             "Bytes held now: the rows plus, beyond exact_limit, the index blocks.")
      .def_property_readonly("blocks", Locked(&OnlineDetector::Blocks),
                             "Index blocks in use (0 while the search is exact).")
      .def_property_readonly(
          "channels", [](Detector& d) { return d.detector->Channels(); },
          "The descriptors the map describes every frame with (descriptor's, then "
          "kept_descriptors').")
      .def_property_readonly(
          "tuning",
          [](Detector& d) -> py::object {
            std::lock_guard<std::mutex> lock(d.mutex);
            return TuningDict(d.detector->Tuning());
          },
          "What tune() chose (a dict, kept in saved maps), or None when the map is not tuned.")
      .def_property_readonly(
          "uses_tuning", Locked(&OnlineDetector::UsesTuning),
          "Whether the search uses the tuned settings (an unreliable map then accepts "
          "nothing).")
      .def(
          "tune",
          [](Detector& det, const py::object& reference, const py::object& query,
             const std::string& candidates, double min_consistency, double threshold,
             int max_frames) {
            OnlineDetector::TuneOptions t;
            if (!reference.is_none()) t.reference = reference.cast<std::string>();
            if (!query.is_none()) t.query = query.cast<std::string>();
            if (reference.is_none() != query.is_none())
              throw InputError(
                  "tune: reference and query: expected both session names, or "
                  "neither (the map's first two sessions)");
            t.candidates = candidates;
            t.min_consistency = min_consistency;
            t.threshold = threshold;
            t.max_frames = max_frames;
            MapTuning tuning;
            {
              py::gil_scoped_release release;
              std::lock_guard<std::mutex> lock(det.mutex);
              tuning = det.detector->Tune(t);
            }
            return TuningDict(tuning);
          },
          py::arg("reference") = py::none(), py::arg("query") = py::none(),
          py::arg("candidates") = "", py::arg("min_consistency") = 0.5, py::arg("threshold") = -1.0,
          py::arg("max_frames") = 0,
          R"doc(tune(reference=None, query=None, candidates="", min_consistency=0.5, threshold=-1, max_frames=0) -> dict

Chooses the search settings from the map's own frames, with no ground truth, as
Test_OpenABLE's auto mode does: the frames of session `query` are matched against those of
session `reference` (the first two sessions when both are None) with every candidate of
`candidates` (Auto_candidates' syntax; "": those of the default the map's descriptors allow),
and the one with the highest agreement becomes the search: descriptor, fusion weights,
contrast enhancement, sequence_length, the ratio score <= `threshold` (< 0: 0.9) confirmed by
one earlier independent query (consistency 1). save_map() keeps it. When the chosen
candidate's consistency is below `min_consistency` the map is unreliable and accepts nothing
while these settings are used. `max_frames` > 0 judges on the first max_frames frames of each
session. Returns the tuning dict (see the property tuning). Raises openable.InputError on
unknown sessions, candidates that vary how frames are described or need rows the map does not
hold.)doc")
      .def_property_readonly(
          "options", [](Detector& d) { return d.detector->Options(); },
          "The options in effect (an openable.OnlineOptions; options[\"name\"] and "
          "to_dict() read them like a dict of the constructor's keyword arguments).")
      .def("__repr__", [](Detector& d) {
        std::lock_guard<std::mutex> lock(d.mutex);
        const OnlineOptions& o = d.detector->Options();
        return "<openable.OnlineDetector " + o.descriptor.name + " " + EnumName(o.description) +
               ", L=" + std::to_string(o.sequence_length) + ", " +
               std::to_string(d.detector->Size()) + " frames>";
      });
}

}  // namespace

void RegisterOnline(py::module_& m) {
  RegisterOnlineHelpers(m);
  RegisterDetector(m);
  m.def(
      "merge_maps",
      [](const py::object& a_object, const py::object& b_object, const py::object& out_object) {
        const std::string a = FileSystemPath(a_object, "merge_maps: a");
        const std::string b = FileSystemPath(b_object, "merge_maps: b");
        const std::string out = FileSystemPath(out_object, "merge_maps: output");
        py::gil_scoped_release release;
        const MapWriteLock lock(out);  // as openable_map merge: one writer of `output` at a time
        OnlineDetector d(MapOptions(a));
        d.LoadMap(a);
        d.AppendMap(b);
        d.SaveMap(out);
        return d.Size();
      },
      py::arg("a"), py::arg("b"), py::arg("output"),
      R"doc(merge_maps(a, b, output) -> int

Writes to `output` the map of the sessions of map `a`, then those of map `b` (saved maps of the
same description options and frame size, with distinct session names), indexed with a's index
options: openable_map merge A B -o C. Returns the frames of the merged map. Raises
openable.InputError naming the map and what differs; `output` is then not written.)doc");
}

}  // namespace openable::python
