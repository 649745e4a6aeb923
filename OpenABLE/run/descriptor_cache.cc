#include "OpenABLE/run/descriptor_cache.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/input_file.h"
#include "OpenABLE/base/version.h"

namespace openable {
namespace {

// File layout (little-endian, docs/output_formats.md "Descriptor cache"):
//   header: "OADCACHE" | u32 version | u32 row bytes | i32 row width | i32 row type |
//           u64 settings hash | u32 settings text length | settings text | u64 FNV-1a 64 of
//           every header byte before it
//   record: u64 content hash | u64 content size | i32 frame width | i32 frame height |
//           row bytes | u64 FNV-1a 64 of the record's bytes before it
constexpr char kMagic[8] = {'O', 'A', 'D', 'C', 'A', 'C', 'H', 'E'};
constexpr size_t kRecordHead = 24;

template <typename T>
void Put(std::string& out, T v) {
  out.append(reinterpret_cast<const char*>(&v), sizeof v);
}
template <typename T>
bool Get(const std::string& in, size_t& at, T* v) {
  if (at + sizeof(T) > in.size()) return false;
  std::memcpy(v, in.data() + at, sizeof(T));
  at += sizeof(T);
  return true;
}

std::string Header(const std::string& settings, size_t row_bytes, int row_width, int row_type) {
  std::string h(kMagic, sizeof kMagic);
  Put<std::uint32_t>(h, kDescriptorCacheVersion);
  Put<std::uint32_t>(h, static_cast<std::uint32_t>(row_bytes));
  Put<std::int32_t>(h, row_width);
  Put<std::int32_t>(h, row_type);
  Put<std::uint64_t>(h, Fnv1a64(settings.data(), settings.size()));
  Put<std::uint32_t>(h, static_cast<std::uint32_t>(settings.size()));
  h += settings;
  Put<std::uint64_t>(h, Fnv1a64(h.data(), h.size()));
  return h;
}

std::string Hex(std::uint64_t v) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(v));
  return buf;
}

// False for anything but a regular file that can be read (a FIFO put in the cache folder
// neither blocks nor is read): a miss, never an error.
bool ReadFile(const std::string& path, std::string* out) {
  try {
    *out = ReadInputFile(path, "descriptor cache");
    return true;
  } catch (const InputError&) {
    return false;
  }
}

bool WriteAll(int fd, const char* data, size_t size) {
  while (size > 0) {
    const ssize_t n = ::write(fd, data, size);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    data += n;
    size -= static_cast<size_t>(n);
  }
  return true;
}

}  // namespace

const std::vector<std::string>& DescriptionKeys() {
  // From the option table: the keys of the structs that make a row (the description, the
  // descriptor, the preprocessing), in the table's order, and the camera type, the one input
  // key that changes a row (stereo pairs give D-LDB its disparity channel).
  static const std::vector<std::string> keys = [] {
    Config c;
    std::vector<std::string> out;
    for (const OptionBinding& b : ConfigTable(c).Bindings())
      if (b.key == "Camera_type" || b.owner == &c.description || b.owner == &c.descriptor ||
          b.owner == &c.preprocess)
        out.push_back(b.key);
    return out;
  }();
  return keys;
}

std::string DescriptionSettingsText(const Config& config, const std::string& descriptor_name,
                                    int row_width, int row_type) {
  std::string s = "OpenABLE descriptor cache " + std::to_string(kDescriptorCacheVersion) +
                  "\nOpenABLE " + kVersion + "\ndescriptor: " + descriptor_name +
                  "\nrow: " + std::to_string(row_width) + " x " + cv::typeToString(row_type) + "\n";
  // The keys of a network (Model_*) only for rows a network made ("ONNX", with its weights'
  // digest), so that the caches of the other descriptors keep the keys they were written with.
  const bool network = descriptor_name.rfind("ONNX", 0) == 0;
  for (const std::string& key : DescriptionKeys())
    if (network || key.rfind("Model_", 0) != 0)
      s += key + ": " + ConfigValueText(config, key) + "\n";
  return s;
}

