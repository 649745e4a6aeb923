// The bad-input corpus: every file is generated at run time in a temporary
// folder, then given to Test_OpenABLE. For each case the program must exit with status 1,
// write exactly one line on stderr naming the file or key, leave no output behind, not crash
// (a signal) and not hang (every run goes through `timeout`). docs/robustness.md lists the
// cases and the decided behaviours (1x1 and huge images, odd names, symbolic links).
#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iomanip>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "OpenABLE/io/frame_source.h"
#include "config/config.h"
#include "tests/e2e/e2e_support.h"
#include "tests/test_support.h"

namespace openable {
namespace {

using namespace e2e;  // NOLINT: the e2e helpers are this file's vocabulary

// Runs Test_OpenABLE under `timeout`: a hang ends with status 124 (or 137), which fails the
// status checks below like any other wrong status.
Outcome RunBounded(const std::string& dir, const std::vector<std::string>& args) {
  std::vector<std::string> all = {"-k", "5", "60", testing::TestOpenableExe()};
  all.insert(all.end(), args.begin(), args.end());
  return RunProgram("timeout", all, dir);
}

// A Config.txt reading `images` (one sequence, single images) and writing three outputs to
// <dir>/out.
std::string WriteConfig(const std::string& dir, const std::string& images,
                        const std::string& extra = "") {
  const std::string path = dir + "/Config.txt";
  std::istringstream base("Frame_mode: 0\nImages_path: \"" + images +
                          "\"\nTxt_name: \"out/matrix.txt\"\nNpy_name: \"out/matrix.npy\"\n"
                          "Png_name: \"out/matrix.png\"\nImage_descriptor: LDB\n"
                          "Image_sequences: 1\nThreads: 2\n");
  std::string text = "%YAML:1.0\n";
  for (std::string line; std::getline(base, line);)  // the lines `extra` does not replace
    if (("\n" + extra).find("\n" + line.substr(0, line.find(':') + 1)) == std::string::npos)
      text += line + "\n";
  std::ofstream(path) << text << extra;
  return path;
}

// The checks of every bad input. `needle` is text the single line must hold.
void ExpectRefused(const Outcome& o, const std::string& dir, const std::string& needle) {
  EXPECT_NE(o.status, 128) << "crashed (signal); stderr: " << o.err;
  EXPECT_NE(o.status, 124) << "hung (killed by timeout)";
  EXPECT_EQ(o.status, 1) << "stderr: " << o.err;
  EXPECT_TRUE(OneLine(o.err)) << "stderr is not one line: " << o.err;
  EXPECT_NE(o.err.find(needle), std::string::npos) << "stderr: " << o.err << "expected: " << needle;
  const bool no_outputs = !fs::exists(dir + "/out") || fs::is_empty(dir + "/out");
  EXPECT_TRUE(no_outputs) << "outputs left behind in " << dir << "/out";
}

std::string Bytes(const std::vector<unsigned char>& v) { return std::string(v.begin(), v.end()); }

std::string Encoded(const std::string& ext, int width, int height, int seed) {
  cv::Mat m(height, width, CV_8UC1);
  cv::RNG rng(static_cast<uint64_t>(seed));
  rng.fill(m, cv::RNG::UNIFORM, 0, 256);
  std::vector<unsigned char> buf;
  EXPECT_TRUE(cv::imencode(ext, m, buf));
  return Bytes(buf);
}

// A folder <dir>/<name> holding two sound 32x24 PNGs (a1.png, a2.png).
std::string SoundFolder(const std::string& dir, const std::string& name = "imgs") {
  const std::string folder = dir + "/" + name;
  fs::create_directories(folder);
  testing::WriteBytes(folder + "/a1.png", Encoded(".png", 32, 24, 1));
  testing::WriteBytes(folder + "/a2.png", Encoded(".png", 32, 24, 2));
  return folder;
}

// ---------------------------------------------------------------------------------------
// Broken image files: each case adds one bad file to a folder of two sound images.

struct BadImage {
  const char* name;
  const char* file;        // the bad file's name in the folder
  std::string (*bytes)();  // its content
};

void PrintTo(const BadImage& c, std::ostream* os) { *os << c.name; }

std::string Png() { return Encoded(".png", 32, 24, 3); }
std::string Jpeg() { return Encoded(".jpg", 64, 64, 4); }
std::size_t Idat(const std::string& png) { return png.find("IDAT") - 4; }

const BadImage kBadImages[] = {
    {"PngCutInSignature", "bad.png", [] { return Png().substr(0, 4); }},
    {"PngCutInIhdr", "bad.png", [] { return Png().substr(0, 20); }},
    {"PngCutInIdat", "bad.png",
     [] {
       const std::string p = Png();
       return p.substr(0, Idat(p) + 30);
     }},
    {"PngCutBeforeIend", "bad.png",
     [] {
       const std::string p = Png();
       return p.substr(0, p.size() - 12);
     }},
    {"PngCutInIend", "bad.png",
     [] {
       const std::string p = Png();
       return p.substr(0, p.size() - 3);
     }},
    {"PngCorruptCrc", "bad.png",
     [] {
       std::string p = Png();
       p[Idat(p) + 20] = static_cast<char>(p[Idat(p) + 20] ^ 0x5a);
       return p;
     }},
    {"JpegWithoutEnd", "bad.jpg",
     [] {
       const std::string j = Jpeg();
       return j.substr(0, j.size() / 2);
     }},
    {"JpegGarbageInTheMiddle", "bad.jpg",
     [] {
       std::string j = Jpeg();
       for (std::size_t i = j.size() / 2; i < j.size() / 2 + 64; ++i)
         j[i] = static_cast<char>((i * 37) & 0xff);
       return j;
     }},
    {"EmptyPng", "bad.png", [] { return std::string(); }},
    {"EmptyJpeg", "bad.jpg", [] { return std::string(); }},
    {"TextAsPng", "bad.png", [] { return std::string("this is a text file, not a PNG\n"); }},
    {"PngSignatureOnly", "bad.png", [] { return Png().substr(0, 8); }},
    {"JpegAsPng", "bad.png", [] { return Jpeg(); }},
};

class BadImageFiles : public ::testing::TestWithParam<BadImage> {};

TEST_P(BadImageFiles, OneLineNamingTheFileExit1) {
  const BadImage& c = GetParam();
  const std::string dir = testing::TempDir();
  const std::string folder = SoundFolder(dir);
  testing::WriteBytes(folder + "/" + c.file, c.bytes());
  const Outcome o = RunBounded(dir, {WriteConfig(dir, folder)});
  // JpegAsPng is a sound image under the wrong extension: it is read (by its content).
  if (std::string(c.name) == "JpegAsPng") {
    EXPECT_EQ(o.status, 1) << o.err;  // 64x64 among 32x24 frames: a size mismatch
  }
  ExpectRefused(o, dir, c.file);
}

INSTANTIATE_TEST_SUITE_P(Corpus, BadImageFiles, ::testing::ValuesIn(kBadImages),
                         [](const ::testing::TestParamInfo<BadImage>& info) {
                           return std::string(info.param.name);
                         });

// Skip_unreadable 1 skips the same files with a warning and runs on the sound ones.
TEST(BadInputCorpus, SkipUnreadableRunsOnTheSoundImages) {
  const std::string dir = testing::TempDir();
  const std::string folder = SoundFolder(dir);
  testing::WriteBytes(folder + "/b1.png", Png().substr(0, 40));
  testing::WriteBytes(folder + "/b2.jpg", "");
  const Outcome o = RunBounded(dir, {WriteConfig(dir, folder, "Skip_unreadable: 1\n")});
  ASSERT_EQ(o.status, 0) << o.err;
  EXPECT_NE(o.out.find("skipped: "), std::string::npos) << o.out;  // listed on stdout
  EXPECT_NE(o.out.find("b1.png"), std::string::npos) << o.out;
  EXPECT_NE(o.out.find("b2.jpg"), std::string::npos) << o.out;
  EXPECT_EQ(ReadNpy(dir + "/out/matrix.npy").rows, 2);
}

// The report of a run that skipped unreadable frames shows each row's own frame: a skipped
// file that sorts first used to make the report read it again (the run failed), and one in the
// middle would have shifted every later frame's name and thumbnail by one.
TEST(BadInputCorpus, ReportOfASkippingRunShowsEachRowsFrame) {
  const std::string dir = testing::TempDir();
  const std::string summer = dir + "/summer", winter = dir + "/winter";
  fs::create_directories(summer);
  fs::create_directories(winter);
  const std::vector<std::string> names = ListImages(testing::SampleDir() + "/summer", "");
  for (int i = 0; i < 30; ++i) {
    const std::string name = fs::path(names[i]).filename().string();
    fs::copy_file(names[i], summer + "/" + name);
    fs::copy_file(testing::SampleDir() + "/winter/" + name, winter + "/" + name);
  }
  testing::WriteBytes(summer + "/images-00000.png", Png().substr(0, 40));  // sorts first
  std::string pairs;
  for (int i = 0; i < 30; ++i) pairs += std::to_string(i) + "," + std::to_string(i) + "\n";
  testing::WriteBytes(dir + "/pairs.txt", pairs);
  const Outcome o = RunBounded(
      dir, {WriteConfig(dir, summer,
                        "Skip_unreadable: 1\nImages_path_2: \"" + winter +
                            "\"\nImage_sequences: 3\nGround_truth_type: pairs\n"
                            "Ground_truth: \"pairs.txt\"\nReport_name: \"out/report.html\"\n"
                            "Report_examples: 30\n")});
  ASSERT_EQ(o.status, 0) << o.err;
  const std::string report = ReadAll(dir + "/out/report.html");
  EXPECT_EQ(report.find("could not be found"), std::string::npos);
  // Every query's true place is the reference of the same name: with rows shifted by the
  // skipped file, the names shown beside each other would differ by 10 (images-000k0.png).
  for (int i = 0; i < 30; ++i) {
    const std::string name = fs::path(names[i]).filename().string();
    EXPECT_NE(report.find(name), std::string::npos) << name;
  }
}

// A folder named like an image is not a frame: it is passed over like any subfolder; alone,
// the folder holds no image.
TEST(BadInputCorpus, FolderNamedLikeAnImage) {
  const std::string dir = testing::TempDir();
  const std::string folder = SoundFolder(dir);
  fs::create_directories(folder + "/x.png");
  Outcome o = RunBounded(dir, {WriteConfig(dir, folder)});
  ASSERT_EQ(o.status, 0) << o.err;
  EXPECT_EQ(ReadNpy(dir + "/out/matrix.npy").rows, 2);
  fs::remove_all(dir + "/out");
  fs::create_directories(dir + "/only/x.png");
  o = RunBounded(dir, {WriteConfig(dir, dir + "/only")});
  ExpectRefused(o, dir, "holds no image");
}

// ---------------------------------------------------------------------------------------
// Image sizes.

// 1x1 frames: the global description resizes every frame to the patch, so they are described
// (a constant patch); a grid needs at least Grid_x x Grid_y pixels and says so.
TEST(BadInputCorpus, OnePixelImages) {
  const std::string dir = testing::TempDir();
  fs::create_directories(dir + "/tiny");
  for (int i = 0; i < 3; ++i)
    cv::imwrite(dir + "/tiny/t" + std::to_string(i) + ".png",
                cv::Mat(1, 1, CV_8UC1, cv::Scalar(40 * i)));
  Outcome o = RunBounded(dir, {WriteConfig(dir, dir + "/tiny")});
  ASSERT_EQ(o.status, 0) << o.err;
  EXPECT_EQ(ReadNpy(dir + "/out/matrix.npy").rows, 3);
  fs::remove_all(dir + "/out");
  o = RunBounded(dir, {WriteConfig(dir, dir + "/tiny", "Description_type: 1\nGrid_x: 2\n")});
  ExpectRefused(o, dir, "Grid_x");
  EXPECT_NE(o.err.find("1x1"), std::string::npos) << o.err;
}

// 20000 x 20000 (400 MB of 8-bit grey once decoded; a few hundred kB as a uniform PNG).
TEST(BadInputCorpus, HugeImage) {
  const std::string dir = testing::TempDir();
  fs::create_directories(dir + "/huge");
  {
    const cv::Mat big(20000, 20000, CV_8UC1, cv::Scalar(90));
    ASSERT_TRUE(cv::imwrite(dir + "/huge/h1.png", big, {cv::IMWRITE_PNG_COMPRESSION, 1}));
  }
  fs::create_symlink("h1.png", dir + "/huge/h2.png");
  // RunBounded's timeout catches a hang; the time itself is not a test's business.
  const Outcome o = RunBounded(dir, {WriteConfig(dir, dir + "/huge")});
  ExpectRefused(o, dir, "h1.png");
  EXPECT_NE(o.err.find("20000x20000"), std::string::npos) << o.err;
}

// ---------------------------------------------------------------------------------------
// Odd file names, many files.

// 2000 tiny frames whose names hold spaces, Unicode, leading dashes, quotes and newlines: the
// run reads them all; a broken one among them is named on one line, its newline escaped.
TEST(BadInputCorpus, ThousandsOfOddNames) {
  const std::string dir = testing::TempDir();
  const std::string folder = dir + "/odd";
  fs::create_directories(folder);
  const std::string png = Encoded(".png", 16, 12, 5);
  const char* const kStyles[] = {"frame %04d.png",    "-%04d.png",          "caf\xc3\xa9 %04d.png",
                                 "it's \"%04d\".png", "new\nline %04d.png", "--set=%04d.png"};
  char name[64];
  for (int i = 0; i < 2000; ++i) {
    std::snprintf(name, sizeof name, kStyles[i % 6], i);
    testing::WriteBytes(folder + "/" + name, png);
  }
  Outcome o =
      RunBounded(dir, {WriteConfig(dir, folder, "Txt_name: \"\"\nPng_name: \"\"\n"), "--quiet"});
  ASSERT_EQ(o.status, 0) << o.err;
  EXPECT_EQ(ReadNpy(dir + "/out/matrix.npy").rows, 2000);
  fs::remove_all(dir + "/out");

  testing::WriteBytes(folder + "/-broken \"caf\xc3\xa9\"\nline.png", "not a png");
  o = RunBounded(dir, {WriteConfig(dir, folder), "--quiet"});
  ExpectRefused(o, dir, "-broken \\\"caf\xc3\xa9\\\"\\nline.png");
}

// ---------------------------------------------------------------------------------------
// Symbolic links.

TEST(BadInputCorpus, SymbolicLinkLoop) {
  const std::string dir = testing::TempDir();
  const std::string folder = SoundFolder(dir);
  fs::create_symlink("b.png", folder + "/a.png");
  fs::create_symlink("a.png", folder + "/b.png");
  const Outcome o = RunBounded(dir, {WriteConfig(dir, folder)});
  ExpectRefused(o, dir, "a.png");
  EXPECT_NE(o.err.find("symbolic link"), std::string::npos) << o.err;
}

TEST(BadInputCorpus, DanglingSymbolicLink) {
  const std::string dir = testing::TempDir();
  const std::string folder = SoundFolder(dir);
  fs::create_symlink(dir + "/gone.png", folder + "/a3.png");
  const Outcome o = RunBounded(dir, {WriteConfig(dir, folder)});
  ExpectRefused(o, dir, "a3.png");
  EXPECT_NE(o.err.find("symbolic link"), std::string::npos) << o.err;
}

// A FIFO, a socket or a link to a device under an image name is a frame the user meant: the run
// names it and stops (reading a FIFO would block), or Skip_unreadable skips and lists it; it is
// never dropped without a word, which would shift the later frame numbers.
TEST(BadInputCorpus, SpecialFilesUnderImageNamesAreNamed) {
  const std::string dir = testing::TempDir();
  struct Case {
    const char* name;
    std::function<void(const std::string&)> make;
    const char* what;
  } cases[] = {
      {"a15.png", [](const std::string& p) { ASSERT_EQ(::mkfifo(p.c_str(), 0644), 0); }, "FIFO"},
      {"a16.png", [](const std::string& p) { fs::create_symlink("/dev/zero", p); },
       "character device"},
      {"a17.png",
       [](const std::string& p) {
         const int fd = ::socket(AF_UNIX, SOCK_STREAM, 0);
         ASSERT_GE(fd, 0);
         sockaddr_un addr{};
         addr.sun_family = AF_UNIX;
         ASSERT_LT(p.size(), sizeof addr.sun_path);
         std::strcpy(addr.sun_path, p.c_str());
         ASSERT_EQ(::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0);
         ::close(fd);
       },
       "socket"},
  };
  for (const Case& c : cases) {
    fs::remove_all(dir + "/out");  // the previous case's Skip_unreadable run wrote it
    const std::string folder = SoundFolder(dir, std::string("imgs_") + c.name);
    if (std::string(c.what) == "socket" && (folder + "/" + c.name).size() >= 100) continue;
    c.make(folder + "/" + c.name);
    const Outcome o = RunBounded(dir, {WriteConfig(dir, folder)});
    ExpectRefused(o, dir, c.name);
    EXPECT_NE(o.err.find(c.what), std::string::npos) << o.err;
    const Outcome skipped = RunBounded(dir, {WriteConfig(dir, folder, "Skip_unreadable: 1\n")});
    ASSERT_EQ(skipped.status, 0) << skipped.err;
    EXPECT_NE(skipped.out.find(std::string("skipped: ")), std::string::npos) << skipped.out;
    EXPECT_NE(skipped.out.find(c.name), std::string::npos) << skipped.out;
    EXPECT_EQ(ReadNpy(dir + "/out/matrix.npy").rows, 2);
  }
}

// A link to a folder is that folder; links to sound images are those images.
TEST(BadInputCorpus, SymbolicLinksToAFolderAndToImagesWork) {
  const std::string dir = testing::TempDir();
  const std::string folder = SoundFolder(dir);
  fs::create_symlink(folder + "/a1.png", folder + "/a3.png");
  fs::create_directory_symlink(folder, dir + "/link");
  const Outcome o = RunBounded(dir, {WriteConfig(dir, dir + "/link")});
  ASSERT_EQ(o.status, 0) << o.err;
  EXPECT_EQ(ReadNpy(dir + "/out/matrix.npy").rows, 3);
}

// ---------------------------------------------------------------------------------------
// Configuration files.

struct KeyInfo {
  std::string key, values;  // "integer in [0, 2]", "number >= 0", "text"
};

// Every key and its values, from the reference table (the text of --help-markdown).
std::vector<KeyInfo> Keys() {
  std::vector<KeyInfo> keys;
  std::istringstream in(ConfigMarkdownReference());
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("| `", 0) != 0) continue;
    const auto k0 = line.find('`') + 1, k1 = line.find('`', k0);
    const auto v0 = line.find("| ", k1) + 2, v1 = line.find(" |", v0);
    keys.push_back({line.substr(k0, k1 - k0), line.substr(v0, v1 - v0)});
  }
  return keys;
}

