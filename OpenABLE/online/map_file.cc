#include "OpenABLE/online/map_file.h"

#include <fcntl.h>
#include <libdeflate.h>
#include <sys/file.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <deque>
#include <filesystem>
#include <limits>
#include <sstream>
#include <string_view>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/hash.h"
#include "OpenABLE/base/input_file.h"
#include "OpenABLE/base/output_batch.h"

namespace openable {
namespace {

constexpr char kSignature[] = "OpenABLE-map\r\n\x1a\n";
constexpr size_t kSignatureBytes = 16;
static_assert(sizeof(kSignature) == kSignatureBytes + 1, "16 bytes and the terminating zero");
constexpr size_t kAlign = 64;       // sections start at multiples of this
constexpr size_t kEntryBytes = 32;  // one entry of the table of sections
constexpr std::uint32_t kMaxSections = 1u << 20;

enum SectionKind : std::uint32_t {
  kSettings = 1,
  kSessions = 2,
  kRows = 3,
  kBlock = 4,
  kFeatures = 5,
  kFrameFiles = 6,
};

// Little-endian integers, byte by byte (the file does not depend on the host's order).
template <typename T>
void Put(std::string& out, T value) {
  std::uint64_t v = 0;
  std::memcpy(&v, &value, sizeof(T));
  for (size_t i = 0; i < sizeof(T); ++i) out.push_back(static_cast<char>((v >> (8 * i)) & 0xFF));
}

template <typename T>
T GetAt(const char* p) {
  std::uint64_t v = 0;
  for (size_t i = 0; i < sizeof(T); ++i)
    v |= static_cast<std::uint64_t>(static_cast<unsigned char>(p[i])) << (8 * i);
  T out;
  std::memcpy(&out, &v, sizeof(T));
  return out;
}

std::string_view View(const void* data, size_t size) {
  return {static_cast<const char*>(data), size};
}

// CRC-32 of libdeflate (the library the PNG writer uses), several GB/s with the CPU's
// carry-less multiply: checking a 700 MB map takes a fraction of a second.
std::uint32_t Crc32(const void* data, size_t size, std::uint32_t crc = 0) {
  return libdeflate_crc32(crc, data, size);
}

// Reads a span of bytes, every read bounded: a short span gives one line naming what was cut.
struct Reader {
  const char* data;
  size_t pos = 0;
  size_t end = 0;
  const std::string& path;

