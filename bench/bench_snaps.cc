// SNAPS latency and loops on KITTI 00 frames 0-1699 (../shared/datasets/kitti00_first1700):
// thumbnails at 1/6, the online search with the ground-truth poses as the trajectory (and, when
// present, SO-DSO's drifting keyframes), per-frame latency of the search (no candidate /
// candidates compared) and of the correction: mean and quartiles (the paper's Fig. 5).
// Usage: bench_snaps [datasets folder]
#include <cmath>
#include <cstdio>
#include <fstream>
#include <opencv2/core.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "OpenABLE/image/preprocess.h"
#include "OpenABLE/io/frame_source.h"
#include "OpenABLE/snaps/loops.h"

using namespace openable::snaps;

namespace {

// KITTI poses: 12 numbers per line (with_id: a frame id first); world_to_camera: inverted.
Trajectory ReadPoses(const std::string& path, bool with_id, bool world_to_camera) {
  Trajectory t;
  t.format = with_id ? TrajectoryFormat::kKittiWithId : TrajectoryFormat::kKitti;
  std::ifstream in(path);
  std::string line;
  for (long n = 0; std::getline(in, line);) {
    std::istringstream s(line);
    long id = n;
    if (with_id && !(s >> id)) continue;
    Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) s >> m(r, c);
    if (!s) continue;
    Eigen::Isometry3d p(m);
    if (world_to_camera) p = p.inverse();
    t.poses.push_back(p);
    t.frame_ids.push_back(id);
    ++n;
  }
  return t;
}

void Print(const char* what, const std::vector<double>& seconds) {
  const LatencyStats s = Summarize(seconds);
  std::printf("%-34s n=%5d mean %10.3g s  min %9.3g  q1 %9.3g  median %9.3g  q3 %9.3g  max %9.3g\n",
              what, s.count, s.mean, s.min, s.q1, s.median, s.q3, s.max);
}

void Report(const char* name, const Trajectory& trajectory, const Trajectory& truth,
            const std::vector<cv::Mat>& all_thumbnails, const SearchOptions& options) {
  std::vector<cv::Mat> thumbnails;
  for (const long id : trajectory.frame_ids) thumbnails.push_back(all_thumbnails[id]);
  const ImageSearchResult r = SearchLoopsInThumbnails(thumbnails, trajectory, options);
  std::vector<double> none, paused, compared, loop;
  for (const StepRecord& s : r.steps) {
    if (s.paused)
      paused.push_back(s.seconds);
    else if (s.candidates == 0)
      none.push_back(s.seconds);
    else
      compared.push_back(s.seconds);
    if (s.loop) loop.push_back(s.seconds);
  }
  std::vector<double> total;
  for (std::size_t i = 0; i < r.steps.size(); ++i) total.push_back(r.steps[i].seconds);
  for (std::size_t k = 0; k < r.loops.size(); ++k)
    total[static_cast<std::size_t>(r.loops[k].query)] += r.correction_seconds[k];
  std::printf("\n== %s: %d poses\n", name, trajectory.Size());
  Print("search, no candidate", none);
  Print("search, paused", paused);
  Print("search, candidates compared", compared);
  Print("search, loop found", loop);
  Print("correction (Eq. 6), per loop", r.correction_seconds);
  Print("search + correction, every frame", total);
  int within = 0;
  for (const LoopPair& l : r.loops) {
    const long q = trajectory.frame_ids[l.query], j = trajectory.frame_ids[l.reference];
    const double d = (truth.poses[q].translation() - truth.poses[j].translation()).norm();
    within += d < 5;
    std::printf("  loop frame %4ld -> %4ld  Q %.3f  ground-truth distance %6.2f m\n", q, j,
                l.similarity, d);
  }
  std::printf("loops %zu, within 5 m in the ground truth %d\n", r.loops.size(), within);
}

}  // namespace

int main(int argc, char** argv) {
  const std::string datasets = argc > 1 ? argv[1] : OPENABLE_DATASETS_DIR;
  const std::string kitti = datasets + "/kitti00_first1700";
  const Trajectory truth = ReadPoses(kitti + "/poses/00_first1700.txt", false, false);
  if (truth.Size() != 1700) {
    std::printf("dataset absent or incomplete: %s\n", kitti.c_str());
    return 0;
  }
  SearchOptions options;
  const auto images = openable::ListImages(kitti + "/image_0", "png");
  std::vector<cv::Mat> thumbnails;
  std::vector<double> thumb_seconds;
  for (int i = 0; i < truth.Size(); ++i) {
    const auto start = std::chrono::steady_clock::now();
    thumbnails.push_back(
        Thumbnail(openable::ToGray8(openable::ReadImageFile(images[static_cast<std::size_t>(i)])),
                  options.thumbnail_scale));
    thumb_seconds.push_back(
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  std::printf("thumbnails %dx%d (1/6 of the 620x188 half-size frames)\n", thumbnails[0].cols,
              thumbnails[0].rows);
  Print("read + grey + thumbnail", thumb_seconds);
  Report("ground-truth poses", truth, truth, thumbnails, options);
  const std::string dso = datasets + "/kitti_trajectories/vo_so_dso/seq00/poses_history_file.txt";
  Trajectory keyframes = ReadPoses(dso, true, true);
  Trajectory kept;
  for (int i = 0; i < keyframes.Size(); ++i)
    if (keyframes.frame_ids[i] < 1700) {
      kept.poses.push_back(keyframes.poses[i]);
      kept.frame_ids.push_back(keyframes.frame_ids[i]);
    }
  if (kept.Size() > 0) {
    SearchOptions kf = options;
    kf.frame_distance = 30;  // keyframes: roughly every 3rd frame
    kf.discount.pause = 7;
    kf.discount.discount_length = 100;
    Report("SO-DSO keyframes (M 30, pause 7, K 100 keyframes)", kept, truth, thumbnails, kf);
  }
  return 0;
}