// For every numeric key in turn: a word instead of a number, a fraction for an integer, and
// a value below its range and (when bounded) above it. Each is one line naming the file, line
// and key, exit 1.
TEST(BadInputCorpus, EveryNumericKeyWrongInTurn) {
  const std::string dir = testing::TempDir();
  const std::string folder = SoundFolder(dir);
  const std::vector<KeyInfo> keys = Keys();
  ASSERT_EQ(keys.size(), ConfigKeyNames().size());
  struct Case {
    std::string key, value, values;
    Outcome outcome;
  };
  std::vector<Case> cases;
  for (const KeyInfo& k : keys) {
    if (k.values == "text") continue;
    // A word for every key; a fraction for an integer and "nan" for a number, on every third
    // key (the same check; each run costs the program's start-up).
    std::vector<std::string> bad = {"twelve"};
    if (cases.size() % 3 == 0) bad.push_back(k.values.rfind("integer", 0) == 0 ? "2.5" : "nan");
    double lo = 0, hi = 0;
    if (std::sscanf(k.values.c_str(), "%*s in [%lf, %lf]", &lo, &hi) == 2) {
      std::ostringstream a, b;  // full precision: "1e+09" would round 1000000001 back in range
      a << std::setprecision(15) << lo - 1;
      b << std::setprecision(15) << hi + 1;
      bad.push_back(a.str());
      bad.push_back(b.str());
    } else {
      ASSERT_EQ(std::sscanf(k.values.c_str(), "%*s >= %lf", &lo), 1) << k.values;
      std::ostringstream a;
      a << std::setprecision(15) << lo - 1;
      bad.push_back(a.str());
    }
    for (const std::string& value : bad) cases.push_back({k.key, value, k.values, {}});
  }
  // The runs wait mostly on loading the program: eight at a time, each in its own folder.
  std::atomic<std::size_t> next{0};
  std::vector<std::thread> workers;
  for (int w = 0; w < 8; ++w)
    workers.emplace_back([&] {
      for (std::size_t i; (i = next++) < cases.size();) {
        const std::string run = dir + "/run" + std::to_string(i);
        fs::create_directories(run);
        cases[i].outcome = RunBounded(
            run, {WriteConfig(run, folder, cases[i].key + ": " + cases[i].value + "\n")});
      }
    });
  for (auto& t : workers) t.join();
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const Case& c = cases[i];
    SCOPED_TRACE(c.key + ": " + c.value);
    ExpectRefused(c.outcome, dir + "/run" + std::to_string(i),
                  c.key + ": value \"" + c.value + "\" is not valid; expected " + c.values);
  }
  for (const Case& c : cases)
    EXPECT_NE(c.outcome.err.find("Config.txt:"), std::string::npos) << c.outcome.err;
  std::cout << "[ keys ] " << cases.size() << " bad values refused\n";
}

