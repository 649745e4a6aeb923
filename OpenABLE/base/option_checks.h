// Uniform validation messages for the Check() of option structs (after COLMAP's
// CHECK_OPTION_*): every refused value reads "<name>: <value> is not valid; expected <what>",
// <name> being the Config.txt key of the field and, for structs that programs also fill by
// hand, the field itself ("Odometry_max_depth (StereoOdometryOptions.max_depth)").
#pragma once

#include <string>

namespace openable {

// Throws InputError "<name>: <value> is not valid; expected <expected>".
[[noreturn]] void RefuseOption(const std::string& name, const std::string& value,
                               const std::string& expected);

// Refuses `value` unless lo <= value <= hi ("an integer in [lo, hi]").
void CheckIntRange(const std::string& name, long long value, long long lo, long long hi);
// Refuses `value` unless value >= lo ("an integer >= lo").
void CheckIntAtLeast(const std::string& name, long long value, long long lo);
// Refuses `value` unless finite and lo <= value <= hi ("a number in [lo, hi]").
void CheckNumberRange(const std::string& name, double value, double lo, double hi);
// Refuses `value` unless finite and value >= lo, or value > lo when `lo_excluded`
// ("a number >= lo", "a number > lo").
void CheckNumberAtLeast(const std::string& name, double value, double lo, bool lo_excluded = false);

}  // namespace openable
