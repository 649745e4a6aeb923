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

namespace openable {

class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& message) : std::runtime_error(message) {}
};

}  // namespace openable
