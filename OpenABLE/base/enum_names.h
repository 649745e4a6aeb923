// One way to name an enum and to parse it back (after COLMAP's MAKE_ENUM_CLASS): each enum
// whose values are 0, 1, 2, ... in declaration order gets one table of names, declared next to
// it with OPENABLE_ENUM_NAMES; EnumName, ParseEnum and EnumChoices then serve every use (the
// configuration keys, reports, JSON, the Python module).
//
//   enum class RobustKernel { kNone, kHuber, kCauchy };
//   OPENABLE_ENUM_NAMES(RobustKernel, "none", "huber", "cauchy")
//   ParseEnum<RobustKernel>("Huber", "Snaps_robust_kernel")  // RobustKernel::kHuber
#pragma once

#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/strings.h"

// Declares the names of the values of `Enum`, in order, in Enum's namespace (found by
// argument-dependent lookup).
#define OPENABLE_ENUM_NAMES(Enum, ...)                                  \
  inline const std::vector<std::string_view>& OpenableEnumNames(Enum) { \
    static const std::vector<std::string_view> names{__VA_ARGS__};      \
    return names;                                                       \
  }

namespace openable {

// The names of every value of E, in order.
template <typename E>
const std::vector<std::string_view>& EnumNames() {
  static_assert(std::is_enum_v<E>, "EnumNames needs an enum declared with OPENABLE_ENUM_NAMES");
  return OpenableEnumNames(E{});
}

// The name of `value`. Throws std::logic_error for a value outside the table.
template <typename E>
std::string EnumName(E value) {
  const auto& names = EnumNames<E>();
  const auto index = static_cast<std::size_t>(value);
  if (index >= names.size()) throw std::logic_error("EnumName: value outside the name table");
  return std::string(names[index]);
}

// "a, b or c" (an empty name reads as (empty)).
template <typename E>
std::string EnumChoices() {
  const auto& names = EnumNames<E>();
  std::string out;
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (i > 0) out += i + 1 == names.size() ? " or " : ", ";
    out += names[i].empty() ? std::string("(empty)") : std::string(names[i]);
  }
  return out;
}

// The value named `text`, case-insensitively. Throws InputError
// "<key>: "<text>" is not valid; expected a, b or c" otherwise.
template <typename E>
E ParseEnum(std::string_view text, const std::string& key) {
  const auto& names = EnumNames<E>();
  const std::string lower = Lower(text);
  for (std::size_t i = 0; i < names.size(); ++i)
    if (lower == Lower(names[i])) return static_cast<E>(i);
  throw InputError(key + ": " + Quoted(text) + " is not valid; expected " + EnumChoices<E>());
}

}  // namespace openable
