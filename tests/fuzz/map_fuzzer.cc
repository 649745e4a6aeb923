// libFuzzer target: arbitrary bytes as a saved online map (the file of OnlineDetector::SaveMap,
// OpenABLE/online/map_file.h), written to a temporary file. ReadMapFile reads the bytes as
// they are; then the same bytes with their checksums made right (format version 2: each
// section's CRC-32 named by the table, then the table's own (versions 2 and 3); version 1: the last
// 8 bytes, the FNV-1a of the rest), so that mutations reach the sections behind the checksums, go
// through ReadMapFile and OnlineDetector::LoadMap into the detector whose settings the map names
// (tests/fuzz/map_detectors.h), and, when it loads, one more frame is searched among the
// loaded ones (and verified against their saved features). The expected outcomes are a loaded
// map or one InputError line naming the file (and for the frame added, a refusal of a frame of
// another size than the map's); any other exception, a crash or a sanitizer report is a
// finding. Built with -DOPENABLE_BUILD_FUZZERS=ON (clang); see docs/robustness.md.
#include <libdeflate.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <string>

#include "OpenABLE/base/hash.h"
#include "OpenABLE/base/strings.h"
#include "OpenABLE/online/map_file.h"
#include "OpenABLE/online/online.h"
#include "tests/fuzz/fuzz_support.h"
#include "tests/fuzz/map_detectors.h"

namespace {

using openable::fuzz::MapKind;
using openable::fuzz::Refuses;
using openable::fuzz::TempFile;

std::uint64_t Le(const std::string& b, std::size_t at, int bytes) {
  std::uint64_t v = 0;
  for (int i = 0; i < bytes; ++i)
    v |= static_cast<std::uint64_t>(static_cast<unsigned char>(b[at + i])) << (8 * i);
  return v;
}

void PutLe(std::string& b, std::size_t at, std::uint64_t v, int bytes) {
  for (int i = 0; i < bytes; ++i, v >>= 8) b[at + i] = static_cast<char>(v & 0xFF);
}

// The checksums of `b` made right, as far as its table can be read; false when there is no
// place for them.
bool FixChecksums(std::string& b) {
  if (b.size() < 24) return false;
  if (Le(b, 16, 4) == 1) {
    PutLe(b, b.size() - 8, openable::Fnv1a64(b.data(), b.size() - 8), 8);
    return true;
  }
  const std::uint64_t count = Le(b, 20, 4);
  const std::size_t table_end =
      24 + static_cast<std::size_t>(std::min<std::uint64_t>(count, 1u << 16)) * 32;
  if (count > (1u << 16) || table_end + 4 > b.size()) return false;
  for (std::size_t e = 24; e < table_end; e += 32) {
    const std::uint64_t offset = Le(b, e + 8, 8), bytes = Le(b, e + 16, 8);
    if (offset <= b.size() && bytes <= b.size() - offset)
      PutLe(b, e + 24, libdeflate_crc32(0, b.data() + offset, static_cast<std::size_t>(bytes)), 4);
  }
  PutLe(b, table_end, libdeflate_crc32(0, b.data(), table_end), 4);
  return true;
}

MapKind KindOf(const openable::MapFile& map) {
  if (!map.more_rows.empty()) return MapKind::kSeveral;
  if (openable::Upper(map.Setting("descriptor")) == "NPY") return MapKind::kGiven;
  if (map.Setting("row_type") == "CV_32F") return MapKind::kFloat;
  return map.Setting("features") == "none" ? MapKind::kRows : MapKind::kVerifying;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::string bytes = openable::fuzz::Bytes(data, size);
  {
    const TempFile file(bytes, ".map");
    Refuses([&] { openable::ReadMapFile(file.Path()); }, file.Path());
  }
  if (!FixChecksums(bytes)) return 0;
  const TempFile file(bytes, ".map");
  openable::MapFile map;
  openable::MapReadOptions read;
  read.check_in_background = false;
  if (Refuses([&] { map = openable::ReadMapFile(file.Path(), read); }, file.Path())) return 0;
  const MapKind kind = KindOf(map);
  openable::OnlineDetector detector(openable::fuzz::MapDetectorOptions(kind));
  if (Refuses([&] { detector.LoadMap(file.Path()); }, file.Path())) return 0;
  if (kind == MapKind::kVerifying) {
    // A map whose frames are of another size refuses the frame (one line).
    Refuses([&] { detector.AddFrame(openable::fuzz::MapFrame(0)); });
  } else {
    detector.AddDescriptor(cv::Mat::zeros(1, detector.RowWidth(), detector.RowType()));
  }
  // A map of rows given by a file (descriptor NPY) is also opened with its own settings
  // (MapOptions: the rows' width and type from the map), as openable_map opens it. Maps of
  // other descriptors are not: a network's would name a model file to read.
  if (openable::Upper(map.Setting("descriptor")) == "NPY") {
    openable::OnlineOptions own;
    if (Refuses([&] { own = openable::MapOptions(file.Path(), openable::OnlineOptions()); },
                file.Path()))
      return 0;
    std::unique_ptr<openable::OnlineDetector> given;
    if (Refuses([&] { given = std::make_unique<openable::OnlineDetector>(own); }) ||
        Refuses([&] { given->LoadMap(file.Path()); }, file.Path()))
      return 0;
    given->AddDescriptor(cv::Mat::zeros(1, given->RowWidth(), given->RowType()));
  }
  return 0;
}
