// The SNAPS add-on (docs/snaps.md) as openable.snaps: trajectories, loops, the discounted
// update (Eq. 6), the pose graph, the absolute trajectory error.
#include <pybind11/stl.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <string>
#include <vector>

#include "OpenABLE/app/snaps_chain.h"
#include "OpenABLE/base/error.h"
#include "OpenABLE/base/output_batch.h"
#include "OpenABLE/python/common.h"
#include "OpenABLE/snaps/discounted.h"
#include "OpenABLE/snaps/loops.h"
#include "OpenABLE/snaps/pose_graph.h"
#include "OpenABLE/snaps/trajectory.h"

namespace openable::python {
namespace {

using snaps::ChainErrors;
using snaps::ChainResult;
using snaps::CheckedPose;
using snaps::LoopPair;
using snaps::Trajectory;

// Poses (N, 3, 4) or (N, 4, 4), camera-to-world, as isometries: each passes the check of
// trajectory files (CheckedPose: a rotation within kRotationTolerance, a finite translation).
std::vector<Eigen::Isometry3d> IsometriesOf(const py::handle& object, const char* what) {
  const auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(object);
  if (!a || a.ndim() != 3 || (a.shape(1) != 3 && a.shape(1) != 4) || a.shape(2) != 4) {
    throw py::value_error(std::string(what) +
                          ": expected poses of shape (N, 3, 4) or (N, 4, 4): camera-to-world "
                          "matrices [R | t]");
  }
  std::vector<Eigen::Isometry3d> poses;
  const py::ssize_t n = a.shape(0), stride = a.shape(1) * 4;
  for (py::ssize_t i = 0; i < n; ++i) {
    const double* p = a.data() + i * stride;
    Eigen::Matrix3d r;
    Eigen::Vector3d t;
    for (int row = 0; row < 3; ++row) {
      for (int col = 0; col < 3; ++col) r(row, col) = p[row * 4 + col];
      t(row) = p[row * 4 + 3];
    }
    poses.push_back(CheckedPose(r, t, std::string(what) + "[" + std::to_string(i) + "]"));
  }
  return poses;
}

// The keywords' defaults that are Snaps_* keys (or Initial_image), from the option table.
struct KeyDefaults {
  std::string format = TableDefault("Snaps_trajectory_format");
  bool world_to_camera = TableDefault("Snaps_world_to_camera") == "1";
  double time_tolerance = std::stod(TableDefault("Snaps_time_tolerance"));
  int keyframe_tolerance = std::stoi(TableDefault("Snaps_keyframe_tolerance"));
  bool drop_outside = TableDefault("Snaps_drop_outside") == "1";
  bool middle_of_runs = TableDefault("Snaps_middle_of_runs") == "1";
  double matrix_threshold = std::stod(TableDefault("Snaps_matrix_threshold"));
  int frame_distance = std::stoi(TableDefault("Snaps_frame_distance"));
  int initial = std::stoi(TableDefault("Initial_image"));
  int discount_length = std::stoi(TableDefault("Snaps_discount_length"));
  int pause = std::stoi(TableDefault("Snaps_pause"));
  double odometry_translation_weight = std::stod(TableDefault("Snaps_odometry_translation_weight"));
  double odometry_rotation_weight = std::stod(TableDefault("Snaps_odometry_rotation_weight"));
  double loop_weight = std::stod(TableDefault("Snaps_loop_weight"));
  std::string robust_kernel = TableDefault("Snaps_robust_kernel");
  double robust_scale = std::stod(TableDefault("Snaps_robust_scale"));

