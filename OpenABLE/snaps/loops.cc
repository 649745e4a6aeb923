#include "OpenABLE/snaps/loops.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/input_file.h"
#include "OpenABLE/evaluation/matrix_file.h"
#include "OpenABLE/evaluation/pairs_file.h"
#include "OpenABLE/image/preprocess.h"
#include "OpenABLE/io/frame_source.h"

namespace openable::snaps {

int IndexOfFrame(const Trajectory& trajectory, long frame_id, long tolerance) {
  const auto& ids = trajectory.frame_ids;
  const auto it = std::lower_bound(ids.begin(), ids.end(), frame_id);
  int best = -1;
  long best_gap = tolerance + 1;
  if (it != ids.begin()) {
    const long gap = frame_id - *(it - 1);
    if (gap <= tolerance) {
      best = static_cast<int>(it - ids.begin() - 1);
      best_gap = gap;
    }
  }
  if (it != ids.end() && *it - frame_id < best_gap) best = static_cast<int>(it - ids.begin());
  return best;
}

namespace {

// Whether both frames of a pair mapped (by IndexOfFrame, to valid indices) onto their own poses.
bool OnPoses(const Trajectory& trajectory, int qi, long query_frame, int ri, long reference_frame) {
  return trajectory.frame_ids[static_cast<std::size_t>(qi)] == query_frame &&
         trajectory.frame_ids[static_cast<std::size_t>(ri)] == reference_frame;
}

}  // namespace

std::vector<LoopPair> LoopsFromMatrix(const std::string& path, const Trajectory& trajectory,
                                      const MatrixLoopOptions& options, PairCounts* counts) {
  const cv::Mat1f m = ReadMatrixFile(path);
  if (m.rows != m.cols)
    throw InputError("matrix file " + Quoted(path) + ": " + std::to_string(m.rows) + "x" +
                     std::to_string(m.cols) +
                     " is not square; expected the matrix of one sequence");
  return LoopsFromMatrix(m, trajectory, options, counts);
}

namespace {

// Loops from matches whose frames `pose_of(match)` maps to trajectory indices (query,
// reference, and whether both frames are poses exactly), -1 for a frame without a pose: pairs
// that map to no pose or not to query > reference are dropped, one loop per query pose (the
// most similar), every pair counted once.
template <class PoseOf>
std::vector<LoopPair> CollectLoops(const std::vector<FrameMatch>& matches, PoseOf pose_of,
                                   PairCounts* counts) {
  std::map<int, LoopPair> by_query;
  PairCounts n;
  for (const FrameMatch& match : matches) {
    const auto [qi, ri, exact] = pose_of(match);
    if (qi < 0 || ri < 0 || ri >= qi) {
      ++n.dropped;
      continue;
    }
    ++(exact ? n.on_poses : n.associated);
    const LoopPair loop{qi, ri, 1.0 - match.distance};
    auto [it, inserted] = by_query.emplace(qi, loop);
    if (!inserted) {
      ++n.merged;
      if (loop.similarity > it->second.similarity) it->second = loop;
    }
  }
  if (counts) *counts = n;
  std::vector<LoopPair> out;
  for (const auto& [q, loop] : by_query) out.push_back(loop);
  return out;
}

struct Mapped {
  int query, reference;
  bool exact;
};

}  // namespace

std::vector<LoopPair> LoopsFromMatches(const std::vector<FrameMatch>& matches,
                                       const Trajectory& trajectory, long initial, long tolerance,
                                       PairCounts* counts) {
  return CollectLoops(
      matches,
      [&](const FrameMatch& match) {
        const long query_frame = initial + match.query;
        const long reference_frame = initial + match.reference;
        const int qi = IndexOfFrame(trajectory, query_frame, tolerance);
        const int ri = IndexOfFrame(trajectory, reference_frame, tolerance);
        const bool exact =
            qi >= 0 && ri >= 0 && OnPoses(trajectory, qi, query_frame, ri, reference_frame);
        return Mapped{qi, ri, exact};
      },
      counts);
}

int IndexOfTime(const Trajectory& trajectory, double t, double tolerance) {
  const auto& times = trajectory.timestamps;
  if (times.empty()) return -1;
  const auto after = std::lower_bound(times.begin(), times.end(), t);
  auto nearest = after == times.end() ? after - 1 : after;
  if (after != times.begin() && after != times.end() && t - *(after - 1) < *after - t)
    nearest = after - 1;
  return std::abs(*nearest - t) <= tolerance ? static_cast<int>(nearest - times.begin()) : -1;
}

std::vector<LoopPair> LoopsFromMatches(const std::vector<FrameMatch>& matches,
                                       const Trajectory& trajectory,
                                       const MatrixLoopOptions& options, PairCounts* counts) {
  if (options.frame_times.empty() || trajectory.timestamps.empty())
    return LoopsFromMatches(matches, trajectory, options.initial, options.tolerance, counts);
  return CollectLoops(
      matches,
      [&](const FrameMatch& match) {
        const double tq = options.frame_times.at(static_cast<std::size_t>(match.query));
        const double tr = options.frame_times.at(static_cast<std::size_t>(match.reference));
        const int qi = IndexOfTime(trajectory, tq, options.time_tolerance);
        const int ri = IndexOfTime(trajectory, tr, options.time_tolerance);
        const bool exact = qi >= 0 && ri >= 0 && std::abs(trajectory.timestamps[qi] - tq) < 1e-6 &&
                           std::abs(trajectory.timestamps[ri] - tr) < 1e-6;
        return Mapped{qi, ri, exact};
      },
      counts);
}

std::vector<double> ReadFrameTimes(const std::string& path, const std::string& key) {
  std::istringstream in(ReadInputFile(path, key + ": frame times " + Quoted(path),
                                      "expected the file Timestamps_name wrote"));
  std::vector<double> times;
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    const std::size_t start = line.find_first_not_of(" \t\r");
    if (start == std::string::npos || line[start] == '#') continue;
    std::istringstream fields(line);
    long row = -1;
    double t = 0;
    std::string rest;
    if (!(fields >> row >> t) || (fields >> rest) || !std::isfinite(t) ||
        row != static_cast<long>(times.size()))
      throw InputError(key + ": frame times " + Quoted(path) + ":" + std::to_string(number) + ": " +
                       Quoted(line) + "; expected \"" + std::to_string(times.size()) +
                       " <seconds>\" (rows in order, as Timestamps_name writes them)");
    times.push_back(t);
  }
  if (times.empty())
    throw InputError(key + ": frame times " + Quoted(path) +
                     " holds no line; expected one \"<row> <seconds>\" per matrix row");
  return times;
}

