// libFuzzer target: arbitrary bytes as the text of a configuration (Config.txt).
// The parser, the override syntax and the cross-key checks must either accept the input or
// throw InputError; any other exception, a crash or a sanitizer report is a finding.
// Built with -DOPENABLE_BUILD_FUZZERS=ON (clang); see docs/robustness.md.
#include <cstddef>
#include <cstdint>
#include <string>

#include "config/config.h"
#include "tests/fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using openable::fuzz::Refuses;
  const std::string text = openable::fuzz::Bytes(data, size);
  openable::Config config;
  if (Refuses([&] { config = openable::ParseConfigText(text, "fuzz.txt"); })) return 0;
  Refuses([&] { openable::CheckConfig(config); });
  Refuses([&] { openable::CheckSnapsConfig(config); });
  // The same bytes as one --set override (first line only, as a shell argument would be).
  Refuses([&] { openable::ApplyOverride(config, text.substr(0, text.find('\n'))); });
  return 0;
}
