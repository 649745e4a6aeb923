#include "OpenABLE/evaluation/ground_truth.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <opencv2/core.hpp>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/strings.h"
#include "OpenABLE/evaluation/matrix_file.h"
#include "OpenABLE/evaluation/pairs_file.h"
#include "OpenABLE/evaluation/pose_file.h"
#include "OpenABLE/evaluation/text_parsing.h"
#include "OpenABLE/io/npy.h"
#include "OpenABLE/io/npy_objects.h"

namespace openable {
namespace {

using evaluation_internal::ForEachLine;
using evaluation_internal::IsBlank;
using evaluation_internal::Line;
using evaluation_internal::ParseIndex;
using evaluation_internal::ParseNumber;
using evaluation_internal::ReadWholeFile;

namespace fs = std::filesystem;

// ---------------------------------------------------------------------------------------------
// Text files of pairs and poses

// ---------------------------------------------------------------------------------------------
// Options

// The options PairsFromPoses uses.
void CheckPoseOptions(const GroundTruthOptions& o) {
  if (!(std::isfinite(o.radius) && o.radius > 0)) {
    throw InputError("Ground_truth_radius: " + FormatNumber(o.radius) +
                     " is not valid; expected a number > 0");
  }
  if (o.heading_limit != -1.0 && !(o.heading_limit > 0 && o.heading_limit <= 180)) {
    throw InputError("Ground_truth_heading: " + FormatNumber(o.heading_limit) +
                     " is not valid; expected -1 (no limit) or degrees in (0, 180]");
  }
  if (o.min_frame_gap < 0) {
    throw InputError("Ground_truth_min_gap: " + std::to_string(o.min_frame_gap) +
                     " is not valid; expected an integer >= 0");
  }
  if (o.axes != "xyz" && o.axes != "xz" && o.axes != "xy") {
    throw InputError("Ground_truth_axes: " + Quoted(o.axes) +
                     " is not valid; expected xyz, xz or xy");
  }
}

// ---------------------------------------------------------------------------------------------
// Poses

// Positions and unit forward vectors over the chosen axes, flat (3 doubles per frame, the
// unused component 0); has_forward[i] = 0 when frame i has no usable forward vector.
struct Projected {
  std::vector<double> position;
  std::vector<double> forward;
  std::vector<char> has_forward;
};

Projected Project(const std::vector<FramePose>& poses, const std::string& axes) {
  const bool use[3] = {true, axes != "xz", axes != "xy"};
  Projected p;
  p.position.assign(poses.size() * 3, 0.0);
  p.forward.assign(poses.size() * 3, 0.0);
  p.has_forward.assign(poses.size(), 0);
  for (std::size_t i = 0; i < poses.size(); ++i) {
    double f[3] = {0, 0, 0};
    double norm2 = 0;
    for (int k = 0; k < 3; ++k) {
      if (!use[k]) continue;
      p.position[3 * i + k] = poses[i].position[k];
      f[k] = poses[i].forward[k];
      norm2 += f[k] * f[k];
    }
    // A direction (nearly) perpendicular to the plane has no heading in it.
    const double norm = std::sqrt(norm2);
    if (!poses[i].has_forward || !(norm > 1e-9)) continue;
    for (int k = 0; k < 3; ++k) p.forward[3 * i + k] = f[k] / norm;
    p.has_forward[i] = 1;
  }
  return p;
}

// The poses [first, first + count) of a pose file, or an InputError saying the file is short.
std::vector<FramePose> PosesOfRun(const std::string& path, GroundTruthType type, int first,
                                  int count, const std::string& frames_what) {
  std::vector<FramePose> poses = ReadPoses(path, type);
  const std::int64_t needed = static_cast<std::int64_t>(first) + count;
  if (static_cast<std::int64_t>(poses.size()) < needed) {
    throw InputError(std::string(type.Format().label) + " " + Quoted(path) + ": file has " +
                     std::to_string(poses.size()) + " poses, the run needs " +
                     std::to_string(needed) + " (Initial_image " + std::to_string(first) + " + " +
                     std::to_string(count) + " " + frames_what + ")");
  }
  return std::vector<FramePose>(poses.begin() + first, poses.begin() + needed);
}

// The poses of frames that carry times (`times`, one per frame of the traversal): each frame
// takes the pose with the nearest timestamp, which must be within `tolerance` seconds.
std::vector<FramePose> PosesByTime(const std::string& path, GroundTruthType type,
                                   const std::vector<double>& times, double tolerance,
                                   const std::string& frames_what) {
  const std::vector<FramePose> lines = ReadPoses(path, type);
  std::vector<FramePose> poses;
  poses.reserve(times.size());
  for (std::size_t i = 0; i < times.size(); ++i) {
    // Timestamps increase (ReadPoseFile checks it): the nearest is beside the first >= t.
    const auto after =
        std::lower_bound(lines.begin(), lines.end(), times[i],
                         [](const FramePose& line, double t) { return line.time < t; });
    auto nearest = after == lines.end() ? after - 1 : after;
    if (after != lines.begin() && after != lines.end() &&
        times[i] - (after - 1)->time < after->time - times[i])
      nearest = after - 1;
    const double gap = std::abs(nearest->time - times[i]);
    if (!(gap <= tolerance)) {
      std::string frame = frames_what;  // "frames", "query frames": one of them
      if (!frame.empty() && frame.back() == 's') frame.pop_back();
      char text[240];
      std::snprintf(text, sizeof text,
                    ": no pose within %g s of %s %zu (time %.6f; the nearest, line %d, is %.6f "
                    "s away); expected a ground truth that covers the frames, or a larger "
                    "Ground_truth_time_tolerance",
                    tolerance, frame.c_str(), i, times[i], nearest->line, gap);
      throw InputError(std::string(type.Format().label) + " " + Quoted(path) + text);
    }
    poses.push_back(*nearest);
  }
  return poses;
}

// The poses of the frames of one traversal: by time when the frames carry times (tum), else
// the lines [first, first + count) (PosesOfRun).
std::vector<FramePose> TraversalPoses(const GroundTruthOptions& o, const std::string& path,
                                      const std::vector<double>& times, int count,
                                      const std::string& frames_what) {
  if (o.type.Format().timestamps && !times.empty()) {
    if (static_cast<int>(times.size()) != count)
      throw std::logic_error("TraversalPoses: one time per frame expected");
    return PosesByTime(path, o.type, times, o.time_tolerance, frames_what);
  }
  return PosesOfRun(path, o.type, o.first_frame, count, frames_what);
}

// ---------------------------------------------------------------------------------------------
// Loaders; each fills gt->matches (unsorted, maybe with duplicates) and gt->dropped.

void LoadMatrix(const GroundTruthOptions& o, const EvaluationLayout& layout, int full_rows,
                int full_cols, GroundTruth* gt) {
  cv::Mat1f m;
  try {
    m = ReadMatrixFile(o.path);
  } catch (const InputError& e) {
    throw InputError(std::string("ground truth ") + e.what());
  }
  const std::string where = "ground truth matrix file " + Quoted(o.path);
  const int rows = layout.queries, cols = layout.references;
  auto size_text = [](int r, int c) { return std::to_string(r) + "x" + std::to_string(c); };
  cv::Mat1f block;
  if (m.rows == rows && m.cols == cols) {
    block = m;
  } else if (m.rows == full_rows && m.cols == full_cols) {
    block = m(cv::Rect(layout.col_offset, layout.row_offset, cols, rows));
  } else {
    std::string expected = size_text(rows, cols) + " (the evaluated block)";
    if (full_rows != rows || full_cols != cols) {
      expected += " or " + size_text(full_rows, full_cols) + " (the whole distance matrix)";
    }
    throw InputError(where + ": " + size_text(m.rows, m.cols) + " (rows x columns); expected " +
                     expected +
                     (o.first_frame > 0 ? "; a matrix is not cut at Initial_image" : ""));
  }
  const bool loop = layout.kind == EvaluationLayout::Kind::kLoopClosure;
  for (int r = 0; r < rows; ++r) {
    const float* row = block[r];
    for (int c = 0; c < cols; ++c) {
      const float v = row[c];
      if (!std::isfinite(v)) {
        throw InputError(where + ": cell (" + std::to_string(r) + ", " + std::to_string(c) +
                         ") of the block is " + FormatNumber(v) +
                         "; expected 0 (different places) or a non-zero number (same place)");
      }
      if (v == 0.f) continue;
      if (!loop) {
        gt->matches[static_cast<std::size_t>(r)].push_back(c);
      } else if (r == c) {
        ++gt->dropped;
      } else {
        gt->matches[static_cast<std::size_t>(std::max(r, c))].push_back(std::min(r, c));
      }
    }
  }
}

void LoadPairs(const GroundTruthOptions& o, const EvaluationLayout& layout, int, int,
               GroundTruth* gt) {
  const PairsFile file = ReadPairsFile(o.path, o.base, "ground truth pairs");
  if (file.header_line > 0)
    gt->skipped_header = "line " + std::to_string(file.header_line) + " of " + Quoted(o.path) +
                         ": " + Quoted(file.header);
  const bool loop = layout.kind == EvaluationLayout::Kind::kLoopClosure;
  const int base = file.base;
  const std::int64_t rows = layout.queries, cols = layout.references;
  const std::int64_t first = o.first_frame;
  const bool ranged = first > 0 || o.range_selected;
  for (const PairsFile::Pair& p : file.pairs) {
    const std::int64_t a = p.a - first, b = p.b - first;
    const bool negative = p.a < 0 || p.b < 0;
    const bool outside = a < 0 || b < 0 || a >= rows || b >= (loop ? rows : cols);
    if (negative || (outside && !ranged)) {
      std::string range;
      if (ranged) {
        range = "expected indices >= " + std::to_string(base);
      } else if (loop) {
        range = "expected frame indices in [" + std::to_string(base) + ", " +
                std::to_string(base + rows - 1) + "] (" + std::to_string(rows) + " frames)";
      } else {
        range = "expected query indices in [" + std::to_string(base) + ", " +
                std::to_string(base + rows - 1) + "] and reference indices in [" +
                std::to_string(base) + ", " + std::to_string(base + cols - 1) + "]";
      }
      throw InputError(file.where + ":" + std::to_string(p.line) + ": pair " +
                       std::to_string(p.a + base) + "," + std::to_string(p.b + base) +
                       " is out of range; " + range + file.base_note);
    }
    if (outside || (loop && a == b)) {  // outside the selected frames, or diagonal
      ++gt->dropped;
      continue;
    }
    if (loop) {
      gt->matches[static_cast<std::size_t>(std::max(a, b))].push_back(
          static_cast<int>(std::min(a, b)));
    } else {
      gt->matches[static_cast<std::size_t>(a)].push_back(static_cast<int>(b));
    }
  }
}

// Pose formats: the pairs from the poses of the run's frames (PairsFromPoses).
void LoadPoses(const GroundTruthOptions& o, const EvaluationLayout& layout, GroundTruth* gt) {
  if (layout.kind == EvaluationLayout::Kind::kLoopClosure) {
    const std::vector<FramePose> poses =
        TraversalPoses(o, o.path, o.frame_times, layout.queries, "frames");
    gt->matches = PairsFromPoses(poses, {}, o);
    for (std::size_t q = 0; q < gt->matches.size(); ++q) {  // a gap of 0 lets (q, q) in
      auto& m = gt->matches[q];
      if (!m.empty() && m.back() == static_cast<int>(q)) {
        m.pop_back();
        ++gt->dropped;
      }
    }
    return;
  }
  if (o.path_2.empty()) {
    throw InputError(
        "Ground_truth_2: empty; expected the poses of the query traversal (with two "
        "traversals Ground_truth holds the reference poses)");
  }
  if (layout.references == 0) return;  // an empty reference would mean loop closure below
  const std::vector<FramePose> reference =
      TraversalPoses(o, o.path, o.frame_times, layout.references, "reference frames");
  const std::vector<FramePose> queries =
      TraversalPoses(o, o.path_2, o.frame_times_2, layout.queries, "query frames");
  gt->matches = PairsFromPoses(queries, reference, o);
}

// The formats' readers and loaders (GroundTruthFormats).

// KITTI and TUM: the pose reader SNAPS uses too (pose_file.h), one format, one set of checks
// (a rotation that is not one, timestamps out of order, ...).
std::vector<FramePose> ReadPoseLines(const std::string& path, PoseFileFormat format,
                                     const char* label) {
  std::vector<FramePose> poses;
  for (const PoseFileLine& line : ReadPoseFile(path, format, label)) {
    FramePose pose;
    pose.position = line.translation;
    pose.forward = line.rotation.col(2);  // the optical axis (R is orthonormal)
    pose.has_forward = true;
    if (format == PoseFileFormat::kTum) pose.time = line.timestamp;
    pose.line = line.line;
    poses.push_back(pose);
  }
  return poses;
}

std::vector<FramePose> ReadKittiPoses(const std::string& path, const char* label) {
  return ReadPoseLines(path, PoseFileFormat::kKitti, label);
}

std::vector<FramePose> ReadTumPoses(const std::string& path, const char* label) {
  return ReadPoseLines(path, PoseFileFormat::kTum, label);
}

// Positions: x,y[,z] per line (CSV or whitespace), '#' comments, a header line allowed.
std::vector<FramePose> ReadPositions(const std::string& path, const char* label) {
  std::vector<FramePose> poses;
  const std::string where = std::string(label) + " " + Quoted(path);
  const std::string data = ReadWholeFile(path, where);
  bool first_content = true;
  std::size_t position_count = 0;  // numbers per line of a positions file
  int position_line = 0;
  std::vector<double> v;
  ForEachLine(data, [&](const Line& line) {
    if (line.fields.empty()) return;
    const std::string at = where + ":" + std::to_string(line.number);
    const bool header = first_content && evaluation_internal::IsHeaderLine(line);
    first_content = false;
    if (header) return;  // "x,y,z"
    v.resize(line.fields.size());
    for (std::size_t k = 0; k < line.fields.size(); ++k) {
      if (!ParseNumber(line.fields[k], &v[k]) || !std::isfinite(v[k])) {
        throw InputError(at + ": value " + Quoted(line.fields[k]) + " in column " +
                         std::to_string(k + 1) + " is not a finite number");
      }
    }
    const std::string count = std::to_string(v.size()) + (v.size() == 1 ? " number" : " numbers");
    FramePose pose;
    if (v.size() != 2 && v.size() != 3) {
      throw InputError(at + ": line has " + count + "; expected 2 or 3 (x, y[, z])");
    }
    if (position_count == 0) {
      position_count = v.size();
      position_line = line.number;
    } else if (v.size() != position_count) {
      throw InputError(at + ": line has " + count + "; expected " + std::to_string(position_count) +
                       " like the first position (line " + std::to_string(position_line) + ")");
    }
    pose.position = Eigen::Vector3d(v[0], v[1], v.size() == 3 ? v[2] : 0.0);
    pose.line = line.number;
    poses.push_back(pose);
  });
  if (poses.empty()) {
    throw InputError(where +
                     ": no poses; expected one pose per line (the file is empty or "
                     "holds only comments)");
  }
  return poses;
}

}  // namespace

void CheckAlignedLengths(int queries, int references) {
  // Frame i of one traversal is frame i of the other only when both have as many frames:
  // with one longer, its frames past the other's end would have no place, and the places of
  // the others would drift (evaluated, a run that finds every place scores near 0).
  if (queries != references)
    throw InputError(
        "Ground_truth_type: aligned pairs query frame i with reference frame i, "
        "but the query traversal has " +
        std::to_string(queries) + " frames and the reference traversal " +
        std::to_string(references) +
        "; expected traversals of equal length (else a pairs or poses ground "
        "truth)");
}

namespace {

void LoadAligned(const GroundTruthOptions&, const EvaluationLayout& layout, int, int,
                 GroundTruth* gt) {
  if (layout.kind == EvaluationLayout::Kind::kLoopClosure) {
    throw InputError(
        "Ground_truth_type: aligned needs two traversals (Images_path_2 or Frame_mode 2)");
  }
  CheckAlignedLengths(layout.queries, layout.references);
  for (int q = 0; q < layout.queries; ++q) {
    gt->matches[static_cast<std::size_t>(q)].push_back(q);
  }
}

// VPR-Bench's ground_truth_new.npy: an object array, row q = [query index, the indices of
// its true references] (a list, tuple, range or integer array). The row's position is the
// query, as performance_comparison.py reads it (ground_truth_info[query][1]); indices count
// from the start of each traversal, as Initial_image does.
std::int64_t IntegerOf(const PyValue& v, bool* ok) {
  *ok = true;
  if (v.kind == PyValue::Kind::kInt || v.kind == PyValue::Kind::kBool) return v.integer;
  if (v.kind == PyValue::Kind::kFloat && std::floor(v.real) == v.real && std::fabs(v.real) < 9.0e15)
    return static_cast<std::int64_t>(v.real);
  *ok = false;
  return 0;
}

void LoadVprBench(const GroundTruthOptions& o, const EvaluationLayout& layout, int, int,
                  GroundTruth* gt) {
  if (layout.kind == EvaluationLayout::Kind::kLoopClosure)
    throw InputError(
        "Ground_truth_type: vpr_bench needs two traversals (Images_path_2 or Frame_mode 2): "
        "its file lists the true references of each query");
  const std::string where = "VPR-Bench ground truth " + Quoted(o.path);
  const std::string bytes = ReadWholeFile(o.path, where);
  const std::int64_t first = o.first_frame;
  const bool ranged = first > 0 || o.range_selected;
  // The header first: the pickle is read for as many queries as the run has (for a range of
  // frames, as many as the header says), each listing at most every reference frame up to the
  // run's last and 64 more (VPR-Bench's files name a few past the last); larger is refused
  // before it is made.
  const std::vector<std::int64_t> header = ReadNpyHeader(bytes, where).shape;
  const bool header_pairs = header.size() == 2 && header[1] == 2;
  if (header_pairs && !ranged && header[0] != layout.queries)
    throw InputError(where + ": " + std::to_string(header[0]) + " queries; expected " +
                     std::to_string(layout.queries) + ", the frames of the query traversal");
  const std::int64_t queries = header_pairs ? header[0] : layout.queries;
  const std::int64_t listed = first + layout.references + 64;
  NpyObjectLimits limits;
  if (queries >= 0 && queries < (limits.values - 1) / (2 + listed))
    limits.values = 1 + queries * (2 + listed);
  limits.range = std::min(limits.range, listed);
  limits.expected = std::to_string(queries) + " queries listing at most " + std::to_string(listed) +
                    " reference indices each: the " + std::to_string(first + layout.references) +
                    " reference frames up to the run's last, and 64 more";
  const NpyObjects gt_file = DecodeNpyObjects(bytes, where, limits);
  const bool pairs = gt_file.shape.size() == 2 && gt_file.shape[1] == 2;
  if (!pairs)
    throw InputError(where + ": an array of shape " + NpyShapeText(gt_file.shape) +
                     "; expected (queries, 2): per query its index and the list of its true "
                     "references, as VPR-Bench's ground_truth_new.npy");
  const std::int64_t rows = gt_file.shape[0];
  for (std::int64_t i = 0; i < rows; ++i) {
    const PyValue& list = *gt_file.items[static_cast<std::size_t>(2 * i + 1)];
    std::vector<std::int64_t> refs;
    bool ok = false;
    if (list.kind == PyValue::Kind::kList || list.kind == PyValue::Kind::kTuple ||
        list.kind == PyValue::Kind::kArray) {
      for (const auto& item : list.items) {
        refs.push_back(IntegerOf(*item, &ok));
        if (!ok) break;
      }
      ok = ok || list.items.empty();
    } else {
      refs.push_back(IntegerOf(list, &ok));  // one index alone
    }
    if (!ok)
      throw InputError(where + ": row " + std::to_string(i) +
                       " does not list reference indices (integers) in its second column");
    const std::int64_t q = i - first;
    for (std::int64_t r : refs) {
      if (r < 0)
        throw InputError(where + ": row " + std::to_string(i) + " names reference " +
                         std::to_string(r) + "; expected indices >= 0");
      // An index past the last reference is dropped, not refused: VPR-Bench's own files list
      // them (Gardens Point's last queries name references 200 and 201 of 0-199), and its
      // code only asks whether a retrieved index is in the list.
      const std::int64_t c = r - first;
      if (q < 0 || q >= layout.queries || c < 0 || c >= layout.references) {
        ++gt->dropped;
        continue;
      }
      gt->matches[static_cast<std::size_t>(q)].push_back(static_cast<int>(c));
    }
  }
}

// VPR_Tutorial's ground truth: GThard and GTsoft, boolean matrices of the database
// (reference traversal, rows) by the queries (columns), as .npy files or members GThard.npy
// and GTsoft.npy of a .npz (its datasets' GT.npz), told apart by the ZIP signature. A file is
// read once, whichever of its members are taken.
struct TutorialFile {
  std::string bytes;
  std::string where;  // "VPR_Tutorial ground truth \"GT.npz\"" in messages
  bool npz = false;
};

TutorialFile ReadTutorialFile(const std::string& path, const std::string& what) {
  TutorialFile f;
  f.where = what + " " + Quoted(path);
  f.bytes = ReadWholeFile(path, f.where);
  f.npz = IsNpzArchive(f.bytes);
  return f;
}

// Refuses a matrix of `rows` x `cols` that is not references x queries.
void CheckTutorialSize(std::int64_t rows, std::int64_t cols, const std::string& what,
                       const EvaluationLayout& layout, const GroundTruthOptions& o) {
  if (rows != layout.references || cols != layout.queries)
    throw InputError(what + ": " + std::to_string(rows) + "x" + std::to_string(cols) +
                     " (database x queries); expected " + std::to_string(layout.references) + "x" +
                     std::to_string(layout.queries) + ": the " + std::to_string(layout.references) +
                     " reference frames (rows, VPR_Tutorial's database) by the " +
                     std::to_string(layout.queries) + " queries" +
                     (o.first_frame > 0 || o.range_selected
                          ? "; a matrix is not cut at Initial_image or Final_image"
                          : ""));
}

// The matrix of a .npy file, or the member `member` of a .npz; none when an optional member
// is not in the archive (a required one: NpzMember's error, naming those there are). Its size
// is checked before its cells are read: a member's declared size against the most a matrix of
// references x queries takes, then the shape its header gives (`what` names the file).
std::optional<cv::Mat1f> TutorialMatrix(const TutorialFile& f, const std::string& member,
                                        bool required, const std::string& what,
                                        const EvaluationLayout& layout,
                                        const GroundTruthOptions& o) {
  std::string inflated;
  std::string_view bytes = f.bytes;
  std::string where = f.where;
  if (f.npz) {
    const std::string wanted = member + ".npy";
    if (!required) {
      const std::vector<std::string> names = NpzMemberNames(f.bytes, f.where);
      if (std::find(names.begin(), names.end(), wanted) == names.end()) return std::nullopt;
    }
    NpzLimit limit;
    const auto cells =
        static_cast<std::uint64_t>(layout.references) * static_cast<std::uint64_t>(layout.queries);
    limit.bytes = 65536 + 8 * cells;
    limit.expected = "a " + std::to_string(layout.references) + "x" +
                     std::to_string(layout.queries) +
                     " matrix (database x queries) takes 8 bytes a cell at most, and a header "
                     "of 64 KiB at most";
    inflated = NpzMember(f.bytes, wanted, f.where, limit);
    bytes = inflated;
    where = f.where + " (" + wanted + ")";
  }
  const std::vector<std::int64_t> shape = ReadNpyHeader(bytes, where).shape;
  if (shape.size() == 2) CheckTutorialSize(shape[0], shape[1], what, layout, o);
  return DecodeNpyMatrix(bytes, where);
}

// Adds the cells of `m` (references x queries, non-zero = same place) to `out` per query.
void TutorialCells(const cv::Mat1f& m, const std::string& what, const EvaluationLayout& layout,
                   const GroundTruthOptions& o, std::vector<std::vector<int>>* out) {
  CheckTutorialSize(m.rows, m.cols, what, layout, o);
  for (int r = 0; r < m.rows; ++r)
    for (int q = 0; q < m.cols; ++q) {
      const float v = m(r, q);
      if (!std::isfinite(v))
        throw InputError(what + ": cell (" + std::to_string(r) + ", " + std::to_string(q) +
                         ") is " + FormatNumber(v) + "; expected 0 or 1");
      if (v != 0.f) (*out)[static_cast<std::size_t>(q)].push_back(r);
    }
}

void LoadVprTutorial(const GroundTruthOptions& o, const EvaluationLayout& layout, int, int,
                     GroundTruth* gt) {
  if (layout.kind == EvaluationLayout::Kind::kLoopClosure)
    throw InputError(
        "Ground_truth_type: vpr_tutorial needs two traversals (Images_path_2 or Frame_mode 2): "
        "its matrices are the database (reference traversal) by the queries");
  const TutorialFile file = ReadTutorialFile(o.path, "VPR_Tutorial ground truth");
  TutorialCells(*TutorialMatrix(file, "GThard", true, file.where, layout, o), file.where, layout, o,
                &gt->matches);
  // GTsoft: Ground_truth_soft, else the archive's own when it has one.
  std::optional<cv::Mat1f> soft_matrix;
  const std::string& soft_path = o.soft_path;
  const std::string soft_what =
      "VPR_Tutorial soft ground truth " + Quoted(soft_path.empty() ? o.path : soft_path);
  if (!soft_path.empty()) {
    soft_matrix = TutorialMatrix(ReadTutorialFile(soft_path, "VPR_Tutorial soft ground truth"),
                                 "GTsoft", true, soft_what, layout, o);
  } else if (file.npz) {
    soft_matrix = TutorialMatrix(file, "GTsoft", false, soft_what, layout, o);
  }
  if (!soft_matrix) return;
  std::vector<std::vector<int>> soft(static_cast<std::size_t>(layout.queries));
  TutorialCells(*soft_matrix, soft_what, layout, o, &soft);
  gt->soft = std::move(soft);
}
}  // namespace

GroundTruthType ParseGroundTruthType(const std::string& name) {
  if (name.empty()) return GroundTruthType::kNone;
  const std::string lower = Lower(name);
  if (lower == "none") return GroundTruthType::kNone;
  for (const GroundTruthFormat& format : GroundTruthFormats())
    if (lower == format.name) return GroundTruthType(format.name);
  throw InputError("Ground_truth_type: " + Quoted(name) + " is not valid; expected " +
                   GroundTruthFormatList() + " (or empty: no evaluation)");
}

std::string GroundTruthTypeName(GroundTruthType type) {
  return type.IsNone() ? "none" : type.Format().name;
}

const GroundTruthFormat& GroundTruthType::Format() const {
  for (const GroundTruthFormat& format : GroundTruthFormats())
    if (name_ == format.name) return format;
  throw std::logic_error("GroundTruthType: no format named \"" + std::string(name_) + "\"");
}

const GroundTruthType GroundTruthType::kNone{};
const GroundTruthType GroundTruthType::kMatrix{"matrix"};
const GroundTruthType GroundTruthType::kPairs{"pairs"};
const GroundTruthType GroundTruthType::kAligned{"aligned"};
const GroundTruthType GroundTruthType::kKitti{"kitti"};
const GroundTruthType GroundTruthType::kTum{"tum"};
const GroundTruthType GroundTruthType::kPositions{"positions"};
const GroundTruthType GroundTruthType::kVprBench{"vpr_bench"};
const GroundTruthType GroundTruthType::kVprTutorial{"vpr_tutorial"};

const std::vector<GroundTruthFormat>& GroundTruthFormats() {
  static const std::vector<GroundTruthFormat> formats = {
      {"matrix", "a binary matrix: 0/1 text, an image (non-zero = same place) or .npy",
       "ground truth matrix file", true, false, nullptr, false, false, &LoadMatrix},
      {"pairs", "a list of pairs row,col (CSV or whitespace)", "ground truth pairs", true, false,
       nullptr, false, false, &LoadPairs},
      {"aligned", "two traversals frame by frame: query i is reference i (no file)",
       "aligned traversals", false, true, nullptr, false, false, &LoadAligned},
      {"kitti", "KITTI poses: 12 numbers per line, a 3x4 camera-to-world matrix", "KITTI poses",
       true, false, &ReadKittiPoses, true, false, nullptr},
      {"tum", "a TUM trajectory: timestamp tx ty tz qx qy qz qw per line", "TUM trajectory", true,
       false, &ReadTumPoses, true, true, nullptr},
      {"positions", "positions x,y[,z] per line (no orientation)", "positions", true, false,
       &ReadPositions, false, false, nullptr},
      {"vpr_bench", "VPR-Bench's ground_truth_new.npy: per query, the list of its true references",
       "VPR-Bench ground truth", true, true, nullptr, false, false, &LoadVprBench},
      {"vpr_tutorial", "VPR_Tutorial's GThard (database x queries, .npy, or GT.npz with GTsoft)",
       "VPR_Tutorial ground truth", true, true, nullptr, false, false, &LoadVprTutorial},
  };
  return formats;
}

std::string GroundTruthFormatList(const char* last_separator) {
  const std::vector<GroundTruthFormat>& formats = GroundTruthFormats();
  std::string out;
  for (std::size_t i = 0; i < formats.size(); ++i) {
    if (i > 0) out += i + 1 == formats.size() ? last_separator : ", ";
    out += formats[i].name;
  }
  return out;
}

void GroundTruthOptions::Check() const {
  if (!type.IsNone() && type.Format().needs_file && path.empty()) {
    throw InputError(
        "Ground_truth: empty; expected the path of the ground-truth file "
        "(Ground_truth_type " +
        GroundTruthTypeName(type) + ")");
  }
  if (!soft_path.empty() && type != GroundTruthType::kVprTutorial)
    throw InputError("Ground_truth_soft: " + Quoted(soft_path) +
                     " is VPR_Tutorial's soft ground truth; expected Ground_truth_type "
                     "vpr_tutorial (it is " +
                     GroundTruthTypeName(type) + "), or an empty value");
  if (base < -1 || base > 1) {
    throw InputError("Ground_truth_base: " + std::to_string(base) +
                     " is not valid; expected -1 (from a comment of the file), 0 or 1");
  }
  if (first_frame < 0) {
    throw InputError("Initial_image: " + std::to_string(first_frame) +
                     " is not valid; expected an integer >= 0");
  }
  CheckPoseOptions(*this);
  if (!(time_tolerance >= 0) || !std::isfinite(time_tolerance)) {
    throw InputError("Ground_truth_time_tolerance: " + FormatNumber(time_tolerance) +
                     " is not valid; expected seconds >= 0");
  }
  if (!type.IsNone() && type.Format().read_poses && !type.Format().orientations &&
      heading_limit >= 0) {
    std::string oriented;
    for (const GroundTruthFormat& f : GroundTruthFormats())
      if (f.read_poses && f.orientations)
        oriented += std::string(oriented.empty() ? "" : " or ") + f.name;
    throw InputError("Ground_truth_heading: " + FormatNumber(heading_limit) +
                     " needs orientations, but " + type.Format().label +
                     " have no orientation; expected -1 (no limit), or "
                     "Ground_truth_type " +
                     oriented);
  }
}

GroundTruth LoadGroundTruth(const GroundTruthOptions& options, const EvaluationLayout& layout,
                            int full_rows, int full_cols) {
  options.Check();
  const bool loop = layout.kind == EvaluationLayout::Kind::kLoopClosure;
  if (layout.queries < 0 || layout.references < 0 || layout.row_offset < 0 ||
      layout.col_offset < 0 || layout.row_offset + layout.queries > full_rows ||
      layout.col_offset + layout.references > full_cols ||
      (loop && layout.queries != layout.references)) {
    throw std::logic_error("LoadGroundTruth: layout " + std::to_string(layout.queries) + "x" +
                           std::to_string(layout.references) + " at (" +
                           std::to_string(layout.row_offset) + ", " +
                           std::to_string(layout.col_offset) + ") does not fit a " +
                           std::to_string(full_rows) + "x" + std::to_string(full_cols) + " matrix");
  }
  GroundTruth gt;
  gt.references = layout.references;
  gt.matches.assign(static_cast<std::size_t>(layout.queries), {});
  if (options.type.IsNone()) return gt;
  const GroundTruthFormat& format = options.type.Format();
  if (format.read_poses)
    LoadPoses(options, layout, &gt);
  else
    format.load(options, layout, full_rows, full_cols, &gt);
  for (auto& m : gt.matches) {
    std::sort(m.begin(), m.end());
    m.erase(std::unique(m.begin(), m.end()), m.end());
  }
  // GTsoft keeps the cells outside GThard: those the protocol ignores.
  for (std::size_t q = 0; q < gt.soft.size(); ++q) {
    std::vector<int> only;
    for (int c : gt.soft[q])
      if (!std::binary_search(gt.matches[q].begin(), gt.matches[q].end(), c)) only.push_back(c);
    gt.soft[q] = std::move(only);
  }
  return gt;
}

std::vector<FramePose> ReadPoses(const std::string& path, GroundTruthType type) {
  if (type.IsNone() || !type.Format().read_poses)
    throw std::logic_error("ReadPoses: type " + GroundTruthTypeName(type) + " is not a pose type");
  return type.Format().read_poses(path, type.Format().label);
}

std::vector<std::vector<int>> PairsFromPoses(const std::vector<FramePose>& queries,
                                             const std::vector<FramePose>& reference,
                                             const GroundTruthOptions& options) {
  CheckPoseOptions(options);
  const bool loop = reference.empty();
  const bool heading = options.heading_limit >= 0;
  if (heading) {
    auto oriented = [](const FramePose& p) { return p.has_forward; };
    if (!std::all_of(queries.begin(), queries.end(), oriented) ||
        !std::all_of(reference.begin(), reference.end(), oriented)) {
      throw InputError("Ground_truth_heading: " + FormatNumber(options.heading_limit) +
                       " needs orientations, but the poses have none; expected -1 (no limit)");
    }
  }
  const Projected q_proj = Project(queries, options.axes);
  const Projected r_proj = loop ? Projected() : Project(reference, options.axes);
  const Projected& rp = loop ? q_proj : r_proj;
  const double radius = options.radius;
  const double limit = options.heading_limit;
  constexpr double kDegrees = 180.0 / 3.14159265358979323846;

  std::vector<std::vector<int>> matches(queries.size());
  const auto n_ref = static_cast<std::int64_t>(loop ? queries.size() : reference.size());
  for (std::size_t q = 0; q < queries.size(); ++q) {
    const std::int64_t end =
        loop ? std::min<std::int64_t>(static_cast<std::int64_t>(q) - options.min_frame_gap + 1,
                                      n_ref)
             : n_ref;
    const double* pq = &q_proj.position[3 * q];
    const double* fq = &q_proj.forward[3 * q];
    if (heading && !q_proj.has_forward[q]) continue;
    for (std::int64_t j = 0; j < end; ++j) {
      const auto ju = static_cast<std::size_t>(j);
      const double* pj = &rp.position[3 * ju];
      const double dx = pq[0] - pj[0], dy = pq[1] - pj[1], dz = pq[2] - pj[2];
      if (!(std::sqrt(dx * dx + dy * dy + dz * dz) < radius)) continue;
      if (heading) {
        if (!rp.has_forward[ju]) continue;
        const double* fj = &rp.forward[3 * ju];
        const double dot = fq[0] * fj[0] + fq[1] * fj[1] + fq[2] * fj[2];
        const double cx = fq[1] * fj[2] - fq[2] * fj[1];
        const double cy = fq[2] * fj[0] - fq[0] * fj[2];
        const double cz = fq[0] * fj[1] - fq[1] * fj[0];
        const double angle = std::atan2(std::sqrt(cx * cx + cy * cy + cz * cz), dot) * kDegrees;
        if (!(angle < limit)) continue;
      }
      matches[q].push_back(static_cast<int>(j));
    }
  }
  return matches;
}

}  // namespace openable
