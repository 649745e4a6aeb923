// Error channels of OpenABLE (see docs/architecture.md).
//
// InputError: the user gave something we cannot use (a file, a key, a value). Its message is
// one line naming the file or key, the value and what was expected; programs print it and exit
// with a non-zero status. Library code never calls exit() or abort().
//
// A broken internal precondition is a bug and throws std::logic_error instead.
#pragma once

#include <stdexcept>
#include <string>
#include <string_view>

#include "OpenABLE/base/strings.h"

namespace openable {

class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& message) : std::runtime_error(message) {}
};

// `s` with double quotes and control characters escaped so that a message stays on one line
// whatever a file name or a value holds, and bytes that are not valid UTF-8 written
// as \xNN (ToValidUtf8, strings.h), as every text output shows them.
inline std::string Escaped(std::string_view s) {
  static const char* const kHex = "0123456789abcdef";
  std::string out;
  for (const char c : ToValidUtf8(s)) {
    const auto u = static_cast<unsigned char>(c);
    if (c == '"') {
      out += "\\\"";
    } else if (c == '\n') {
      out += "\\n";
    } else if (c == '\r') {
      out += "\\r";
    } else if (c == '\t') {
      out += "\\t";
    } else if (u < 0x20 || u == 0x7f) {
      out += "\\x";
      out += kHex[u >> 4];
      out += kHex[u & 0xf];
    } else {
      out += c;
    }
  }
  return out;
}

// `s` between double quotes, escaped as by Escaped.
inline std::string Quoted(std::string_view s) { return "\"" + Escaped(s) + "\""; }

// Runs `f` and prefixes `key` (a config key naming the source) to any InputError it throws.
template <typename F>
auto WithKey(const std::string& key, F f) {
  try {
    return f();
  } catch (const InputError& e) {
    throw InputError(key + ": " + e.what());
  }
}

}  // namespace openable