// Text keys that name a choice: an unknown choice names the key.
TEST(BadInputCorpus, TextKeysWithAnUnknownChoice) {
  const std::string dir = testing::TempDir();
  const std::string folder = SoundFolder(dir);
  for (const char* key : {"Image_descriptor", "Ground_truth_type", "Ground_truth_axes"}) {
    const Outcome o = RunBounded(
        dir,
        {WriteConfig(dir, folder, std::string(key) + ": bogus\n" + "Ground_truth: \"gt.txt\"\n")});
    SCOPED_TRACE(key);
    ExpectRefused(o, dir, key);
  }
}

// Whatever the file holds, a configuration that is not one is one line naming it.
TEST(BadInputCorpus, GarbageAsConfiguration) {
  const std::string dir = testing::TempDir();
  std::mt19937 rng(7);
  std::string random(4096, '\0');
  for (char& c : random) c = static_cast<char>(rng() & 0xff);
  const std::pair<const char*, std::string> cases[] = {
      {"random.txt", random},
      {"image.png", Encoded(".png", 32, 24, 6)},
      {"empty.txt", ""},
      {"nul.txt", std::string("Frame_mode: 0\nImages_path: \"a\0b\"\n\0\0\0\n", 34)},
      {"nulkey.txt", std::string("Frame_\0mode: 0\n", 15)},
      {"crlf.txt", "Frame_mode: 0\r\nbroken line\r\n"},
  };
  for (const auto& [name, bytes] : cases) {
    testing::WriteBytes(dir + "/" + name, bytes);
    const Outcome o = RunBounded(dir, {dir + "/" + name});
    SCOPED_TRACE(name);
    ExpectRefused(o, dir, name);
    if (bytes.find('\0') != std::string::npos || name == std::string("random.txt")) {
      EXPECT_NE(o.err.find("is not text"), std::string::npos) << o.err;
    }
    for (char c : o.err.substr(0, o.err.size() - 1))
      EXPECT_TRUE(static_cast<unsigned char>(c) >= 0x20 || c == '\t')
          << "control character " << static_cast<int>(c) << " in: " << o.err;
  }
}

