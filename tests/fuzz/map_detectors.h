// The online detectors of the map fuzzer and the maps of its seed corpus
// (tests/fuzz/map_fuzzer.cc, tests/fuzz/write_seeds.cc): small maps whose settings are these,
// so that a mutated seed gets past LoadMap's comparison of settings and into the rows, the
// index blocks and the verification features.
#pragma once

#include <opencv2/core.hpp>

#include "OpenABLE/online/online.h"

namespace openable::fuzz {

enum class MapKind { kRows, kFloat, kVerifying, kSeveral, kGiven };

// kRows: LDB rows (CV_8U) with index blocks from 16 searchable frames on (exact_limit 0,
// block_frames 16; FLANN's LSH, kept small, which a loaded map builds again). kFloat: HOG rows
// of a 16-pixel patch (36 CV_32F), exact search. kVerifying: LDB rows and each frame's ORB
// features (10 a frame), candidates verified with 5 inliers. kSeveral: LDB rows and SAD's
// (a 16-pixel patch, 128 bytes) kept beside them, exact search, the contrast enhancement of the
// search and a tuned search in its seed. kGiven: rows computed elsewhere (descriptor NPY, 8
// floats a frame), exact search.
inline OnlineOptions MapDetectorOptions(MapKind kind) {
  OnlineOptions o;
  o.exclusion = 2;
  o.candidates = 2;
  o.background_merges = false;
  o.approximate.engine = "flann";
  o.approximate.lsh_tables = 2;
  o.approximate.lsh_key_bits = 8;
  if (kind == MapKind::kRows) {
    o.exact_limit = 0;
    o.block_frames = 16;
  } else if (kind == MapKind::kFloat) {
    o.descriptor.name = "HOG";
    o.descriptor.patch_size = 16;
  } else if (kind == MapKind::kGiven) {
    o.descriptor.name = "NPY";
    o.descriptor.given_width = 8;
  } else if (kind == MapKind::kSeveral) {
    o.descriptor.patch_size = 16;
    o.kept_descriptors = "SAD";
    o.contrast.enabled = true;
  } else {
    o.exclusion = 1;
    o.verification.enabled = true;
    o.verification.max_features = 10;
    o.verification.min_inliers = 5;
    o.verification.candidates = 2;
  }
  return o;
}

// Frame i of the verifying map: 96 x 96 grey noise, the same bytes on every machine (OpenCV's
// RNG with a fixed seed). The fuzzer adds frame 0 after loading a map, so that the saved
// features of its seeds match it and the verification runs to its geometric check.
inline cv::Mat MapFrame(int i) {
  cv::Mat frame(96, 96, CV_8UC1);
  cv::RNG rng(1000 + i);
  rng.fill(frame, cv::RNG::UNIFORM, 0, 256);
  return frame;
}

}  // namespace openable::fuzz