  // `text` with each "@name@" replaced by the default of that keyword (Python's spelling).
  std::string Fill(std::string text) const {
    const auto flag = [](bool b) { return std::string(b ? "True" : "False"); };
    const std::pair<const char*, std::string> values[] = {
        {"@format@", format},
        {"@world_to_camera@", flag(world_to_camera)},
        {"@time_tolerance@", FormatNumber(time_tolerance)},
        {"@keyframe_tolerance@", std::to_string(keyframe_tolerance)},
        {"@drop_outside@", flag(drop_outside)},
        {"@middle_of_runs@", flag(middle_of_runs)},
        {"@matrix_threshold@", FormatNumber(matrix_threshold)},
        {"@frame_distance@", std::to_string(frame_distance)},
        {"@initial@", std::to_string(initial)},
        {"@discount_length@", std::to_string(discount_length)},
        {"@pause@", std::to_string(pause)},
        {"@odometry_translation_weight@", FormatNumber(odometry_translation_weight)},
        {"@odometry_rotation_weight@", FormatNumber(odometry_rotation_weight)},
        {"@loop_weight@", FormatNumber(loop_weight)},
        {"@robust_kernel@", robust_kernel},
        {"@robust_scale@", FormatNumber(robust_scale)}};
    return FillPlaceholders(std::move(text), values);
  }
};

const KeyDefaults& Defaults() {
  static const KeyDefaults defaults;
  return defaults;
}

// The hint at the conventions (snaps::ConventionHint) in the words of this module.
constexpr snaps::ConventionWords kPythonConventionWords = {
    "the estimate", "world_to_camera", "True",
    "the format of each file (read_trajectory's format)"};

py::array_t<double> PosesArray(const Trajectory& t, int rows) {
  py::array_t<double> a(
      {static_cast<py::ssize_t>(t.Size()), static_cast<py::ssize_t>(rows), py::ssize_t{4}});
  double* out = a.mutable_data();
  for (const Eigen::Isometry3d& pose : t.poses) {
    const Eigen::Matrix4d& m = pose.matrix();
    for (int r = 0; r < rows; ++r)
      for (int c = 0; c < 4; ++c) *out++ = m(r, c);
  }
  return a;
}

snaps::TrajectoryFormat FormatOf(const std::string& name) {
  return snaps::ParseTrajectoryFormat(name, "format");
}

Trajectory MakeTrajectory(const py::object& poses, const py::object& frame_ids,
                          const py::object& timestamps, const std::string& format,
                          bool world_to_camera) {
  Trajectory t;
  t.format = FormatOf(format);
  t.poses = IsometriesOf(poses, "poses");
  t.world_to_camera = world_to_camera;
  const std::size_t n = t.poses.size();
  if (frame_ids.is_none()) {
    for (std::size_t i = 0; i < n; ++i) t.frame_ids.push_back(static_cast<long>(i));
  } else {
    t.frame_ids = frame_ids.cast<std::vector<long>>();
  }
  if (!timestamps.is_none()) t.timestamps = timestamps.cast<std::vector<double>>();
  // The checks a trajectory file passes (ids and timestamps one per pose, increasing), so that
  // what save() writes reads back.
  snaps::CheckTrajectory(t, "Trajectory");
  return t;
}

std::vector<LoopPair> LoopsOf(const py::handle& loops, const Trajectory* t) {
  std::vector<LoopPair> out;
  if (loops.is_none()) return out;
  const py::sequence items = py::reinterpret_borrow<py::sequence>(
      py::isinstance<py::array>(loops) ? loops.attr("tolist")() : loops);
  for (std::size_t i = 0; i < items.size(); ++i) {
    const py::sequence item = items[i].cast<py::sequence>();
    if (item.size() != 2 && item.size() != 3)
      throw py::value_error("loops[" + std::to_string(i) +
                            "]: expected (query, reference) or (query, reference, similarity)");
    LoopPair p;
    p.query = item[0].cast<int>();
    p.reference = item[1].cast<int>();
    p.similarity = item.size() == 3 ? item[2].cast<double>() : 1.0;
    if (t && (p.query < 0 || p.query >= t->Size() || p.reference < 0 || p.reference >= p.query))
      throw py::value_error("loops[" + std::to_string(i) + "]: (" + std::to_string(p.query) + ", " +
                            std::to_string(p.reference) +
                            ") are not pose indices with 0 <= reference < query < " +
                            std::to_string(t->Size()));
    out.push_back(p);
  }
  return out;
}

py::list LoopsList(const std::vector<LoopPair>& loops) {
  py::list out;
  for (const LoopPair& p : loops) out.append(py::make_tuple(p.query, p.reference, p.similarity));
  return out;
}

py::array_t<double> Matrix4(const Eigen::Isometry3d& pose) {
  py::array_t<double> a({py::ssize_t{4}, py::ssize_t{4}});
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) a.mutable_at(r, c) = pose.matrix()(r, c);
  return a;
}

// `value` as a Python object when `ran`, else None.
template <typename T>
py::object IfRan(bool ran, const T& value) {
  return ran ? py::cast(value) : py::none();
}

// One run of the chain with the configuration it ran (the report needs both).
struct ChainRun {
  Config config;
  ChainResult result;
  std::vector<std::string> written;
};

}  // namespace

