#include "OpenABLE/base/output_batch.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <set>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/interrupt.h"

namespace openable {

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
      if (dash == 0 || dash == std::string::npos || rest.find_first_not_of("0123456789") != dash)
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
        throw InputError(
            ClashMessage(outputs[i].first, outputs[i].second, outputs[j].first, outputs[j].second));
  }
}

void CheckOutputPrefix(const std::string& key, const std::string& prefix) {
  std::error_code ec;
  if (!prefix.empty() && (prefix.back() == '/' || std::filesystem::is_directory(prefix, ec)))
    throw InputError(key + ": \"" + prefix + "\" is a folder; expected a path prefix for the " +
                     "files, such as \"" +
                     (std::filesystem::path(prefix) / "eval").lexically_normal().string() +
                     "\" (writing eval.json, eval_pr.png, ... in it)");
}

void OutputBatch::Stage(const std::string& key, const std::string& path, const std::string& bytes) {
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
                                      std::to_string(::getpid()) + "-" + std::to_string(staged++)))
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
  const std::string note = TakeInterruptNoteOnCommit();
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
      backup = (folder / ("." + dest.filename().string() + ".old-" + std::to_string(::getpid()) +
                          "-" + std::to_string(backups++)))
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
  if (!note.empty()) SetInterruptNote(note);  // before a deferred signal acts
}

std::vector<std::string> OutputBatch::Paths() const {
  std::vector<std::string> paths;
  for (const auto& item : items_) paths.push_back(item.path);
  return paths;
}

}  // namespace openable
