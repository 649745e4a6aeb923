#include "OpenABLE/online/map_file.h"

#include <cmath>
#include <cstring>
#include <deque>
#include <limits>
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

// Little-endian integers, byte by byte (the file does not depend on the host's order).
template <typename T>
void Put(std::string& out, T value) {
  std::uint64_t v = 0;
  std::memcpy(&v, &value, sizeof(T));
  for (size_t i = 0; i < sizeof(T); ++i) out.push_back(static_cast<char>((v >> (8 * i)) & 0xFF));
}

std::string_view View(const void* data, size_t size) {
  return {static_cast<const char*>(data), size};
}

// Reads the parsed file, every read bounded: a short file gives one line naming what was cut.
struct Reader {
  const std::string& data;
  size_t pos = 0;
  size_t end = 0;
  const std::string& path;

  const char* Take(size_t n, const char* what) {
    if (n > end - pos)
      throw InputError(path + ": the map is truncated: " + std::to_string(end - pos) +
                       " bytes left at byte " + std::to_string(pos) + " for " + what +
                       ", expected " + std::to_string(n));
    const char* p = data.data() + pos;
    pos += n;
    return p;
  }
  template <typename T>
  T Get(const char* what) {
    const auto* p = reinterpret_cast<const unsigned char*>(Take(sizeof(T), what));
    std::uint64_t v = 0;
    for (size_t i = 0; i < sizeof(T); ++i) v |= static_cast<std::uint64_t>(p[i]) << (8 * i);
    T out;
    std::memcpy(&out, &v, sizeof(T));
    return out;
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

}  // namespace

std::string MapFile::Setting(const std::string& key) const {
  for (const auto& [k, v] : settings)
    if (k == key) return v;
  return "";
}

void WriteMapFile(const std::string& path, const MapFile& map) {
  const cv::Mat rows = map.rows.isContinuous() ? map.rows : map.rows.clone();
  // Small pieces (headers) are kept in a deque, whose elements do not move; the large ones
  // (rows, indexes, feature descriptors) are written from where they are.
  std::deque<std::string> small;
  std::vector<std::string_view> parts;
  auto add_small = [&](std::string s) {
    small.push_back(std::move(s));
    parts.push_back(small.back());
  };
  std::string text;
  for (const auto& [k, v] : map.settings) text += k + " " + v + "\n";
  std::string head(kSignature, kSignatureBytes);
  Put<std::uint32_t>(head, kMapFormatVersion);
  Put<std::uint64_t>(head, text.size());
  head += text;
  const size_t row_bytes = rows.total() * rows.elemSize();
  Put<std::uint64_t>(head, row_bytes);
  add_small(std::move(head));
  parts.push_back(View(rows.data, row_bytes));

  std::string blocks;
  Put<std::uint32_t>(blocks, static_cast<std::uint32_t>(map.blocks.size()));
  add_small(std::move(blocks));
  for (const auto& b : map.blocks) {
    std::string h;
    Put<std::uint32_t>(h, static_cast<std::uint32_t>(b.first));
    Put<std::uint32_t>(h, static_cast<std::uint32_t>(b.count));
    Put<std::uint64_t>(h, b.index.size());
    add_small(std::move(h));
    parts.push_back(View(b.index.data(), b.index.size()));
  }

  std::string flag;
  Put<std::uint32_t>(flag, map.has_features ? 1u : 0u);
  add_small(std::move(flag));
  std::deque<cv::Mat> copies;  // descriptors that were not continuous
  if (map.has_features)
    for (const FrameFeatures& f : map.features) {
      std::string h;
      Put<std::uint32_t>(h, static_cast<std::uint32_t>(f.points.size()));
      add_small(std::move(h));
      parts.push_back(View(f.points.data(), f.points.size() * sizeof(cv::Point2f)));
      const cv::Mat* d = &f.descriptors;
      if (!d->isContinuous()) d = &copies.emplace_back(d->clone());
      std::string dh;
      Put<std::int32_t>(dh, d->rows);
      Put<std::int32_t>(dh, d->cols);
      Put<std::int32_t>(dh, d->type());
      add_small(std::move(dh));
      parts.push_back(View(d->data, d->total() * d->elemSize()));
    }

  std::uint64_t sum = kFnv1a64Offset;
  for (const std::string_view p : parts) sum = Fnv1a64(p.data(), p.size(), sum);
  std::string tail;
  Put<std::uint64_t>(tail, sum);
  add_small(std::move(tail));

  OutputBatch batch;
  batch.Stage("map", path, parts);
  batch.Commit();
}

MapFile ReadMapFile(const std::string& path) {
  const std::string expected_what = "expected a file written by OnlineDetector::SaveMap";
  const std::string data = ReadInputFile(path, "map " + Quoted(path), expected_what);
  if (data.size() < kSignatureBytes || data.compare(0, kSignatureBytes, kSignature) != 0)
    throw InputError(path + ": not an OpenABLE map (" + expected_what +
                     ", which begins with \"OpenABLE-map\")");
  Reader r{data, kSignatureBytes, data.size(), path};
  const auto version = r.Get<std::uint32_t>("the format version");
  if (version != kMapFormatVersion)
    throw InputError(path + ": map format version " + std::to_string(version) +
                     "; expected version " + std::to_string(kMapFormatVersion) +
                     " (the version this OpenABLE writes and reads)");
  if (data.size() < r.pos + 8)
    throw InputError(path + ": the map is truncated (" + std::to_string(data.size()) +
                     " bytes): expected its contents and an 8-byte checksum");
  r.end = data.size() - 8;
  {
    Reader tail{data, r.end, data.size(), path};
    const auto stored = tail.Get<std::uint64_t>("the checksum");
    const std::uint64_t sum = Fnv1a64(data.data(), r.end);
    if (stored != sum)
      throw InputError(path + ": the map is damaged or truncated: its checksum does not match "
                       "its contents (expected the file exactly as SaveMap wrote it)");
  }

  MapFile map;
  const auto text_bytes = r.Get<std::uint64_t>("the settings' length");
  const std::string text(r.Take(text_bytes, "the settings"), text_bytes);
  for (size_t start = 0; start < text.size();) {
    size_t stop = text.find('\n', start);
    if (stop == std::string::npos) stop = text.size();
    const std::string line = text.substr(start, stop - start);
    // Settings are printable text (SaveMap writes names and numbers): a control character
    // would also break the one-line messages that quote them.
    for (const char c : line)
      if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f)
        throw InputError(path + ": the map's setting line " + Quoted(line) +
                         " holds a control character; expected lines \"key value\" of text");
    const size_t space = line.find(' ');
    map.settings.emplace_back(line.substr(0, space),
                              space == std::string::npos ? "" : line.substr(space + 1));
    start = stop + 1;
  }
  const int frames = ParseInt(map, "frames", path, 0);
  const int width = ParseInt(map, "row_width", path, 1);
  const std::string type_name = map.Setting("row_type");
  if (type_name != "CV_8U" && type_name != "CV_32F")
    throw InputError(path + ": setting \"row_type\" of the map is \"" + type_name +
                     "\": expected CV_8U or CV_32F");
  const int type = type_name == "CV_8U" ? CV_8U : CV_32F;
  const auto row_bytes = r.Get<std::uint64_t>("the rows' length");
  const std::uint64_t expected =
      static_cast<std::uint64_t>(frames) * static_cast<std::uint64_t>(width) * CV_ELEM_SIZE(type);
  if (row_bytes != expected)
    throw InputError(path + ": the map's rows take " + std::to_string(row_bytes) +
                     " bytes; expected " + std::to_string(expected) + " (" +
                     std::to_string(frames) + " frames of " + std::to_string(width) + " " +
                     type_name + ")");
  // Every size read from the file is checked against the bytes that follow before anything of
  // that size is allocated: a damaged or made-up size gives one line, not an allocation.
  const char* row_data = r.Take(row_bytes, "the rows");
  map.rows = cv::Mat(frames, width, type);
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
  if (map.has_features) {
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
        throw InputError(path + ": a frame's feature descriptors are " + std::to_string(drows) +
                         "x" + std::to_string(dcols) + " of type " + std::to_string(dtype) +
                         " for " + std::to_string(points) + " feature points: expected one " +
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
  if (r.pos != r.end)
    throw InputError(path + ": the map has " + std::to_string(r.end - r.pos) +
                     " bytes after its last section; expected none");
  return map;
}

}  // namespace openable