// ---------------------------------------------------------------------------------------
// Stereo calibration files that load but cannot be a calibration.

std::string Calibration(const std::string& ml, const std::string& r, const std::string& t) {
  auto matrix = [](const char* key, int rows, int cols, const std::string& data) {
    return std::string(key) + ": !!opencv-matrix\n   rows: " + std::to_string(rows) +
           "\n   cols: " + std::to_string(cols) + "\n   dt: d\n   data: [ " + data + " ]\n";
  };
  return "%YAML:1.0\n" + matrix("ML", 3, 3, ml) +
         matrix("MR", 3, 3, "40, 0, 16, 0, 40, 12, 0, 0, 1") + matrix("DL", 1, 5, "0, 0, 0, 0, 0") +
         matrix("DR", 1, 5, "0, 0, 0, 0, 0") + matrix("R", 3, 3, r) + matrix("T", 3, 1, t);
}

TEST(BadInputCorpus, SingularCalibrations) {
  const std::string dir = testing::TempDir();
  SoundFolder(dir, "left");
  SoundFolder(dir, "right");
  const std::string k = "40, 0, 16, 0, 40, 12, 0, 0, 1", eye = "1, 0, 0, 0, 1, 0, 0, 0, 1",
                    t = "-0.1, 0, 0";
  const struct {
    const char* name;
    std::string yaml, expect;
  } cases[] = {
      {"sound", Calibration(k, eye, t), ""},
      {"ml_zero_rows", Calibration("0, 0, 0, 0, 0, 0, 0, 0, 1", eye, t), "ML: focal length"},
      {"ml_all_zero", Calibration("0, 0, 0, 0, 0, 0, 0, 0, 0", eye, t), "ML: "},
      {"r_not_rotation", Calibration(k, "1, 0, 0, 0, 1, 0, 0, 0, 0", t), "R: not a rotation"},
      {"r_reflection", Calibration(k, "-1, 0, 0, 0, 1, 0, 0, 0, 1", t), "R: not a rotation"},
      {"t_zero", Calibration(k, eye, "0, 0, 0"), "T: (0, 0, 0)"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.name);
    testing::WriteBytes(dir + "/calibration.yaml", c.yaml);
    const std::string config =
        WriteConfig(dir, "",
                    "Camera_type: 1\nImages_path_left: \"left\"\nImages_path_right: \"right\"\n"
                    "Calibration_path: \"calibration.yaml\"\n");
    const Outcome o = RunBounded(dir, {config, "--set", "Images_path="});
    if (c.expect.empty()) {
      EXPECT_EQ(o.status, 0) << o.err;  // the template itself is sound
      fs::remove_all(dir + "/out");
      continue;
    }
    ExpectRefused(o, dir, "calibration \"calibration.yaml\": " + c.expect);
  }
}