namespace {

void RegisterTrajectory(py::module_& m) {
  const KeyDefaults& d = Defaults();

  py::class_<Trajectory>(
      m, "Trajectory",
      d.Fill(R"doc(Trajectory(poses, frame_ids=None, timestamps=None, format="@format@",
    world_to_camera=@world_to_camera@)

Camera-to-world poses of a camera over a run.

Args:
    poses (numpy.ndarray): (N, 3, 4) or (N, 4, 4) camera-to-world matrices [R | t]
        (R a rotation within 1e-3).
    frame_ids (list[int] | None): frame number of each pose, strictly increasing; None:
        0 .. N-1.
    timestamps (list[float] | None): seconds per pose (needed for format "tum").
    format (str): the file format it is saved in: "kitti" (12 numbers a line, pose i is
        frame i), "kitti-id" (a frame number then 12 numbers), "tum" (timestamp tx ty tz qx qy
        qz qw).
    world_to_camera (bool): save() writes the inverse matrices (as SO-DSO's files are).)doc")
          .c_str())
      .def(py::init(&MakeTrajectory), py::arg("poses"), py::arg("frame_ids") = py::none(),
           py::arg("timestamps") = py::none(), py::arg("format") = d.format,
           py::arg("world_to_camera") = d.world_to_camera,
           d.Fill("__init__(poses, frame_ids=None, timestamps=None, format=\"@format@\", "
                  "world_to_camera=@world_to_camera@)\n\nSee help(openable.snaps.Trajectory).")
               .c_str())
      .def_property_readonly(
          "poses", [](const Trajectory& t) { return PosesArray(t, 4); },
          "float64 (N, 4, 4) camera-to-world matrices (a copy).")
      .def_property_readonly(
          "poses_3x4", [](const Trajectory& t) { return PosesArray(t, 3); },
          "float64 (N, 3, 4) camera-to-world matrices [R | t] (a copy), the KITTI layout.")
      .def_property_readonly(
          "positions",
          [](const Trajectory& t) {
            py::array_t<double> a({static_cast<py::ssize_t>(t.Size()), py::ssize_t{3}});
            for (int i = 0; i < t.Size(); ++i)
              for (int k = 0; k < 3; ++k) a.mutable_at(i, k) = t.poses[i].translation()(k);
            return a;
          },
          "float64 (N, 3) camera positions (the translations).")
      .def_property_readonly(
          "frame_ids",
          [](const Trajectory& t) {
            py::array_t<std::int64_t> a(static_cast<py::ssize_t>(t.frame_ids.size()));
            std::copy(t.frame_ids.begin(), t.frame_ids.end(), a.mutable_data());
            return a;
          },
          "int64 (N,) frame number of each pose.")
      .def_property_readonly(
          "timestamps", [](const Trajectory& t) { return DoubleArray(t.timestamps); },
          "float64 (N,) seconds (empty unless the format is tum).")
      .def_property_readonly(
          "format", [](const Trajectory& t) { return snaps::TrajectoryFormatName(t.format); },
          "\"kitti\", \"kitti-id\" or \"tum\".")
      .def_property_readonly(
          "world_to_camera", [](const Trajectory& t) { return t.world_to_camera; },
          "The file stores world-to-camera matrices (inverted on reading and writing).")
      .def("encode", &snaps::EncodeTrajectory,
           "encode() -> str\n\nThe trajectory as the text of its file (its format and "
           "convention, 17 significant digits: read_trajectory gives it back).")
      .def(
          "save",
          [](const Trajectory& t, const std::string& path) {
            const std::string text = snaps::EncodeTrajectory(t);
            OutputBatch batch;
            batch.Stage("path", path, text);
            batch.Commit();
          },
          py::arg("path"),
          "save(path)\n\nWrites encode() to `path` (through a temporary file renamed when "
          "complete; folders created). Raises openable.InputError when it cannot be written.")
      .def("__len__", &Trajectory::Size, "Number of poses.")
      .def("__repr__", [](const Trajectory& t) {
        std::string s = "<openable.snaps.Trajectory " + std::to_string(t.Size()) + " poses, " +
                        snaps::TrajectoryFormatName(t.format);
        if (!t.frame_ids.empty())
          s += ", frames " + std::to_string(t.frame_ids.front()) + "-" +
               std::to_string(t.frame_ids.back());
        return s + ">";
      });

  m.def(
      "read_trajectory",
      [](const std::string& path, const std::string& format, bool world_to_camera) {
        const snaps::TrajectoryFormat f = FormatOf(format);
        py::gil_scoped_release release;
        return snaps::ReadTrajectory(path, f, world_to_camera);
      },
      py::arg("path"), py::arg("format") = d.format, py::arg("world_to_camera") = d.world_to_camera,
      d.Fill(R"doc(read_trajectory(path, format="@format@", world_to_camera=@world_to_camera@)
    -> Trajectory

Reads a trajectory file.

Args:
    path (str): the file.
    format (str): "kitti" (12 numbers a line: row-major [R | t], pose i = frame i),
        "kitti-id" (a frame number, then the 12 numbers; e.g. SO-DSO keyframes) or "tum"
        ("timestamp tx ty tz qx qy qz qw", '#' comments).
    world_to_camera (bool): the file's matrices map world points into the camera (SO-DSO's
        poses_history_file.txt); they are inverted so that poses are camera-to-world.

Raises:
    openable.InputError: one line naming the file and line (wrong count of numbers, not a
    number, a matrix that is not a rotation, frame ids not increasing, empty file; a line of
    the other KITTI format names it: kitti-id for a frame number then 12 numbers).)doc")
          .c_str());

  m.def(
      "associate",
      [](const Trajectory& estimate, const Trajectory& truth, double time_tolerance) {
        const std::vector<int> a =
            snaps::AssociateWithTruth(estimate, truth, time_tolerance, "truth");
        py::array_t<std::int32_t> out(static_cast<py::ssize_t>(a.size()));
        std::copy(a.begin(), a.end(), out.mutable_data());
        return out;
      },
      py::arg("estimate"), py::arg("truth"), py::arg("time_tolerance") = d.time_tolerance,
      d.Fill(R"doc(associate(estimate, truth, time_tolerance=@time_tolerance@) -> numpy.ndarray

For each pose of `estimate`, the index of its pose in `truth`: by frame id (kitti and
kitti-id), or by nearest timestamp within time_tolerance seconds (both tum).

Returns:
    numpy.ndarray: int32 (N,).

Raises:
    openable.InputError: a pose without counterpart (naming the first such frame).)doc")
          .c_str());
}

void RegisterTrajectoryErrors(py::module_& m) {
  const KeyDefaults& d = Defaults();

  py::class_<snaps::TrajectoryError>(m, "TrajectoryError",
                                     "Absolute trajectory error of the positions (metres).")
      .def_readonly("rmse", &snaps::TrajectoryError::rmse, "Root of the mean squared distance.")
      .def_readonly("mean", &snaps::TrajectoryError::mean,
                    "Mean distance: the paper's \"mean deviation from the ground truth\".")
      .def_readonly("median", &snaps::TrajectoryError::median, "Median distance.")
      .def_readonly("max", &snaps::TrajectoryError::max, "Largest distance.")
      .def_readonly("aligned", &snaps::TrajectoryError::aligned,
                    "A rigid alignment (rotation + translation, Umeyama) was applied first.")
      .def_property_readonly(
          "alignment", [](const snaps::TrajectoryError& e) { return Matrix4(e.alignment); },
          "float64 (4, 4): the rigid motion applied to the estimate (identity when not aligned).")
      .def("__repr__", [](const snaps::TrajectoryError& e) {
        char b[200];
        std::snprintf(b, sizeof b,
                      "<openable.snaps.TrajectoryError%s: RMSE %.4f m, mean %.4f m, median %.4f m, "
                      "max %.4f m>",
                      e.aligned ? " (aligned)" : "", e.rmse, e.mean, e.median, e.max);
        return std::string(b);
      });

  m.def(
      "trajectory_error",
      [](const Trajectory& estimate, const Trajectory& truth, const py::object& association,
         bool align, double time_tolerance) {
        std::vector<int> a;
        if (association.is_none()) {
          a = snaps::AssociateWithTruth(estimate, truth, time_tolerance, "truth");
        } else {
          a = association.cast<std::vector<int>>();
          if (a.size() != estimate.poses.size())
            throw py::value_error("association: " + std::to_string(a.size()) +
                                  " indices; expected one per pose of the estimate");
          for (const int i : a)
            if (i < 0 || i >= truth.Size())
              throw py::value_error("association: index " + std::to_string(i) +
                                    " is not a pose of the truth");
        }
        snaps::TrajectoryError error, aligned;
        {
          py::gil_scoped_release release;
          error = snaps::AbsoluteTrajectoryError(estimate, truth, a, align);
          aligned = align ? error : snaps::AbsoluteTrajectoryError(estimate, truth, a, true);
        }
        if (const std::string hint = snaps::ConventionHint(aligned, truth, kPythonConventionWords);
            !hint.empty())
          Warn(hint);
        return error;
      },
      py::arg("estimate"), py::arg("truth"), py::arg("association") = py::none(),
      py::arg("align") = false, py::arg("time_tolerance") = d.time_tolerance,
      d.Fill(R"doc(trajectory_error(estimate, truth, association=None, align=False,
    time_tolerance=@time_tolerance@) -> TrajectoryError

Absolute trajectory error of the estimate's positions against their ground-truth
counterparts, as openable_snaps reports it.

Args:
    estimate (Trajectory): the trajectory evaluated.
    truth (Trajectory): the ground truth.
    association (array-like | None): index in `truth` of each estimate pose; None:
        associate(estimate, truth, time_tolerance).
    align (bool): first apply the rigid motion (no scale) that best maps the estimate onto
        the truth (Umeyama); False measures the trajectory as it is.

Returns:
    TrajectoryError: rmse, mean, median, max (metres), aligned, alignment.

Warns:
    UserWarning: when the estimate is farther from the truth after alignment than a quarter of
    the route's extent: a convention (world_to_camera, the format) rather than drift, as
    openable_snaps hints (docs/snaps.md, "Conventions").)doc")
          .c_str());

