// Top view of trajectories (the SNAPS add-on): ground truth, the drifting input and the
// corrected trajectory, with the loop pairs, drawn with OpenCV in the house style of
// evaluation/plots.cc (shared helpers in evaluation/drawing.h).
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "OpenABLE/snaps/trajectory.h"

namespace openable::snaps {

struct TrajectoryPlot {
  // The trajectories (not owned; null = absent). `input` is required.
  const Trajectory* truth = nullptr;
  const Trajectory* input = nullptr;
  const Trajectory* corrected = nullptr;
  // Legend labels (a figure such as " (mean 5.9 m)" may be appended by the caller).
  std::string truth_label = "ground truth";
  std::string input_label = "input (visual odometry)";
  std::string corrected_label = "corrected";
  // Loop pairs, indices into `input` (and `corrected`, which has the same poses): a thin line
  // between the two positions on `corrected`, or on `input` when there is no corrected one.
  std::vector<LoopPair> loops;
  // Ground plane: "xz" (KITTI cameras: x right, z forward, y down; x to the right, z up the
  // page, a view from above) or "xy" (x right, y up).
  std::string axes = "xz";
  std::string title;
  // Width and height of the figure, pixels (>= 300).
  int size = 1000;
};

// A white square figure of plot.size pixels: the title on top; a plot area with equal metres
// per pixel on both axes, a light grid and ticks every 1, 2 or 5 x 10^k metres (about 8 to 12
// on the longer axis), axis labels "x [m]", "z [m]"; the loop lines (light reddish purple,
// 1 px, below the rest), then ground truth (black), input (vermillion), corrected (blue), 2 px
// each, a dot at each start; a legend in the corner of the plot area that the trajectories
// cover least. Throws std::logic_error without `input` or with another axes name, or a loop
// index out of range.
cv::Mat3b RenderTrajectories(const TrajectoryPlot& plot);

}  // namespace openable::snaps