// ---------------------------------------------------------------------------------------
// Videos without frames.

TEST(BadInputCorpus, VideoWithoutFrames) {
  const std::string dir = testing::TempDir();
  const std::string video = dir + "/none.avi";
  {
    cv::VideoWriter writer = MjpgWriter(video);
    if (!writer.isOpened()) GTEST_SKIP() << "this OpenCV cannot write MJPG video";
  }
  ASSERT_TRUE(fs::exists(video));
  Outcome o =
      RunBounded(dir, {WriteConfig(dir, "", "Frame_mode: 1\nVideo_path_1: \"none.avi\"\n")});
  ExpectRefused(o, dir, "none.avi");
  // A header only: the first 32 bytes of a RIFF AVI, or an empty file with a video extension.
  testing::WriteBytes(dir + "/header.avi", ReadAll(video).substr(0, 32));
  testing::WriteBytes(dir + "/empty.mp4", "");
  for (const char* name : {"header.avi", "empty.mp4"}) {
    o = RunBounded(
        dir,
        {WriteConfig(dir, "", std::string("Frame_mode: 1\nVideo_path_1: \"") + name + "\"\n")});
    SCOPED_TRACE(name);
    ExpectRefused(o, dir, name);
  }
}

// Stereo folders of different lengths, without the shared dataset.
TEST(BadInputCorpus, StereoFoldersOfDifferentLengths) {
  const std::string dir = testing::TempDir();
  SoundFolder(dir, "left");
  SoundFolder(dir, "right");
  fs::remove(dir + "/right/a2.png");
  testing::WriteBytes(
      dir + "/calibration.yaml",
      Calibration("40, 0, 16, 0, 40, 12, 0, 0, 1", "1, 0, 0, 0, 1, 0, 0, 0, 1", "-0.1, 0, 0"));
  const Outcome o =
      RunBounded(dir, {WriteConfig(dir, "",
                                   "Camera_type: 1\nImages_path_left: \"left\"\nImages_path_right: "
                                   "\"right\"\nCalibration_path: \"calibration.yaml\"\n"),
                       "--set", "Images_path="});
  ExpectRefused(o, dir, "Images_path_right");
}

}  // namespace
}  // namespace openable
