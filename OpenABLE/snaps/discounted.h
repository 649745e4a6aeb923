// SNAPS's trajectory correction (Sec. III-C, Eq. 6): when frame N closes a loop with a reference
// frame, the positions of frames N-K..N are pulled towards the reference, the more the closer
// they are to N ("discount factor"). Where the paper is ambiguous: the update is read as an
// increment x_s <- x_s + Q gamma delta_x (read literally, every position would collapse near
// the origin), gamma is clamped at 0 where Eq. 6 turns it negative, and only positions move
// (Eq. 6 has no rotation term). docs/snaps.md, "Discounted update (Eq. 6)".
#pragma once

#include <Eigen/Geometry>
#include <vector>

#include "OpenABLE/snaps/trajectory.h"

namespace openable::snaps {

struct DiscountOptions {
  // K, "discount factor length" (Table I): frames N-K..N are updated. Not given in the paper;
  // 300 covers the whole support of gamma for the first loop (gamma > 0 for s' < 300 / alpha).
  int discount_length = 300;
  // "Inter-frame pause" (Table I): a loop is closed only when its query is more than `pause`
  // frames (trajectory indices) after the last pinned frame. Not given in the paper; 20 frames
  // = 2 s of KITTI at 10 Hz.
  int pause = 20;

  // Throws InputError naming the key (Snaps_discount_length, Snaps_pause) of a negative value.
  // Defined in options.cc.
  void Check() const;
};

// gamma of Eq. 6 for s' = N - s >= 0 and alpha >= 1, clamped at 0.
double DiscountGamma(int s_prime, int alpha);

// One loop (Eq. 6) on `poses` (camera-to-world): frame `n` (N) closes a loop with a reference
// at `reference_position`, similarity `q`; frames max(0, n-k)..n move by q * gamma(n-s) *
// (reference_position - p_n). Frames after n (offline: built by the odometry on top of frame
// N) move with frame N, by q * gamma(0) * delta; online there are none. Returns the shift of
// frame n. Throws std::invalid_argument when n is outside `poses`, k < 0 or alpha < 1.
Eigen::Vector3d ApplyDiscountedUpdate(std::vector<Eigen::Isometry3d>& poses, int n,
                                      const Eigen::Vector3d& reference_position, double q,
                                      int alpha, int k);

// The same with the reference given as an index of `trajectory` (reference < n).
Eigen::Vector3d ApplyDiscountedUpdate(Trajectory& trajectory, int n, int reference, double q,
                                      int alpha, int k);

// Offline correction of a whole trajectory by `loops` (indices of `input`): loops are taken in
// the order of their query (as they would have been found online; ties keep the given order),
// a loop is skipped when its query is not more than `options.pause` frames after the last
// closed loop's query (the last pinned frame; so of several loops of one query only the first
// is closed), and each closed loop applies ApplyDiscountedUpdate with alpha = loops closed so
// far including it and delta from the positions as corrected by the earlier loops. Throws
// std::invalid_argument when a loop's indices are outside `input` or reference >= query.
Trajectory CorrectDiscounted(const Trajectory& input, const std::vector<LoopPair>& loops,
                             const DiscountOptions& options);

// The loops CorrectDiscounted closes (same rule), in order.
std::vector<LoopPair> ClosedLoops(const std::vector<LoopPair>& loops, int pause);

}  // namespace openable::snaps
