// Distance matrices: hamming_distances, l2_distances, l1_distances, sequence_distances,
// contrast_enhancement, normalize_by_max, threshold_matrix, best_matches, read_matrix.
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <cmath>
#include <limits>

#include "OpenABLE/evaluation/matrix_file.h"
#include "OpenABLE/python/common.h"
#include "matching/blas.h"
#include "matching/contrast.h"
#include "matching/distances.h"
#include "matching/normalize.h"
#include "matching/score.h"
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

// hamming_distances, l2_distances and l1_distances: every row of `a` against every row of `b`
// (None: `a` itself) with `distances`, the GIL released.
py::array PairDistances(const py::object& a, const py::object& b, int threads, Elements elements,
                        cv::Mat1f (*distances)(const cv::Mat&, const cv::Mat&, int,
                                               const PairProgress&)) {
  const MatView va = Matrix2D(a, elements, "a");
  MatView vb;
  if (!b.is_none()) vb = Matrix2D(b, elements, "b");
  CheckWidths(va.mat, vb.mat);
  cv::Mat1f out;
  {
    py::gil_scoped_release release;
    out = distances(va.mat, vb.mat, threads, PairProgress());
  }
  return ToNumpy(out);
}

}  // namespace

namespace {

void RegisterDistances(py::module_& m) {
  m.def(
      "hamming_distances",
      [](const py::object& a, const py::object& b, int threads) {
        return PairDistances(a, b, threads, Elements::kUint8, HammingDistances);
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

  m.def("blas_description", &BlasDescription,
        R"doc(blas_description() -> str

The OpenBLAS the float matrices run on: its build, the kernels it runs (and whether OpenABLE
chose them, on a CPU the library does not know) and its threading. For bug reports and
benchmarks.)doc");

  m.def(
      "l2_distances",
      [](const py::object& a, const py::object& b, int threads) {
        return PairDistances(a, b, threads, Elements::kFloat32, L2Distances);
      },
      py::arg("a"), py::arg("b") = py::none(), py::arg("threads") = 0,
      R"doc(l2_distances(a, b=None, threads=0) -> numpy.ndarray

Euclidean distances (Eq. 8) between every row of `a` and every row of `b`: matrix products
on OpenBLAS (the one numpy uses), with the cells that lose precision to cancellation
recomputed directly, so every cell is within float rounding of the direct sum. A symmetric
matrix (b=None) costs half the arithmetic.

Args:
    a (numpy.ndarray): shape (N, W) vector descriptor rows; float32 is read in place, other
        numeric types are converted to float32.
    b (numpy.ndarray | None): shape (M, W); None compares `a` with itself.
    threads (int): threads; 0 = all cores.

Returns:
    numpy.ndarray: float32, shape (N, M) (no copy of the C++ result).)doc");

  m.def(
      "l1_distances",
      [](const py::object& a, const py::object& b, int threads) {
        return PairDistances(a, b, threads, Elements::kUint8, L1Distances);
      },
      py::arg("a"), py::arg("b") = py::none(), py::arg("threads") = 0,
      R"doc(l1_distances(a, b=None, threads=0) -> numpy.ndarray

Sums of absolute byte differences between every row of `a` and every row of `b`: the
distance of SAD rows (SeqSLAM), with the CPU's sum-of-absolute-differences instruction (AVX2)
when it has one.

Args:
    a (numpy.ndarray): uint8, shape (N, W) (a 1-D array is one row).
    b (numpy.ndarray | None): uint8, shape (M, W); None compares `a` with itself.
    threads (int): threads; 0 = all cores.

Returns:
    numpy.ndarray: float32, shape (N, M) (no copy of the C++ result).

Raises:
    ValueError: not uint8, or rows of different widths.)doc");

  m.def(
      "sequence_distances",
      [](const py::object& d, int sequence_length, const std::string& direction,
         const py::object& row_starts, const py::object& col_starts, int threads, bool in_place,
         const std::string& partial) -> py::object {
        const auto dir = ParseEnum<SequenceDirection>(direction, "direction");
        const auto part = ParseEnum<SequencePartial>(partial, "partial");
        const std::vector<int> rows = Starts(row_starts, "row_starts");
        const std::vector<int> cols = Starts(col_starts, "col_starts");
        if (in_place) {
          MatView view;
          cv::Mat1f target = WritableFloatView(d, view);
          const uchar* before = target.data;
          {
            py::gil_scoped_release release;
            SequenceDistancesInPlace(target, sequence_length, rows, cols, dir, threads, part);
            if (target.data != before) target.copyTo(view.mat);  // never expected; kept safe
          }
          return view.owner;
        }
        const MatView view = Matrix2D(d, Elements::kFloat32, "d");
        cv::Mat1f out;
        {
          py::gil_scoped_release release;
          out = SequenceDistances(cv::Mat1f(view.mat), sequence_length, rows, cols, dir, threads,
                                  part);
        }
        return ToNumpy(out);
      },
      py::arg("d"), py::arg("sequence_length"), py::arg("direction") = "forward",
      py::arg("row_starts") = py::none(), py::arg("col_starts") = py::none(),
      py::arg("threads") = 0, py::arg("in_place") = false, py::arg("partial") = "ahead",
      R"doc(sequence_distances(d, sequence_length, direction="forward", row_starts=None,
    col_starts=None, threads=0, in_place=False, partial="ahead") -> numpy.ndarray

Sequence matching (ABLE, after SeqSLAM): the distance of the places of frames i and j is the
sum of the L single-frame distances along the diagonal ending at (i, j):
forward S(i, j) = sum_k D(i-k, j-k), reverse S(i, j) = sum_k D(i-k, j+k) (the reference
route driven the other way), both = the smaller of the two; k = 0 .. L-1. Where fewer than L
terms exist (the first frames of a traversal) the cell takes the L frames ahead of it along
its diagonal (partial="ahead"; +inf when the whole diagonal is shorter than L), the available
terms are scaled to L (partial="scale") or the cell holds +inf (partial="skip", OpenSeqSLAM's
rule). Sums never cross from one traversal into another. One pass whatever L.

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
    partial (str): "ahead", "scale" or "skip" (Sequence_partial).

Returns:
    numpy.ndarray: float32, shape (N, M).

Raises:
    ValueError: L < 1, starts not increasing from 0, a bad direction or partial.)doc");
}

void RegisterSequencesAndScores(py::module_& m) {
  m.def(
      "contrast_enhancement",
      [](const py::object& d, int window, const py::object& col_starts, int threads) {
        const MatView view = Matrix2D(d, Elements::kFloat32, "d");
        const std::vector<int> cols = Starts(col_starts, "col_starts");
        if (window < 1)
          throw py::value_error("window: " + std::to_string(window) +
                                "; expected >= 1 (references on each side)");
        cv::Mat1f out;
        {
          py::gil_scoped_release release;
          cv::Mat1f(view.mat).copyTo(out);
          EnhanceContrast(out, window, cols, threads);
        }
        return ToNumpy(out);
      },
      py::arg("d"), py::arg("window") = 10, py::arg("col_starts") = py::none(),
      py::arg("threads") = 0,
      R"doc(contrast_enhancement(d, window=10, col_starts=None, threads=0) -> numpy.ndarray

SeqSLAM's local contrast enhancement of single-frame distances (Contrast_enhancement): each
cell minus the mean of its row's cells within +-window columns of its traversal, divided by
their standard deviation (0 where they are all equal), then the whole matrix shifted so that
its smallest value is 0. Non-finite cells are left out and kept.

Args:
    d (numpy.ndarray): shape (N, M) single-frame distances (a new matrix is returned).
    window (int): columns on each side (Contrast_window), >= 1.
    col_starts (list[int] | None): first column of each traversal (None: one traversal).
    threads (int): threads; 0 = all cores.

Returns:
    numpy.ndarray: float32, shape (N, M).)doc");

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
stays 0). +inf entries (sequence cells skipped, partial="skip") are left out of the maximum
and stay +inf.

Args:
    matrix (numpy.ndarray): non-negative distances, shape (N, M).

Returns:
    (numpy.ndarray, float): M' (float32, a new array) and the largest finite entry of M.

Raises:
    ValueError: a negative or NaN entry.)doc");

