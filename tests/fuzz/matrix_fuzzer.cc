// libFuzzer target: the matrix readers of openable_evaluate, the ground truth and SNAPS. The
// rest of the input after its first byte is decoded as a NumPy file from memory
// (DecodeNpyMatrix, OpenABLE/io/npy.h), as a NumPy file of Python objects (DecodeNpyObjects,
// the restricted pickle reader of OpenABLE/io/npy_objects.h), as a .npz archive (every
// member listed and read by NpzMember, then decoded as a matrix) and as the settings file
// beside a matrix (DecodeMatrixSettings, OpenABLE/evaluation/saved_settings.h, checked against
// the decoded matrix by CheckMatrixFitsSettings), then written to a temporary file whose extension
// the first byte chooses (modulo 4: .npy, .txt, .csv, .png) and read by ReadMatrixFile
// (OpenABLE/evaluation/matrix_file.h: the .npy reader, the text reader, or an image through
// OpenCV's codecs). A .npy file must read as the same matrix as its bytes decode to. The
// expected outcomes are a matrix or one InputError line (naming the file for ReadMatrixFile);
// any other exception, a crash or a sanitizer report is a finding. Built with
// -DOPENABLE_BUILD_FUZZERS=ON (clang); see docs/robustness.md.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "OpenABLE/evaluation/matrix_file.h"
#include "OpenABLE/evaluation/saved_settings.h"
#include "OpenABLE/io/npy.h"
#include "OpenABLE/io/npy_objects.h"
#include "tests/fuzz/frame_check.h"
#include "tests/fuzz/fuzz_support.h"

namespace {

bool SameBits(const cv::Mat1f& a, const cv::Mat1f& b) {
  if (a.size() != b.size()) return false;
  if (a.empty()) return true;  // an empty matrix has no rows to compare (and no data pointer)
  for (int r = 0; r < a.rows; ++r)
    if (std::memcmp(a[r], b[r], a.cols * sizeof(float)) != 0) return false;
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  openable::fuzz::LimitDecodedPixels();  // matrix images are read with OpenCV's codecs
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using openable::fuzz::Refuses;
  if (size == 0) return 0;
  static const char* const kExtensions[] = {".npy", ".txt", ".csv", ".png"};
  const int choice = data[0] % 4;
  const std::string bytes = openable::fuzz::Bytes(data + 1, size - 1);
  cv::Mat1f decoded;
  const bool refused = Refuses([&] { decoded = openable::DecodeNpyMatrix(bytes, "fuzz.npy"); });
  Refuses([&] { openable::DecodeNpyObjects(bytes, "fuzz.npy"); });
  std::vector<std::string> members;
  if (!Refuses([&] { members = openable::NpzMemberNames(bytes, "fuzz.npz"); }))
    for (const std::string& name : members) {
      std::string member;
      if (!Refuses([&] { member = openable::NpzMember(bytes, name, "fuzz.npz"); }))
        Refuses([&] { openable::DecodeNpyMatrix(member, "fuzz.npz"); });
    }
  Refuses([&] {
    const openable::SavedMatrixSettings settings =
        openable::DecodeMatrixSettings(bytes, "fuzz.npy.json");
    // Against the decoded matrix, or the sample's 600 x 600 when the bytes are no matrix.
    openable::CheckMatrixFitsSettings(settings, "fuzz.npy", refused ? 600 : decoded.rows,
                                      refused ? 600 : decoded.cols);
  });
  const openable::fuzz::TempFile file(bytes, kExtensions[choice]);
  cv::Mat1f read;
  if (Refuses([&] { read = openable::ReadMatrixFile(file.Path()); }, file.Path())) return 0;
  if (choice == 0 && (refused || !SameBits(read, decoded))) {
    std::fprintf(stderr, "matrix_fuzzer: ReadMatrixFile gave %d x %d, DecodeNpyMatrix %s\n",
                 read.rows, read.cols, refused ? "refused the bytes" : "another matrix");
    std::abort();
  }
  return 0;
}