  m.def(
      "loops_from_csv",
      [](const std::string& path, const Trajectory& t, long tolerance, bool drop_outside,
         bool middle_of_runs, bool counts) -> py::object {
        int dropped = 0, outside = 0;
        std::vector<LoopPair> loops;
        {
          py::gil_scoped_release release;
          loops =
              snaps::LoopsFromCsv(path, t, tolerance, &dropped, drop_outside ? &outside : nullptr);
          if (middle_of_runs) loops = snaps::MiddleOfRuns(loops, t);
        }
        if (!counts) return LoopsList(loops);
        py::dict c;
        c["dropped"] = dropped;
        c["outside"] = outside;
        return py::make_tuple(LoopsList(loops), c);
      },
      py::arg("path"), py::arg("trajectory"), py::arg("tolerance") = d.keyframe_tolerance,
      py::arg("drop_outside") = d.drop_outside, py::arg("middle_of_runs") = d.middle_of_runs,
      py::arg("counts") = false,
      d.Fill(R"doc(loops_from_csv(path, trajectory, tolerance=@keyframe_tolerance@,
    drop_outside=@drop_outside@, middle_of_runs=@middle_of_runs@, counts=False) -> list

Loop pairs from a CSV of frame pairs ("row,col" a line, row the later frame; '#' comments),
as openable_snaps reads Snaps_loops_file with Snaps_loops = pairs, with its defaults (the
option table's): by default the middle reference of each run is kept, as the program does.

Args:
    path (str): the pairs file.
    trajectory (Trajectory): frames are mapped to its poses by frame id.
    tolerance (int): a frame that is not a pose maps to the nearest pose within this many
        frames (Snaps_keyframe_tolerance); 0 drops such pairs.
    drop_outside (bool): drop pairs with a frame outside the trajectory's frames instead of
        raising (Snaps_drop_outside).
    middle_of_runs (bool): keep only the middle reference of each run of consecutive
        references of a query (Snaps_middle_of_runs; ground-truth lists pair a query with
        every frame within some radius).
    counts (bool): also return {"dropped": pairs whose frame is not a pose, "outside":
        pairs outside the trajectory}.

Returns:
    list[tuple[int, int, float]]: (query, reference, similarity 1.0) pose indices
    (or (list, dict) with counts=True).)doc")
          .c_str());

