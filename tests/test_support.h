// Helpers shared by the tests: where the data lives, temporary folders, skipping when the
// shared datasets are absent.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <functional>
#include <initializer_list>
#include <string>

namespace openable::testing {

// Writes `bytes` to `path` as they are (fails the test when the file cannot be written).
void WriteBytes(const std::string& path, const std::string& bytes);
// The bytes of `path` (empty when it cannot be read).
std::string ReadBytes(const std::string& path);

// The offset of the first byte of `text` that is not part of valid UTF-8, or std::string::npos
// when all of it is valid. Written from the definition of UTF-8 (RFC 3629, section 3), not
// from the project's converter (ToValidUtf8): the lead byte's high bits give the length, the
// others are 10xxxxxx, and the code point they hold must be a Unicode scalar value (at most
// U+10FFFF, not a surrogate D800-DFFF) that needs exactly that many bytes.
std::size_t FirstInvalidUtf8Byte(const std::string& text);

// Runs `f` and expects an InputError whose message is one line (no '\n' or '\r') holding every
// one of `parts`.
void ExpectInputError(const std::function<void()>& f, std::initializer_list<std::string> parts);

// The message of the InputError that `f` throws; fails the test (and returns "") when `f` throws
// nothing or another exception.
std::string InputErrorMessage(const std::function<void()>& f);

// The message of the InputError that Check() throws on `Options` at their defaults but for what
// `change` sets; fails the test (and returns "") when it throws nothing or another exception.
template <typename Options>
std::string CheckError(const std::function<void(Options&)>& change) {
  return InputErrorMessage([&] {
    Options o;
    change(o);
    o.Check();
  });
}

// `path` between double quotes, as error messages quote file names.
inline std::string Q(const std::string& path) { return "\"" + path + "\""; }

// The repository root (the folder with the top-level CMakeLists.txt).
std::string SourceDir();
// ../shared/datasets beside the repository; may not exist on a user's clone.
std::string DatasetsDir();
// The bundled Nordland sample: <root>/examples/data/nordland_sample.
std::string SampleDir();
// A fresh, empty temporary folder, unique to the calling test; removed at exit of the process
// unless OPENABLE_KEEP_TEST_FILES is set.
std::string TempDir();
// Path of the Test_OpenABLE program built beside the tests.
std::string TestOpenableExe();
// The openable_evaluate program built with the tests.
std::string OpenableEvaluateExe();
// The openable_snaps program built with the tests.
std::string OpenableSnapsExe();
// The openable_sweep program built with the tests.
std::string OpenableSweepExe();
// The openable_map program built with the tests.
std::string OpenableMapExe();

}  // namespace openable::testing

// Skips the current test with a message when `path` does not exist.
#define OPENABLE_REQUIRE_PATH(path)                                                   \
  do {                                                                                \
    if (!std::filesystem::exists(path)) GTEST_SKIP() << "dataset absent: " << (path); \
  } while (0)