std::unique_ptr<DescriptorCache> DescriptorCache::Open(const std::string& folder,
                                                       const std::string& settings_text,
                                                       int row_width, int row_type,
                                                       std::vector<std::string>& warnings) {
  namespace fs = std::filesystem;
  std::error_code ec;
  // Another run may create the folder first (create_directories then returns false).
  if (!fs::is_directory(folder, ec) && !fs::create_directories(folder, ec) &&
      !fs::is_directory(folder))
    throw InputError("Descriptor_cache: folder \"" + folder + "\" cannot be created (" +
                     ec.message() + "); expected a writable folder, or empty for no cache");
  std::unique_ptr<DescriptorCache> c(new DescriptorCache());
  c->row_width_ = row_width;
  c->row_type_ = row_type;
  c->row_bytes_ = static_cast<size_t>(row_width) * CV_ELEM_SIZE(row_type);
  c->path_ =
      (fs::path(folder) / (Hex(Fnv1a64(settings_text.data(), settings_text.size())) + ".rows"))
          .string();
  const std::string where = "Descriptor_cache: \"" + c->path_ + "\": ";
  const std::string header = Header(settings_text, c->row_bytes_, row_width, row_type);

  c->fd_ = ::open(c->path_.c_str(), O_RDWR | O_CREAT | O_APPEND | O_NONBLOCK | O_CLOEXEC, 0666);
  if (c->fd_ < 0) {
    warnings.push_back(where + "cannot be opened (" + std::strerror(errno) +
                       "); every frame is described, nothing is cached");
    return c;
  }
  struct stat st;
  if (::fstat(c->fd_, &st) != 0 || !S_ISREG(st.st_mode)) {
    ::close(c->fd_);
    c->fd_ = -1;
    warnings.push_back(where +
                       "is not a regular file (a folder, FIFO or device); every frame "
                       "is described, nothing is cached");
    return c;
  }
  // Back to blocking reads and writes on the regular file (O_NONBLOCK only kept the open from
  // waiting).
  ::fcntl(c->fd_, F_SETFL, ::fcntl(c->fd_, F_GETFL) & ~O_NONBLOCK);
  // One run at a time writes a cache file; another run reads what is there.
  const bool locked = ::flock(c->fd_, LOCK_EX | LOCK_NB) == 0;
  if (!locked) warnings.push_back(where + "in use by another run; this run only reads it");
  std::string bytes;
  if (!ReadFile(c->path_, &bytes)) {
    warnings.push_back(where + "cannot be read (" + std::strerror(errno) +
                       "); every frame is described, nothing is cached");
    ::close(c->fd_);
    c->fd_ = -1;
    return c;
  }
  size_t valid = 0;  // bytes of the file that are a good header and whole, checked records
  if (bytes.size() >= header.size() && bytes.compare(0, header.size(), header) == 0) {
    valid = header.size();
    const size_t record = kRecordHead + c->row_bytes_ + 8;
    while (valid + record <= bytes.size()) {
      const char* r = bytes.data() + valid;
      std::uint64_t sum;
      std::memcpy(&sum, r + record - 8, 8);
      if (Fnv1a64(r, record - 8) != sum) break;
      size_t at = valid;
      Key key;
      std::int32_t w = 0, h = 0;
      Get(bytes, at, &key.hash);
      Get(bytes, at, &key.size);
      Get(bytes, at, &w);
      Get(bytes, at, &h);
      if (c->entries_.find(key) == c->entries_.end()) {
        c->entries_[key] = Entry{c->rows_.size(), w, h};
        c->rows_.insert(c->rows_.end(), r + kRecordHead, r + kRecordHead + c->row_bytes_);
      }
      valid += record;
    }
    if (valid != bytes.size())
      warnings.push_back(where + std::to_string(bytes.size() - valid) +
                         " bytes after the last good record (a run killed while writing, "
                         "or a damaged file) were " +
                         (locked ? "dropped" : "ignored") + "; those frames are described again");
  } else if (!bytes.empty()) {
    warnings.push_back(where + "not a cache file of these settings and version (bad header); " +
                       (locked ? "started afresh" : "ignored"));
  }
  if (!locked) return c;
  if (valid < header.size() || valid != bytes.size()) {
    // Keep the good prefix only (or start with the header), so that appended records follow
    // good ones.
    const bool fresh = valid < header.size();
    if (::ftruncate(c->fd_, static_cast<off_t>(fresh ? 0 : valid)) != 0 ||
        (fresh && !WriteAll(c->fd_, header.data(), header.size()))) {
      warnings.push_back(where + "cannot be written (" + std::strerror(errno) +
                         "); nothing new is cached");
      ::ftruncate(c->fd_, 0);
      return c;
    }
  }
  c->writable_ = true;
  return c;
}

DescriptorCache::~DescriptorCache() {
  if (fd_ >= 0) ::close(fd_);
}

size_t DescriptorCache::Records() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return entries_.size();
}

std::string DescriptorCache::WriteProblem() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return write_problem_;
}

bool DescriptorCache::KeyOf(const FrameSource& source, int i, Key* key) {
  const std::string name = source.FrameName(i);
  std::string bytes;
  if (!ReadFile(name, &bytes)) return false;
  key->hash = Fnv1a64(bytes.data(), bytes.size());
  key->size = bytes.size();
  std::lock_guard<std::mutex> lock(mutex_);
  keys_[name] = *key;
  return true;
}

bool DescriptorCache::Lookup(const FrameSource& source, int i, cv::Mat row, cv::Size* frame_size) {
  Key key;
  if (!KeyOf(source, i, &key)) return false;
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = entries_.find(key);
  if (it == entries_.end()) return false;
  if (row.rows != 1 || row.cols != row_width_ || row.type() != row_type_ || !row.isContinuous())
    return false;
  std::memcpy(row.data, rows_.data() + it->second.offset, row_bytes_);
  *frame_size = cv::Size(it->second.width, it->second.height);
  ++hits_;
  return true;
}

void DescriptorCache::Store(const FrameSource& source, int i, const cv::Mat& row,
                            cv::Size frame_size) {
  if (!writable_ || row.rows != 1 || row.cols != row_width_ || row.type() != row_type_ ||
      !row.isContinuous())
    return;
  const std::string name = source.FrameName(i);
  std::lock_guard<std::mutex> lock(mutex_);
  const auto k = keys_.find(name);
  if (k == keys_.end() || !write_problem_.empty()) return;
  const Key key = k->second;
  if (entries_.count(key)) return;
  std::string rec;
  Put<std::uint64_t>(rec, key.hash);
  Put<std::uint64_t>(rec, key.size);
  Put<std::int32_t>(rec, frame_size.width);
  Put<std::int32_t>(rec, frame_size.height);
  rec.append(reinterpret_cast<const char*>(row.data), row_bytes_);
  Put<std::uint64_t>(rec, Fnv1a64(rec.data(), rec.size()));
  if (!WriteAll(fd_, rec.data(), rec.size())) {
    write_problem_ = "Descriptor_cache: \"" + path_ + "\": cannot append (" + std::strerror(errno) +
                     "); the run goes on without caching";
    return;
  }
  entries_[key] = Entry{rows_.size(), frame_size.width, frame_size.height};
  rows_.insert(rows_.end(), row.data, row.data + row_bytes_);
  ++stored_;
}

}  // namespace openable
