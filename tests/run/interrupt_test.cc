// Interrupted runs (OpenABLE/base/interrupt.h) and write errors leave no output that looks
// complete: temporaries removed on signals, commits deferred until a batch is whole, write
// errors named, old sets restored, stale temporaries swept (OutputBatch,
// OpenABLE/base/output_batch.h).
#include "OpenABLE/base/interrupt.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/mount.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <set>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/output_batch.h"
#include "OpenABLE/describe/describe.h"
#include "OpenABLE/io/frame_source.h"
#include "OpenABLE/run/descriptor_cache.h"
#include "config/config.h"
#include "descriptors/registry.h"
#include "tests/test_support.h"

namespace openable {
namespace {

namespace fs = std::filesystem;

std::string ReadAll(const std::string& path) { return testing::ReadBytes(path); }

std::vector<std::string> Entries(const std::string& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

// --- Interrupted runs and write errors -------------------------------------------------------

TEST(Interrupt, SigtermDuringStagingRemovesTemporariesAndExits143) {
  for (int sig : {SIGTERM, SIGINT}) {
    const std::string dir = testing::TempDir() + "/sig" + std::to_string(sig);
    fs::create_directories(dir);
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      InstallInterruptCleanup("robustness_test");
      OutputBatch batch;
      batch.Stage("Npy_name", dir + "/m.npy", std::string(100000, 'x'));
      batch.Stage("Txt_name", dir + "/m.txt", "text");
      ::raise(sig);  // the handler exits; reaching the next line is a failure
      ::_exit(0);
    }
    int status = 0;
    ASSERT_EQ(::waitpid(child, &status, 0), child);
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_EQ(WEXITSTATUS(status), 128 + sig);
    EXPECT_TRUE(Entries(dir).empty()) << "left behind: " << Entries(dir).front();
  }
}

// A signal during a commit acts once the batch is whole, and reports the files as the commit
// left them: the note of SetInterruptNoteOnCommit is set before the deferred signal acts.
TEST(Interrupt, SignalDuringCommitIsDeferredUntilTheBatchIsWholeAndReportsIt) {
  const std::string dir = testing::TempDir();
  const std::string err_path = testing::TempDir() + "/stderr.txt";
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    ::dup2(::open(err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644), 2);
    InstallInterruptCleanup("robustness_test");
    SetInterruptNote("m.npy unchanged");
    OutputBatch batch;
    batch.Stage("Npy_name", dir + "/m.npy", "a");
    batch.Stage("Txt_name", dir + "/m.txt", "b");
    SetInterruptNoteOnCommit("m.npy written");
    {
      InterruptDeferral defer;  // as inside Commit
      ::raise(SIGTERM);
      batch.Commit();
    }
    ::_exit(0);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 143);
  EXPECT_EQ(Entries(dir), (std::vector<std::string>{"m.npy", "m.txt"}));
  const std::string err = ReadAll(err_path);
  EXPECT_NE(err.find("interrupted by SIGTERM (temporary files removed; m.npy written)"),
            std::string::npos)
      << err;
}

TEST(OutputBatch, WriteErrorNamesKeyAndPathAndLeavesNothing) {
  const std::string dir = testing::TempDir();
  OutputBatch batch;
  batch.Stage("Txt_name", dir + "/a.txt", "hello");
  FailStagedWritesAfterForTesting(1000, ENOSPC);
  try {
    batch.Stage("Npy_name", dir + "/b.npy", std::string(5000, 'x'));
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("Npy_name"), std::string::npos) << m;
    EXPECT_NE(m.find(dir + "/b.npy"), std::string::npos) << m;
    EXPECT_NE(m.find(std::strerror(ENOSPC)), std::string::npos) << m;
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
  }
  FailStagedWritesAfterForTesting(-1, 0);
  // Only a.txt's temporary is left before the batch ends; none after.
  EXPECT_EQ(Entries(dir).size(), 1u);
  EXPECT_EQ(Entries(dir).front().rfind(".a.txt.tmp-", 0), 0u) << Entries(dir).front();
}

TEST(OutputBatch, FullTmpfsFailsAndLeavesNothing) {
  const std::string dir = testing::TempDir() + "/small";
  fs::create_directories(dir);
  if (::mount("tmpfs", dir.c_str(), "tmpfs", 0, "size=64k") != 0)
    GTEST_SKIP() << "cannot mount a 64k tmpfs (" << std::strerror(errno)
                 << "); the test hook test covers ENOSPC";
  {
    OutputBatch batch;
    batch.Stage("Txt_name", dir + "/a.txt", "hello");
    EXPECT_THROW(batch.Stage("Npy_name", dir + "/b.npy", std::string(1 << 20, 'x')), InputError);
  }
  EXPECT_TRUE(Entries(dir).empty()) << "left behind: " << Entries(dir).front();
  ::umount(dir.c_str());
}

TEST(OutputBatch, FailedRenameRestoresTheWholeOldSet) {
  const std::string dir = testing::TempDir();
  testing::WriteBytes(dir + "/a.txt", "old a");
  OutputBatch batch;
  batch.Stage("Txt_name", dir + "/a.txt", "new a");
  batch.Stage("Npy_name", dir + "/b.npy", "new b");
  batch.Stage("Png_name", dir + "/c.png", "new c");
  // c.png becomes a non-empty folder after staging: its rename fails after two succeeded.
  fs::create_directories(dir + "/c.png/inside");
  try {
    batch.Commit();
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("Png_name"), std::string::npos) << e.what();
  }
  EXPECT_EQ(ReadAll(dir + "/a.txt"), "old a");  // restored from its backup
  EXPECT_FALSE(fs::exists(dir + "/b.npy"));     // did not exist before: removed
  // No backup left.
  for (const std::string& f : Entries(dir)) EXPECT_EQ(f.find(".old-"), std::string::npos) << f;
}

TEST(OutputBatch, StaleTemporariesOfDeadRunsAreRemoved) {
  const std::string dir = testing::TempDir();
  // pid 99999999 is above Linux's largest pid: that process cannot exist.
  testing::WriteBytes(dir + "/.m.npy.tmp-99999999-0", "killed run");
  testing::WriteBytes(dir + "/.m.npy.old-99999999-0", "killed commit");
  const std::string alive = "/.m.npy.tmp-" + std::to_string(::getppid()) + "-0";
  testing::WriteBytes(dir + alive, "a live run's");
  testing::WriteBytes(dir + "/.other.npy.tmp-99999999-0", "another output's");
  {
    OutputBatch batch;
    batch.Stage("Npy_name", dir + "/m.npy", "x");
    batch.Commit();
  }
  EXPECT_EQ(Entries(dir),
            (std::vector<std::string>{alive.substr(1), ".other.npy.tmp-99999999-0", "m.npy"}));
}

}  // namespace
}  // namespace openable