  const char* Take(size_t n, const char* what) {
    if (n > end - pos)
      throw InputError(path + ": the map is truncated: " + std::to_string(end - pos) +
                       " bytes left at byte " + std::to_string(pos) + " for " + what +
                       ", expected " + std::to_string(n));
    const char* p = data + pos;
    pos += n;
    return p;
  }
  template <typename T>
  T Get(const char* what) {
    return GetAt<T>(Take(sizeof(T), what));
  }
};

int ParseInt(const MapFile& map, const std::string& key, const std::string& path, int lo) {
  const std::string text = map.Setting(key);
  try {
    size_t used = 0;
    const long long v = std::stoll(text, &used);
    if (used == text.size() && v >= lo && v <= std::numeric_limits<int>::max())
      return static_cast<int>(v);
  } catch (const std::exception&) {
  }
  throw InputError(path + ": setting \"" + key + "\" of the map is \"" + text +
                   "\": expected an integer >= " + std::to_string(lo));
}

bool IsControl(char c) { return static_cast<unsigned char>(c) < 0x20 || c == 0x7f; }

// Lines of a text section; a control character in one is refused (it would also break the
// one-line messages that quote them).
std::vector<std::string> TextLines(std::string_view text, const std::string& path,
                                   const char* what) {
  std::vector<std::string> lines;
  for (size_t start = 0; start < text.size();) {
    size_t stop = text.find('\n', start);
    if (stop == std::string::npos) stop = text.size();
    std::string line(text.substr(start, stop - start));
    for (const char c : line)
      if (IsControl(c) && c != '\t')
        throw InputError(path + ": the map's " + what + " line " + Quoted(line) +
                         " holds a control character; expected lines of text");
    lines.push_back(std::move(line));
    start = stop + 1;
  }
  return lines;
}

void ParseSettings(std::string_view text, const std::string& path, MapFile& map) {
  for (const std::string& line : TextLines(text, path, "setting")) {
    if (line.find('\t') != std::string::npos)
      throw InputError(path + ": the map's setting line " + Quoted(line) +
                       " holds a tab; expected lines \"key value\" of text");
    const size_t space = line.find(' ');
    map.settings.emplace_back(line.substr(0, space),
                              space == std::string::npos ? "" : line.substr(space + 1));
  }
}

// The rows' shape from the settings, and their byte count.
struct RowShape {
  int frames = 0, width = 0, type = CV_8U;
  std::uint64_t bytes = 0;
};
RowShape RowShapeOf(const MapFile& map, const std::string& path) {
  // The frames' size: "" (unknown) or "WxH", each a whole number from 1.
  const std::string size = map.Setting("frame_size");
  if (!size.empty()) {
    int w = 0, h = 0, used = 0;
    if (std::sscanf(size.c_str(), "%9dx%9d%n", &w, &h, &used) != 2 ||
        used != static_cast<int>(size.size()) || w < 1 || h < 1 ||
        size != std::to_string(w) + "x" + std::to_string(h))
      throw InputError(path + ": setting \"frame_size\" of the map is " + Quoted(size) +
                       ": expected WxH (e.g. 640x480) or nothing");
  }
  RowShape shape;
  shape.frames = ParseInt(map, "frames", path, 0);
  shape.width = ParseInt(map, "row_width", path, 1);
  const std::string type_name = map.Setting("row_type");
  if (type_name != "CV_8U" && type_name != "CV_32F")
    throw InputError(path + ": setting \"row_type\" of the map is \"" + type_name +
                     "\": expected CV_8U or CV_32F");
  shape.type = type_name == "CV_8U" ? CV_8U : CV_32F;
  shape.bytes = static_cast<std::uint64_t>(shape.frames) * static_cast<std::uint64_t>(shape.width) *
                CV_ELEM_SIZE(shape.type);
  return shape;
}

// The shapes of the rows of the other descriptors of a map of several (format 3): settings
// "channel_widths" and "channel_types" list every descriptor's, the first being `first`'s.
std::vector<RowShape> MoreRowShapes(const MapFile& map, const RowShape& first,
                                    const std::string& path) {
  const std::string widths = map.Setting("channel_widths"), types = map.Setting("channel_types");
  if (widths.empty() && types.empty()) return {};
  std::vector<std::string> w, t;
  std::istringstream wi(widths), ti(types);
  for (std::string x; wi >> x;) w.push_back(x);
  for (std::string x; ti >> x;) t.push_back(x);
  const auto bad = [&](const std::string& why) {
    return InputError(path + ": settings \"channel_widths\" " + Quoted(widths) +
                      " and \"channel_types\" " + Quoted(types) + " of the map: " + why);
  };
  if (w.size() != t.size() || w.empty() || w.size() > 64)
    throw bad("expected one width and one type (CV_8U or CV_32F) per descriptor");
  std::vector<RowShape> out;
  for (size_t k = 0; k < w.size(); ++k) {
    RowShape shape = first;
    long long v = -1;
    try {
      size_t used = 0;
      v = std::stoll(w[k], &used);
      if (used != w[k].size()) v = -1;
    } catch (const std::exception&) {
    }
    if (v < 1 || v > (1 << 24) || (t[k] != "CV_8U" && t[k] != "CV_32F"))
      throw bad("expected widths from 1 and types CV_8U or CV_32F");
    shape.width = static_cast<int>(v);
    shape.type = t[k] == "CV_8U" ? CV_8U : CV_32F;
    shape.bytes = static_cast<std::uint64_t>(shape.frames) *
                  static_cast<std::uint64_t>(shape.width) * CV_ELEM_SIZE(shape.type);
    if (k == 0 && (shape.width != first.width || shape.type != first.type))
      throw bad("expected the first to be row_width and row_type");
    if (k > 0) out.push_back(shape);
  }
  return out;
}

void CheckRowBytes(std::uint64_t bytes, const RowShape& shape, const MapFile& map,
                   const std::string& path) {
  if (bytes != shape.bytes)
    throw InputError(path + ": the map's rows take " + std::to_string(bytes) + " bytes; expected " +
                     std::to_string(shape.bytes) + " (" + std::to_string(shape.frames) +
                     " frames of " + std::to_string(shape.width) + " " + map.Setting("row_type") +
                     ")");
}

// The local features of `frames` frames (the encoding both versions share).
void ParseFeatures(Reader& r, int frames, const std::string& path, MapFile& map) {
  map.features.resize(static_cast<size_t>(frames));
  for (FrameFeatures& f : map.features) {
    const auto points = r.Get<std::uint32_t>("a frame's feature count");
    const size_t point_bytes = static_cast<size_t>(points) * sizeof(cv::Point2f);
    const char* point_data = r.Take(point_bytes, "a frame's feature points");
    f.points.resize(points);
    if (point_bytes > 0) std::memcpy(f.points.data(), point_data, point_bytes);
    for (const cv::Point2f& p : f.points)
      if (!std::isfinite(p.x) || !std::isfinite(p.y))
        throw InputError(path + ": a frame's feature point is (" + std::to_string(p.x) + ", " +
                         std::to_string(p.y) + "): expected pixel coordinates");
    const int drows = r.Get<std::int32_t>("a frame's descriptor rows");
    const int dcols = r.Get<std::int32_t>("a frame's descriptor columns");
    const int dtype = r.Get<std::int32_t>("a frame's descriptor type");
    // One descriptor row per feature point (none without points), as the verification
    // extracted them.
    if (drows < 0 || dcols < 0 || (dtype != CV_8UC1 && dtype != CV_32FC1) ||
        static_cast<std::uint32_t>(drows) != points || (drows > 0 && dcols == 0))
      throw InputError(path + ": a frame's feature descriptors are " + std::to_string(drows) + "x" +
                       std::to_string(dcols) + " of type " + std::to_string(dtype) + " for " +
                       std::to_string(points) + " feature points: expected one " +
                       "CV_8UC1 (ORB) or CV_32FC1 (SIFT) row per point");
    if (drows > 0) {
      const size_t bytes =
          static_cast<size_t>(drows) * static_cast<size_t>(dcols) * CV_ELEM_SIZE(dtype);
      const char* data = r.Take(bytes, "a frame's feature descriptors");
      f.descriptors = cv::Mat(drows, dcols, dtype);
      std::memcpy(f.descriptors.data, data, bytes);
    }
  }
}

std::shared_future<std::string> Ready(std::string error) {
  std::promise<std::string> done;
  done.set_value(std::move(error));
  return done.get_future().share();
}

// ---- Version 1 ------------------------------------------------------------------------------

MapFile ReadFirstVersion(const std::string& path, std::string_view data) {
  Reader r{data.data(), kSignatureBytes + 4, data.size(), path};
  if (data.size() < r.pos + 8)
    throw InputError(path + ": the map is truncated (" + std::to_string(data.size()) +
                     " bytes): expected its contents and an 8-byte checksum");
  r.end = data.size() - 8;
  if (GetAt<std::uint64_t>(data.data() + r.end) != Fnv1a64(data.data(), r.end))
    throw InputError(path +
                     ": the map is damaged or truncated: its checksum does not match "
                     "its contents (expected the file exactly as SaveMap wrote it)");
  MapFile map;
  map.version = 1;
  const auto text_bytes = r.Get<std::uint64_t>("the settings' length");
  ParseSettings(View(r.Take(text_bytes, "the settings"), text_bytes), path, map);
  const RowShape shape = RowShapeOf(map, path);
  const auto row_bytes = r.Get<std::uint64_t>("the rows' length");
  CheckRowBytes(row_bytes, shape, map, path);
  // Every size read from the file is checked against the bytes that follow before anything of
  // that size is allocated: a damaged or made-up size gives one line, not an allocation.
  const char* row_data = r.Take(row_bytes, "the rows");
  map.rows = cv::Mat(shape.frames, shape.width, shape.type);
  if (row_bytes > 0) std::memcpy(map.rows.data, row_data, row_bytes);
  const auto blocks = r.Get<std::uint32_t>("the block count");
  for (std::uint32_t i = 0; i < blocks; ++i) {
    IncrementalIndex::SavedBlock b;
    b.first = static_cast<int>(r.Get<std::uint32_t>("a block's first row"));
    b.count = static_cast<int>(r.Get<std::uint32_t>("a block's rows"));
    const auto bytes = r.Get<std::uint64_t>("a block's length");
    const char* p = r.Take(bytes, "a block's index");
    b.index.assign(p, p + bytes);
    map.blocks.push_back(std::move(b));
  }
  map.has_features = r.Get<std::uint32_t>("the features flag") != 0;
  if (map.has_features) ParseFeatures(r, shape.frames, path, map);
  if (r.pos != r.end)
    throw InputError(path + ": the map has " + std::to_string(r.end - r.pos) +
                     " bytes after its last section; expected none");
  map.sessions.push_back({"default", "", 0, shape.frames});
  map.check = Ready("");
  return map;
}

// ---- Mapping --------------------------------------------------------------------------------

// The file mapped read-only; unmapped when the last holder lets go. A map file is replaced by
// renaming a new file over it (WriteMapFile), never rewritten in place, so the mapped bytes
// do not change under a reader.
struct Mapped {
  const char* data = nullptr;
  size_t size = 0;
  ~Mapped() {
    if (data != nullptr && size > 0) munmap(const_cast<char*>(data), size);
  }
};

std::shared_ptr<Mapped> MapWholeFile(const std::string& path, const std::string& expected) {
  std::error_code error;
  if (std::filesystem::symlink_status(path, error).type() == std::filesystem::file_type::not_found)
    throw InputError("no map at " + Quoted(path) +
                     " (create one with openable_map add, or "
                     "OnlineDetector::SaveMap)");
  CheckInputFile(path, "map " + Quoted(path), expected);
  const int fd = open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0)
    throw InputError("map " + Quoted(path) + " cannot be opened (" + std::strerror(errno) + ")");
  struct stat st {};
  if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    close(fd);
    throw InputError("map " + Quoted(path) + " is not a regular file (" + expected + ")");
  }
  auto m = std::make_shared<Mapped>();
  m->size = static_cast<size_t>(st.st_size);
  if (m->size > 0) {
    void* p = mmap(nullptr, m->size, PROT_READ, MAP_PRIVATE, fd, 0);
    if (p == MAP_FAILED) {
      const int error = errno;
      close(fd);
      throw InputError("map " + Quoted(path) + " cannot be mapped into memory (" +
                       std::strerror(error) + ")");
    }
    m->data = static_cast<const char*>(p);
  }
  close(fd);
  return m;
}

