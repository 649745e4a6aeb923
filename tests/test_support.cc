#include "tests/test_support.h"

#include <unistd.h>

#include <atomic>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <vector>

#include "OpenABLE/base/error.h"

namespace fs = std::filesystem;

namespace openable::testing {

std::string ReadBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

void WriteBytes(const std::string& path, const std::string& bytes) {
  std::ofstream f(path, std::ios::binary);
  f << bytes;
  ASSERT_TRUE(f.good()) << path;
}

std::size_t FirstInvalidUtf8Byte(const std::string& text) {
  const std::uint32_t kSmallest[] = {0, 0, 0x80, 0x800, 0x10000};  // by length
  for (std::size_t i = 0; i < text.size();) {
    const auto lead = static_cast<unsigned char>(text[i]);
    std::size_t length = 0;
    std::uint32_t code = 0;
    if (lead < 0x80) {
      ++i;
      continue;
    } else if ((lead & 0xe0) == 0xc0) {
      length = 2, code = lead & 0x1fu;
    } else if ((lead & 0xf0) == 0xe0) {
      length = 3, code = lead & 0x0fu;
    } else if ((lead & 0xf8) == 0xf0) {
      length = 4, code = lead & 0x07u;
    } else {
      return i;  // a continuation byte, or a lead of 5 or more bytes
    }
    if (i + length > text.size()) return i;
    for (std::size_t k = 1; k < length; ++k) {
      const auto next = static_cast<unsigned char>(text[i + k]);
      if ((next & 0xc0) != 0x80) return i;
      code = (code << 6) | (next & 0x3fu);
    }
    if (code < kSmallest[length] || code > 0x10ffff || (code >= 0xd800 && code <= 0xdfff)) return i;
    i += length;
  }
  return std::string::npos;
}

void ExpectInputError(const std::function<void()>& f, std::initializer_list<std::string> parts) {
  try {
    f();
    ADD_FAILURE() << "no InputError thrown";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    EXPECT_EQ(message.find('\r'), std::string::npos) << message;
    for (const std::string& part : parts) {
      EXPECT_NE(message.find(part), std::string::npos)
          << "message \"" << message << "\" lacks \"" << part << "\"";
    }
  } catch (const std::exception& e) {
    ADD_FAILURE() << "expected InputError, got another exception: " << e.what();
  }
}
std::string InputErrorMessage(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "expected InputError, got another exception: " << e.what();
    return "";
  }
  ADD_FAILURE() << "expected InputError, nothing was thrown";
  return "";
}

namespace {

struct TempRoot {
  fs::path root;
  TempRoot() {
    root = fs::temp_directory_path() /
           ("openable_tests_" + std::to_string(static_cast<long>(::getpid())));
    fs::create_directories(root);
  }
  ~TempRoot() {
    if (std::getenv("OPENABLE_KEEP_TEST_FILES") == nullptr) {
      std::error_code ec;
      fs::remove_all(root, ec);
    }
  }
};

TempRoot& Root() {
  static TempRoot r;
  return r;
}

}  // namespace

std::string SourceDir() { return OPENABLE_SOURCE_DIR; }
std::string DatasetsDir() { return OPENABLE_DATASETS_DIR; }
std::string SampleDir() { return SourceDir() + "/examples/data/nordland_sample"; }
std::string TestOpenableExe() { return OPENABLE_TEST_OPENABLE_EXE; }

std::string OpenableEvaluateExe() { return OPENABLE_EVALUATE_EXE; }

std::string OpenableSnapsExe() { return OPENABLE_SNAPS_EXE; }
std::string OpenableSweepExe() { return OPENABLE_SWEEP_EXE; }
std::string OpenableMapExe() { return OPENABLE_MAP_EXE; }

std::string TempDir() {
  static std::atomic<int> counter{0};
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  std::string name = info ? std::string(info->test_suite_name()) + "." + info->name() : "none";
  for (char& c : name)
    if (c == '/') c = '_';
  fs::path dir = Root().root / (name + "_" + std::to_string(counter++));
  fs::create_directories(dir);
  return dir.string();
}

}  // namespace openable::testing
