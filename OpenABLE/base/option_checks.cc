#include "OpenABLE/base/option_checks.h"

#include <cmath>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/strings.h"

namespace openable {

void RefuseOption(const std::string& name, const std::string& value, const std::string& expected) {
  throw InputError(name + ": " + value + " is not valid; expected " + expected);
}

void CheckIntRange(const std::string& name, long long value, long long lo, long long hi) {
  if (value < lo || value > hi)
    RefuseOption(name, std::to_string(value),
                 "an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
}

void CheckIntAtLeast(const std::string& name, long long value, long long lo) {
  if (value < lo) RefuseOption(name, std::to_string(value), "an integer >= " + std::to_string(lo));
}

void CheckNumberRange(const std::string& name, double value, double lo, double hi) {
  if (!(std::isfinite(value) && value >= lo && value <= hi))
    RefuseOption(name, FormatNumber(value),
                 "a number in [" + FormatNumber(lo) + ", " + FormatNumber(hi) + "]");
}

void CheckNumberAtLeast(const std::string& name, double value, double lo, bool lo_excluded) {
  if (!(std::isfinite(value) && (lo_excluded ? value > lo : value >= lo)))
    RefuseOption(name, FormatNumber(value),
                 std::string("a number ") + (lo_excluded ? "> " : ">= ") + FormatNumber(lo));
}

}  // namespace openable
