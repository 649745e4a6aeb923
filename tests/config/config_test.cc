#include "config/config.h"

#include <gtest/gtest.h>

#include <fstream>
#include <functional>
#include <string>

#include "OpenABLE/base/error.h"
#include "tests/test_support.h"

namespace openable {
namespace {

std::string WriteFile(const std::string& text) {
  const std::string path = testing::TempDir() + "/Config.txt";
  std::ofstream(path) << text;
  return path;
}

// The message of the InputError that `f` throws (testing::InputErrorMessage).
std::string ErrorOf(const std::function<void()>& f) { return testing::InputErrorMessage(f); }

// '#' starts a comment only at the start of a line or after a space or tab (YAML, and OpenCV's
// FileStorage, which read the original's files): inside an unquoted value it is a character.
TEST(Config, HashInsideAnUnquotedValueIsKept) {
  const std::string path = WriteFile(
      "%YAML:1.0\n"
      "#Txt_name: commented.txt\n"
      "   # an indented comment\n"
      "Npy_name: out/run#1.npy\n"
      "Png_name: out/run#2.png # the image\n"
      "Txt_name: out/m.txt\t# after a tab\n"
      "Images_format: png#\n");
  const Config c = LoadConfig(path);
  EXPECT_EQ(c.output.npy_name, "out/run#1.npy");
  EXPECT_EQ(c.output.png_name, "out/run#2.png");
  EXPECT_EQ(c.output.txt_name, "out/m.txt");
  EXPECT_EQ(c.input.images_format, "png#");
}

TEST(Config, ReadsTheOriginalFormat) {
  const std::string path = WriteFile(R"(%YAML:1.0
# a comment
Frame_mode: 0
Images_path: "/data/seq # not a comment"
Images_format: png   # trailing comment
Initial_image: 10
Final_image: 200
Txt_name: 'out.txt'
Camera_type: 0
Image_descriptor: ORB
Patch_size: 48
Image_sequences: 7
Threshold: 0.25
Show_images: 0
)");
  const Config c = LoadConfig(path);
  EXPECT_EQ(c.input.images_path, "/data/seq # not a comment");
  EXPECT_EQ(c.input.images_format, "png");
  EXPECT_EQ(c.input.initial_image, 10);
  EXPECT_EQ(c.input.final_image, 200);
  EXPECT_EQ(c.output.txt_name, "out.txt");
  EXPECT_EQ(c.descriptor.name, "ORB");
  EXPECT_EQ(c.descriptor.patch_size, 48);
  EXPECT_EQ(c.matching.sequence_length, 7);
  EXPECT_DOUBLE_EQ(c.matching.threshold, 0.25);
  // Keys not given keep their defaults.
  EXPECT_EQ(c.output.matrix_color, 0);
  EXPECT_EQ(c.descriptor.ldb_bits, 256);
}

TEST(Config, RoundTripsEveryKey) {
  Config c;
  c.input.frame_mode = FrameMode::kTwoVideos;
  c.input.video_path_1 = "a b.avi";
  c.input.video_path_2 = "/x/y.mp4";
  c.input.images_path_2 = "winter";
  c.output.matrix_color = 11;
  c.preprocess.alpha = 0.123;
  c.matching.threshold = 0.5;
  c.descriptor.name = "HOG";
  c.descriptor.ldb_bits = 1386;
  c.matching.threads = 3;
  c.input.final_image = 77;
  const Config back = LoadConfig(WriteFile(FormatConfig(c)));
  EXPECT_EQ(back, c);
  EXPECT_NE(back, Config());
  EXPECT_EQ(back.input.video_path_1, "a b.avi");
  EXPECT_DOUBLE_EQ(back.preprocess.alpha, 0.123);
}

TEST(Config, MissingFileNamesIt) {
  const std::string msg = ErrorOf([] { LoadConfig("/no/such/Config.txt"); });
  EXPECT_NE(msg.find("/no/such/Config.txt"), std::string::npos) << msg;
}

TEST(Config, UnknownKeySuggestsTheNearest) {
  const std::string msg = ErrorOf([&] { LoadConfig(WriteFile("Patch_sise: 64\n")); });
  EXPECT_NE(msg.find("Config.txt:1"), std::string::npos) << msg;
  EXPECT_NE(msg.find("\"Patch_sise\""), std::string::npos) << msg;
  EXPECT_NE(msg.find("did you mean \"Patch_size\""), std::string::npos) << msg;
  const std::string far = ErrorOf([&] { LoadConfig(WriteFile("Zzzzzzzzzzzzzzzzzz: 1\n")); });
  EXPECT_EQ(far.find("did you mean"), std::string::npos) << far;
}

TEST(Config, WrongTypeAndOutOfRangeNameKeyValueAndRange) {
  struct Case {
    const char* text;
    const char* expect;
  };
  const Case cases[] = {
      {"Camera_type: 7\n", "Camera_type: value \"7\" is not valid; expected integer in [0, 2]"},
      {"Patch_size: big\n", "Patch_size: value \"big\""},
      {"Patch_size: 64.5\n", "Patch_size: value \"64.5\""},
      {"Patch_size: 8\n", "expected integer in [16, 1024]"},
      {"Threshold: 1.5\n", "Threshold: value \"1.5\""},
      {"Matrix_color: 12\n", "expected integer in [0, 11]"},
      {"Image_sequences: 0\n", "Image_sequences: value \"0\""},
      {"Alpha: nan\n", "Alpha: value \"nan\""},
      {"Frame_mode:\n", "Frame_mode: value \"\""},
  };
  for (const auto& c : cases) {
    const std::string msg = ErrorOf([&] { LoadConfig(WriteFile(c.text)); });
    EXPECT_NE(msg.find(c.expect), std::string::npos) << c.text << " -> " << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  }
}

TEST(Config, MalformedLinesDuplicatesAndEmptyFiles) {
  EXPECT_NE(ErrorOf([&] { LoadConfig(WriteFile("Frame_mode 0\n")); }).find("Key: value"),
            std::string::npos);
  EXPECT_NE(ErrorOf([&] {
              LoadConfig(WriteFile("Frame_mode: 0\nFrame_mode: 1\n"));
            }).find("given twice (first at line 1)"),
            std::string::npos);
  EXPECT_NE(ErrorOf([&] { LoadConfig(WriteFile("%YAML:1.0\n# nothing\n")); }).find("no key"),
            std::string::npos);
  EXPECT_NE(ErrorOf([&] { LoadConfig(WriteFile("Images_path: \"abc\n")); }).find("unterminated"),
            std::string::npos);
  // A carriage return inside the value (not at the line's end) is shown escaped: the message
  // stays on one line. So does a configuration whose name holds a newline.
  const std::string cr = ErrorOf([&] { ParseConfigText("Images_path: \"a=\r4\n", "m"); });
  EXPECT_NE(cr.find("unterminated quoted value \"\\\"a=\\r4\""), std::string::npos) << cr;
  EXPECT_EQ(cr.find_first_of("\r\n"), std::string::npos) << cr;
  const std::string named = ErrorOf([&] { ParseConfigText("Nope: 1\n", "two\nlines"); });
  EXPECT_EQ(named.rfind("two\\nlines:1: unknown key", 0), 0u) << named;
}

TEST(Config, ParsesTextInMemoryLikeAFile) {
  const std::string text = "%YAML:1.0\nPatch_size: 32\nImage_descriptor: \"HOG\"\n";
  const Config from_text = ParseConfigText(text, "memory");
  EXPECT_EQ(from_text.descriptor.patch_size, 32);
  EXPECT_EQ(from_text.descriptor.name, "HOG");
  EXPECT_EQ(from_text, LoadConfig(WriteFile(text)));
  const std::string msg =
      ErrorOf([] { ParseConfigText("Patch_size: 32\nPatch_size: x\n", "mem"); });
  EXPECT_EQ(msg.rfind("mem:2: Patch_size:", 0), 0u) << msg;
}

// Found by tests/fuzz/config_fuzzer.cc: a first line starting with 0xEF but shorter than a
// UTF-8 byte-order mark threw std::out_of_range instead of InputError.
TEST(Config, ByteOrderMarkOnlyWhenComplete) {
  EXPECT_EQ(ParseConfigText("\xEF\xBB\xBFPatch_size: 16\n", "bom").descriptor.patch_size, 16);
  for (const std::string text : {"\xEF", "\xEFT", "\xEF\xBB", "\xEF\xBBPatch_size: 16\n"}) {
    const std::string msg = ErrorOf([&] { ParseConfigText(text, "bom"); });
    EXPECT_EQ(msg.rfind("bom:1: ", 0), 0u) << msg;
  }
}

TEST(Config, OverridesUseTheSameBinding) {
  Config c;
  ApplyOverride(c, "Image_sequences=12");
  ApplyOverride(c, "Images_path = /tmp/x");
  EXPECT_EQ(c.matching.sequence_length, 12);
  EXPECT_EQ(c.input.images_path, "/tmp/x");
  EXPECT_NE(ErrorOf([&] {
              ApplyOverride(c, "Image_sequence=3");
            }).find("did you mean \"Image_sequences\""),
            std::string::npos);
  EXPECT_NE(ErrorOf([&] { ApplyOverride(c, "Patch_size"); }).find("Key=Value"), std::string::npos);
  EXPECT_NE(ErrorOf([&] { ApplyOverride(c, "Threads=-1"); }).find("--set: Threads"),
            std::string::npos);
}

// Approximate_engine takes the three engine names (any case) and refuses others in one line
// naming the key, the value and the names; hnsw and ivf with Approximate_search 1 need FAISS in
// the build (else one line saying so, never FLANN in their place).
TEST(Config, ApproximateEngineValues) {
  Config c;
  c.input.images_path = "x";
  c.scale.matches_name = "m.csv";
  EXPECT_EQ(c.scale.approximate.engine, "auto");  // the default
  ApplyOverride(c, "Approximate_engine=flann");
  EXPECT_EQ(c.scale.approximate.engine, "flann");
  ApplyOverride(c, "Approximate_engine=IVF");
  EXPECT_EQ(c.scale.approximate.engine, "ivf");
  ApplyOverride(c, "Approximate_engine=hnsw");
  EXPECT_EQ(c.scale.approximate.engine, "hnsw");
  EXPECT_EQ(ConfigValueText(c, "Approximate_engine"), "\"hnsw\"");
  const std::string bad = ErrorOf([&] { ApplyOverride(c, "Approximate_engine=annoy"); });
  EXPECT_NE(bad.find("Approximate_engine"), std::string::npos) << bad;
  EXPECT_NE(bad.find("annoy"), std::string::npos) << bad;
  EXPECT_NE(bad.find("flann, hnsw, ivf, binary_ivf or auto"), std::string::npos) << bad;
  EXPECT_EQ(bad.find('\n'), std::string::npos) << bad;
  EXPECT_EQ(c.scale.approximate.engine, "hnsw");  // unchanged
  // Read from a file as well.
  const Config f =
      LoadConfig(WriteFile("%YAML:1.0\nApproximate_engine: ivf\n"
                           "Approximate_nprobe: 32\nApproximate_ef_search: 128\n"));
  EXPECT_EQ(f.scale.approximate.engine, "ivf");
  EXPECT_EQ(f.scale.approximate.nprobe, 32);
  EXPECT_EQ(f.scale.approximate.ef_search, 128);
  EXPECT_EQ(f.scale.approximate.engine, "ivf");

  c.scale.approximate_search = true;
  for (const char* engine : {"flann", "hnsw", "ivf", "auto"}) {
    ApplyOverride(c, std::string("Approximate_engine=") + engine);
    if (FaissAvailable() || std::string(engine) == "flann") {
      EXPECT_NO_THROW(CheckConfig(c)) << engine;
    } else {
      const std::string message = ErrorOf([&] { CheckConfig(c); });
      EXPECT_EQ(message.rfind(std::string("Approximate_engine: ") + engine, 0), 0u) << message;
      EXPECT_NE(message.find("expected flann"), std::string::npos) << message;
    }
  }
}

TEST(Config, CrossKeyChecks) {
  Config c;
  EXPECT_NE(ErrorOf([&] { CheckConfig(c); }).find("Images_path: empty"), std::string::npos);
  c.input.images_path = "x";
  CheckConfig(c);
  c.input.camera_type = CameraType::kPanoramic;
  CheckConfig(c);  // panoramas read Images_path like a monocular run
  // Peak responses: all three or none.
  c.preprocess.lambda_red = 610;
  EXPECT_NE(
      ErrorOf([&] { CheckConfig(c); }).find("Lambda_red, Lambda_green, Lambda_blue: 610, 0, 0"),
      std::string::npos);
  c.preprocess.lambda_green = 535;
  c.preprocess.lambda_blue = 470;
  CheckConfig(c);
  c.preprocess.lambda_red = c.preprocess.lambda_green = c.preprocess.lambda_blue = 0;
  // Stereo: its folders and calibration are required, Images_path is not.
  c.input.camera_type = CameraType::kStereo;
  c.input.images_path = "";
  EXPECT_NE(ErrorOf([&] { CheckConfig(c); }).find("Images_path_left: empty"), std::string::npos);
  c.input.images_path_left = "l";
  EXPECT_NE(ErrorOf([&] { CheckConfig(c); }).find("Images_path_right: empty"), std::string::npos);
  c.input.images_path_right = "r";
  EXPECT_NE(ErrorOf([&] { CheckConfig(c); }).find("Calibration_path: empty"), std::string::npos);
  c.input.calibration_path = "cal.yaml";
  c.descriptor.name = "D-LDB";
  CheckConfig(c);
  c.preprocess.illumination_invariance = true;  // stereo frames are grey
  EXPECT_NE(ErrorOf([&] { CheckConfig(c); }).find("Illumination_invariance: 1 with Camera_type 1"),
            std::string::npos);
  c.preprocess.illumination_invariance = false;
  c.input.images_path_2 = "second";
  EXPECT_NE(ErrorOf([&] { CheckConfig(c); }).find("Images_path_2: \"second\" with Camera_type 1"),
            std::string::npos);
  c.input.images_path_2 = "";
  c.input.frame_mode = FrameMode::kVideo;
  c.input.video_path_1 = "a.avi";
  EXPECT_NE(ErrorOf([&] { CheckConfig(c); }).find("Frame_mode: 1 with Camera_type 1"),
            std::string::npos);
  c.input.frame_mode = FrameMode::kImageFolders;
  c.input.video_path_1 = "";
  // D-LDB needs the disparity of a stereo camera (any case of the name).
  c.input.camera_type = CameraType::kMonocular;
  c.input.images_path = "x";
  for (const char* name : {"D-LDB", "d-ldb"}) {
    c.descriptor.name = name;
    EXPECT_EQ(ErrorOf([&] { CheckConfig(c); }),
              "Image_descriptor: D-LDB needs Camera_type 1 (stereo); Camera_type is 0");
  }
  c.descriptor.name = "LDB";
  c.input.frame_mode = FrameMode::kTwoVideos;
  c.input.video_path_1 = "a.avi";
  EXPECT_NE(ErrorOf([&] { CheckConfig(c); }).find("Video_path_2"), std::string::npos);
  c.input.frame_mode = FrameMode::kImageFolders;
  c.input.initial_image = 5;
  c.input.final_image = 5;
  EXPECT_NE(ErrorOf([&] { CheckConfig(c); }).find("Final_image: 5"), std::string::npos);
  c.input.final_image = -1;
  c.matching.threshold = -0.5;
  EXPECT_NE(ErrorOf([&] { CheckConfig(c); }).find("Threshold: -0.5"), std::string::npos);
}

TEST(Config, HelpAndReferenceListEveryKey) {
  const std::string help = ConfigHelpText(), md = ConfigMarkdownReference();
  for (const auto& key : ConfigKeyNames()) {
    EXPECT_NE(help.find("  " + key + " "), std::string::npos) << key;
    EXPECT_NE(md.find("`" + key + "`"), std::string::npos) << key;
  }
}

TEST(Config, DocsReferenceIsUpToDate) {
  // docs/configuration.md embeds ConfigMarkdownReference() between two markers; regenerate it
  // with `Test_OpenABLE --help-markdown` when a key changes.
  std::ifstream in(testing::SourceDir() + "/docs/configuration.md");
  ASSERT_TRUE(in) << "docs/configuration.md missing";
  const std::string doc((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string begin = "<!-- BEGIN KEYS -->\n", end = "<!-- END KEYS -->";
  const auto b = doc.find(begin), e = doc.find(end);
  ASSERT_NE(b, std::string::npos);
  ASSERT_NE(e, std::string::npos);
  EXPECT_EQ(doc.substr(b + begin.size(), e - b - begin.size()), ConfigMarkdownReference());
}

TEST(Config, ShippedConfigFilesLoad) {
  const Config c = LoadConfig(testing::SourceDir() + "/config/Config.txt");
  CheckConfig(c);
  EXPECT_EQ(c.descriptor.name, "LDB");
}

}  // namespace
}  // namespace openable
