#include "OpenABLE/run/exports.h"

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <set>
#include <fstream>
#include <stdexcept>

#include <fcntl.h>
#include <sys/file.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <opencv2/core/utility.hpp>

#include "OpenABLE/base/error.h"
#include "OpenABLE/io/png_codec.h"
#include "OpenABLE/run/interrupt.h"

namespace openable {

cv::Vec3f ColorOf(float s, int map) {
  // (blue, green, red), as the original OpenABLE's table (docs/output_formats.md).
  switch (map) {
    case 0: return {s, s, s};
    case 1: return {0, 0, s};
    case 2: return {0, s, 0};
    case 3: return {s, 0, 0};
    case 4: return {1 - s, 1 - s, s};
    case 5: return {1 - s, s, 1 - s};
    case 6: return {s, 1 - s, 1 - s};
    case 7: return {0, s, 1};
    case 8: return {1, 1 - s, s};
    case 9: return {0.4980f * s, 0.7804f * s, s};
    case 10: return {1 - s, s, 1};
    case 11: return {0, 0.5f * s + 0.5f, s};
    default: throw std::logic_error("ColorOf: colour map outside 0-11");
  }
}

cv::Mat3b ColorizeMatrix(const cv::Mat1f& normalized, int map) {
  // Every map is affine in s per channel: c = b + a s, with b = ColorOf(0), a = ColorOf(1) - b,
  // which gives the same floats as ColorOf (the slopes are 0, +-1, 0.4980 or 0.5).
  const cv::Vec3f b = ColorOf(0.f, map);  // also validates the map
  const cv::Vec3f a = ColorOf(1.f, map) - b;
  cv::Mat3b out(normalized.size());
  cv::parallel_for_(cv::Range(0, normalized.rows), [&](const cv::Range& rows) {
    for (int i = rows.start; i < rows.end; ++i) {
      const float* in = normalized.ptr<float>(i);
      std::uint8_t* o = out.ptr<std::uint8_t>(i);
      for (int j = 0; j < normalized.cols; ++j) {
        const float v = std::min(1.f, std::max(0.f, in[j]));
        for (int k = 0; k < 3; ++k)
          o[3 * j + k] = cv::saturate_cast<std::uint8_t>((b[k] + a[k] * v) * 255.f);
      }
    }
  });
  return out;
}

std::string NpyHeader(int rows, int cols) {
  // The .npy format: magic, version 1.0, a little-endian uint16 header length, then a Python
  // dict literal padded with spaces and ended by '\n' so that the data starts at a multiple
  // of 64 bytes. Written by hand: none of our dependencies writes .npy.
  std::string dict = "{'descr': '<f4', 'fortran_order': False, 'shape': (" +
                     std::to_string(rows) + ", " + std::to_string(cols) + "), }";
  const size_t preamble = 10;  // magic (6) + version (2) + length (2)
  size_t total = preamble + dict.size() + 1;
  const size_t padded = (total + 63) / 64 * 64;
  dict.append(padded - total, ' ');
  dict.push_back('\n');
  std::string out("\x93NUMPY\x01\x00", 8);
  const auto len = static_cast<std::uint16_t>(dict.size());
  out.push_back(static_cast<char>(len & 0xFF));
  out.push_back(static_cast<char>(len >> 8));
  return out + dict;
}

std::string EncodeNpy(const cv::Mat1f& m) {
  std::string out = NpyHeader(m.rows, m.cols);
  static_assert(sizeof(float) == 4, "float32 expected");
  const size_t bytes = static_cast<size_t>(m.rows) * m.cols * sizeof(float);
  out.reserve(out.size() + bytes);
  for (int i = 0; i < m.rows; ++i)  // x86 and ARM Linux are little-endian, like '<f4'
    out.append(reinterpret_cast<const char*>(m.ptr<float>(i)), m.cols * sizeof(float));
  return out;
}

namespace {

// The text of a float as printf's "%.6g" writes it (std::to_chars with a precision: no locale,
// no format string), remembered by its bits: a matrix of Hamming sums divided by their largest
// holds a few thousand distinct values (at most L x bits + 1), so most cells are a lookup.
// Direct-mapped, one per thread; a collision formats again. The digits are those of to_chars
// either way.
class FloatTexts {
 public:
  FloatTexts() : entries_(kSize) {}
  std::string_view Of(float v) {
    std::uint32_t bits;
    std::memcpy(&bits, &v, sizeof bits);
    Entry& e = entries_[(bits * 2654435761u) >> (32 - kBits)];
    if (e.length == 0 || e.bits != bits) {
      const std::to_chars_result r =
          std::to_chars(e.text, e.text + sizeof e.text, v, std::chars_format::general, 6);
      e.bits = bits;
      e.length = static_cast<std::uint8_t>(r.ptr - e.text);
    }
    return {e.text, e.length};
  }

