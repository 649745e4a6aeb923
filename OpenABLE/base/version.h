// The version of OpenABLE (also the CMake project version).
#pragma once

namespace openable {
inline constexpr const char* kVersion = "0.1.0";
}  // namespace openable