  m.def(
      "middle_of_runs",
      [](const py::object& loops, const Trajectory& t, long run_gap) {
        std::vector<LoopPair> l = LoopsOf(loops, &t);
        {
          py::gil_scoped_release release;
          l = snaps::MiddleOfRuns(l, t, run_gap);
        }
        return LoopsList(l);
      },
      py::arg("loops"), py::arg("trajectory"), py::arg("run_gap") = 10,
      R"doc(middle_of_runs(loops, trajectory, run_gap=10) -> list

The references of each query split into runs (frame ids less than run_gap apart); only the
middle reference of each run is kept (the earlier of two middles). Sorted by query, then
reference.)doc");
}

void RegisterLoopsAndCorrections(py::module_& m) {
  const KeyDefaults& d = Defaults();

  m.def(
      "loops_from_matrix",
      [](const py::object& matrix, const Trajectory& t, double threshold, int exclusion,
         long initial, long tolerance) {
        snaps::MatrixLoopOptions o;
        o.threshold = threshold;
        o.exclusion = exclusion;
        o.initial = initial;
        o.tolerance = tolerance;
        std::vector<LoopPair> loops;
        if (py::isinstance<py::str>(matrix)) {
          const std::string path = matrix.cast<std::string>();
          py::gil_scoped_release release;
          loops = snaps::LoopsFromMatrix(path, t, o);
        } else {
          const MatView v = Matrix2D(matrix, Elements::kFloat32, "matrix");
          if (v.mat.rows != v.mat.cols)
            throw py::value_error("matrix: " + std::to_string(v.mat.rows) + "x" +
                                  std::to_string(v.mat.cols) +
                                  "; expected a square matrix of one sequence");
          py::gil_scoped_release release;
          loops = snaps::LoopsFromMatrix(cv::Mat1f(v.mat), t, o);
        }
        return LoopsList(loops);
      },
      py::arg("matrix"), py::arg("trajectory"), py::arg("threshold") = d.matrix_threshold,
      py::arg("exclusion") = d.frame_distance, py::arg("initial") = d.initial,
      py::arg("tolerance") = d.keyframe_tolerance,
      d.Fill(R"doc(loops_from_matrix(matrix, trajectory, threshold=@matrix_threshold@,
    exclusion=@frame_distance@, initial=@initial@, tolerance=@keyframe_tolerance@) -> list

Loops from an OpenABLE matrix of one sequence (Snaps_loops = matrix): for each row q its best
earlier match j (smallest M'(q, j) with j <= q - exclusion) with M'(q, j) < threshold gives
(pose of q, pose of j, 1 - M'(q, j)); row i is frame initial + i, mapped to a pose by frame id
(nearest within `tolerance` frames). A matrix whose maximum exceeds 1 is first divided by it.

Args:
    matrix (numpy.ndarray | str): the square normalised matrix, or a file (.npy, .txt, image).
    trajectory (Trajectory): the poses.
    threshold (float): Snaps_matrix_threshold.
    exclusion (int): Snaps_frame_distance.
    initial (int): frame id of row 0 (Initial_image).
    tolerance (int): Snaps_keyframe_tolerance.)doc")
          .c_str());

  m.def(
      "closed_loops",
      [](const py::object& loops, int pause) {
        return LoopsList(snaps::ClosedLoops(LoopsOf(loops, nullptr), pause));
      },
      py::arg("loops"), py::arg("pause") = d.pause,
      d.Fill(R"doc(closed_loops(loops, pause=@pause@) -> list

The loops correct_discounted() closes, in order: taken by query, a loop is skipped when its
query is not more than `pause` poses after the last closed loop's query (Snaps_pause).)doc")
          .c_str());

  m.def("discount_gamma", &snaps::DiscountGamma, py::arg("s_prime"), py::arg("alpha"),
        R"doc(discount_gamma(s_prime, alpha) -> float

gamma of Eq. 6: 1 - 1 / exp(3 - alpha * 0.01 * s_prime), clamped at 0; s_prime = N - s >= 0
frames before the loop's frame N, alpha >= 1 the number of loops closed so far.)doc");

  m.def(
      "apply_discounted_update",
      [](const Trajectory& t, int n, int reference, double similarity, int alpha,
         int discount_length) {
        if (n < 0 || n >= t.Size() || reference < 0 || reference >= n)
          throw py::value_error("n, reference: expected 0 <= reference < n < " +
                                std::to_string(t.Size()));
        Trajectory out = t;
        const Eigen::Vector3d shift =
            snaps::ApplyDiscountedUpdate(out, n, reference, similarity, alpha, discount_length);
        return py::make_tuple(out, DoubleArray({shift.x(), shift.y(), shift.z()}));
      },
      py::arg("trajectory"), py::arg("n"), py::arg("reference"), py::arg("similarity") = 1.0,
      py::arg("alpha") = 1, py::arg("discount_length") = d.discount_length,
      d.Fill(R"doc(apply_discounted_update(trajectory, n, reference, similarity=1.0, alpha=1,
    discount_length=@discount_length@) -> tuple[Trajectory, numpy.ndarray]

One loop of Eq. 6: pose n closes a loop with pose `reference`; positions of poses
max(0, n-K)..n move by similarity * gamma(n - s) * (p_reference - p_n), later poses with pose
n; rotations are kept. Returns the corrected copy and the shift of pose n.)doc")
          .c_str());

  m.def(
      "correct_discounted",
      [](const Trajectory& t, const py::object& loops, int discount_length, int pause) {
        const std::vector<LoopPair> l = LoopsOf(loops, &t);
        snaps::DiscountOptions o;
        o.discount_length = discount_length;
        o.pause = pause;
        if (discount_length < 0 || pause < 0)
          throw py::value_error("discount_length, pause: expected >= 0");
        py::gil_scoped_release release;
        return snaps::CorrectDiscounted(t, l, o);
      },
      py::arg("trajectory"), py::arg("loops"), py::arg("discount_length") = d.discount_length,
      py::arg("pause") = d.pause,
      d.Fill(R"doc(correct_discounted(trajectory, loops, discount_length=@discount_length@,
    pause=@pause@) -> Trajectory

The paper's correction (Eq. 6) of a whole trajectory, offline, as openable_snaps does with
Snaps_corrector = discounted: loops taken in the order of their query, a loop skipped while its
query is not more than `pause` poses after the last closed one (Snaps_pause), each closed loop
applying apply_discounted_update with alpha = loops closed so far and K = discount_length
(Snaps_discount_length).

Args:
    trajectory (Trajectory): the drifting input.
    loops (list): (query, reference[, similarity]) pose indices.

Returns:
    Trajectory: the corrected copy (frame ids, format and convention kept).)doc")
          .c_str());

  py::class_<snaps::PoseGraphReport>(m, "PoseGraphReport", "What correct_pose_graph() did.")
      .def_readonly("iterations", &snaps::PoseGraphReport::iterations, "Steps tried.")
      .def_readonly("loop_edges", &snaps::PoseGraphReport::loop_edges, "Loop edges in the graph.")
      .def_readonly("initial_cost", &snaps::PoseGraphReport::initial_cost,
                    "Robustified cost of the input.")
      .def_readonly("final_cost", &snaps::PoseGraphReport::final_cost, "Cost of the output.")
      .def_readonly("seconds", &snaps::PoseGraphReport::seconds, "Wall time of the correction.")
      .def_readonly("converged", &snaps::PoseGraphReport::converged,
                    "Stopped by relative_tolerance (not max_iterations).")
      .def("__repr__", [](const snaps::PoseGraphReport& r) {
        char b[200];
        std::snprintf(
            b, sizeof b,
            "<openable.snaps.PoseGraphReport %d loop edges, %d iterations, cost %.6g -> %.6g%s>",
            r.loop_edges, r.iterations, r.initial_cost, r.final_cost,
            r.converged ? "" : " (not converged)");
        return std::string(b);
      });
}

void RegisterPoseGraph(py::module_& m) {
  const KeyDefaults& d = Defaults();
  const snaps::PoseGraphOptions kGraph;  // the solver's settings that are no key

  m.def(
      "correct_pose_graph",
      [](const Trajectory& t, const py::object& loops, double odometry_translation_weight,
         double odometry_rotation_weight, double loop_weight, bool use_similarity,
         const std::string& robust_kernel, double robust_scale, double relative_tolerance,
         int max_iterations, double initial_lambda, bool report) -> py::object {
        const std::vector<LoopPair> l = LoopsOf(loops, &t);
        snaps::PoseGraphOptions o;
        o.odometry_translation_weight = odometry_translation_weight;
        o.odometry_rotation_weight = odometry_rotation_weight;
        o.loop_weight = loop_weight;
        o.use_similarity = use_similarity;
        o.robust_kernel = snaps::ParseRobustKernel(robust_kernel, "robust_kernel");
        o.robust_scale = robust_scale;
        o.relative_tolerance = relative_tolerance;
        o.max_iterations = max_iterations;
        o.initial_lambda = initial_lambda;
        o.Check();
        snaps::PoseGraphReport r;
        Trajectory out;
        {
          py::gil_scoped_release release;
          out = snaps::CorrectPoseGraph(t, l, o, &r);
        }
        if (report) return py::make_tuple(out, r);
        return py::cast(out);
      },
      py::arg("trajectory"), py::arg("loops"),
      py::arg("odometry_translation_weight") = d.odometry_translation_weight,
      py::arg("odometry_rotation_weight") = d.odometry_rotation_weight,
      py::arg("loop_weight") = d.loop_weight, py::arg("use_similarity") = kGraph.use_similarity,
      py::arg("robust_kernel") = d.robust_kernel, py::arg("robust_scale") = d.robust_scale,
      py::arg("relative_tolerance") = kGraph.relative_tolerance,
      py::arg("max_iterations") = kGraph.max_iterations,
      py::arg("initial_lambda") = kGraph.initial_lambda, py::arg("report") = false,
      d.Fill(R"doc(correct_pose_graph(trajectory, loops,
    odometry_translation_weight=@odometry_translation_weight@,
    odometry_rotation_weight=@odometry_rotation_weight@, loop_weight=@loop_weight@,
    use_similarity=False, robust_kernel="@robust_kernel@", robust_scale=@robust_scale@,
    relative_tolerance=1e-9, max_iterations=100, initial_lambda=1e-6, report=False)
    -> Trajectory

Least-squares pose-graph correction (docs/snaps.md): odometry edges between consecutive poses
(relative pose of the input; information diag(w_t I, w_R I)), loop edges pulling the two
positions of each loop together (information loop_weight, times the similarity when
use_similarity; robust kernel "none", "huber" or "cauchy" of scale robust_scale), pose 0
fixed; iteratively reweighted Levenberg-Marquardt on SE(3), sparse LDLT. The same solver and
defaults as openable_snaps (Snaps_corrector pose-graph).

Args:
    trajectory (Trajectory): the drifting input.
    loops (list): (query, reference[, similarity]) pose indices.
    odometry_translation_weight (float): 1/m^2 (Snaps_odometry_translation_weight).
    odometry_rotation_weight (float): 1/rad^2 (Snaps_odometry_rotation_weight).
    loop_weight (float): 1/m^2 (Snaps_loop_weight).
    use_similarity (bool): multiply each loop's weight by its similarity.
    robust_kernel (str), robust_scale (float): Snaps_robust_kernel, Snaps_robust_scale.
    relative_tolerance (float), max_iterations (int), initial_lambda (float): the solver's
        stopping rule and initial damping.
    report (bool): also return a PoseGraphReport.

Returns:
    Trajectory (or (Trajectory, PoseGraphReport) with report=True).)doc")
          .c_str());

  py::class_<ChainRun>(m, "ChainResult", R"doc(What run() did: the trajectories, the loops, the
corrections and their errors, as openable_snaps reports them.)doc")
      .def_property_readonly(
          "input", [](const ChainRun& c) { return c.result.input; },
          "Trajectory: the one corrected (read, or computed by the odometry).")
      .def_property_readonly(
          "discounted",
          [](const ChainRun& c) { return IfRan(c.result.discounted_ran, c.result.discounted); },
          "Trajectory corrected by the discounted update (Eq. 6); None when it did not run.")
      .def_property_readonly(
          "pose_graph", [](const ChainRun& c) { return IfRan(c.result.graph_ran, c.result.graph); },
          "Trajectory corrected by the pose graph; None when it did not run.")
      .def_property_readonly(
          "pose_graph_report",
          [](const ChainRun& c) { return IfRan(c.result.graph_ran, c.result.graph_report); },
          "PoseGraphReport of the pose graph; None when it did not run.")
      .def_property_readonly(
          "truth", [](const ChainRun& c) { return IfRan(c.result.evaluated, c.result.truth); },
          "Trajectory of Snaps_ground_truth; None without one.")
      .def_property_readonly(
          "loops", [](const ChainRun& c) { return LoopsList(c.result.loops); },
          "Loop pairs (query, reference, similarity) of `input`'s poses.")
      .def_property_readonly(
          "closed", [](const ChainRun& c) { return LoopsList(c.result.closed); },
          "The loops the discounted update closed.")
      .def_property_readonly(
          "errors",
          [](const ChainRun& c) {
            py::dict out;
            for (const ChainErrors& e : c.result.errors)
              out[e.name.c_str()] = py::make_tuple(e.raw, e.aligned);
            return out;
          },
          "With a ground truth: {\"input\" | \"discounted\" | \"pose_graph\": (unaligned, "
          "aligned)} TrajectoryError pairs; empty without one.")
      .def_property_readonly(
          "written", [](const ChainRun& c) { return c.written; },
          "Paths of the files written (write=True).")
      .def(
          "report", [](const ChainRun& c) { return snaps::FormatChainReport(c.config, c.result); },
          "report() -> str\n\nThe report openable_snaps prints.")
      .def(
          "to_json", [](const ChainRun& c) { return snaps::EncodeChainJson(c.config, c.result); },
          "to_json() -> str\n\nThe figures, as <Snaps_output_name>.json.")
      .def("__repr__", [](const ChainRun& c) {
        return "<openable.snaps.ChainResult " + std::to_string(c.result.input.Size()) + " poses, " +
               std::to_string(c.result.loops.size()) + " loops>";
      });
}

