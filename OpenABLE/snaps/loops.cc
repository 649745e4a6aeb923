#include "OpenABLE/snaps/loops.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <map>
#include <stdexcept>
#include <sstream>
#include <string>

#include "OpenABLE/base/error.h"
#include "OpenABLE/evaluation/matrix_file.h"
#include "OpenABLE/io/frame_source.h"
#include "OpenABLE/image/preprocess.h"

namespace openable::snaps {
namespace {

std::string Trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t\r");
  return s.substr(b, e - b + 1);
}

// A non-negative integer written with digits only; false otherwise (or on overflow).
bool ParseFrameId(const std::string& s, long* out) {
  if (s.empty() || s.size() > 15) return false;
  long v = 0;
  for (const char c : s) {
    if (c < '0' || c > '9') return false;
    v = v * 10 + (c - '0');
  }
  *out = v;
  return true;
}

}  // namespace

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

std::vector<LoopPair> LoopsFromMatrix(const std::string& path, const Trajectory& trajectory,
                                      const MatrixLoopOptions& options) {
  const cv::Mat1f m = ReadMatrixFile(path);
  if (m.rows != m.cols)
    throw InputError("matrix file " + Quoted(path) + ": " + std::to_string(m.rows) + "x" +
                     std::to_string(m.cols) +
                     " is not square; expected the matrix of one sequence");
  return LoopsFromMatrix(m, trajectory, options);
}

std::vector<LoopPair> LoopsFromMatrix(cv::Mat1f m, const Trajectory& trajectory,
                                      const MatrixLoopOptions& options) {
  if (m.rows != m.cols) throw std::invalid_argument("LoopsFromMatrix: matrix not square");
  double max_value = 0;
  cv::minMaxLoc(m, nullptr, &max_value);
  if (max_value > 1) m = m / max_value;
  std::map<int, LoopPair> by_query;
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
    const int qi = IndexOfFrame(trajectory, options.initial + q, options.tolerance);
    const int ri = IndexOfFrame(trajectory, options.initial + best_j, options.tolerance);
    if (qi < 0 || ri < 0 || ri >= qi) continue;
    const LoopPair loop{qi, ri, 1.0 - best};
    auto [it, inserted] = by_query.emplace(qi, loop);
    if (!inserted && loop.similarity > it->second.similarity) it->second = loop;
  }
  std::vector<LoopPair> out;
  for (const auto& [q, loop] : by_query) out.push_back(loop);
  return out;
}

std::vector<LoopPair> LoopsFromCsv(const std::string& path, const Trajectory& trajectory,
                                   long tolerance, int* dropped, int* outside) {
  std::ifstream in(path);
  if (!in) throw InputError("loop pairs file " + Quoted(path) + ": cannot be opened");
  if (trajectory.frame_ids.empty())
    throw InputError("loop pairs file " + Quoted(path) + ": the trajectory is empty");
  const long first = trajectory.frame_ids.front(), last = trajectory.frame_ids.back();
  std::vector<LoopPair> out;
  int drop = 0, outside_count = 0;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    const std::string at = "loop pairs file " + Quoted(path) + ":" + std::to_string(number);
    const auto hash = line.find('#');
    const std::string content = Trim(line.substr(0, hash));
    if (content.empty()) continue;
    const auto comma = content.find(',');
    const std::string a = Trim(content.substr(0, comma));
    const std::string b = comma == std::string::npos ? "" : Trim(content.substr(comma + 1));
    long row = 0, col = 0;
    if (comma == std::string::npos || b.find(',') != std::string::npos)
      throw InputError(at + ": " + Quoted(content) +
                       " is not `row,col`; expected two frame numbers");
    if (!ParseFrameId(a, &row))
      throw InputError(at + ": row " + Quoted(a) + " is not a non-negative integer frame number");
    if (!ParseFrameId(b, &col))
      throw InputError(at + ": col " + Quoted(b) + " is not a non-negative integer frame number");
    if (row <= col)
      throw InputError(at + ": row " + a + " <= col " + b + "; expected row = the later frame");
    bool out_of_range = false;
    for (const long f : {row, col})
      if (f < first || f > last) {
        if (!outside)
          throw InputError(at + ": frame " + std::to_string(f) +
                           " outside the trajectory's frames " + std::to_string(first) + ".." +
                           std::to_string(last));
        out_of_range = true;
      }
    if (out_of_range) {
      ++outside_count;
      continue;
    }
    const int qi = IndexOfFrame(trajectory, row, tolerance);
    const int ri = IndexOfFrame(trajectory, col, tolerance);
    if (qi < 0 || ri < 0 || ri >= qi) {
      ++drop;
      continue;
    }
    out.push_back(LoopPair{qi, ri, 1.0});
  }
  if (dropped) *dropped = drop;
  if (outside) *outside = outside_count;
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
