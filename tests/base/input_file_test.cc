// The one way the readers open an input file (base/input_file.h): every kind of file that is
// not a regular file is refused by name before a byte is read, and never blocks.
#include "OpenABLE/base/input_file.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <future>
#include <string>
#include <thread>

#include "OpenABLE/base/error.h"
#include "tests/test_support.h"

namespace openable {
namespace {

namespace fs = std::filesystem;
using testing::InputErrorMessage;
using testing::Q;
using testing::TempDir;
using testing::WriteBytes;

std::string Problem(const std::string& path) { return InputFileProblem(path); }

TEST(InputFile, ARegularFileIsReadWhole) {
  const std::string path = TempDir() + "/input_file_regular.bin";
  std::string bytes(200000, '\0');
  for (size_t i = 0; i < bytes.size(); ++i) bytes[i] = static_cast<char>(i * 7 + 3);
  WriteBytes(path, bytes);
  EXPECT_EQ(Problem(path), "");
  EXPECT_EQ(ReadInputFile(path, "file"), bytes);
  WriteBytes(path, "");
  EXPECT_EQ(ReadInputFile(path, "file"), "");  // empty is the reader's business
}

TEST(InputFile, EachKindOfSpecialFileIsNamed) {
  const std::string dir = TempDir() + "/input_file_kinds";
  fs::remove_all(dir);
  fs::create_directories(dir);
  EXPECT_EQ(Problem(dir), "is a folder, not a regular file");
  EXPECT_EQ(Problem("/dev/null"), "is a character device, not a regular file");
  EXPECT_EQ(Problem(dir + "/missing.txt"), "does not exist");
  EXPECT_EQ(Problem(dir + "/missing.txt/x"), "does not exist");
  EXPECT_EQ(Problem(""), "is an empty path");
  fs::create_symlink(dir + "/nowhere", dir + "/dangling");
  EXPECT_EQ(Problem(dir + "/dangling"),
            "is a symbolic link to " + Q(dir + "/nowhere") + " that leads nowhere");
  fs::create_symlink(dir + "/loop_b", dir + "/loop_a");
  fs::create_symlink(dir + "/loop_a", dir + "/loop_b");
  EXPECT_EQ(Problem(dir + "/loop_a"), "is a loop of symbolic links");

  const std::string socket_path = dir + "/socket";
  const int s = ::socket(AF_UNIX, SOCK_STREAM, 0);
  ASSERT_GE(s, 0);
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  ASSERT_LT(socket_path.size(), sizeof address.sun_path);
  socket_path.copy(address.sun_path, socket_path.size());
  ASSERT_EQ(::bind(s, reinterpret_cast<const sockaddr*>(&address), sizeof address), 0);
  EXPECT_EQ(Problem(socket_path), "is a socket, not a regular file");
  ::close(s);

  // The message: the name the reader gives, the problem, what was expected.
  EXPECT_EQ(InputErrorMessage([&] { ReadInputFile(dir, "map " + Q(dir), "expected a map"); }),
            "map " + Q(dir) + " is a folder, not a regular file (expected a map)");
  EXPECT_EQ(InputErrorMessage([&] { CheckInputFile("/dev/null", "bag " + Q("/dev/null")); }),
            "bag \"/dev/null\" is a character device, not a regular file");
}

// A FIFO with no writer: opening it for reading the usual way waits for ever. The check opens
// it without blocking and refuses it by name. A writer is started after 3 s so that a reader
// that did block would end (reading nothing) and fail on the message rather than hang.
TEST(InputFile, AFifoIsRefusedAtOnceAndNeverBlocks) {
  const std::string fifo = TempDir() + "/input_file.fifo";
  fs::remove(fifo);
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  std::atomic<bool> done{false};
  std::thread unblock([&] {
    for (int i = 0; i < 30 && !done; ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    if (!done) {
      const int fd = ::open(fifo.c_str(), O_WRONLY | O_NONBLOCK);
      if (fd >= 0) ::close(fd);
    }
  });
  const std::string message =
      InputErrorMessage([&] { ReadInputFile(fifo, "map " + Q(fifo), "expected a map"); });
  done = true;
  unblock.join();
  EXPECT_EQ(message,
            "map " + Q(fifo) + " is a FIFO (named pipe), not a regular file (expected a map)");
  EXPECT_EQ(Problem(fifo), "is a FIFO (named pipe), not a regular file");
  fs::remove(fifo);
}

TEST(InputFile, AFileThatCannotBeReadSaysPermissionDenied) {
  if (::geteuid() == 0) GTEST_SKIP() << "root reads every file: permissions cannot be tested";
  const std::string path = TempDir() + "/input_file_private.txt";
  WriteBytes(path, "secret");
  fs::permissions(path, fs::perms::none);
  EXPECT_EQ(Problem(path), "cannot be read (permission denied)");
  fs::permissions(path, fs::perms::owner_all);
}

}  // namespace
}  // namespace openable