void RegisterChain(py::module_& m) {
  m.def(
      "run",
      [](const py::object& config, const py::object& settings, bool write, bool quiet) {
        auto c = std::make_unique<ChainRun>();
        if (!config.is_none()) c->config = LoadConfig(py::str(config).cast<std::string>());
        if (!settings.is_none())
          for (const auto item : settings.cast<py::dict>()) {
            const py::handle v = item.second;
            const std::string text = py::isinstance<py::bool_>(v) ? (v.cast<bool>() ? "1" : "0")
                                                                  : py::str(v).cast<std::string>();
            ApplyOverride(c->config, item.first.cast<std::string>() + "=" + text);
          }
        py::gil_scoped_release release;
        ProgressReporter progress(std::cerr, !quiet, IsTerminal(2));
        c->result = snaps::RunChain(c->config, progress);
        if (write) c->written = snaps::WriteChainOutputs(c->config, c->result);
        py::gil_scoped_acquire acquire;
        if (!c->result.errors.empty())
          if (const std::string hint =
                  snaps::ConventionHint(c->result.errors.front().aligned, c->result.truth);
              !hint.empty())
            Warn(hint);
        return c;
      },
      py::arg("config") = py::none(), py::kw_only(), py::arg("settings") = py::none(),
      py::arg("write") = false, py::arg("quiet") = true,
      R"doc(run(config=None, *, settings=None, write=False, quiet=True) -> ChainResult

The whole SNAPS chain, as openable_snaps runs it (the same library call): the trajectory (a
file, or the odometry on the images), the loops (Snaps_loops), the corrections
(Snaps_corrector) and, with Snaps_ground_truth, their errors.

Args:
    config (str | os.PathLike | None): a Config.txt; None: the defaults.
    settings (dict | None): keys set over it, {"Snaps_loops": "pairs", ...}, as --set does
        (values as text; True and False as 1 and 0).
    write (bool): also write the files of Snaps_output_name (all or nothing).
    quiet (bool): no progress lines on stderr.

Returns:
    ChainResult: input, discounted, pose_graph, truth, loops, closed, errors, written,
    report(), to_json().

Raises:
    openable.InputError: one line naming the key, file or value (as openable_snaps).)doc");
}

}  // namespace

void RegisterSnaps(py::module_& parent) {
  py::module_ m = parent.def_submodule("snaps", R"doc(The SNAPS add-on (docs/snaps.md).

Trajectories (camera-to-world poses per frame), their files (KITTI, KITTI with frame ids,
TUM), loop pairs (from a pairs file or an OpenABLE matrix), the paper's discounted update
(Eq. 6), a least-squares pose graph, and the absolute trajectory error against a ground truth.
Loops are lists of (query, reference, similarity) tuples of pose indices (query > reference).)doc");
  RegisterTrajectory(m);
  RegisterTrajectoryErrors(m);
  RegisterLoopsAndCorrections(m);
  RegisterPoseGraph(m);
  RegisterChain(m);
}

}  // namespace openable::python