std::vector<LoopPair> LoopsFromMatrix(cv::Mat1f m, const Trajectory& trajectory,
                                      const MatrixLoopOptions& options, PairCounts* counts) {
  if (m.rows != m.cols) throw std::invalid_argument("LoopsFromMatrix: matrix not square");
  double max_value = 0;
  cv::minMaxLoc(m, nullptr, &max_value);
  if (max_value > 1) m = m / max_value;
  std::vector<FrameMatch> best_matches;
  for (int q = options.exclusion; q < m.rows; ++q) {
    const float* row = m.ptr<float>(q);
    int best_j = -1;
    float best = 0;
    for (int j = 0; j <= q - options.exclusion; ++j)
      if (best_j < 0 || row[j] < best) {
        best = row[j];
        best_j = j;
      }
    if (best_j < 0 || !(best < options.threshold)) continue;
    best_matches.push_back({q, best_j, best});
  }
  if (!options.frame_times.empty() && static_cast<int>(options.frame_times.size()) != m.rows)
    throw InputError("Snaps_frame_times: " + std::to_string(options.frame_times.size()) +
                     " frame times for a matrix of " + std::to_string(m.rows) +
                     " rows; expected the times of the run that wrote the matrix");
  return LoopsFromMatches(best_matches, trajectory, options, counts);
}

