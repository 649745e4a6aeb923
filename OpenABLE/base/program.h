// What every command-line program of OpenABLE does around its work: the exit statuses
// (docs/output_formats.md, "Exit status") and the one place that maps errors to them.
#pragma once

#include <functional>
#include <string>

namespace openable {

inline constexpr int kExitSuccess = 0;
inline constexpr int kExitInputError = 1;  // bad configuration, input data or output path
inline constexpr int kExitUsageError = 2;  // bad command line
inline constexpr int kExitInternalError = 3;  // a bug: a broken internal precondition

// Runs `body` and returns its status; an InputError becomes one line
// "<program>: error: <message>" on stderr and status 1, any other exception
// "<program>: internal error (please report): <message>" and status 3.
int RunProgram(const std::string& program, const std::function<int()>& body);

}  // namespace openable
