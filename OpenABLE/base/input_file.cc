#include "OpenABLE/base/input_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <system_error>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/strings.h"

namespace openable {
namespace {

namespace fs = std::filesystem;

// The words for a file of `mode` that is not a regular file ("" for a regular file).
std::string TypeProblem(mode_t mode) {
  if (S_ISREG(mode)) return "";
  const char* type = S_ISDIR(mode)    ? "a folder"
                     : S_ISFIFO(mode) ? "a FIFO (named pipe)"
                     : S_ISSOCK(mode) ? "a socket"
                     : S_ISCHR(mode)  ? "a character device"
                     : S_ISBLK(mode)  ? "a block device"
                                      : "a special file";
  return std::string("is ") + type + ", not a regular file";
}

// The words for a failed open() or read() with `error` (errno).
std::string SystemProblem(const std::string& path, int error) {
  switch (error) {
    case ENOENT: {
      std::error_code ec;
      if (fs::is_symlink(fs::symlink_status(path, ec))) {
        const std::string target = fs::read_symlink(path, ec).string();
        return "is a symbolic link to " + Quoted(target) + " that leads nowhere";
      }
      return "does not exist" + WorkingDirectoryNote(path);
    }
    case ENOTDIR:
      return "does not exist (a part of its path is not a folder)";
    case ELOOP:
      return "is a loop of symbolic links";
    case EACCES:
    case EPERM:
      return "cannot be read (permission denied)";
    case EISDIR:
      return TypeProblem(S_IFDIR);
    case ENAMETOOLONG:
      return "has a name too long for the system";
    default:
      return "cannot be read (" + std::string(std::strerror(error)) + ")";
  }
}

std::string Message(const std::string& name, const std::string& problem,
                    const std::string& expected) {
  return name + " " + problem + (expected.empty() ? "" : " (" + expected + ")");
}

// An open file descriptor, closed on every path out.
class Fd {
 public:
  explicit Fd(int fd) : fd_(fd) {}
  ~Fd() {
    if (fd_ >= 0) ::close(fd_);
  }
  Fd(const Fd&) = delete;
  Fd& operator=(const Fd&) = delete;
  int get() const { return fd_; }

 private:
  int fd_;
};

// Opens `path` for reading without blocking on a FIFO and checks that the opened file is a
// regular file. Returns the descriptor and its size, or sets `problem`.
int OpenRegular(const std::string& path, std::string* problem, off_t* size) {
  if (path.empty()) {
    *problem = "is an empty path";
    return -1;
  }
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    const int error = errno;
    // A socket cannot be opened at all (ENXIO): name what it is rather than the system's words.
    struct stat st;
    if (::stat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode)) {
      *problem = TypeProblem(st.st_mode);
      return -1;
    }
    *problem = SystemProblem(path, error);
    return -1;
  }
  struct stat st;
  if (::fstat(fd, &st) != 0) {
    *problem = SystemProblem(path, errno);
    ::close(fd);
    return -1;
  }
  *problem = TypeProblem(st.st_mode);
  if (!problem->empty()) {
    ::close(fd);
    return -1;
  }
  *size = st.st_size;
  return fd;
}

}  // namespace

std::string InputFileProblem(const std::string& path) {
  std::string problem;
  off_t size = 0;
  const Fd fd(OpenRegular(path, &problem, &size));
  return problem;
}

void CheckInputFile(const std::string& path, const std::string& name, const std::string& expected) {
  const std::string problem = InputFileProblem(path);
  if (!problem.empty()) throw InputError(Message(name, problem, expected));
}

std::string ReadInputFile(const std::string& path, const std::string& name,
                          const std::string& expected) {
  std::string problem;
  off_t size = 0;
  const Fd fd(OpenRegular(path, &problem, &size));
  if (fd.get() < 0) throw InputError(Message(name, problem, expected));
  // Plain POSIX reads of the descriptor already checked: std::ifstream would reopen the path
  // (a second lookup that could meet another file) and reports failures without errno.
  std::string data;
  data.reserve(static_cast<std::size_t>(size > 0 ? size : 0));
  char buffer[1 << 16];
  while (true) {
    const ssize_t n = ::read(fd.get(), buffer, sizeof buffer);
    if (n == 0) break;
    if (n < 0) {
      if (errno == EINTR) continue;
      throw InputError(Message(name, SystemProblem(path, errno), expected));
    }
    data.append(buffer, static_cast<std::size_t>(n));
  }
  return data;
}

}  // namespace openable
