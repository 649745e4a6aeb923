// Evaluation against ground truth (docs/evaluation.md): evaluate() and its result.
#include <pybind11/stl.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <deque>
#include <optional>
#include <utility>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/version.h"
#include "OpenABLE/evaluation/ground_truth.h"
#include "OpenABLE/evaluation/layout.h"
#include "OpenABLE/evaluation/matrix_file.h"
#include "OpenABLE/evaluation/metrics.h"
#include "OpenABLE/evaluation/report.h"
#include "OpenABLE/evaluation/saved_settings.h"
#include "OpenABLE/evaluation/unsupervised.h"
#include "OpenABLE/python/common.h"
#include "OpenABLE/run/evaluate.h"
#include "matching/matrix.h"
#include "matching/normalize.h"

namespace openable::python {
namespace {

// A precision-recall curve.
struct Curve {
  std::vector<CurvePoint> points;
};

// The result of evaluate().
struct Result {
  EvaluationSettings settings;
  EvaluatedRun run;
  GroundTruth truth;
};

// InputError for a ground truth or protocol (`what`: 'truth_type: "vpr_bench"') that pairs a
// query traversal with a reference one, given a square matrix evaluated as one sequence.
[[noreturn]] void NeedsTwoTraversals(const std::string& what, int rows, int cols) {
  throw InputError(what + " needs two traversals, but the " + std::to_string(rows) + "x" +
                   std::to_string(cols) +
                   " matrix is evaluated as one sequence (a square matrix without layout or "
                   "reference_frames); expected layout=\"query_reference\" (rows are queries, "
                   "columns references) or reference_frames=N (the first N frames of a square "
                   "matrix over both traversals are the reference)");
}

// Poses as FramePose: (N, 3, 4) or (N, 4, 4) camera-to-world matrices (forward = third column
// of R), or (N, 3) / (N, 2) positions (no orientation).
std::vector<FramePose> PosesOf(const py::handle& object, const char* what) {
  const auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(object);
  if (!a) throw py::value_error(std::string(what) + ": expected a NumPy array of poses");
  std::vector<FramePose> poses;
  const double* v = a.data();
  if (a.ndim() == 3 && (a.shape(1) == 3 || a.shape(1) == 4) && a.shape(2) == 4) {
    const py::ssize_t n = a.shape(0), stride = a.shape(1) * 4;
    for (py::ssize_t i = 0; i < n; ++i) {
      const double* p = v + i * stride;
      FramePose pose;
      pose.position = Eigen::Vector3d(p[3], p[7], p[11]);
      pose.forward = Eigen::Vector3d(p[2], p[6], p[10]);
      const double norm = pose.forward.norm();
      if (!(norm > 0) || !pose.position.allFinite()) {
        throw py::value_error(std::string(what) + "[" + std::to_string(i) +
                              "]: not a finite pose with a rotation (third column of R is zero)");
      }
      pose.forward /= norm;
      pose.has_forward = true;
      poses.push_back(pose);
    }
    return poses;
  }
  if (a.ndim() == 2 && (a.shape(1) == 2 || a.shape(1) == 3)) {
    const py::ssize_t n = a.shape(0), k = a.shape(1);
    for (py::ssize_t i = 0; i < n; ++i) {
      FramePose pose;
      pose.position = Eigen::Vector3d(v[i * k], v[i * k + 1], k == 3 ? v[i * k + 2] : 0.0);
      if (!pose.position.allFinite())
        throw py::value_error(std::string(what) + "[" + std::to_string(i) + "]: not finite");
      poses.push_back(pose);
    }
    return poses;
  }
  throw py::value_error(std::string(what) +
                        ": expected poses of shape (N, 3, 4) or (N, 4, 4) (camera-to-world) or "
                        "positions of shape (N, 3) or (N, 2)");
}

bool HaveOrientations(const std::vector<FramePose>& poses) {
  return std::all_of(poses.begin(), poses.end(), [](const FramePose& p) { return p.has_forward; });
}

// The keywords' defaults that are Config.txt keys, from the option table.
struct KeyDefaults {
  int base = std::stoi(TableDefault("Ground_truth_base"));
  int first_frame = std::stoi(TableDefault("Initial_image"));
  int tolerance = std::stoi(TableDefault("Tolerance"));
  int exclusion = std::stoi(TableDefault("Exclusion"));
  int vicinity = std::stoi(TableDefault("Vicinity"));
  double radius = std::stod(TableDefault("Ground_truth_radius"));
  double heading_limit = std::stod(TableDefault("Ground_truth_heading"));
  std::string axes = TableDefault("Ground_truth_axes");
  std::string score = TableDefault("Match_score");
  int score_window = std::stoi(TableDefault("Match_score_window"));
  int accept_consistency = std::stoi(TableDefault("Match_consistency"));
  int sequence_length = std::stoi(TableDefault("Image_sequences"));
  std::string partial = TableDefault("Sequence_partial");
  // Sequence_direction is read by number, as the original's keys are; Python takes its name.
  std::string direction =
      EnumName(static_cast<SequenceDirection>(std::stoi(TableDefault("Sequence_direction"))));
  std::string protocol = TableDefault("Evaluation_protocol");
  std::string truth_file_soft = TableDefault("Ground_truth_soft");

