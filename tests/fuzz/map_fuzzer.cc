// libFuzzer target: arbitrary bytes as a saved online map (the file of OnlineDetector::SaveMap,
// OpenABLE/online/map_file.h), written to a temporary file. ReadMapFile reads the bytes as
// they are; then the same bytes with their last 8 replaced by the right checksum (the FNV-1a
// of the rest), so that mutations reach the sections behind the checksum, go through
// ReadMapFile and OnlineDetector::LoadMap into the detector whose settings the map names
// (tests/fuzz/map_detectors.h), and, when it loads, one more frame is searched among the
// loaded ones (and verified against their saved features). The expected outcomes are a loaded
// map or one InputError line naming the file; any other exception, a crash or a sanitizer
// report is a finding. Built with -DOPENABLE_BUILD_FUZZERS=ON (clang); see docs/robustness.md.
#include <cstddef>
#include <cstdint>
#include <string>

#include <opencv2/core.hpp>

#include "OpenABLE/base/hash.h"
#include "OpenABLE/online/map_file.h"
#include "OpenABLE/online/online.h"
#include "tests/fuzz/fuzz_support.h"
#include "tests/fuzz/map_detectors.h"

namespace {

using openable::fuzz::MapKind;
using openable::fuzz::Refuses;
using openable::fuzz::TempFile;

MapKind KindOf(const openable::MapFile& map) {
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
  if (bytes.size() < 8) return 0;
  std::uint64_t sum = openable::Fnv1a64(bytes.data(), bytes.size() - 8);
  for (std::size_t i = 0; i < 8; ++i, sum >>= 8)
    bytes[bytes.size() - 8 + i] = static_cast<char>(sum & 0xFF);
  const TempFile file(bytes, ".map");
  openable::MapFile map;
  if (Refuses([&] { map = openable::ReadMapFile(file.Path()); }, file.Path())) return 0;
  const MapKind kind = KindOf(map);
  openable::OnlineDetector detector(openable::fuzz::MapDetectorOptions(kind));
  if (Refuses([&] { detector.LoadMap(file.Path()); }, file.Path())) return 0;
  if (kind == MapKind::kVerifying) {
    detector.AddFrame(openable::fuzz::MapFrame(0));
  } else {
    detector.AddDescriptor(cv::Mat::zeros(1, detector.RowWidth(), detector.RowType()));
  }
  return 0;
}
