// libFuzzer target: arbitrary bytes as the text of a configuration (Config.txt).
// The parser, the override syntax and the cross-key checks must either accept the input or
// throw InputError; any other exception, a crash or a sanitizer report is a finding.
// Built with -DOPENABLE_BUILD_FUZZERS=ON (clang); see docs/robustness.md.
#include <cstddef>
#include <cstdint>
#include <string>

#include "OpenABLE/base/error.h"
#include "config/config.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  openable::Config config;
  try {
    config = openable::ParseConfigText(text, "fuzz.txt");
  } catch (const openable::InputError&) {
    return 0;
  }
  try {
    openable::CheckConfig(config);
  } catch (const openable::InputError&) {
  }
  try {
    openable::CheckSnapsConfig(config);
  } catch (const openable::InputError&) {
  }
  // The same bytes as one --set override (first line only, as a shell argument would be).
  try {
    openable::ApplyOverride(config, text.substr(0, text.find('\n')));
  } catch (const openable::InputError&) {
  }
  return 0;
}
