// Distance matrices: hamming_distances, l2_distances, sequence_distances, normalize_by_max,
// threshold_matrix, read_matrix.
#include <pybind11/stl.h>

#include "OpenABLE/evaluation/matrix_file.h"
#include "OpenABLE/python/common.h"
#include "matching/distances.h"
#include "matching/normalize.h"
#include "matching/sequence.h"

namespace openable::python {
namespace {

std::vector<int> Starts(const py::object& starts, const char* what) {
  if (starts.is_none()) return {};
  try {
    return starts.cast<std::vector<int>>();
  } catch (const py::cast_error&) {
    throw py::value_error(std::string(what) +
                          ": expected a list of frame indices (first frame of each traversal)");
  }
}

void CheckWidths(const cv::Mat& a, const cv::Mat& b) {
  if (!b.empty() && b.cols != a.cols) {
    throw py::value_error("b: rows of " + std::to_string(b.cols) + " elements; expected " +
                          std::to_string(a.cols) + " like the rows of a");
  }
}

// A float32 view of `d` that may be written in place (the caller's own memory).
cv::Mat1f WritableFloatView(const py::object& d, MatView& view) {
  view = Matrix2D(d, Elements::kFloat32, "d");
  if (view.copied || !view.owner.writeable()) {
    throw py::value_error(
        "d: in_place=True needs a writable float32 NumPy array whose rows are contiguous (this "
        "one would be converted or copied); pass in_place=False");
  }
  return cv::Mat1f(view.mat);
}

}  // namespace

void RegisterMatching(py::module_& m) {
  m.def(
      "hamming_distances",
      [](const py::object& a, const py::object& b, int threads) {
        const MatView va = Matrix2D(a, Elements::kUint8, "a");
        MatView vb;
        if (!b.is_none()) vb = Matrix2D(b, Elements::kUint8, "b");
        CheckWidths(va.mat, vb.mat);
        cv::Mat1f out;
        {
          py::gil_scoped_release release;
          out = HammingDistances(va.mat, vb.mat, threads);
        }
        return ToNumpy(out);
      },
      py::arg("a"), py::arg("b") = py::none(), py::arg("threads") = 0,
      R"doc(hamming_distances(a, b=None, threads=0) -> numpy.ndarray

Hamming distances (Eq. 4: the count of differing bits) between every row of `a` and every
row of `b`, with the fastest kernel the CPU has (AVX2, POPCNT or portable).

Args:
    a (numpy.ndarray): uint8, shape (N, W): N binary descriptor rows of W bytes (a 1-D array
        is one row). Read in place when its rows are contiguous.
    b (numpy.ndarray | None): uint8, shape (M, W); None compares `a` with itself (symmetric
        result, zero diagonal).
    threads (int): threads for blocks of rows; 0 = all cores.

Returns:
    numpy.ndarray: float32, shape (N, M), bit counts. The array owns the C++ result (no copy).

Raises:
    ValueError: not uint8, or rows of different widths.)doc");

  m.def(
      "l2_distances",
      [](const py::object& a, const py::object& b, int threads) {
        const MatView va = Matrix2D(a, Elements::kFloat32, "a");
        MatView vb;
        if (!b.is_none()) vb = Matrix2D(b, Elements::kFloat32, "b");
        CheckWidths(va.mat, vb.mat);
        cv::Mat1f out;
        {
          py::gil_scoped_release release;
          out = L2Distances(va.mat, vb.mat, threads);
        }
        return ToNumpy(out);
      },
      py::arg("a"), py::arg("b") = py::none(), py::arg("threads") = 0,
      R"doc(l2_distances(a, b=None, threads=0) -> numpy.ndarray

Euclidean distances (Eq. 8) between every row of `a` and every row of `b`: one matrix
product (Eigen), with the cells that lose precision to cancellation recomputed directly, so
every cell is within float rounding of the direct sum.

Args:
    a (numpy.ndarray): shape (N, W) vector descriptor rows; float32 is read in place, other
        numeric types are converted to float32.
    b (numpy.ndarray | None): shape (M, W); None compares `a` with itself.
    threads (int): threads; 0 = all cores.

Returns:
    numpy.ndarray: float32, shape (N, M) (no copy of the C++ result).)doc");

  m.def(
      "sequence_distances",
      [](const py::object& d, int sequence_length, const std::string& direction,
         const py::object& row_starts, const py::object& col_starts, int threads,
         bool in_place) -> py::object {
        const auto dir = ParseEnum<SequenceDirection>(direction, "direction");
        const std::vector<int> rows = Starts(row_starts, "row_starts");
        const std::vector<int> cols = Starts(col_starts, "col_starts");
        if (in_place) {
          MatView view;
          cv::Mat1f target = WritableFloatView(d, view);
          const uchar* before = target.data;
          {
            py::gil_scoped_release release;
            SequenceDistancesInPlace(target, sequence_length, rows, cols, dir, threads);
            if (target.data != before) target.copyTo(view.mat);  // never expected; kept safe
          }
          return view.owner;
        }
        const MatView view = Matrix2D(d, Elements::kFloat32, "d");
        cv::Mat1f out;
        {
          py::gil_scoped_release release;
          out = SequenceDistances(cv::Mat1f(view.mat), sequence_length, rows, cols, dir, threads);
        }
        return ToNumpy(out);
      },
      py::arg("d"), py::arg("sequence_length"), py::arg("direction") = "forward",
      py::arg("row_starts") = py::none(), py::arg("col_starts") = py::none(),
      py::arg("threads") = 0, py::arg("in_place") = false,
      R"doc(sequence_distances(d, sequence_length, direction="forward", row_starts=None,
    col_starts=None, threads=0, in_place=False) -> numpy.ndarray

Sequence matching (ABLE, after SeqSLAM): the distance of the places of frames i and j is the
sum of the L single-frame distances along the diagonal ending at (i, j):
forward S(i, j) = sum_k D(i-k, j-k), reverse S(i, j) = sum_k D(i-k, j+k) (the reference
route driven the other way), both = the smaller of the two; k = 0 .. L-1. Where fewer than L
terms exist (the first frames of a traversal) the available terms are scaled to L. Sums never
cross from one traversal into another. One pass whatever L.

Args:
    d (numpy.ndarray): shape (N, M) single-frame distances (float32 is read in place; other
        numeric types are converted).
    sequence_length (int): L >= 1 (1 returns D).
    direction (str): "forward", "reverse" or "both".
    row_starts (list[int] | None): first row of each traversal along the rows, increasing from
        0 (None: one traversal).
    col_starts (list[int] | None): the same along the columns.
    threads (int): threads; 0 = all cores.
    in_place (bool): overwrite `d` (a writable float32 array with contiguous rows) and return
        it, instead of returning a new matrix.

Returns:
    numpy.ndarray: float32, shape (N, M).

Raises:
    ValueError: L < 1, starts not increasing from 0, a bad direction.)doc");