struct Section {
  std::uint32_t kind = 0, a = 0, b = 0, crc = 0;
  std::uint64_t offset = 0, bytes = 0;
};

std::string CheckSection(const char* base, const Section& s, const std::string& path,
                         const std::string& what) {
  if (Crc32(base + s.offset, s.bytes) != s.crc)
    return path + ": the map is damaged: the checksum of " + what +
           " does not match its contents (expected the file exactly as it was saved)";
  return "";
}

std::string SectionName(const Section& s) {
  switch (s.kind) {
    case kRows:
      return s.a == 0 ? "its descriptor rows" : "the rows of its descriptor " + std::to_string(s.a);
    case kFrameFiles:
      return "its frames' file names";
    case kBlock:
      return "the index block of rows " + std::to_string(s.a) + " to " +
             std::to_string(static_cast<std::uint64_t>(s.a) + s.b - 1);
    default:
      return "section " + std::to_string(s.kind);
  }
}

}  // namespace

MapWriteLock::MapWriteLock(const std::string& path,
                           const std::function<void(const std::string&)>& waiting) {
  const std::string lock = path + ".lock";
  fd_ = ::open(lock.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd_ < 0)
    throw InputError("map lock " + Quoted(lock) + " cannot be created (" + std::strerror(errno) +
                     "; expected a writable folder beside the map)");
  if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    if (errno != EWOULDBLOCK) {
      const int error = errno;
      ::close(fd_);
      throw InputError("map lock " + Quoted(lock) + " cannot be taken (" + std::strerror(error) +
                       ")");
    }
    if (waiting) {
      // The holder wrote its process id there.
      char text[32] = {0};
      const ssize_t n = ::pread(fd_, text, sizeof text - 1, 0);
      const std::string holder = n > 0 ? std::string(text, static_cast<size_t>(n)) : "";
      waiting("waiting for another writer of " + Quoted(path) +
              (holder.empty() ? "" : " (process " + holder + ")") + " to finish");
    }
    while (::flock(fd_, LOCK_EX) != 0) {
      if (errno == EINTR) continue;
      const int error = errno;
      ::close(fd_);
      throw InputError("map lock " + Quoted(lock) + " cannot be taken (" + std::strerror(error) +
                       ")");
    }
  }
  const std::string pid = std::to_string(::getpid());
  if (::ftruncate(fd_, 0) == 0) {
    const ssize_t written = ::pwrite(fd_, pid.data(), pid.size(), 0);
    (void)written;  // the id only names the holder in another writer's message
  }
}

