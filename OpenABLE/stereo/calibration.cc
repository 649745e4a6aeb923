#include "OpenABLE/stereo/calibration.h"

#include <cmath>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/input_file.h"
#include "OpenABLE/base/strings.h"

namespace openable {
namespace {

std::string Num(double v) {
  return std::isnan(v) ? "nan" : FormatNumber(v);  // not "-nan": the sign of a NaN means nothing
}

// The prefix of every message: calibration "<path>": <key>:
class Reader {
 public:
  Reader(const std::string& path, cv::FileStorage& fs) : path_(path), fs_(fs) {}

  [[noreturn]] void Fail(const std::string& key, const std::string& what) const {
    throw InputError("calibration \"" + path_ + "\": " + key + ": " + what);
  }

  // An opencv-matrix of `rows` x `cols` (or its transpose when `either_way`), as doubles.
  cv::Mat1d Matrix(const std::string& key, int rows, int cols, bool either_way,
                   const std::string& meaning) const {
    const cv::FileNode node = fs_[key];
    const std::string expected = "expected a " + SizeText(rows, cols) +
                                 (either_way ? " (or " + SizeText(cols, rows) + ")" : "") +
                                 " opencv-matrix (" + meaning + ")";
    if (node.empty() || node.isNone()) Fail(key, "missing; " + expected);
    cv::Mat m;
    try {
      if (node.isMap()) node >> m;
    } catch (const cv::Exception&) {
      m.release();
    }
    if (m.empty()) Fail(key, "not a matrix; " + expected);
    if (m.channels() != 1) Fail(key, std::to_string(m.channels()) + "-channel matrix; " + expected);
    const bool exact = m.rows == rows && m.cols == cols;
    const bool transposed = either_way && m.rows == cols && m.cols == rows;
    if (!exact && !transposed) Fail(key, "a " + SizeText(m.rows, m.cols) + " matrix; " + expected);
    cv::Mat1d d;
    m.convertTo(d, CV_64F);
    if (transposed) d = d.t();
    for (int r = 0; r < d.rows; ++r)
      for (int c = 0; c < d.cols; ++c)
        if (!std::isfinite(d(r, c)))
          Fail(key, "element (" + std::to_string(r) + "," + std::to_string(c) + ") is " +
                        Num(d(r, c)) + "; expected finite numbers");
    return d;
  }

  cv::Matx33d Camera(const std::string& key, const std::string& side) const {
    const cv::Matx33d k(Matrix(key, 3, 3, false, "camera matrix of the " + side + " camera"));
    if (!(k(0, 0) > 0.0) || !(k(1, 1) > 0.0))
      Fail(key, "focal length fx = " + Num(k(0, 0)) + ", fy = " + Num(k(1, 1)) +
                    "; expected both > 0 (pixels)");
    if (k(1, 0) != 0.0 || k(2, 0) != 0.0 || k(2, 1) != 0.0 || k(2, 2) != 1.0)
      Fail(key, "rows 2-3 are (" + Num(k(1, 0)) + " ... ; " + Num(k(2, 0)) + " " + Num(k(2, 1)) +
                    " " + Num(k(2, 2)) + "); expected a camera matrix (0 fy cy; 0 0 1)");
    return k;
  }

  int OptionalInt(const std::string& key, int fallback, int lo, int hi) const {
    const cv::FileNode node = fs_[key];
    if (node.empty() || node.isNone()) return fallback;
    if (!node.isInt())
      Fail(key, "not an integer; expected an integer in [" + std::to_string(lo) + ", " +
                    std::to_string(hi) + "]");
    const int v = static_cast<int>(node);
    if (v < lo || v > hi)
      Fail(key, std::to_string(v) + " is out of range; expected an integer in [" +
                    std::to_string(lo) + ", " + std::to_string(hi) + "]");
    return v;
  }