 private:
  static constexpr int kBits = 14;
  static constexpr std::size_t kSize = std::size_t{1} << kBits;
  struct Entry {
    std::uint32_t bits = 0;
    std::uint8_t length = 0;  // 0: empty
    char text[19];            // "-1.23457e-05" and the like: at most 13 characters
  };
  std::vector<Entry> entries_;
};

// Rows [r0, r1) of `m` as text into `out` (appended).
void FormatRows(const cv::Mat& m, int r0, int r1, FloatTexts& texts, std::string& out) {
  char buf[8];
  for (int i = r0; i < r1; ++i) {
    for (int j = 0; j < m.cols; ++j) {
      if (j) out.push_back(' ');
      if (m.depth() == CV_8U) {
        const std::to_chars_result res =
            std::to_chars(buf, buf + sizeof buf, int{m.at<std::uint8_t>(i, j)});
        out.append(buf, res.ptr);
      } else {
        out.append(texts.Of(m.at<float>(i, j)));
      }
    }
    out.push_back('\n');
  }
}

}  // namespace

TextChunks::TextChunks(const cv::Mat& m) : m_(m) {
  if (m.depth() != CV_8U && m.depth() != CV_32F)
    throw std::logic_error("TextChunks: expected CV_8U or CV_32F");
}

bool TextChunks::Next(std::string_view& piece) {
  if (next_row_ >= m_.rows) return false;
  // A chunk is kBlocks blocks of kBlockRows rows, formatted in parallel (one block per task)
  // and written while the next is formatted: the whole text is never in memory.
  constexpr int kBlockRows = 32, kBlocks = 16;
  const int r0 = next_row_, r1 = std::min(m_.rows, r0 + kBlockRows * kBlocks);
  const int blocks = (r1 - r0 + kBlockRows - 1) / kBlockRows;
  parts_.resize(static_cast<std::size_t>(blocks));
  cv::parallel_for_(cv::Range(0, blocks), [&](const cv::Range& range) {
    thread_local FloatTexts texts;
    for (int b = range.start; b < range.end; ++b) {
      std::string& out = parts_[static_cast<std::size_t>(b)];
      out.clear();
      FormatRows(m_, r0 + b * kBlockRows, std::min(r1, r0 + (b + 1) * kBlockRows), texts, out);
    }
  });
  chunk_.clear();
  for (const std::string& part : parts_) chunk_ += part;
  next_row_ = r1;
  piece = chunk_;
  return true;
}

std::string EncodeText(const cv::Mat& m) {
  TextChunks chunks(m);
  std::string out;
  for (std::string_view piece; chunks.Next(piece);) out += piece;
  return out;
}

std::string EncodePng(const cv::Mat& image) { return EncodePngFile(image); }

namespace {

std::atomic<long long> g_fail_after{-1};
std::atomic<long long> g_written{0};
std::atomic<int> g_fail_error{ENOSPC};

// write(2) of every byte, retrying short writes and EINTR. Returns 0 or the errno.
int WriteAll(int fd, const char* data, size_t size) {
  while (size > 0) {
    const long long limit = g_fail_after.load();
    size_t chunk = std::min<size_t>(size, 1 << 30);
    if (limit >= 0) {
      const long long left = limit - g_written.load();
      if (left <= 0) return g_fail_error.load();
      chunk = std::min<size_t>(chunk, static_cast<size_t>(left));
    }
    const ssize_t n = ::write(fd, data, chunk);
    if (n < 0) {
      if (errno == EINTR) continue;
      return errno;
    }
    g_written += n;
    data += n;
    size -= static_cast<size_t>(n);
  }
  return 0;
}

// Removes ".<name>.tmp-<pid>-*" and ".<name>.old-<pid>-*" beside `dest` whose process is gone.
void RemoveStaleTemporaries(const std::filesystem::path& folder, const std::string& name) {
  namespace fs = std::filesystem;
  std::error_code ec;
  for (const char* kind : {".tmp-", ".old-"}) {
    const std::string prefix = "." + name + kind;
    for (fs::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
      const std::string f = it->path().filename().string();
      if (f.compare(0, prefix.size(), prefix) != 0) continue;
      const std::string rest = f.substr(prefix.size());
      const size_t dash = rest.find('-');
      if (dash == 0 || dash == std::string::npos ||
          rest.find_first_not_of("0123456789") != dash)
        continue;
      const long pid = std::strtol(rest.substr(0, dash).c_str(), nullptr, 10);
      if (pid <= 0 || pid == ::getpid()) continue;
      if (::kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH) {
        std::error_code rm;
        fs::remove(it->path(), rm);
      }
    }
  }
}

}  // namespace

void FailStagedWritesAfterForTesting(long long bytes, int error) {
  g_fail_error = error;
  g_written = 0;
  g_fail_after = bytes;
}

OutputBatch::~OutputBatch() {
  for (const auto& item : items_) {
    ::unlink(item.temp.c_str());
    UnregisterTemporary(item.slot);
  }
}

namespace {

// The file `path` names, for comparing outputs: absolute, ".", ".." and existing links resolved.
std::string SameFileKey(const std::string& path) {
  std::error_code ec;
  const std::filesystem::path absolute = std::filesystem::absolute(path, ec);
  if (ec) return path;
  const std::filesystem::path resolved = std::filesystem::weakly_canonical(absolute, ec);
  return (ec ? absolute.lexically_normal() : resolved).string();
}

std::string ClashMessage(const std::string& key, const std::string& path,
                         const std::string& other_key, const std::string& other_path) {
  return key + ": \"" + path + "\" is also the file of " + other_key +
         (other_path == path ? std::string() : " (\"" + other_path + "\")") +
         "; expected a different file for each output (one would overwrite the other)";
}

}  // namespace

void CheckDistinctOutputs(const std::vector<std::pair<std::string, std::string>>& outputs) {
  std::vector<std::string> keys;
  for (size_t i = 0; i < outputs.size(); ++i) {
    keys.push_back(SameFileKey(outputs[i].second));
    for (size_t j = 0; j < i; ++j)
      if (keys[j] == keys[i])
        throw InputError(ClashMessage(outputs[i].first, outputs[i].second, outputs[j].first,
                                      outputs[j].second));
  }
}

void CheckOutputPrefix(const std::string& key, const std::string& prefix) {
  std::error_code ec;
  if (!prefix.empty() &&
      (prefix.back() == '/' || std::filesystem::is_directory(prefix, ec)))
    throw InputError(key + ": \"" + prefix + "\" is a folder; expected a path prefix for the " +
                     "files, such as \"" +
                     (std::filesystem::path(prefix) / "eval").lexically_normal().string() +
                     "\" (writing eval.json, eval_pr.png, ... in it)");
}

void OutputBatch::Stage(const std::string& key, const std::string& path,
                        const std::string& bytes) {
  Stage(key, path, std::vector<std::string_view>{bytes});
}

void OutputBatch::Stage(const std::string& key, const std::string& path,
                        const std::vector<std::string_view>& parts) {
  std::size_t i = 0;
  Stage(key, path, [&](std::string_view& piece) {
    if (i == parts.size()) return false;
    piece = parts[i++];
    return true;
  });
}

void OutputBatch::Stage(const std::string& key, const std::string& path,
                        const std::function<bool(std::string_view&)>& next) {
  namespace fs = std::filesystem;
  for (const Item& item : items_)
    if (SameFileKey(item.path) == SameFileKey(path))
      throw InputError(ClashMessage(key, path, item.key, item.path));
  const fs::path dest(path);
  const fs::path folder = dest.has_parent_path() ? dest.parent_path() : fs::path(".");
  std::error_code ec;
  // create_directories returns false when another process created the folder first: an
  // existing folder is what is needed, so look again before reporting a failure.
  if (!fs::is_directory(folder, ec) && !fs::create_directories(folder, ec) &&
      !fs::is_directory(folder))
    throw InputError(key + ": cannot write \"" + path + "\": folder \"" + folder.string() +
                     "\" cannot be created (" + ec.message() + ")");
  if (fs::is_directory(dest, ec))
    throw InputError(key + ": cannot write \"" + path +
                     "\": it is a folder (expected a file name)");
  RemoveStaleTemporaries(folder, dest.filename().string());
  // Unique within the process too: two batches of one process (threads, a Python program
  // running two runs) may stage the same destination at once.
  static std::atomic<std::uint64_t> staged{0};
  const std::string temp = (folder / ("." + dest.filename().string() + ".tmp-" +
                                      std::to_string(::getpid()) + "-" +
                                      std::to_string(staged++)))
                               .string();
  // Registered before it exists, so that a signal between open and write removes it too.
  items_.push_back({key, temp, path, RegisterTemporary(temp)});
  const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  int error = fd < 0 ? errno : 0;
  for (std::string_view piece; error == 0 && next(piece);)
    error = WriteAll(fd, piece.data(), piece.size());
  // On disk before the rename makes it visible: a power cut after the commit must not leave a
  // renamed but empty file (ext4 and XFS may order the rename before the data).
  if (fd >= 0 && error == 0 && ::fsync(fd) != 0 && errno != EINVAL) error = errno;
  // close() reports the errors of delayed writes on some file systems (NFS).
  if (fd >= 0 && ::close(fd) != 0 && error == 0) error = errno;
  if (error != 0) {
    ::unlink(temp.c_str());
    UnregisterTemporary(items_.back().slot);
    items_.pop_back();
    throw InputError(key + ": cannot write \"" + path + "\": " + std::strerror(error) +
                     " (expected a writable location with free space)");
  }
}

namespace {

// fsync of a folder: its entries (the temporaries before the renames, the renamed names after)
// reach the disk. Best effort: a file system that cannot sync folders says EINVAL.
void SyncFolder(const std::string& folder) {
  const int fd = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return;
  ::fsync(fd);
  ::close(fd);
}

// The folders of `paths`, each once, sorted (so that two commits lock them in the same order).
std::vector<std::string> FoldersOf(const std::vector<std::string>& paths) {
  std::set<std::string> folders;
  for (const std::string& p : paths) {
    const std::filesystem::path dest(p);
    folders.insert(std::filesystem::absolute(dest.has_parent_path() ? dest.parent_path()
                                                                    : std::filesystem::path("."))
                       .lexically_normal()
                       .string());
  }
  return {folders.begin(), folders.end()};
}

// An advisory lock (flock) on each folder the commit writes into, held while its renames run:
// two runs writing the same outputs commit one after the other, so the final set is one run's,
// never a mix. Linux locks a folder's descriptor like a file's, so no lock file is left behind.
class CommitLocks {
 public:
  explicit CommitLocks(const std::vector<std::string>& folders) {
    for (const std::string& folder : folders) {
      const int fd = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
      if (fd < 0) continue;  // cannot happen for a folder just staged into; no lock then
      while (::flock(fd, LOCK_EX) != 0 && errno == EINTR) {
      }
      fds_.push_back(fd);
    }
  }
  ~CommitLocks() {
    for (const int fd : fds_) ::close(fd);  // closing releases the lock
  }
  CommitLocks(const CommitLocks&) = delete;
  CommitLocks& operator=(const CommitLocks&) = delete;

