// The file of a saved online map (OnlineDetector::SaveMap / LoadMap, docs/output_formats.md,
// "Saved maps"): the settings the map was made with, every frame's descriptor row, the index
// blocks (FAISS's serialisation of each), and the local features kept for verification.
//
// Layout, integers little-endian:
//   16 bytes  signature "OpenABLE-map\r\n\x1a\n" (the \r\n and \x1a catch a file mangled by a
//             text-mode copy, as PNG's signature does)
//   u32       format version (kMapFormatVersion)
//   u64 + n   settings: text lines "key value"
//   u64 + n   descriptor rows: frames x row bytes, row after row
//   u32       index blocks; each: u32 first row, u32 rows, u64 + n serialised index
//   u32       1 when local features follow, else 0; each frame: u32 points, 2 f32 a point,
//             i32 rows, i32 cols, i32 OpenCV type, the descriptor bytes
//   u64       FNV-1a 64 of every byte before it
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

#include "OpenABLE/verification/verification.h"
#include "matching/search/incremental_index.h"

namespace openable {

inline constexpr std::uint32_t kMapFormatVersion = 1;

struct MapFile {
  std::vector<std::pair<std::string, std::string>> settings;  // in the file's order
  cv::Mat rows;  // frames x width, CV_8U or CV_32F, continuous
  std::vector<IncrementalIndex::SavedBlock> blocks;
  bool has_features = false;
  std::vector<FrameFeatures> features;  // one per frame when has_features

  // The value of setting `key`; "" when absent.
  std::string Setting(const std::string& key) const;
};

// Writes `map` to `path` through a temporary file renamed into place when complete (an
// interrupted save leaves the old file, or none). Throws InputError naming the path.
void WriteMapFile(const std::string& path, const MapFile& map);

// Reads a map written by WriteMapFile. Every defect is one InputError beginning with the
// path: unreadable, not a map, another format version, damaged (checksum) or truncated, or
// inconsistent sizes.
MapFile ReadMapFile(const std::string& path);

}  // namespace openable
