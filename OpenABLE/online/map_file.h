// The file of a saved online map (OnlineDetector::SaveMap / LoadMap, openable_map): the settings
// the map was made with, its sessions, every frame's descriptor rows and image file, the index
// blocks, and the local features kept for verification. Version 3 is a table of sections, each
// 64-byte aligned with its own CRC-32, so that a memory-mapped map of millions of places reads
// only its small sections when opened and uses rows and blocks where they lie, checking them in
// the background. Versions 1 and 2 are still read. Layout: docs/output_formats.md, "Saved maps".
#pragma once

#include <cstdint>
#include <functional>
#include <future>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <utility>
#include <vector>

#include "OpenABLE/verification/verification.h"
#include "matching/search/incremental_index.h"

namespace openable {

inline constexpr std::uint32_t kMapFormatVersion = 3;

// One traversal of a map: frames [first, first + count), its name (unique in the map) and the
// time it was added (ISO 8601 UTC, "" when unknown).
struct MapSession {
  std::string name;
  std::string time;
  int first = 0, count = 0;
};

// Now, as sessions and tunings keep their times: ISO 8601 UTC ("2026-11-29T09:30:00Z").
std::string MapTimeNow();

// A session time: ISO 8601 UTC, "YYYY-MM-DDTHH:MM:SSZ" with optional decimals of the seconds
// ("2026-11-29T09:30:00.25Z"), a real date (a 29 February of a leap year only) and time.
// Throws InputError beginning with `what`, quoting the value and the form expected.
void CheckSessionTime(const std::string& time, const std::string& what);

// A session name: 1 to 200 printable characters (no control characters, no tab or line
// break), not beginning or ending with a space. Throws InputError beginning with `what`.
void CheckSessionName(const std::string& name, const std::string& what);

struct MapFile {
  std::uint32_t version = kMapFormatVersion;                  // of the file read
  std::vector<std::pair<std::string, std::string>> settings;  // in the file's order
  std::vector<MapSession> sessions;  // tiling frames 0 .. rows.rows - 1 in order
  cv::Mat rows;  // frames x width, CV_8U or CV_32F, continuous: the first descriptor's
  // The rows of the map's other descriptors (format 3), each as `rows`; settings
  // "channel_widths" and "channel_types" give their shapes.
  std::vector<cv::Mat> more_rows;
  // The image file of each frame ("" when not known); empty: none kept.
  std::vector<std::string> frame_files;
  std::vector<IncrementalIndex::SavedBlock> blocks;
  bool has_features = false;
  std::vector<FrameFeatures> features;  // one per frame when has_features
  // When read in place: the mapped file, which `rows` and the blocks' bytes point into.
  std::shared_ptr<const void> mapping;
  // The check of the sections used in place (rows, blocks): "" when they match their
  // checksums, else the one-line error beginning with the path. Ready at once when the read
  // checked them itself.
  std::shared_future<std::string> check;

  // The value of setting `key`; "" when absent.
  std::string Setting(const std::string& key) const;
};

struct MapReadOptions {
  // Map the file and use its rows and index blocks where they lie (no copy): a map of ten
  // million places opens in well under a second. Otherwise they are copied into memory.
  bool in_place = true;
  // Verify the checksums of the rows and blocks on a background thread (MapFile::check)
  // rather than before returning. The header, settings, sessions, features and each index's
  // structure (sizes, row numbers) are always checked before returning, so a damaged file can
  // give wrong distances until the check reports it, never a read out of bounds.
  bool check_in_background = true;
  // Read the settings and sessions only (MapFile::rows stays empty, no blocks, no check): what
  // a program needs to know which options a map was made with (MapOptions, online.h).
  bool header_only = false;
};

// The right to replace the map at `path`, held by one writer at a time across processes: an
// advisory lock (flock) on the file `path` + ".lock" beside it, created when missing and left
// there (removing it while another process waits on it would let a third one in). A program
// that reads a map, changes it and saves it (openable_map add, tune, merge) holds it from
// before the read to after the save, so two appends at once both land, one after the other.
// When another process holds it, `waiting` (when set) is told once, naming it, and the
// constructor waits. Released by the destructor or when the process ends. Throws InputError
// naming the lock file when it cannot be created or locked.
class MapWriteLock {
 public:
  explicit MapWriteLock(const std::string& path,
                        const std::function<void(const std::string&)>& waiting = {});
  ~MapWriteLock();
  MapWriteLock(const MapWriteLock&) = delete;
  MapWriteLock& operator=(const MapWriteLock&) = delete;

 private:
  int fd_ = -1;
};

// Writes `map` (format version 3) to `path` through a temporary file renamed into place when
// complete (an interrupted save leaves the old file, or none). Throws InputError naming the
// path.
void WriteMapFile(const std::string& path, const MapFile& map);

// Reads a map written by WriteMapFile (version 3, 2 or 1). Every defect found before returning
// is one InputError beginning with the path: unreadable, not a map, a newer format version,
// damaged (checksum) or truncated, inconsistent sizes or sessions.
MapFile ReadMapFile(const std::string& path, const MapReadOptions& options = {});

}  // namespace openable