  // `text` with each "@name@" replaced by the default of that keyword.
  std::string Fill(std::string text) const {
    const std::pair<const char*, std::string> values[] = {
        {"@base@", std::to_string(base)},
        {"@first_frame@", std::to_string(first_frame)},
        {"@tolerance@", std::to_string(tolerance)},
        {"@exclusion@", std::to_string(exclusion)},
        {"@vicinity@", std::to_string(vicinity)},
        {"@able_thresholds@", std::to_string(EvaluationOptions().able_thresholds)},
        {"@radius@", FormatNumber(radius)},
        {"@heading_limit@", FormatNumber(heading_limit)},
        {"@axes@", axes},
        {"@score@", score},
        {"@score_window@", std::to_string(score_window)},
        {"@accept_consistency@", std::to_string(accept_consistency)},
        {"@sequence_length@", std::to_string(sequence_length)},
        {"@partial@", partial},
        {"@direction@", direction},
        {"@protocol@", protocol},
        {"@truth_file_soft@", truth_file_soft}};
    return FillPlaceholders(std::move(text), values);
  }
};

const KeyDefaults& Defaults() {
  static const KeyDefaults defaults;
  return defaults;
}

// The layout of `layout` ("loop_closure", "query_reference" or None) on a rows x cols matrix.
EvaluationLayout LayoutOf(const py::object& layout, const py::object& reference_frames, int rows,
                          int cols) {
  std::string kind = layout.is_none() ? "" : openable::Lower(layout.cast<std::string>());
  if (kind.empty()) {
    kind = (!reference_frames.is_none() || rows != cols) ? "query_reference" : "loop_closure";
  }
  if (kind == "loop_closure") {
    if (rows != cols) {
      throw py::value_error("layout: loop_closure needs a square matrix; got " +
                            std::to_string(rows) + "x" + std::to_string(cols));
    }
    if (!reference_frames.is_none())
      throw py::value_error("reference_frames: only with layout=\"query_reference\"");
    return EvaluationLayout::LoopClosure(rows);
  }
  if (kind != "query_reference") {
    throw py::value_error("layout: \"" + layout.cast<std::string>() +
                          "\"; expected \"loop_closure\" or \"query_reference\"");
  }
  if (reference_frames.is_none()) return EvaluationLayout::QueryReference(rows, cols);
  const int r = reference_frames.cast<int>();
  if (rows != cols || r < 1 || r >= rows) {
    throw py::value_error("reference_frames: " + std::to_string(r) +
                          " needs a square matrix over both traversals with more frames than "
                          "that (reference first, then queries); got " +
                          std::to_string(rows) + "x" + std::to_string(cols));
  }
  return EvaluationLayout::TwoTraversals(r, rows - r);
}

// Pairs (query, reference) in the block's indices; loop closure stores (later, earlier).
void AddPair(GroundTruth& gt, const EvaluationLayout& layout, std::int64_t a, std::int64_t b,
             py::ssize_t index) {
  const bool loop = layout.kind == EvaluationLayout::Kind::kLoopClosure;
  const std::int64_t rows = layout.queries, cols = loop ? layout.queries : layout.references;
  if (a < 0 || b < 0 || a >= rows || b >= cols) {
    throw py::value_error("pairs[" + std::to_string(index) + "]: (" + std::to_string(a) + ", " +
                          std::to_string(b) + ") is outside the " + std::to_string(rows) + "x" +
                          std::to_string(cols) + " evaluated block");
  }
  if (loop && a == b) {
    ++gt.dropped;
  } else if (loop) {
    gt.matches[static_cast<std::size_t>(std::max(a, b))].push_back(
        static_cast<int>(std::min(a, b)));
  } else {
    gt.matches[static_cast<std::size_t>(a)].push_back(static_cast<int>(b));
  }
}

GroundTruth FromMatrix(const py::handle& object, const EvaluationLayout& layout, int full_rows,
                       int full_cols) {
  const MatView v = Matrix2D(object, Elements::kFloat32, "truth_matrix");
  const int rows = layout.queries, cols = layout.references;
  cv::Mat1f block(v.mat);
  if (block.rows == full_rows && block.cols == full_cols &&
      (rows != full_rows || cols != full_cols)) {
    block = block(cv::Rect(layout.col_offset, layout.row_offset, cols, rows));
  } else if (block.rows != rows || block.cols != cols) {
    throw py::value_error("truth_matrix: shape (" + std::to_string(block.rows) + ", " +
                          std::to_string(block.cols) + "); expected (" + std::to_string(rows) +
                          ", " + std::to_string(cols) + ") (the evaluated block) or (" +
                          std::to_string(full_rows) + ", " + std::to_string(full_cols) +
                          ") (the whole matrix)");
  }
  GroundTruth gt;
  gt.references = cols;
  gt.matches.assign(static_cast<std::size_t>(rows), {});
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      const float x = block(r, c);
      if (!std::isfinite(x)) {
        throw py::value_error("truth_matrix: cell (" + std::to_string(r) + ", " +
                              std::to_string(c) + ") is not finite");
      }
      if (x != 0.f) AddPair(gt, layout, r, c, 0);
    }
  return gt;
}

GroundTruth FromPairs(const py::handle& object, const EvaluationLayout& layout) {
  py::array raw = py::array::ensure(object);
  if (!raw || raw.ndim() != 2 || raw.shape(1) < 2 ||
      (raw.size() > 0 && raw.dtype().kind() != 'i' && raw.dtype().kind() != 'u')) {
    throw py::value_error(
        "pairs: expected integer pairs of shape (P, 2): (query, reference) frame indices of the "
        "evaluated block");
  }
  const auto a = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>::ensure(raw);
  GroundTruth gt;
  gt.references = layout.references;
  gt.matches.assign(static_cast<std::size_t>(layout.queries), {});
  const py::ssize_t width = a.shape(1);
  for (py::ssize_t i = 0; i < a.shape(0); ++i)
    AddPair(gt, layout, a.data()[i * width], a.data()[i * width + 1], i);
  return gt;
}

py::array_t<std::int64_t> TruthPairs(const GroundTruth& truth) {
  py::array_t<std::int64_t> out({static_cast<py::ssize_t>(truth.PairCount()), py::ssize_t{2}});
  std::int64_t* p = out.mutable_data();
  for (std::size_t q = 0; q < truth.matches.size(); ++q)
    for (const int r : truth.matches[q]) {
      *p++ = static_cast<std::int64_t>(q);
      *p++ = r;
    }
  return out;
}

template <typename T>
py::array_t<T> ArrayOf(const std::vector<T>& v) {
  py::array_t<T> a(static_cast<py::ssize_t>(v.size()));
  std::copy(v.begin(), v.end(), a.mutable_data());
  return a;
}

template <typename F>
py::array_t<double> Column(const Curve& c, F f) {
  std::vector<double> v;
  v.reserve(c.points.size());
  for (const CurvePoint& p : c.points) v.push_back(static_cast<double>(f(p)));
  return DoubleArray(v);
}

std::string LayoutName(const EvaluationLayout& l) {
  return l.kind == EvaluationLayout::Kind::kLoopClosure ? "loop_closure" : "query_reference";
}

// The docstring of evaluate, with the ground-truth formats of the registry.
const std::string& EvaluateDoc() {
  static const std::string doc = [] {
    std::string text =
        R"doc(evaluate(matrix, *, truth_matrix=None, pairs=None, poses=None, reference_poses=None,
    aligned=False, truth_file=None, truth_type=None, truth_file_2="", base=@base@,
    first_frame=@first_frame@, range_selected=False, layout=None, reference_frames=None,
    tolerance=@tolerance@, exclusion=@exclusion@, vicinity=@vicinity@,
    able_thresholds=@able_thresholds@, radius=@radius@, heading_limit=@heading_limit@,
    min_frame_gap=None, axes="@axes@", normalize=True, label="python", score="@score@",
    score_window=@score_window@, accept_threshold=None,
    accept_consistency=@accept_consistency@, sequence_length=@sequence_length@,
    partial="@partial@", direction="@direction@", protocol="@protocol@",
    truth_file_soft="@truth_file_soft@", truth_soft_matrix=None) -> EvaluationResult

Evaluates a distance matrix against ground truth with the protocols of docs/evaluation.md,
exactly as Test_OpenABLE (Ground_truth_type, Evaluation_protocol) and openable_evaluate do.
The defaults of the keywords that are Config.txt keys (tolerance: Tolerance, exclusion:
Exclusion, score: Match_score, ...) are those of the programs, from their option table.

Args:
    matrix (numpy.ndarray): distances (small = similar), shape (N, N) or (Q, R); float32 is
        read in place. +inf is a cell without a value (never an answer); NaN is refused as
        damage.
    truth_matrix (numpy.ndarray): ground truth as a matrix, non-zero = same place, of the
        evaluated block's shape or of the whole matrix's (the block is then taken from it).
        Loop closure: cell (a, b) is the pair (max, min); the diagonal is dropped.
    pairs (array-like): integer (P, 2) pairs (query, reference) in the block's 0-based
        indices (loop closure: two frame indices, either order).
    poses (numpy.ndarray): poses of the frames (loop closure) or of the query frames:
        (N, 3, 4) / (N, 4, 4) camera-to-world matrices, or (N, 3) / (N, 2) positions. A pair
        is a loop when the positions over `axes` are closer than `radius` and, with
        heading_limit >= 0, the viewing directions (third column of R) differ by less than
        heading_limit degrees; loop closure also needs the frames min_frame_gap apart.
    reference_poses (numpy.ndarray): poses of the reference frames (query-reference with poses).
    aligned (bool): two frame-aligned traversals: query i is reference i.
    truth_file (str): a ground-truth file read as Test_OpenABLE reads Ground_truth, with
        truth_type one of @FORMATS@;
        truth_file_2 holds the query poses of two traversals; base (-1, 0, 1) is the index
        base of a pairs file; first_frame (Initial_image) and range_selected say which part
        of the source the matrix covers.
    layout (str | None): "loop_closure" (one sequence, square matrix: the candidates of query
        q are frames j <= q - exclusion) or "query_reference" (rows are queries, columns
        references, every reference a candidate). None: query_reference when the matrix is
        not square or reference_frames is given, else loop_closure.
    reference_frames (int | None): a square matrix over two concatenated traversals, the
        reference's frames first: the lower-left block (queries x reference) is evaluated.
    tolerance (int): frames; an answer within this many frames of a true match is correct.
    exclusion (int): loop closure: candidates are frames at least this far back (>= 1).
    vicinity (int): ABLE-P protocol: temporal vicinity in frames.
    able_thresholds (int): ABLE-P protocol: thresholds evenly spaced in [0, 1].
    radius, heading_limit, min_frame_gap, axes: the loop rule of poses (metres, degrees or
        -1 for no limit, frames or None for `exclusion`, "xyz", "xz" or "xy").
    normalize (bool): divide the matrix by its maximum first (Eq. 5), as openable_evaluate
        does; Test_OpenABLE's M' is unchanged by it.
    label (str): the run's label in to_json().
    score (str): what ranks and accepts each query's best match in the per-query protocol
        (Match_score): "distance" or "ratio" (its distance over the best candidate more than
        score_window frames away; docs/evaluation.md). The ABLE-P cell protocol is unchanged.
    score_window (int): frames on each side of the best match that are not its rivals (>= 0,
        smaller than the references).
    accept_threshold (float | None): an operating point (Match_threshold): operating_point
        gives the precision and recall of the answers whose score is <= it.
    accept_consistency (int): Match_consistency n: an answer is accepted only when the
        answers of n independent queries (one sequence apart) agree with it (0: the score
        alone); sequence_length, partial and direction are those of the matrix (L,
        Sequence_partial, Sequence_direction), which say which queries are independent.
    protocol (str): the protocols reported besides the toolbox's own, always computed
        (Evaluation_protocol): "openable", "vpr_bench", "vpr_tutorial", a comma list or
        "all"; their figures are the vpr_bench and vpr_tutorial properties, and table()
        shows every protocol asked for side by side.
    truth_file_soft (str): truth_type "vpr_tutorial": VPR_Tutorial's GTsoft (.npy, database
        x queries); "" takes the GTsoft of a .npz truth_file, if any.
    truth_soft_matrix (numpy.ndarray): with truth_matrix (queries x references, so
        VPR_Tutorial's GThard.T): GTsoft.T, cells VPR_Tutorial's protocol ignores.

Returns:
    EvaluationResult: figures (auc, recall_at_100p, max_f1, recall_at_1/5/10,
    average_precision, ...) and curves (curve, able_p_curve).

Raises:
    ValueError (openable.InputError for files and options): one line naming the argument.

Warns:
    UserWarning: figures that say little about the matrix (also in the result's warnings): no
    query with a true place among its candidates, none with a value among them, or a ranking
    that looks reversed (a similarity given as distances; docs/evaluation.md, "Warnings").)doc";
    text = Defaults().Fill(text);
    std::string formats;
    for (const GroundTruthFormat& f : GroundTruthFormats())
      formats += std::string(formats.empty() ? "" : ", ") + "\"" + f.name + "\"";
    text.replace(text.find("@FORMATS@"), 9, formats);
    return text;
  }();
  return doc;
}

}  // namespace