MapWriteLock::~MapWriteLock() {
  if (fd_ >= 0) ::close(fd_);  // releases the lock
}

std::string MapTimeNow() {
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%SZ", &utc);
  return text;
}

void CheckSessionTime(const std::string& time, const std::string& what) {
  // Written by hand: std::get_time accepts what the locale allows and does not check the day
  // of the month against the month; the form is fixed and short.
  const auto digits = [&](size_t at, size_t n, int& value) {
    if (at + n > time.size()) return false;
    value = 0;
    for (size_t i = at; i < at + n; ++i) {
      if (time[i] < '0' || time[i] > '9') return false;
      value = value * 10 + (time[i] - '0');
    }
    return true;
  };
  int year = 0, month = 0, day = 0, hour = 0, minute = 0, second = 0;
  bool ok = time.size() >= 20 && time.size() <= 40 && digits(0, 4, year) && time[4] == '-' &&
            digits(5, 2, month) && time[7] == '-' && digits(8, 2, day) && time[10] == 'T' &&
            digits(11, 2, hour) && time[13] == ':' && digits(14, 2, minute) && time[16] == ':' &&
            digits(17, 2, second) && time.back() == 'Z';
  if (ok && time.size() > 20) {  // decimals of the second: ".d..."
    ok = time[19] == '.' && time.size() > 21;
    for (size_t i = 20; ok && i + 1 < time.size(); ++i) ok = time[i] >= '0' && time[i] <= '9';
  }
  static const int kDays[12] = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
  const bool leap = (year % 4 == 0 && year % 100 != 0) || year % 400 == 0;
  ok = ok && month >= 1 && month <= 12 && day >= 1 &&
       day <= kDays[month - 1] + (month == 2 && leap ? 1 : 0) && hour <= 23 && minute <= 59 &&
       second <= 60;  // 60: a leap second
  if (!ok)
    throw InputError(what + " " + Quoted(time) +
                     ": expected a UTC time in ISO 8601, "
                     "YYYY-MM-DDTHH:MM:SSZ (e.g. 2026-11-27T09:30:00Z)");
}

