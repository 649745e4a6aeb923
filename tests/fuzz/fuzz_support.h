// Helpers of the libFuzzer targets.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "OpenABLE/base/error.h"

namespace openable::fuzz {

// The fuzzer's input as a string of bytes.
inline std::string Bytes(const std::uint8_t* data, std::size_t size) {
  return std::string(reinterpret_cast<const char*>(data), size);
}

// Runs `f`: true when it throws InputError (the documented refusal of a bad input), false when
// it returns. Any other exception escapes, to be reported as a finding.
template <typename F>
bool Refuses(F f) {
  try {
    f();
  } catch (const InputError&) {
    return true;
  }
  return false;
}

}  // namespace openable::fuzz
