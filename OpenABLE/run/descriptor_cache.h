// The descriptor cache (Descriptor_cache): descriptor rows kept on disk under a hash
// of the image file's bytes and of every setting that changes the row, so that an interrupted
// or repeated run describes only the frames not cached. Format: docs/output_formats.md.
#pragma once

#include <cstdint>
#include <memory>
#include <mutex>
#include <opencv2/core.hpp>
#include <string>
#include <unordered_map>
#include <vector>

#include "OpenABLE/base/hash.h"
#include "OpenABLE/describe/describe.h"
#include "config/config.h"

namespace openable {

// Version of the cache file layout and of the settings text; bumped when either changes.
inline constexpr int kDescriptorCacheVersion = 1;

// The Config keys whose values change a frame's descriptor row, from the option table: every
// key of the description, descriptor and preprocessing structs, and Camera_type. A key added to
// those structs enters the cache key by itself; tests/run/descriptor_cache_test.cc fails when a
// key of the table is neither here nor in its list of keys known not to change rows.
const std::vector<std::string>& DescriptionKeys();

// The text the settings hash is taken over: the cache version, the library version, the
// descriptor's name, row width and type, then "Key: value" for every DescriptionKeys() key.
std::string DescriptionSettingsText(const Config& config, const std::string& descriptor_name,
                                    int row_width, int row_type);

// One cache file, <folder>/<16 hex digits of FNV-1a 64 of the settings text>.rows, opened for
// one run. Records of frames not in the file are appended as they are described (one write
// each, with a checksum), so a run killed part-way leaves every finished record usable.
// Thread-safe.
class DescriptorCache : public RowCache {
 public:
  // Opens or creates the file. Problems that only cost time (an unreadable or corrupt file, a
  // truncated last record, a cache in use by another run) are appended to `warnings` (one
  // line each, naming Descriptor_cache and the file) and the run goes on: a bad file is
  // started afresh, damaged records are dropped, never used. Throws InputError naming
  // Descriptor_cache when the folder cannot be created.
  static std::unique_ptr<DescriptorCache> Open(const std::string& folder,
                                               const std::string& settings_text, int row_width,
                                               int row_type, std::vector<std::string>& warnings);
  ~DescriptorCache() override;

  bool Lookup(const FrameSource& source, int i, cv::Mat row, cv::Size* frame_size) override;
  void Store(const FrameSource& source, int i, const cv::Mat& row, cv::Size frame_size) override;

  const std::string& Path() const { return path_; }
  int Hits() const { return hits_; }
  int Stored() const { return stored_; }
  size_t Records() const;
  // A write problem met while appending (disk full): empty when none. After one, the run
  // goes on without storing.
  std::string WriteProblem() const;

 private:
  struct Key {
    std::uint64_t hash, size;
    bool operator==(const Key& o) const { return hash == o.hash && size == o.size; }
  };
  struct KeyHash {
    size_t operator()(const Key& k) const { return static_cast<size_t>(k.hash ^ (k.size * 31)); }
  };
  struct Entry {
    size_t offset;  // into rows_
    int width, height;
  };
  DescriptorCache() = default;
  // Hash of frame i's file, computed once per run.
  bool KeyOf(const FrameSource& source, int i, Key* key);

  std::string path_;
  int fd_ = -1;
  bool writable_ = false;
  size_t row_bytes_ = 0;
  int row_width_ = 0, row_type_ = 0;
  mutable std::mutex mutex_;
  std::unordered_map<Key, Entry, KeyHash> entries_;
  std::vector<unsigned char> rows_;
  std::unordered_map<std::string, Key> keys_;  // frame name -> key, for Store
  int hits_ = 0, stored_ = 0;
  std::string write_problem_;
};

}  // namespace openable