void CheckSessionName(const std::string& name, const std::string& what) {
  bool ok = !name.empty() && name.size() <= 200 && name.front() != ' ' && name.back() != ' ';
  for (const char c : name) ok = ok && !IsControl(c);
  if (!ok)
    throw InputError(what + " " + Quoted(name) +
                     ": expected a session name of 1 to 200 "
                     "printable characters (no tab or line break, no space at either end)");
}

std::string MapFile::Setting(const std::string& key) const {
  for (const auto& [k, v] : settings)
    if (k == key) return v;
  return "";
}

void WriteMapFile(const std::string& path, const MapFile& map) {
  const cv::Mat rows = map.rows.isContinuous() ? map.rows : map.rows.clone();
  // The sections' bytes, in order: small ones held here (a deque: its elements do not move),
  // large ones (rows, indexes) written from where they are.
  std::deque<std::string> small;
  struct Piece {
    std::uint32_t kind, a, b;
    std::vector<std::string_view> parts;
  };
  std::vector<Piece> pieces;
  std::string text;
  for (const auto& [k, v] : map.settings) text += k + " " + v + "\n";
  pieces.push_back({kSettings, 0, 0, {small.emplace_back(std::move(text))}});
  std::string sessions;
  for (const MapSession& s : map.sessions)
    sessions += std::to_string(s.first) + "\t" + std::to_string(s.count) + "\t" +
                (s.time.empty() ? "-" : s.time) + "\t" + s.name + "\n";
  pieces.push_back({kSessions, 0, 0, {small.emplace_back(std::move(sessions))}});
  pieces.push_back({kRows, 0, 0, {View(rows.data, rows.total() * rows.elemSize())}});
  std::deque<cv::Mat> continuous;  // rows that were not continuous
  for (size_t k = 0; k < map.more_rows.size(); ++k) {
    const cv::Mat* m = &map.more_rows[k];
    if (!m->isContinuous()) m = &continuous.emplace_back(m->clone());
    pieces.push_back(
        {kRows, static_cast<std::uint32_t>(k + 1), 0, {View(m->data, m->total() * m->elemSize())}});
  }
  for (const auto& b : map.blocks) {
    const SavedIndex bytes = b.Bytes();
    pieces.push_back({kBlock,
                      static_cast<std::uint32_t>(b.first),
                      static_cast<std::uint32_t>(b.count),
                      {View(bytes.data, bytes.size)}});
  }
  if (!map.frame_files.empty()) {
    std::string files;
    for (const std::string& f : map.frame_files) {
      // A name that would break the line structure is not kept.
      const bool plain = std::none_of(f.begin(), f.end(), IsControl);
      files += (plain ? f : std::string()) + "\n";
    }
    pieces.push_back({kFrameFiles, 0, 0, {small.emplace_back(std::move(files))}});
  }
  std::deque<cv::Mat> copies;  // descriptors that were not continuous
  if (map.has_features) {
    Piece features{kFeatures, 0, 0, {}};
    for (const FrameFeatures& f : map.features) {
      std::string h;
      Put<std::uint32_t>(h, static_cast<std::uint32_t>(f.points.size()));
      features.parts.push_back(small.emplace_back(std::move(h)));
      features.parts.push_back(View(f.points.data(), f.points.size() * sizeof(cv::Point2f)));
      const cv::Mat* d = &f.descriptors;
      if (!d->isContinuous()) d = &copies.emplace_back(d->clone());
      std::string dh;
      Put<std::int32_t>(dh, d->rows);
      Put<std::int32_t>(dh, d->cols);
      Put<std::int32_t>(dh, d->type());
      features.parts.push_back(small.emplace_back(std::move(dh)));
      features.parts.push_back(View(d->data, d->total() * d->elemSize()));
    }
    pieces.push_back(std::move(features));
  }

  // The table: each section at the next multiple of kAlign, with its CRC-32.
  const size_t table_end = kSignatureBytes + 8 + pieces.size() * kEntryBytes + 4;
  std::uint64_t offset = (table_end + kAlign - 1) / kAlign * kAlign;
  std::string head(kSignature, kSignatureBytes);
  Put<std::uint32_t>(head, kMapFormatVersion);
  Put<std::uint32_t>(head, static_cast<std::uint32_t>(pieces.size()));
  std::vector<std::uint64_t> pads;
  for (const Piece& p : pieces) {
    std::uint64_t bytes = 0;
    std::uint32_t crc = 0;
    for (const std::string_view part : p.parts) {
      bytes += part.size();
      crc = Crc32(part.data(), part.size(), crc);
    }
    Put<std::uint32_t>(head, p.kind);
    Put<std::uint32_t>(head, p.a);
    Put<std::uint64_t>(head, offset);
    Put<std::uint64_t>(head, bytes);
    Put<std::uint32_t>(head, crc);
    Put<std::uint32_t>(head, p.b);
    const std::uint64_t next = (offset + bytes + kAlign - 1) / kAlign * kAlign;
    pads.push_back(next - offset - bytes);
    offset = next;
  }
  Put<std::uint32_t>(head, Crc32(head.data(), head.size()));
  head.resize((head.size() + kAlign - 1) / kAlign * kAlign, '\0');
  static const std::string kZeros(kAlign, '\0');
  std::vector<std::string_view> parts{small.emplace_back(std::move(head))};
  for (size_t i = 0; i < pieces.size(); ++i) {
    for (const std::string_view part : pieces[i].parts)
      if (!part.empty()) parts.push_back(part);
    // The last section needs no padding after it.
    if (i + 1 < pieces.size() && pads[i] > 0) parts.push_back(View(kZeros.data(), pads[i]));
  }
  OutputBatch batch;
  batch.Stage("map", path, parts);
  batch.Commit();
}