  m.def(
      "normalize_by_max",
      [](const py::object& matrix) {
        const MatView view = Matrix2D(matrix, Elements::kFloat32, "matrix");
        cv::Mat1f out;
        float max = 0;
        {
          py::gil_scoped_release release;
          view.mat.copyTo(out);
          max = NormalizeByMax(out);
        }
        return py::make_tuple(ToNumpy(out), max);
      },
      py::arg("matrix"),
      R"doc(normalize_by_max(matrix) -> tuple[numpy.ndarray, float]

Eq. 5: M' = M / max(M), as Test_OpenABLE normalises its matrix (a matrix whose maximum is 0
stays 0).

Args:
    matrix (numpy.ndarray): non-negative finite distances, shape (N, M).

Returns:
    (numpy.ndarray, float): M' (float32, a new array) and max(M).

Raises:
    ValueError: a negative or non-finite entry.)doc");

  m.def(
      "threshold_matrix",
      [](const py::object& normalized, float theta) {
        const MatView view = Matrix2D(normalized, Elements::kFloat32, "normalized");
        cv::Mat1b out;
        {
          py::gil_scoped_release release;
          out = ThresholdMatrix(cv::Mat1f(view.mat), theta);
        }
        return ToNumpy(out);
      },
      py::arg("normalized"), py::arg("theta"),
      R"doc(threshold_matrix(normalized, theta) -> numpy.ndarray

Eq. 9: M'' = 0 where M' < theta (a loop candidate), 1 elsewhere.

Args:
    normalized (numpy.ndarray): M', shape (N, M).
    theta (float): the threshold, in [0, 1].

Returns:
    numpy.ndarray: uint8 0/1, shape (N, M).)doc");

  m.def(
      "read_matrix",
      [](const std::string& path) {
        cv::Mat1f out;
        {
          py::gil_scoped_release release;
          out = ReadMatrixFile(path);
        }
        return ToNumpy(out);
      },
      py::arg("path"),
      R"doc(read_matrix(path) -> numpy.ndarray

Reads a matrix saved by OpenABLE or given as ground truth, as openable_evaluate reads it:
.npy (any numeric dtype, C or Fortran order), text (.txt/.csv/.dat: numbers separated by
spaces or commas, one row per line, '#' comments) or an image (grey level).

Args:
    path (str): the file.

Returns:
    numpy.ndarray: float32, 2-D.

Raises:
    openable.InputError: one line naming the file (and line) on any problem.)doc");
}

}  // namespace openable::python