 private:
  const std::string& path_;
  cv::FileStorage& fs_;
};

std::string OneLine(std::string s) {
  for (char& c : s)
    if (c == '\n' || c == '\r') c = ' ';
  return s;
}

}  // namespace

StereoCalibration LoadStereoCalibration(const std::string& path) {
  const std::string where = "calibration \"" + path + "\": ";
  if (path.empty()) throw InputError("calibration: empty path; expected a calibration file");
  const std::string text = ReadInputFile(path, "calibration " + Quoted(path),
                                         "expected an OpenCV YAML stereo calibration");
  if (text.empty())
    throw InputError(where +
                     "is empty (0 bytes); expected an OpenCV YAML stereo calibration "
                     "(first line %YAML:1.0)");
  std::string first = text.substr(0, text.find('\n'));
  if (!first.empty() && first.back() == '\r') first.pop_back();
  if (first.rfind("%YAML", 0) != 0)
    throw InputError(where + "first line \"" + OneLine(first.substr(0, 40)) +
                     "\" is not a YAML header; expected OpenCV FileStorage YAML starting with "
                     "%YAML:1.0");
  cv::FileStorage fs;
  try {
    // From the bytes already read and checked: OpenCV would open the path again.
    fs.open(text, cv::FileStorage::READ | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML);
  } catch (const cv::Exception& e) {
    throw InputError(where + "not valid OpenCV YAML (" + OneLine(e.err) +
                     "); expected keys ML, MR, DL, DR, R, T as opencv-matrix nodes");
  }
  if (!fs.isOpened())
    throw InputError(where + "not valid OpenCV YAML; expected keys ML, MR, DL, DR, R, T");

  const Reader r(path, fs);
  StereoCalibration c;
  c.path = path;
  c.left_camera = r.Camera("ML", "left");
  c.right_camera = r.Camera("MR", "right");
  c.left_distortion = cv::Vec<double, 5>(
      r.Matrix("DL", 5, 1, true, "k1 k2 p1 p2 k3 of the left camera").ptr<double>());
  c.right_distortion = cv::Vec<double, 5>(
      r.Matrix("DR", 5, 1, true, "k1 k2 p1 p2 k3 of the right camera").ptr<double>());
  c.rotation =
      cv::Matx33d(r.Matrix("R", 3, 3, false, "rotation from the left camera to the right"));
  const double orthogonality =
      cv::norm(c.rotation.t() * c.rotation - cv::Matx33d::eye(), cv::NORM_INF);
  const double det = cv::determinant(c.rotation);
  if (orthogonality > 1e-3 || det <= 0.0)
    r.Fail("R", "not a rotation (|R^T R - I| = " + Num(orthogonality) + ", det = " + Num(det) +
                    "); expected an orthonormal 3x3 matrix with det +1");
  c.translation = cv::Vec3d(
      r.Matrix("T", 3, 1, true, "translation from the left camera to the right").ptr<double>());
  if (cv::norm(c.translation) == 0.0)
    r.Fail("T", "(0, 0, 0); expected the non-zero baseline from the left camera to the right");
  c.colormap = r.OptionalInt("colormap", -1, -1, 21);
  c.use_log = r.OptionalInt("use_log", 0, 0, 1);
  return c;
}

void CheckPrincipalPointFits(const std::string& calibration, const std::string& camera, double cx,
                             double cy, const cv::Size& size, const std::string& first_image) {
  const double w = size.width, h = size.height;
  if (cx < w / 4 || cx > 3 * w / 4 || cy < h / 4 || cy > 3 * h / 4)
    throw InputError(
        "calibration \"" + calibration + "\" does not fit the images: " + camera +
        " principal point (" + Num(cx) + ", " + Num(cy) + ") lies outside the middle half of the " +
        std::to_string(size.width) + "x" + std::to_string(size.height) + " image \"" + first_image +
        "\" (it suits images of about " + std::to_string(static_cast<int>(std::lround(2 * cx))) +
        "x" + std::to_string(static_cast<int>(std::lround(2 * cy))) +
        "); expected width/4 <= cx <= 3 width/4 and height/4 <= cy <= 3 height/4");
}

void CheckCalibrationFits(const StereoCalibration& c, const cv::Size& size,
                          const std::string& first_image) {
  CheckPrincipalPointFits(c.path, "ML", c.left_camera(0, 2), c.left_camera(1, 2), size,
                          first_image);
  CheckPrincipalPointFits(c.path, "MR", c.right_camera(0, 2), c.right_camera(1, 2), size,
                          first_image);
}

}  // namespace openable