namespace {

void RegisterCurve(py::module_& m) {
  py::class_<Curve>(m, "Curve", R"doc(A precision-recall curve: one point per threshold, in
increasing order of threshold. Each property is a float64 NumPy array with one value per
point.)doc")
      .def_property_readonly(
          "threshold",
          [](const Curve& c) { return Column(c, [](const CurvePoint& p) { return p.threshold; }); },
          "Thresholds: per-query protocol, answers with distance <= threshold are accepted; "
          "ABLE-P, cells with M' < threshold are detections.")
      .def_property_readonly(
          "precision",
          [](const Curve& c) { return Column(c, [](const CurvePoint& p) { return p.precision; }); },
          "Precision at each threshold (ABLE-P: 1 where nothing is detected).")
      .def_property_readonly(
          "recall",
          [](const Curve& c) { return Column(c, [](const CurvePoint& p) { return p.recall; }); },
          "Recall at each threshold.")
      .def_property_readonly(
          "f1", [](const Curve& c) { return Column(c, [](const CurvePoint& p) { return p.f1; }); },
          "F1 = 2PR / (P + R) at each threshold.")
      .def_property_readonly(
          "tp", [](const Curve& c) { return Column(c, [](const CurvePoint& p) { return p.tp; }); },
          "True positives at each threshold (as float64).")
      .def_property_readonly(
          "fp", [](const Curve& c) { return Column(c, [](const CurvePoint& p) { return p.fp; }); },
          "False positives at each threshold (as float64).")
      .def(
          "area", [](const Curve& c) { return CurveArea(c.points); },
          "area() -> float\n\nStep-wise area: the sum of precision x (recall - previous recall) "
          "over the points (AUC of the per-query curve; ABLE-P's average precision / 100).")
      .def(
          "to_dict", [](const py::object& self) { return PropertiesAsDict(self, true); },
          "to_dict() -> dict[str, numpy.ndarray]\n\nThe columns threshold, precision, recall, "
          "f1, tp, fp (as the CSV files openable writes).")
      .def(
          "__len__", [](const Curve& c) { return c.points.size(); }, "Number of points.")
      .def("__repr__", [](const Curve& c) {
        return "<openable.Curve of " + std::to_string(c.points.size()) + " points>";
      });
}

void RegisterEvaluationResult(py::module_& m) {
  py::class_<Result> result(m, "EvaluationResult", R"doc(The figures and curves of evaluate(): the
per-query best-match protocol (auc, recall_at_100p, max_f1, recall_at_1/5/10, curve) and the
ABLE papers' cell protocol (average_precision, able_p_curve); docs/evaluation.md defines each.)doc");
  result
      .def_property_readonly(
          "label", [](const Result& r) { return r.run.label; }, "The label given to evaluate().")
      .def_property_readonly(
          "layout", [](const Result& r) { return LayoutName(r.run.layout); },
          "\"loop_closure\" or \"query_reference\".")
      .def_property_readonly(
          "block",
          [](const Result& r) {
            const EvaluationLayout& l = r.run.layout;
            return py::make_tuple(l.row_offset, l.col_offset, l.queries, l.references);
          },
          "(first row, first column, rows, columns) of the evaluated block in the matrix.")
      .def_property_readonly(
          "auc", [](const Result& r) { return r.run.per_query.auc; },
          "Per-query protocol: step-wise area under the precision-recall curve.")
      .def_property_readonly(
          "recall_at_100p", [](const Result& r) { return r.run.per_query.recall_at_100p; },
          "Per-query protocol: highest recall with precision 1 (0 if none).")
      .def_property_readonly(
          "max_f1", [](const Result& r) { return r.run.per_query.max_f1; },
          "Per-query protocol: the largest F1 along the curve.")
      .def_property_readonly(
          "max_f1_threshold", [](const Result& r) { return r.run.per_query.max_f1_threshold; },
          "Score threshold of max_f1 (the first on ties).")
      .def_property_readonly(
          "score", [](const Result& r) { return EnumName(r.settings.options.score.kind); },
          "The match score that ranked and accepted the answers: \"distance\" or \"ratio\".")
      .def_property_readonly(
          "scores", [](const Result& r) { return ArrayOf(r.run.per_query.score); },
          "float32 array: the score of each query's best candidate (inf without candidates).")
      .def_property_readonly(
          "warnings", [](const Result& r) { return r.run.warnings; },
          "list[str]: what makes the figures say little about the matrix, one line each (also "
          "given as UserWarning by evaluate): no query with a candidate, with a true place or "
          "with a value among its candidates, or a ranking that looks reversed (a similarity "
          "read as a distance; docs/evaluation.md, \"Warnings\").")
      .def_property_readonly(
          "unanswered_queries", [](const Result& r) { return r.run.per_query.unanswered; },
          "Queries whose candidates all hold no value (skipped sequence cells): no answer.")
      .def_property_readonly(
          "operating_point",
          [](const Result& r) -> py::object {
            const PerQueryResult& p = r.run.per_query;
            if (!p.has_operating_point) return py::none();
            py::dict d;
            d["threshold"] = p.operating_point.threshold;
            d["precision"] = p.operating_point.precision;
            d["recall"] = p.operating_point.recall;
            return std::move(d);
          },
          "With accept_threshold: {\"threshold\", \"precision\", \"recall\"} of the answers "
          "whose score is <= it; else None.")
      .def_property_readonly(
          "max_f1_precision", [](const Result& r) { return r.run.per_query.max_f1_precision; },
          "Precision at max_f1.")
      .def_property_readonly(
          "max_f1_recall", [](const Result& r) { return r.run.per_query.max_f1_recall; },
          "Recall at max_f1.")
      .def_property_readonly(
          "recall_at_1", [](const Result& r) { return r.run.per_query.recall_at_1; },
          "Share of positive queries whose best candidate is correct (within tolerance of a true "
          "match).")
      .def_property_readonly(
          "recall_at_5", [](const Result& r) { return r.run.per_query.recall_at_5; },
          "Share of positive queries with a correct match among their 5 best candidates.")
      .def_property_readonly(
          "recall_at_10", [](const Result& r) { return r.run.per_query.recall_at_10; },
          "Share of positive queries with a correct match among their 10 best candidates.")
      .def_property_readonly(
          "queries", [](const Result& r) { return r.run.per_query.queries; },
          "Queries with at least one candidate.")
      .def_property_readonly(
          "positive_queries", [](const Result& r) { return r.run.per_query.positive_queries; },
          "Queries with a true match among their candidates.")
      .def_property_readonly(
          "truth_pairs", [](const Result& r) { return r.run.truth_pairs; },
          "Ground-truth pairs over the evaluated block.")
      .def_property_readonly(
          "truth_dropped", [](const Result& r) { return r.run.truth_dropped; },
          "Pairs dropped while building the ground truth (the diagonal of a loop-closure block, "
          "pairs outside a selected frame range).")
      .def_property_readonly(
          "truth_pairs_outside_candidates",
          [](const Result& r) { return r.run.per_query.truth_pairs_outside_candidates; },
          "True pairs that no candidate set contains (inside the exclusion window); they do not "
          "count.")
      .def_property_readonly(
          "curve", [](const Result& r) { return Curve{r.run.per_query.curve}; },
          "Per-query precision-recall curve (openable.Curve), one point per distinct best-match "
          "score.")
      .def_property_readonly(
          "best", [](const Result& r) { return ArrayOf(r.run.per_query.best); },
          "int32 array, per query row of the block: its best candidate column (-1 without "
          "candidates).")
      .def_property_readonly(
          "best_distance", [](const Result& r) { return ArrayOf(r.run.per_query.best_distance); },
          "float32 array: the distance of each query's best candidate (inf without candidates).")
      .def_property_readonly(
          "positive",
          [](const Result& r) { return ArrayOf(r.run.per_query.positive).attr("astype")("bool"); },
          "bool array: the query has a true match among its candidates.")
      .def_property_readonly(
          "correct",
          [](const Result& r) { return ArrayOf(r.run.per_query.correct).attr("astype")("bool"); },
          "bool array: the query's best candidate is within tolerance of a true match.")
      .def_property_readonly(
          "average_precision", [](const Result& r) { return r.run.able_p.average_precision; },
          "ABLE-P protocol: area under its 100-threshold curve, in percent.")
      .def_property_readonly(
          "able_p_curve", [](const Result& r) { return Curve{r.run.able_p.curve}; },
          "ABLE-P precision-recall curve (openable.Curve), thresholds k / (n - 1).")
      .def_property_readonly(
          "candidate_cells", [](const Result& r) { return r.run.able_p.candidate_cells; },
          "ABLE-P: cells of the block that are candidates.")
      .def_property_readonly(
          "truth_cells", [](const Result& r) { return r.run.able_p.truth_cells; },
          "ABLE-P: ground-truth pairs among the candidate cells.")
      .def(
          "truth_matches", [](const Result& r) { return TruthPairs(r.truth); },
          "truth_matches() -> numpy.ndarray\n\nThe ground truth used: int64 (P, 2) pairs "
          "(query row, reference column) in the block's indices (loop closure: later frame "
          "first).")
      .def(
          "table", [](const Result& r) { return FormatEvaluationTable(r.settings, {r.run}); },
          "table() -> str\n\nThe table openable_evaluate prints: the figures of each protocol "
          "asked for, one row each.")
      .def(
          "to_json",
          [](const Result& r) { return EncodeEvaluationJson(r.settings, {r.run}, kVersion); },
          "to_json() -> str\n\nThe evaluation as the JSON file Test_OpenABLE and "
          "openable_evaluate write (Evaluation_name.json), with this one run.")
      .def(
          "to_dict", [](const py::object& self) { return PropertiesAsDict(self); },
          "to_dict() -> dict\n\nEvery figure, and both curves as dicts of NumPy arrays.")
      .def("__repr__", [](const Result& r) {
        const PerQueryResult& p = r.run.per_query;
        char b[320];
        std::snprintf(b, sizeof b,
                      "<openable.EvaluationResult %s: AUC %.4f, R@100P %.4f, max F1 %.4f, "
                      "R@1/5/10 %.4f/%.4f/%.4f, ABLE-P AP %.2f %%>",
                      LayoutName(r.run.layout).c_str(), p.auc, p.recall_at_100p, p.max_f1,
                      p.recall_at_1, p.recall_at_5, p.recall_at_10, r.run.able_p.average_precision);
        return std::string(b);
      });
  // One property per reference protocol of the table (evaluation/protocols.h): its figures and
  // curves as a dict, None when the protocol was not asked for.
  for (const ReferenceProtocol& protocol : ReferenceProtocols()) {
    const std::string name = protocol.name;
    static std::deque<std::string> docs;  // pybind11 keeps the pointer: never moved
    docs.push_back(std::string(protocol.help) + " (protocol \"" + name +
                   "\"): a dict of its figures and curves; None when not asked for.");
    result.def_property_readonly(
        protocol.name,
        [name](const Result& r) -> py::object {
          for (const ProtocolFigures& f : r.run.reference)
            if (f.protocol == name) return JsonToPython(f.details);
          return py::none();
        },
        docs.back().c_str());
  }
}

void RegisterEvaluate(py::module_& m) {
  // The keywords' defaults are the programs' (the option table's), so that they cannot drift.
  const EvaluationOptions kOptions;
  const KeyDefaults& d = Defaults();

  // read_matrix_settings' checks (openable/__init__.py): the settings file beside a matrix
  // holds together and fits the matrix, as openable_evaluate checks them.
  m.def(
      "_check_matrix_settings",
      [](const std::string& matrix_path) {
        py::gil_scoped_release release;
        const std::optional<SavedMatrixSettings> saved = ReadMatrixSettings(matrix_path);
        if (!saved) return false;
        const cv::Size size = MatrixFileSize(matrix_path);
        CheckMatrixFitsSettings(*saved, matrix_path, size.height, size.width);
        return true;
      },
      py::arg("matrix_path"));

  m.def(
      "evaluate",
      [](const py::object& matrix, const py::object& truth_matrix, const py::object& pairs,
         const py::object& poses, const py::object& reference_poses, bool aligned,
         const py::object& truth_file, const py::object& truth_type,
         const std::string& truth_file_2, int base, int first_frame, bool range_selected,
         const py::object& layout_name, const py::object& reference_frames, int tolerance,
         int exclusion, int vicinity, int able_thresholds, double radius, double heading_limit,
         const py::object& min_frame_gap, const std::string& axes, bool normalize,
         const std::string& label, const std::string& score, int score_window,
         const py::object& accept_threshold, int accept_consistency, int sequence_length,
         const std::string& partial, const std::string& direction, const std::string& protocol,
         const std::string& truth_file_soft, const py::object& truth_soft_matrix) {
        const MatView view = Matrix2D(matrix, Elements::kFloat32, "matrix");
        const int full_rows = view.mat.rows, full_cols = view.mat.cols;
        Result result;
        EvaluationSettings& s = result.settings;
        s.options.protocols = WithArgumentNames([&] { return ParseEvaluationProtocols(protocol); });
        s.options.tolerance = tolerance;
        s.options.exclusion = exclusion;
        s.options.vicinity = vicinity;
        s.options.able_thresholds = able_thresholds;
        s.options.score.kind = ParseEnum<MatchScore>(score, "score");
        s.options.score.window = score_window;
        if (!accept_threshold.is_none()) {
          s.options.accept_threshold = accept_threshold.cast<double>();
          // -1 is the struct's "none", which Python spells None.
          if (s.options.accept_threshold == -1.0)
            throw py::value_error(
                "accept_threshold: -1 is not valid; expected None or a number >= 0");
        }
        s.options.accept_consistency = accept_consistency;
        s.options.agreement.sequence_length = sequence_length;
        s.options.agreement.partial = ParseEnum<SequencePartial>(partial, "partial");
        s.options.agreement.direction = ParseEnum<SequenceDirection>(direction, "direction");
        WithArgumentNames([&] { s.options.Check(); });
        const EvaluationLayout layout =
            LayoutOf(layout_name, reference_frames, full_rows, full_cols);
        const bool loop = layout.kind == EvaluationLayout::Kind::kLoopClosure;
        if (loop && !s.options.protocols.reference.empty())
          NeedsTwoTraversals("protocol: \"" + protocol + "\"", full_rows, full_cols);

        const int given = (truth_matrix.is_none() ? 0 : 1) + (pairs.is_none() ? 0 : 1) +
                          (poses.is_none() ? 0 : 1) + (aligned ? 1 : 0) +
                          (truth_file.is_none() ? 0 : 1);
        if (given != 1) {
          throw py::value_error(
              "evaluate: give exactly one ground truth: truth_matrix, pairs, poses, aligned=True "
              "or truth_file (got " +
              std::to_string(given) + ")");
        }
        GroundTruthOptions& t = s.truth;
        t.radius = radius;
        t.heading_limit = heading_limit;
        t.min_frame_gap = min_frame_gap.is_none() ? exclusion : min_frame_gap.cast<int>();
        t.axes = axes;
        t.base = base;
        t.first_frame = first_frame;
        t.range_selected = range_selected;
        GroundTruth& gt = result.truth;
        if (!truth_file.is_none()) {
          t.path = truth_file.cast<std::string>();
          t.path_2 = truth_file_2;
          t.soft_path = truth_file_soft;
          if (truth_type.is_none())
            throw py::value_error("truth_type: expected with truth_file (" +
                                  GroundTruthFormatList() + ")");
          gt = WithArgumentNames([&] {
            t.type = ParseGroundTruthType(truth_type.cast<std::string>());
            if (loop && t.type.Format().two_traversals)
              NeedsTwoTraversals("truth_type: \"" + GroundTruthTypeName(t.type) + "\"", full_rows,
                                 full_cols);
            return LoadGroundTruth(t, layout, full_rows, full_cols);
          });
        } else if (aligned) {
          t.type = GroundTruthType::kAligned;
          if (loop) {
            throw py::value_error(
                "aligned: needs a query-reference layout (two traversals: reference_frames, or "
                "a queries x references matrix)");
          }
          gt = LoadGroundTruth(t, layout, full_rows, full_cols);
        } else if (!truth_matrix.is_none()) {
          t.type = GroundTruthType::kMatrix;
          t.path = "<truth_matrix>";
          gt = FromMatrix(truth_matrix, layout, full_rows, full_cols);
        } else if (!pairs.is_none()) {
          t.type = GroundTruthType::kPairs;
          t.path = "<pairs>";
          gt = FromPairs(pairs, layout);
        } else {
          const std::vector<FramePose> queries = PosesOf(poses, "poses");
          std::vector<FramePose> reference;
          if (!loop) {
            if (reference_poses.is_none()) {
              throw py::value_error(
                  "reference_poses: expected with a query-reference layout (poses are then the "
                  "poses of the queries)");
            }
            reference = PosesOf(reference_poses, "reference_poses");
          }
          const bool oriented = HaveOrientations(queries) && HaveOrientations(reference);
          t.type = oriented ? GroundTruthType::kKitti : GroundTruthType::kPositions;
          t.path = "<poses>";
          WithArgumentNames([&] { t.Check(); });
          if (static_cast<int>(queries.size()) < layout.queries) {
            throw py::value_error("poses: " + std::to_string(queries.size()) +
                                  " poses; expected one per query frame (" +
                                  std::to_string(layout.queries) + ")");
          }
          if (!loop && static_cast<int>(reference.size()) < layout.references) {
            throw py::value_error("reference_poses: " + std::to_string(reference.size()) +
                                  " poses; expected one per reference frame (" +
                                  std::to_string(layout.references) + ")");
          }
          std::vector<FramePose> q(queries.begin(), queries.begin() + layout.queries);
          if (!loop) reference.resize(static_cast<std::size_t>(layout.references));
          gt.references = layout.references;
          {
            py::gil_scoped_release release;
            gt.matches = PairsFromPoses(q, reference, t);
          }
          if (loop) {
            for (std::size_t i = 0; i < gt.matches.size(); ++i) {
              auto& mm = gt.matches[i];
              const auto self = std::find(mm.begin(), mm.end(), static_cast<int>(i));
              if (self != mm.end()) {
                mm.erase(self);
                ++gt.dropped;
              }
            }
          }
        }
        for (auto& mm : gt.matches) {
          std::sort(mm.begin(), mm.end());
          mm.erase(std::unique(mm.begin(), mm.end()), mm.end());
        }
        if (!truth_soft_matrix.is_none()) {
          if (loop)
            throw py::value_error(
                "truth_soft_matrix: needs a query-reference layout (two traversals)");
          // Queries x references like truth_matrix (VPR_Tutorial's GTsoft transposed); the
          // cells outside the hard ground truth are those its protocol ignores.
          const GroundTruth soft = FromMatrix(truth_soft_matrix, layout, full_rows, full_cols);
          gt.soft.assign(gt.matches.size(), {});
          for (std::size_t q = 0; q < gt.matches.size(); ++q)
            for (int c : soft.matches[q])
              if (!std::binary_search(gt.matches[q].begin(), gt.matches[q].end(), c))
                gt.soft[q].push_back(c);
        }

        EvaluatedRun& run = result.run;
        run.label = label;
        run.source = "Python";
        run.layout = layout;
        run.truth_pairs = gt.PairCount();
        run.truth_dropped = gt.dropped;
        run.truth_skipped_header = gt.skipped_header;
        {
          py::gil_scoped_release release;
          // The checks of openable_evaluate: distances >= 0, +inf for no value, NaN refused.
          cv::Mat1f m = DistancesForEvaluation(cv::Mat1f(view.mat), "matrix");
          if (normalize) {
            double lo = 0, hi = 0;
            cv::minMaxLoc(m, &lo, &hi);
            if (hi != 1.0) {  // M' of Test_OpenABLE is left as it is, without a copy
              cv::Mat1f scaled = m.clone();
              NormalizeByMax(scaled);
              m = scaled;
            }
          }
          run.per_query =
              WithArgumentNames([&] { return EvaluatePerQuery(m, layout, gt, s.options); });
          run.warnings = EvaluationWarnings(m, layout, gt, s.options, run.per_query);
          run.able_p = EvaluateAbleP(m, layout, gt, s.options);
          run.reference = WithArgumentNames([&] {
            return EvaluateReferenceProtocols(m, layout, gt, s.options.protocols,
                                              s.options.tolerance);
          });
        }
        for (const std::string& w : result.run.warnings) Warn(w);
        return result;
      },
      py::arg("matrix"), py::kw_only(), py::arg("truth_matrix") = py::none(),
      py::arg("pairs") = py::none(), py::arg("poses") = py::none(),
      py::arg("reference_poses") = py::none(), py::arg("aligned") = false,
      py::arg("truth_file") = py::none(), py::arg("truth_type") = py::none(),
      py::arg("truth_file_2") = "", py::arg("base") = d.base,
      py::arg("first_frame") = d.first_frame, py::arg("range_selected") = false,
      py::arg("layout") = py::none(), py::arg("reference_frames") = py::none(),
      py::arg("tolerance") = d.tolerance, py::arg("exclusion") = d.exclusion,
      py::arg("vicinity") = d.vicinity, py::arg("able_thresholds") = kOptions.able_thresholds,
      py::arg("radius") = d.radius, py::arg("heading_limit") = d.heading_limit,
      py::arg("min_frame_gap") = py::none(), py::arg("axes") = d.axes, py::arg("normalize") = true,
      py::arg("label") = "python", py::arg("score") = d.score,
      py::arg("score_window") = d.score_window, py::arg("accept_threshold") = py::none(),
      py::arg("accept_consistency") = d.accept_consistency,
      py::arg("sequence_length") = d.sequence_length, py::arg("partial") = d.partial,
      py::arg("direction") = d.direction, py::arg("protocol") = d.protocol,
      py::arg("truth_file_soft") = d.truth_file_soft, py::arg("truth_soft_matrix") = py::none(),
      EvaluateDoc().c_str());
}

void RegisterUnsupervised(py::module_& m) {
  const KeyDefaults& d = Defaults();

  m.def(
      "unsupervised_criteria",
      [](const py::object& matrix, const py::object& layout_name,
         const py::object& reference_frames, int sequence_length, const std::string& partial,
         const std::string& direction, int exclusion, int score_window) {
        const MatView view = Matrix2D(matrix, Elements::kFloat32, "matrix");
        const EvaluationLayout layout =
            LayoutOf(layout_name, reference_frames, view.mat.rows, view.mat.cols);
        UnsupervisedOptions o;
        o.agreement.sequence_length = sequence_length;
        o.agreement.partial = ParseEnum<SequencePartial>(partial, "partial");
        o.agreement.direction = ParseEnum<SequenceDirection>(direction, "direction");
        o.exclusion = exclusion;
        o.score.window = score_window;
        WithArgumentNames([&] { o.Check(); });
        // evaluate's checks: +inf is a cell without a value, NaN is refused as damage.
        const cv::Mat1f checked = DistancesForEvaluation(cv::Mat1f(view.mat), "matrix");
        UnsupervisedFigures f;
        {
          py::gil_scoped_release release;
          f = UnsupervisedCriteria(checked, layout, o);
        }
        py::dict d;
        d["consistency"] = f.consistency;
        d["distinctiveness"] = f.distinctiveness;
        d["agreement"] = f.agreement;
        d["queries"] = f.queries;
        d["answered"] = f.answered;
        d["agreeing"] = f.agreeing;
        d["gap"] = f.gap;
        d["tolerance"] = f.tolerance;
        d["best"] = py::array_t<int>(static_cast<py::ssize_t>(f.best.size()), f.best.data());
        d["ratio"] = py::array_t<float>(static_cast<py::ssize_t>(f.ratio.size()), f.ratio.data());
        std::vector<bool> agrees(f.agrees.begin(), f.agrees.end());
        py::array_t<bool> a(static_cast<py::ssize_t>(agrees.size()));
        for (std::size_t i = 0; i < agrees.size(); ++i) a.mutable_data()[i] = agrees[i];
        d["agrees"] = a;
        return d;
      },
      py::arg("matrix"), py::kw_only(), py::arg("layout") = py::none(),
      py::arg("reference_frames") = py::none(), py::arg("sequence_length") = d.sequence_length,
      py::arg("partial") = d.partial, py::arg("direction") = d.direction,
      py::arg("exclusion") = d.exclusion, py::arg("score_window") = d.score_window,
      d.Fill(R"doc(unsupervised_criteria(matrix, *, layout=None, reference_frames=None,
    sequence_length=@sequence_length@, partial="@partial@", direction="@direction@",
    exclusion=@exclusion@, score_window=@score_window@) -> dict

The criteria openable_sweep --rank-by and the auto mode (Auto 1) judge a matrix by, with no
ground truth (docs/evaluation.md, "Without ground truth"): each query's best match (answer)
and its ratio to the best rival beyond score_window frames; an answer agrees when the answer
of the nearest query whose sequence shares no frame with it (at least max(L, 10) frames away,
back or else forward) lies where the route says, within max(3, gap / 10) frames.

Args:
    matrix (numpy.ndarray): distances (small = similar), as for evaluate: +inf cells are never
        answers, NaN is refused.
    layout, reference_frames, exclusion: the evaluated block and its candidates, as for
        evaluate.
    sequence_length (int), partial (str), direction (str): the matrix's L, Sequence_partial
        and Sequence_direction (which queries are independent, and which way answers move).
    score_window (int): Match_score_window of the ratio.

Returns:
    dict: consistency (share of the queries whose answer agrees), distinctiveness (mean of 1 -
    ratio, 0 for a query without answer), agreement ((10 consistency + distinctiveness) / 11),
    queries, answered, agreeing, gap and tolerance (frames), and per query row of the block
    best (column, -1 none), ratio and agrees (bool).)doc")
          .c_str());
}

}  // namespace

void RegisterEvaluation(py::module_& m) {
  RegisterCurve(m);
  RegisterEvaluationResult(m);
  RegisterEvaluate(m);
  RegisterUnsupervised(m);
}

}  // namespace openable::python
