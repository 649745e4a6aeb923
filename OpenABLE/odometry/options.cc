// The Check() of every odometry option struct lives here, apart from the odometries
// themselves, so that checking a configuration does not link their image processing.
#include "OpenABLE/odometry/options.h"

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/option_checks.h"
#include "OpenABLE/base/strings.h"

namespace openable::odometry {
namespace {

void CheckFeatures(const std::string& owner, const FeatureOptions& o) {
  const std::string f = Upper(o.features);
  if (f != "ORB" && f != "SIFT")
    RefuseOption("Odometry_features (" + owner + ".features)", Quoted(o.features), "ORB or SIFT");
  CheckIntAtLeast("Odometry_max_features (" + owner + ".max_features)", o.max_features, 10);
  CheckNumberRange("Odometry_ratio_test (" + owner + ".ratio_test)", o.ratio_test, 0.1, 1);
}

}  // namespace

void MonoOdometryOptions::Check() const {
  const std::string o = "MonoOdometryOptions";
  CheckFeatures(o, *this);
  CheckNumberAtLeast("Odometry_ransac_threshold (" + o + ".ransac_threshold_px)",
                     ransac_threshold_px, 0, /*lo_excluded=*/true);
  if (!(ransac_confidence > 0 && ransac_confidence < 1))
    RefuseOption(o + ".ransac_confidence", FormatNumber(ransac_confidence), "a number in (0, 1)");
  CheckIntAtLeast("Odometry_min_inliers (" + o + ".min_inliers)", min_inliers, 5);
  CheckNumberAtLeast(o + ".still_step_length", still_step_length, 0);
}

void StereoOdometryOptions::Check() const {
  const std::string o = "StereoOdometryOptions";
  const std::string m = Upper(matcher);
  if (m != "SGBM" && m != "BM")
    RefuseOption("Odometry_matcher (" + o + ".matcher)", Quoted(matcher), "sgbm or bm");
  CheckNumberAtLeast(o + ".wls_lambda", wls_lambda, 0, true);
  CheckNumberAtLeast(o + ".wls_sigma", wls_sigma, 0, true);
  const int range = disparity.num_disparities, block = disparity.block_size;
  if (range < 16 || range > 256 || range % 16 != 0)
    RefuseOption("Odometry_num_disparities (" + o + ".disparity.num_disparities)",
                 std::to_string(range), "a multiple of 16 in [16, 256]");
  if (block % 2 != 1 || block > 11 || block < (m == "BM" ? 5 : 1))
    RefuseOption(o + ".disparity.block_size", std::to_string(block),
                 "odd, 1-11 (sgbm) or 5-11 (bm)");
  CheckFeatures(o, *this);
  CheckNumberAtLeast("Odometry_max_depth (" + o + ".max_depth)", max_depth, 1);
  CheckNumberAtLeast("Odometry_ransac_threshold (" + o + ".pnp_reprojection_px)",
                     pnp_reprojection_px, 0, true);
  CheckIntAtLeast(o + ".pnp_iterations", pnp_iterations, 1);
  if (!(pnp_confidence > 0 && pnp_confidence < 1))
    RefuseOption(o + ".pnp_confidence", FormatNumber(pnp_confidence), "a number in (0, 1)");
  CheckIntAtLeast("Odometry_min_inliers (" + o + ".min_inliers)", min_inliers, 4);
}

namespace {

// The keys both odometries share, over `o`'s defaults (empty or 0 keeps a default).
template <typename Options>
Options WithSharedKeys(const OdometryOptions& k, Options o) {
  if (!k.features.empty()) o.features = k.features;
  o.max_features = k.max_features;
  o.ratio_test = k.ratio_test;
  if (k.min_inliers > 0) o.min_inliers = k.min_inliers;
  return o;
}

}  // namespace

MonoOdometryOptions OdometryOptions::Mono() const {
  MonoOdometryOptions o = WithSharedKeys(*this, MonoOdometryOptions());
  if (ransac_threshold > 0) o.ransac_threshold_px = ransac_threshold;
  return o;
}

StereoOdometryOptions OdometryOptions::Stereo() const {
  StereoOdometryOptions o = WithSharedKeys(*this, StereoOdometryOptions());
  o.matcher = matcher;
  o.wls_filter = wls_filter;
  o.disparity.num_disparities = num_disparities;
  o.max_depth = max_depth;
  if (ransac_threshold > 0) o.pnp_reprojection_px = ransac_threshold;
  return o;
}

void OdometryOptions::Check() const {
  CheckNumberRange("Odometry_calibration_scale", calibration_scale, 0.01, 10);
  CheckNumberAtLeast("Odometry_step_length", step_length, 0);
  CheckNumberRange("Odometry_ransac_threshold", ransac_threshold, 0, 100);
  CheckIntAtLeast("Odometry_min_inliers", min_inliers, 0);
  Mono().Check();
  Stereo().Check();
}

}  // namespace openable::odometry
