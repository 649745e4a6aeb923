// The batch helpers and the online detector of OpenABLE/online/online.h: describe, describe_images,
// distance_matrix, OnlineDetector.
#include <cstdio>
#include <memory>
#include <mutex>
#include <utility>

#include <pybind11/stl.h>

#include "OpenABLE/online/online.h"
#include "OpenABLE/python/common.h"

namespace openable::python {
namespace {

DescriptionType DescriptionOf(const std::string& name) {
  const std::string n = Lower(name);
  if (n == "global") return DescriptionType::kGlobal;
  if (n == "grid") return DescriptionType::kGrid;
  throw py::value_error("description: \"" + name + "\"; expected \"global\" or \"grid\"");
}

std::string DescriptionName(DescriptionType t) {
  return t == DescriptionType::kGrid ? "grid" : "global";
}

// The description part of OnlineOptions.
OnlineOptions DescriptionOptions(const std::string& descriptor, const std::string& description,
                                 int patch_size, int ldb_bits, std::pair<int, int> grid) {
  OnlineOptions o;
  o.descriptor = descriptor;
  o.description = DescriptionOf(description);
  o.patch_size = patch_size;
  o.ldb_bits = ldb_bits;
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

py::tuple ResultTuple(const OnlineResult& r) {
  py::list candidates;
  for (const LoopCandidate& c : r.candidates)
    candidates.append(py::make_tuple(c.frame, c.distance, c.normalized, c.accepted));
  py::dict timings;
  timings["describe_seconds"] = r.describe_seconds;
  timings["search_seconds"] = r.search_seconds;
  timings["approximate"] = r.approximate;
  return py::make_tuple(r.frame, candidates, timings);
}

template <typename... Args>
std::string Format(const char* format, Args... args) {
  char buffer[1024];
  std::snprintf(buffer, sizeof buffer, format, args...);
  return buffer;
}

const char* const kDescriptionArgs = R"doc(    descriptor (str): a name of descriptor_names() but D-LDB (case-insensitive).
    description (str): "global" (the frame resized to patch_size x patch_size and described
        at its centre) or "grid" (grid cells, each resized to the patch, rows concatenated in
        row-major cell order).
    patch_size (int): side of the square patch, pixels (>= 16; HOG: a multiple of 8).
    ldb_bits (int): bits of LDB rows (1..1386; 256 = 32 bytes).
    grid (tuple[int, int]): (cells across, cells down) for description="grid".)doc";

}  // namespace

void RegisterOnline(py::module_& m) {
  m.def(
      "describe",
      [](const py::object& image, const std::string& descriptor, const std::string& description,
         int patch_size, int ldb_bits, std::pair<int, int> grid) {
        const OnlineOptions o = DescriptionOptions(descriptor, description, patch_size, ldb_bits, grid);
        const cv::Mat rows = Describe({Image(image, "image")}, o, 1);
        return ToNumpy(rows.row(0).clone(), true);
      },
      py::arg("image"), py::arg("descriptor") = "LDB", py::arg("description") = "global",
      py::arg("patch_size") = 64, py::arg("ldb_bits") = 256,
      py::arg("grid") = std::make_pair(1, 1),
      (std::string(R"doc(describe(image, descriptor="LDB", description="global", patch_size=64, ldb_bits=256, grid=(1, 1)) -> numpy.ndarray

The descriptor row of one image, as Test_OpenABLE describes a frame (grey conversion, then
global or grid description).

Args:
    image (numpy.ndarray): (H, W) grey or (H, W, 3) BGR; uint8 (0-255) or float32 (0-1, as
        read_image() gives it). Read in place when contiguous.
)doc") + kDescriptionArgs + R"doc(

Returns:
    numpy.ndarray: 1-D; uint8 bytes for binary descriptors, float32 for SIFT and HOG.

Raises:
    openable.InputError: unknown descriptor, bad options, or an image too small.)doc")
          .c_str());

  m.def(
      "describe_images",
      [](const py::object& images, const std::string& descriptor, const std::string& description,
         int patch_size, int ldb_bits, std::pair<int, int> grid, int threads) {
        const OnlineOptions o = DescriptionOptions(descriptor, description, patch_size, ldb_bits, grid);
        return ToNumpy(Describe(Images(images, "images"), o, threads));
      },
      py::arg("images"), py::arg("descriptor") = "LDB", py::arg("description") = "global",
      py::arg("patch_size") = 64, py::arg("ldb_bits") = 256,
      py::arg("grid") = std::make_pair(1, 1), py::arg("threads") = 0,
      (std::string(R"doc(describe_images(images, descriptor="LDB", description="global", patch_size=64, ldb_bits=256, grid=(1, 1), threads=0) -> numpy.ndarray

One descriptor row per image, described in parallel (the GIL is released).

Args:
    images (list[numpy.ndarray] | numpy.ndarray): images as describe() takes them, or a stack
        (N, H, W) / (N, H, W, 3).
)doc") + kDescriptionArgs + R"doc(
    threads (int): threads; 0 = all cores.

Returns:
    numpy.ndarray: (N, W) uint8 (binary) or float32 (SIFT, HOG); no copy of the C++ result.

Raises:
    openable.InputError: naming the image index.)doc")
          .c_str());

  m.def(
      "distance_matrix",
      [](const py::object& rows, int sequence_length, const std::string& direction,
         const py::object& traversal_starts, int threads, bool return_max) -> py::object {
        const MatView v = Matrix2D(rows, Elements::kUint8OrFloat32, "rows");
        const auto dir = static_cast<SequenceDirection>(ParseDirection(direction));
        std::vector<int> starts;
        if (!traversal_starts.is_none()) starts = traversal_starts.cast<std::vector<int>>();
        float max = 0;
        cv::Mat1f out;
        {
          py::gil_scoped_release release;
          out = DistanceMatrix(v.mat, sequence_length, dir, starts, threads, &max);
        }
        py::array a = ToNumpy(out);
        if (return_max) return py::make_tuple(a, max);
        return std::move(a);
      },
      py::arg("rows"), py::arg("sequence_length") = 1, py::arg("direction") = "forward",
      py::arg("traversal_starts") = py::none(), py::arg("threads") = 0,
      py::arg("return_max") = false,
      R"doc(distance_matrix(rows, sequence_length=1, direction="forward", traversal_starts=None, threads=0, return_max=False) -> numpy.ndarray

The normalised matrix M' of Test_OpenABLE over descriptor rows: distances between all rows
(Hamming for uint8 rows, L2 for float32), summed along sequences of L frames
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

Returns:
    numpy.ndarray: float32 (N, N) in [0, 1], owning the C++ result (no copy); or (matrix,
    max) with return_max=True.)doc");

  const OnlineOptions defaults;  // the defaults of the keyword arguments
  const ApproximateOptions& fl = defaults.approximate;
  const std::string signature = Format(
      "OnlineDetector(*, descriptor=\"%s\", description=\"%s\", patch_size=%d, ldb_bits=%d, "
      "grid=(%d, %d), sequence_length=%d, exclusion=%d, candidates=%d, threshold=%g, "
      "exact_limit=%d, block_frames=%d, background_merges=%s, approximate_k=%d, checks=%d, "
      "lsh_tables=%d, "
      "lsh_key_bits=%d, lsh_probe_level=%d, kd_trees=%d, threads=%d, seed=%llu)",
      defaults.descriptor.c_str(), DescriptionName(defaults.description).c_str(),
      defaults.patch_size, defaults.ldb_bits, defaults.grid_x, defaults.grid_y,
      defaults.sequence_length, defaults.exclusion, defaults.candidates, defaults.threshold,
      defaults.exact_limit, defaults.block_frames, defaults.background_merges ? "True" : "False",
      fl.k, fl.checks, fl.lsh_tables,
      fl.lsh_key_bits, fl.lsh_probe_level, fl.kd_trees, fl.threads,
      static_cast<unsigned long long>(fl.seed));
  const std::string class_doc = signature + R"doc(

Loop candidates frame by frame, for a SLAM system: each frame added is described, searched
among the earlier frames (exactly while the map holds at most exact_limit frames, then through
FLANN blocks), and its best candidates are returned.

Args:
)doc" R"doc(    descriptor, description, patch_size, ldb_bits, grid: the description, as describe().
    sequence_length (int): L, frames summed along the diagonal (Image_sequences).
    exclusion (int): frame q's candidates are frames j <= q - exclusion (>= 1).
    candidates (int): candidates returned per frame (the k best, >= 1).
    threshold (float): a candidate is accepted when its normalised distance is <= threshold.
        Normalised: the distance divided by L x the descriptor's bit count for binary
        descriptors (the mean fraction of differing bits), by L x the largest single-frame
        distance seen so far for float descriptors. Not the scale of Config.txt's Threshold.
    exact_limit (int): exact search while the searchable map holds at most this many frames.
    block_frames (int): frames per FLANN block beyond it.
    background_merges (bool): build merges of two blocks on a background thread (no frame
        waits for a large index build; candidates then depend on when a merge finishes);
        False builds them inside add_frame, for repeatable results.
    approximate_k, checks, lsh_tables, lsh_key_bits, lsh_probe_level, kd_trees, threads, seed:
        the FLANN search (candidates per block, k-d tree checks, LSH tables, key bits and
        multi-probe level, k-d trees, threads, seed of the index build).

Raises:
    openable.InputError (or ValueError): an option out of range, naming it.

Calls from several threads are serialised by a lock.)doc";
  py::class_<Detector>(m, "OnlineDetector", class_doc.c_str())
      .def(py::init([](const std::string& descriptor, const std::string& description,
                       int patch_size, int ldb_bits, std::pair<int, int> grid,
                       int sequence_length, int exclusion, int candidates, double threshold,
                       int exact_limit, int block_frames, bool background_merges,
                       int approximate_k, int checks,
                       int lsh_tables, int lsh_key_bits, int lsh_probe_level, int kd_trees,
                       int threads, std::uint64_t seed) {
             OnlineOptions o = DescriptionOptions(descriptor, description, patch_size, ldb_bits, grid);
             o.sequence_length = sequence_length;
             o.exclusion = exclusion;
             o.candidates = candidates;
             o.threshold = threshold;
             o.exact_limit = exact_limit;
             o.block_frames = block_frames;
             o.background_merges = background_merges;
             o.approximate.k = approximate_k;
             o.approximate.checks = checks;
             o.approximate.lsh_tables = lsh_tables;
             o.approximate.lsh_key_bits = lsh_key_bits;
             o.approximate.lsh_probe_level = lsh_probe_level;
             o.approximate.kd_trees = kd_trees;
             o.approximate.threads = threads;
             o.approximate.seed = seed;
             auto d = std::make_unique<Detector>();
             d->detector = std::make_unique<OnlineDetector>(o);
             return d;
           }),
           py::kw_only(), py::arg("descriptor") = defaults.descriptor,
           py::arg("description") = DescriptionName(defaults.description),
           py::arg("patch_size") = defaults.patch_size, py::arg("ldb_bits") = defaults.ldb_bits,
           py::arg("grid") = std::make_pair(defaults.grid_x, defaults.grid_y),
           py::arg("sequence_length") = defaults.sequence_length,
           py::arg("exclusion") = defaults.exclusion, py::arg("candidates") = defaults.candidates,
           py::arg("threshold") = defaults.threshold, py::arg("exact_limit") = defaults.exact_limit,
           py::arg("block_frames") = defaults.block_frames,
           py::arg("background_merges") = defaults.background_merges,
           py::arg("approximate_k") = fl.k,
           py::arg("checks") = fl.checks, py::arg("lsh_tables") = fl.lsh_tables,
           py::arg("lsh_key_bits") = fl.lsh_key_bits,
           py::arg("lsh_probe_level") = fl.lsh_probe_level, py::arg("kd_trees") = fl.kd_trees,
           py::arg("threads") = fl.threads, py::arg("seed") = fl.seed,
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
          [](Detector& d, const py::object& image) {
            const MatView v = Image(image, "image");
            OnlineResult r;
            {
              py::gil_scoped_release release;
              std::lock_guard<std::mutex> lock(d.mutex);
              r = d.detector->AddFrame(v.mat);
            }
            return ResultTuple(r);
          },
          py::arg("image"),
          R"doc(add_frame(image) -> tuple[int, list[tuple[int, float, float, bool]], dict]

Describes `image` and adds it as the next frame (the GIL is released meanwhile).

Args:
    image (numpy.ndarray): (H, W) grey or (H, W, 3) BGR, uint8 or float32 in [0, 1].

Returns:
    (frame, candidates, timings): the index of the frame added (0, 1, ...); its candidates,
    best first (ties: earlier frame first), each (earlier frame, raw sequence distance,
    normalised distance, accepted), empty while no frame is old enough; timings
    {"describe_seconds", "search_seconds", "approximate": whether FLANN blocks were used}.

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
            return ResultTuple(r);
          },
          py::arg("row"),
          R"doc(add_descriptor(row) -> tuple[int, list[tuple[int, float, float, bool]], dict]

Adds an already computed descriptor row (1-D, row_width elements of row_dtype, e.g. a row of
describe_images()) as the next frame; returns what add_frame() returns.)doc")
      .def(
          "finish_merges",
          [](Detector& det) {
            py::gil_scoped_release release;
            std::lock_guard<std::mutex> lock(det.mutex);
            det.detector->FinishMerges();
          },
          R"doc(finish_merges()

Waits for a merge of FLANN blocks being built in the background (background_merges) and
installs its index.)doc")
      .def_property_readonly(
          "size",
          [](Detector& d) {
            std::lock_guard<std::mutex> lock(d.mutex);
            return d.detector->Size();
          },
          "Frames added so far.")
      .def("__len__", [](Detector& d) {
        std::lock_guard<std::mutex> lock(d.mutex);
        return d.detector->Size();
      }, "Frames added so far.")
      .def_property_readonly(
          "row_width",
          [](Detector& d) { return d.detector->RowWidth(); },
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
      .def_property_readonly(
          "memory_bytes",
          [](Detector& d) {
            std::lock_guard<std::mutex> lock(d.mutex);
            return d.detector->MemoryBytes();
          },
          "Bytes held now: the rows plus, beyond exact_limit, the FLANN indices.")
      .def_property_readonly(
          "blocks",
          [](Detector& d) {
            std::lock_guard<std::mutex> lock(d.mutex);
            return d.detector->Blocks();
          },
          "FLANN blocks in use (0 while the search is exact).")
      .def_property_readonly(
          "options",
          [](Detector& d) {
            const OnlineOptions& o = d.detector->Options();
            py::dict r;
            r["descriptor"] = o.descriptor;
            r["description"] = DescriptionName(o.description);
            r["patch_size"] = o.patch_size;
            r["ldb_bits"] = o.ldb_bits;
            r["grid"] = py::make_tuple(o.grid_x, o.grid_y);
            r["sequence_length"] = o.sequence_length;
            r["exclusion"] = o.exclusion;
            r["candidates"] = o.candidates;
            r["threshold"] = o.threshold;
            r["exact_limit"] = o.exact_limit;
            r["block_frames"] = o.block_frames;
            r["background_merges"] = o.background_merges;
            r["approximate_k"] = o.approximate.k;
            r["checks"] = o.approximate.checks;
            r["lsh_tables"] = o.approximate.lsh_tables;
            r["lsh_key_bits"] = o.approximate.lsh_key_bits;
            r["lsh_probe_level"] = o.approximate.lsh_probe_level;
            r["kd_trees"] = o.approximate.kd_trees;
            r["threads"] = o.approximate.threads;
            r["seed"] = o.approximate.seed;
            return r;
          },
          "The options in effect, as a dict of the constructor's keyword arguments.")
      .def("__repr__", [](Detector& d) {
        std::lock_guard<std::mutex> lock(d.mutex);
        const OnlineOptions& o = d.detector->Options();
        return "<openable.OnlineDetector " + o.descriptor + " " + DescriptionName(o.description) +
               ", L=" + std::to_string(o.sequence_length) + ", " +
               std::to_string(d.detector->Size()) + " frames>";
      });
}

}  // namespace openable::python