 private:
  std::vector<int> fds_;
};

}  // namespace

void OutputBatch::Commit() {
  InterruptDeferral defer;  // a signal now acts after the renames (or their undoing)
  const std::vector<std::string> folders = FoldersOf(Paths());
  for (const std::string& folder : folders) SyncFolder(folder);
  const CommitLocks locks(folders);
  struct Done {
    std::string path, backup;  // backup empty: the destination did not exist (or no link)
    bool existed;
  };
  std::vector<Done> done;
  for (size_t k = 0; k < items_.size(); ++k) {
    const Item& item = items_[k];
    std::string backup;
    struct stat st;
    const bool existed = ::lstat(item.path.c_str(), &st) == 0;
    if (existed) {
      const std::filesystem::path dest(item.path);
      const std::filesystem::path folder =
          dest.has_parent_path() ? dest.parent_path() : std::filesystem::path(".");
      static std::atomic<std::uint64_t> backups{0};
      backup = (folder / ("." + dest.filename().string() + ".old-" +
                          std::to_string(::getpid()) + "-" + std::to_string(backups++)))
                   .string();
      ::unlink(backup.c_str());
      if (::link(item.path.c_str(), backup.c_str()) != 0) backup.clear();
    }
    if (std::rename(item.temp.c_str(), item.path.c_str()) != 0) {
      const std::string reason = std::strerror(errno);
      if (!backup.empty()) ::unlink(backup.c_str());
      // Undo: every destination renamed so far goes back to its old state.
      for (const Done& d : done) {
        if (!d.backup.empty()) {
          std::rename(d.backup.c_str(), d.path.c_str());
        } else {
          ::unlink(d.path.c_str());
        }
      }
      // The destructor removes the temporaries not renamed.
      const std::string key = item.key, path = item.path;
      items_.erase(items_.begin(), items_.begin() + static_cast<long>(k));
      throw InputError(key + ": cannot write \"" + path + "\": " + reason +
                       " (no output of this run was kept)");
    }
    UnregisterTemporary(item.slot);
    done.push_back({item.path, backup, existed});
  }
  for (const Done& d : done)
    if (!d.backup.empty()) ::unlink(d.backup.c_str());
  for (const std::string& folder : folders) SyncFolder(folder);
  items_.clear();
}

std::vector<std::string> OutputBatch::Paths() const {
  std::vector<std::string> paths;
  for (const auto& item : items_) paths.push_back(item.path);
  return paths;
}

std::string EncodeMatches(const std::vector<Match>& matches, bool csv) {
  if (csv) {
    std::string out = "query,reference,distance,rank,score\n";
    char buf[128];
    for (const Match& k : matches) {
      char* p = buf;
      p = std::to_chars(p, buf + sizeof buf, k.query).ptr;
      *p++ = ',';
      p = std::to_chars(p, buf + sizeof buf, k.reference).ptr;
      *p++ = ',';
      p = std::to_chars(p, buf + sizeof buf, k.distance, std::chars_format::general, 7).ptr;
      *p++ = ',';
      p = std::to_chars(p, buf + sizeof buf, k.rank).ptr;
      *p++ = ',';
      p = std::to_chars(p, buf + sizeof buf, k.score, std::chars_format::general, 7).ptr;
      *p++ = '\n';
      out.append(buf, p);
    }
    return out;
  }
  // A structured .npy: one record of 20 bytes per match (written by hand, as NpyHeader).
  std::string dict = "{'descr': [('query', '<i4'), ('reference', '<i4'), ('distance', '<f4'), "
                     "('rank', '<i4'), ('score', '<f4')], 'fortran_order': False, 'shape': (" +
                     std::to_string(matches.size()) + ",), }";
  const size_t total = 10 + dict.size() + 1;
  dict.append((total + 63) / 64 * 64 - total, ' ');
  dict.push_back('\n');
  std::string out("\x93NUMPY\x01\x00", 8);
  out.push_back(static_cast<char>(dict.size() & 0xFF));
  out.push_back(static_cast<char>(dict.size() >> 8));
  out += dict;
  out.reserve(out.size() + matches.size() * 20);
  for (const Match& k : matches) {
    char rec[20];
    std::memcpy(rec, &k.query, 4);
    std::memcpy(rec + 4, &k.reference, 4);
    std::memcpy(rec + 8, &k.distance, 4);
    std::memcpy(rec + 12, &k.rank, 4);
    std::memcpy(rec + 16, &k.score, 4);
    out.append(rec, 20);
  }
  return out;
}

}  // namespace openable
