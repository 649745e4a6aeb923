// Helpers of the libFuzzer targets.
#pragma once

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "OpenABLE/base/error.h"

namespace openable::fuzz {

// The fuzzer's input as a string of bytes.
inline std::string Bytes(const std::uint8_t* data, std::size_t size) {
  return std::string(reinterpret_cast<const char*>(data), size);
}

// Runs `f`: true when it throws InputError (the documented refusal of a bad input), false when
// it returns. Any other exception escapes, to be reported as a finding. The refusal's message
// must be one line (no '\n' or '\r') and, when `named` is given (the path of the file read),
// name it; otherwise the message is printed and the fuzzer aborts (a finding too).
template <typename F>
bool Refuses(F f, const std::string& named = "") {
  try {
    f();
  } catch (const InputError& e) {
    const std::string message = e.what();
    const bool one_line = message.find_first_of("\n\r") == std::string::npos;
    if (!one_line || (!named.empty() && message.find(named) == std::string::npos)) {
      std::fprintf(stderr, "InputError %s: %s\n",
                   one_line ? ("without " + named).c_str() : "of several lines", message.c_str());
      std::abort();
    }
    return true;
  }
  return false;
}

// A file of /tmp holding `bytes`, named openable_fuzz_XXXXXX<suffix> (mkstemps), removed when
// the object goes: the readers that take a path read the fuzzer's input through it. (An input
// that crashes the fuzzer leaves its file behind, a copy of the crash artifact.)
class TempFile {
 public:
  explicit TempFile(const std::string& bytes, const std::string& suffix = "") {
    std::string name = "/tmp/openable_fuzz_XXXXXX" + suffix;
    const int fd = mkstemps(name.data(), static_cast<int>(suffix.size()));
    if (fd < 0) Fail("cannot create " + name);
    path_ = name;
    for (std::size_t done = 0; done < bytes.size();) {
      const ssize_t n = write(fd, bytes.data() + done, bytes.size() - done);
      if (n <= 0) Fail("cannot write " + path_);
      done += static_cast<std::size_t>(n);
    }
    close(fd);
  }
  ~TempFile() { unlink(path_.c_str()); }
  TempFile(const TempFile&) = delete;
  TempFile& operator=(const TempFile&) = delete;

  const std::string& Path() const { return path_; }

 private:
  // The fuzzer cannot run without its file (a full /tmp): not a finding of the reader.
  [[noreturn]] static void Fail(const std::string& what) {
    std::perror(what.c_str());
    std::exit(1);
  }
  std::string path_;
};

}  // namespace openable::fuzz