MapFile ReadMapFile(const std::string& path, const MapReadOptions& options) {
  const std::string expected_what = "expected a file written by OnlineDetector::SaveMap";
  const std::shared_ptr<Mapped> file = MapWholeFile(path, expected_what);
  const char* data = file->data;
  const size_t size = file->size;
  if (size < kSignatureBytes || std::memcmp(data, kSignature, kSignatureBytes) != 0)
    throw InputError(path + ": not an OpenABLE map (" + expected_what +
                     ", which begins with \"OpenABLE-map\")");
  Reader r{data, kSignatureBytes, size, path};
  const auto version = r.Get<std::uint32_t>("the format version");
  if (version == 1) return ReadFirstVersion(path, std::string_view(data, size));
  if (version != 2 && version != kMapFormatVersion)
    throw InputError(
        path + ": map format version " + std::to_string(version) + "; this " +
        "OpenABLE reads versions 1 to " + std::to_string(kMapFormatVersion) +
        (version > kMapFormatVersion ? " (the map was written by a newer OpenABLE)" : ""));
  const auto count = r.Get<std::uint32_t>("the section count");
  if (count > kMaxSections)
    throw InputError(path + ": the map is damaged: its table names " + std::to_string(count) +
                     " sections");
  std::vector<Section> sections(count);
  r.Take(static_cast<size_t>(count) * kEntryBytes, "the table of sections");
  const auto stored = r.Get<std::uint32_t>("the table's checksum");
  if (stored != Crc32(data, r.pos - 4))
    throw InputError(path +
                     ": the map is damaged: the checksum of its table of sections does "
                     "not match (expected the file exactly as it was saved)");
  const std::uint32_t last_kind = version == 2 ? kFeatures : kFrameFiles;
  for (std::uint32_t i = 0; i < count; ++i) {
    const char* e = data + kSignatureBytes + 8 + static_cast<size_t>(i) * kEntryBytes;
    Section& s = sections[i];
    s.kind = GetAt<std::uint32_t>(e);
    s.a = GetAt<std::uint32_t>(e + 4);
    s.offset = GetAt<std::uint64_t>(e + 8);
    s.bytes = GetAt<std::uint64_t>(e + 16);
    s.crc = GetAt<std::uint32_t>(e + 24);
    s.b = GetAt<std::uint32_t>(e + 28);
    if (s.offset % kAlign != 0 || s.offset > size || s.bytes > size - s.offset)
      throw InputError(path + ": the map is truncated: section " + std::to_string(i) +
                       " takes bytes " + std::to_string(s.offset) + " to " +
                       std::to_string(s.offset + s.bytes) + " of a file of " +
                       std::to_string(size) +
                       " bytes (expected the file exactly as it was "
                       "saved)");
    if (s.kind < kSettings || s.kind > last_kind)
      throw InputError(path + ": the map's section " + std::to_string(i) + " is of kind " +
                       std::to_string(s.kind) + "; expected kinds 1 to " +
                       std::to_string(last_kind));
  }
  // The layout WriteMapFile gives: settings, sessions, the rows of each descriptor in order,
  // the index blocks, the frames' files (optional) and the features (optional, last).
  if (count < 3 || sections[0].kind != kSettings || sections[1].kind != kSessions ||
      sections[2].kind != kRows || sections[2].a != 0)
    throw InputError(path + ": the map's sections are not settings, sessions and rows first");
  std::uint32_t channels = 1;
  while (2 + channels < count && sections[2 + channels].kind == kRows &&
         sections[2 + channels].a == channels)
    ++channels;
  std::uint32_t i_files = 0;
  for (std::uint32_t i = 2 + channels; i < count; ++i) {
    const std::uint32_t k = sections[i].kind;
    const bool ok = (k == kBlock && i_files == 0) ||
                    (k == kFrameFiles && i_files == 0 &&
                     (i + 1 == count || sections[i + 1].kind == kFeatures)) ||
                    (k == kFeatures && i + 1 == count);
    if (!ok)
      throw InputError(path + ": the map's section " + std::to_string(i) + " is of kind " +
                       std::to_string(k) +
                       "; expected the rows of each descriptor, index "
                       "blocks, the frames' files, then the features last");
    if (k == kFrameFiles) i_files = i;
  }

  MapFile map;
  map.version = version;
  for (int i = 0; i < 2; ++i) {
    const std::string error =
        CheckSection(data, sections[i], path, i == 0 ? "its settings" : "its sessions");
    if (!error.empty()) throw InputError(error);
  }
  ParseSettings(View(data + sections[0].offset, sections[0].bytes), path, map);
  const RowShape shape = RowShapeOf(map, path);
  CheckRowBytes(sections[2].bytes, shape, map, path);
  const std::vector<RowShape> more = MoreRowShapes(map, shape, path);
  if (more.size() + 1 != channels)
    throw InputError(path + ": the map holds the rows of " + std::to_string(channels) +
                     " descriptors; its settings name " + std::to_string(more.size() + 1));
  for (size_t k = 0; k < more.size(); ++k)
    if (sections[3 + k].bytes != more[k].bytes)
      throw InputError(path + ": the rows of the map's descriptor " + std::to_string(k + 1) +
                       " take " + std::to_string(sections[3 + k].bytes) + " bytes; expected " +
                       std::to_string(more[k].bytes) + " (" + std::to_string(shape.frames) +
                       " frames of " + std::to_string(more[k].width) + ")");

  // Sessions: tiling the frames in order.
  int next = 0;
  for (const std::string& line :
       TextLines(View(data + sections[1].offset, sections[1].bytes), path, "session")) {
    MapSession s;
    std::vector<std::string> fields;
    for (size_t start = 0, i = 0; i < 3; ++i) {
      const size_t tab = line.find('\t', start);
      if (tab == std::string::npos) break;
      fields.push_back(line.substr(start, tab - start));
      start = tab + 1;
      if (i == 2) fields.push_back(line.substr(start));
    }
    long long first = -1, frames = -1;
    if (fields.size() == 4) {
      try {
        size_t used = 0;
        first = std::stoll(fields[0], &used);
        if (used != fields[0].size()) first = -1;
        frames = std::stoll(fields[1], &used);
        if (used != fields[1].size()) frames = -1;
      } catch (const std::exception&) {
        first = frames = -1;
      }
    }
    if (fields.size() != 4 || first != next || frames < 0 || frames > shape.frames - next)
      throw InputError(path + ": the map's session line " + Quoted(line) + " is not \"first" +
                       "<TAB>frames<TAB>time<TAB>name\" continuing at frame " +
                       std::to_string(next) + " within its " + std::to_string(shape.frames) +
                       " frames");
    s.first = static_cast<int>(first);
    s.count = static_cast<int>(frames);
    s.time = fields[2] == "-" ? "" : fields[2];
    s.name = fields[3];
    CheckSessionName(s.name, path + ": the map's session");
    for (const MapSession& other : map.sessions)
      if (other.name == s.name)
        throw InputError(path + ": the map has two sessions named " + Quoted(s.name));
    next += s.count;
    map.sessions.push_back(std::move(s));
  }
  if (next != shape.frames)
    throw InputError(path + ": the map's sessions hold " + std::to_string(next) +
                     " frames; expected its " + std::to_string(shape.frames));
  if (options.header_only) {
    map.check = Ready("");
    return map;
  }

  // Features: parsed (copied) here, so checked here.
  if (sections.back().kind == kFeatures) {
    const Section& f = sections.back();
    const std::string error = CheckSection(data, f, path, "its local features");
    if (!error.empty()) throw InputError(error);
    Reader fr{data + f.offset, 0, static_cast<size_t>(f.bytes), path};
    map.has_features = true;
    ParseFeatures(fr, shape.frames, path, map);
    if (fr.pos != fr.end)
      throw InputError(path + ": the map's local features have " + std::to_string(fr.end - fr.pos) +
                       " bytes after the last frame's");
  }

  // The frames' files: small, checked and parsed here.
  if (i_files > 0) {
    const Section& f = sections[i_files];
    const std::string error = CheckSection(data, f, path, "its frames' file names");
    if (!error.empty()) throw InputError(error);
    // A line each, each ending with a line break.
    map.frame_files = TextLines(View(data + f.offset, f.bytes), path, "file name");
    if (map.frame_files.size() != static_cast<size_t>(shape.frames))
      throw InputError(path + ": the map names the files of " +
                       std::to_string(map.frame_files.size()) + " frames; expected its " +
                       std::to_string(shape.frames));
  }

  // Rows and blocks: in place (the mapping kept alive by whoever holds them) or copied.
  const std::shared_ptr<const void> keep = options.in_place ? file : nullptr;
  if (options.in_place) map.mapping = file;
  const auto rows_of = [&](const Section& rows, const RowShape& sh) {
    if (options.in_place)
      return cv::Mat(sh.frames, sh.width, sh.type, const_cast<char*>(data + rows.offset));
    cv::Mat m(sh.frames, sh.width, sh.type);
    if (rows.bytes > 0) std::memcpy(m.data, data + rows.offset, rows.bytes);
    return m;
  };
  map.rows = rows_of(sections[2], shape);
  std::vector<Section> checked{sections[2]};
  for (size_t k = 0; k < more.size(); ++k) {
    map.more_rows.push_back(rows_of(sections[3 + k], more[k]));
    checked.push_back(sections[3 + k]);
  }
  for (std::uint32_t i = 2 + channels; i < count; ++i) {
    const Section& s = sections[i];
    if (s.kind != kBlock) continue;
    checked.push_back(s);
    IncrementalIndex::SavedBlock b;
    b.first = static_cast<int>(s.a);
    b.count = static_cast<int>(s.b);
    const auto* bytes = reinterpret_cast<const std::uint8_t*>(data + s.offset);
    if (options.in_place)
      b.in_place = SavedIndex(bytes, static_cast<size_t>(s.bytes), keep);
    else
      b.index.assign(bytes, bytes + s.bytes);
    map.blocks.push_back(std::move(b));
  }
  // The large sections' checksums: here, or on a thread of their own that holds the mapping.
  auto check = [file, checked, path]() {
    for (const Section& s : checked) {
      std::string error = CheckSection(file->data, s, path, SectionName(s));
      if (!error.empty()) return error;
    }
    return std::string();
  };
  if (options.check_in_background) {
    map.check = std::async(std::launch::async, check).share();
  } else {
    const std::string error = check();
    if (!error.empty()) throw InputError(error);
    map.check = Ready("");
  }
  return map;
}

}  // namespace openable