  m.def(
      "threshold_matrix",
      [](const py::object& normalized, float theta) {
        // Eq. 9 compares M' (in [0, 1]) with theta in [0, 1]; NaN would compare as "not a
        // candidate" without a word.
        if (!(theta >= 0.0f && theta <= 1.0f))
          throw py::value_error("theta: " + FormatNumber(theta) +
                                " is not valid; expected a "
                                "threshold in [0, 1] (Eq. 9 on the normalised matrix)");
        const MatView view = Matrix2D(normalized, Elements::kFloat32, "normalized");
        for (int i = 0; i < view.mat.rows; ++i) {
          const float* row = view.mat.ptr<float>(i);
          for (int j = 0; j < view.mat.cols; ++j)
            if (std::isnan(row[j]))
              throw py::value_error("normalized: NaN at row " + std::to_string(i) + ", column " +
                                    std::to_string(j) +
                                    "; expected M' in [0, 1] (inf for a "
                                    "cell without a value)");
        }
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
}

void RegisterMatrices(py::module_& m) {
  m.def(
      "best_matches",
      [](const py::object& matrix, const std::string& score, int score_window) {
        const MatView view = Matrix2D(matrix, Elements::kFloat32, "matrix");
        const MatchScoreOptions options{ParseEnum<MatchScore>(score, "score"), score_window};
        WithArgumentNames([&] { options.Check(); });
        const cv::Mat1f d(view.mat);
        const int n = d.rows;
        py::array_t<int> best(n);
        py::array_t<float> distance(n), scores(n);
        {
          auto b = best.mutable_unchecked<1>();
          auto dist = distance.mutable_unchecked<1>();
          auto sc = scores.mutable_unchecked<1>();
          py::gil_scoped_release release;
          for (int q = 0; q < n; ++q) {
            const float* row = d.ptr<float>(q);
            const int c = BestCandidate(row, d.cols);
            b(q) = c;
            dist(q) = c < 0 ? std::numeric_limits<float>::quiet_NaN() : row[c];
            sc(q) = c < 0 ? std::numeric_limits<float>::quiet_NaN()
                          : ScoreOfCandidate(row, d.cols, c, options);
          }
        }
        return py::make_tuple(best, distance, scores);
      },
      py::arg("matrix"), py::arg("score") = "distance", py::arg("score_window") = 10,
      R"doc(best_matches(matrix, score="distance", score_window=10) -> tuple

Each row's best match and its confidence (Match_score), as the evaluation and the matches
file score them: the best column is the smallest finite value (lowest column on ties); the
distance score is that value; the ratio score divides it by the smallest finite value of the
row more than score_window columns away from it (1 when there is none, or when that value
is 0). To leave columns out (the last Exclusion frames of a loop-closure row, another
traversal), set them to +inf first.

Args:
    matrix (numpy.ndarray): shape (N, M): queries x candidates (e.g. the query-reference
        block of a normalised matrix).
    score (str): "distance" or "ratio".
    score_window (int): columns on each side of the best that are not its rivals, >= 0.

Returns:
    (best, distance, score): int32 (N,) columns (-1 where a row has no finite value), and
    float32 (N,) distances and scores (NaN there).)doc");

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

}  // namespace

void RegisterMatching(py::module_& m) {
  RegisterDistances(m);
  RegisterSequencesAndScores(m);
  RegisterMatrices(m);
}

}  // namespace openable::python