std::vector<LoopPair> LoopsFromCsv(const std::string& path, const Trajectory& trajectory,
                                   long tolerance, int* dropped, int* outside, PairCounts* counts) {
  // The same reader and checks as the evaluation's ground-truth pairs (pairs_file.h): commas
  // or blanks, a header line, comments, 0-based unless a comment says "1-based".
  const PairsFile file = ReadPairsFile(path, -1, "loop pairs file");
  if (trajectory.frame_ids.empty()) throw InputError(file.where + ": the trajectory is empty");
  const long first = trajectory.frame_ids.front(), last = trajectory.frame_ids.back();
  std::vector<LoopPair> out;
  PairCounts n;
  for (const PairsFile::Pair& p : file.pairs) {
    const std::string at = file.where + ":" + std::to_string(p.line);
    // A loop joins the later frame to the earlier one, in either order in the file.
    const long row = static_cast<long>(std::max(p.a, p.b));
    const long col = static_cast<long>(std::min(p.a, p.b));
    if (row == col) {  // a frame with itself: no loop (as the evaluation drops the diagonal)
      ++n.dropped;
      continue;
    }
    bool out_of_range = false;
    for (const long f : {row, col})
      if (f < first || f > last) {
        if (!outside || f < 0)
          throw InputError(at + ": frame " + std::to_string(f) +
                           " outside the trajectory's frames " + std::to_string(first) + ".." +
                           std::to_string(last));
        out_of_range = true;
      }
    if (out_of_range) {
      ++n.outside;
      continue;
    }
    const int qi = IndexOfFrame(trajectory, row, tolerance);
    const int ri = IndexOfFrame(trajectory, col, tolerance);
    if (qi < 0 || ri < 0 || ri >= qi) {
      ++n.dropped;
      continue;
    }
    ++(OnPoses(trajectory, qi, row, ri, col) ? n.on_poses : n.associated);
    out.push_back(LoopPair{qi, ri, 1.0});
  }
  if (dropped) *dropped = n.dropped;
  if (outside) *outside = n.outside;
  if (counts) *counts = n;
  return out;
}

ImageSearchResult SearchLoopsInThumbnails(const std::vector<cv::Mat>& thumbnails,
                                          const Trajectory& trajectory,
                                          const SearchOptions& options) {
  if (static_cast<int>(thumbnails.size()) != trajectory.Size())
    throw std::invalid_argument("SearchLoopsInThumbnails: one thumbnail per pose expected");
  OnlineSnaps snaps(options);
  for (int i = 0; i < trajectory.Size(); ++i) snaps.Step(trajectory.poses[i], thumbnails[i]);
  ImageSearchResult r;
  r.loops = snaps.loops();
  r.corrected = trajectory;
  r.corrected.poses = snaps.corrected();
  r.steps = snaps.search().records();
  r.correction_seconds = snaps.correction_seconds();
  return r;
}

ImageSearchResult SearchLoopsInImages(const std::string& folder, const std::string& extension,
                                      long initial, const Trajectory& trajectory,
                                      const SearchOptions& options) {
  const std::vector<std::string> images = ListImages(folder, extension);
  std::vector<cv::Mat> thumbnails;
  std::vector<double> seconds;
  thumbnails.reserve(trajectory.poses.size());
  for (int i = 0; i < trajectory.Size(); ++i) {
    const long k = trajectory.frame_ids[i] - initial;
    if (k < 0 || k >= static_cast<long>(images.size()))
      throw InputError("image folder " + Quoted(folder) + ": no image for frame " +
                       std::to_string(trajectory.frame_ids[i]) + " (" +
                       std::to_string(images.size()) + " images from frame " +
                       std::to_string(initial) + ")");
    const auto start = std::chrono::steady_clock::now();
    thumbnails.push_back(Thumbnail(ToGray8(ReadImageFile(images[k])), options.thumbnail_scale));
    seconds.push_back(
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  ImageSearchResult r = SearchLoopsInThumbnails(thumbnails, trajectory, options);
  r.thumbnail_seconds = std::move(seconds);
  return r;
}

std::vector<LoopPair> MiddleOfRuns(std::vector<LoopPair> loops, const Trajectory& trajectory,
                                   long run_gap) {
  std::sort(loops.begin(), loops.end(), [](const LoopPair& a, const LoopPair& b) {
    return a.query != b.query ? a.query < b.query : a.reference < b.reference;
  });
  loops.erase(std::unique(loops.begin(), loops.end(),
                          [](const LoopPair& a, const LoopPair& b) {
                            return a.query == b.query && a.reference == b.reference;
                          }),
              loops.end());
  std::vector<LoopPair> kept;
  std::size_t begin = 0;
  for (std::size_t k = 1; k <= loops.size(); ++k) {
    const bool run_ends =
        k == loops.size() || loops[k].query != loops[k - 1].query ||
        trajectory.frame_ids[static_cast<std::size_t>(loops[k].reference)] -
                trajectory.frame_ids[static_cast<std::size_t>(loops[k - 1].reference)] >=
            run_gap;
    if (run_ends) {
      kept.push_back(loops[(begin + k - 1) / 2]);
      begin = k;
    }
  }
  return kept;
}

}  // namespace openable::snaps
