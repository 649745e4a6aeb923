#include "OpenABLE/evaluation/pose_file.h"

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <sstream>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/strings.h"
#include "OpenABLE/evaluation/text_parsing.h"

namespace openable {
namespace {

// Below this |R^T R - I| a rotation is kept as it is (a file written by the SNAPS encoder reads
// back to the same bits).
constexpr double kExactEnough = 1e-12;

std::vector<std::string> Tokens(const std::string& line) {
  std::vector<std::string> out;
  std::istringstream in(line);
  std::string t;
  while (in >> t) out.push_back(t);
  return out;
}

// A finite double, or InputError naming the place, the token and its column.
double Number(const std::string& token, const std::string& where, int column, const char* what) {
  const char* begin = token.c_str();
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(begin, &end);
  if (end == begin || *end != '\0')
    throw InputError(where + ": " + Quoted(token) + " (column " + std::to_string(column) +
                     ") is not a number; expected " + what);
  if (!std::isfinite(v))
    throw InputError(where + ": " + Quoted(token) + " (column " + std::to_string(column) +
                     ") is not finite; expected a finite " + what);
  return v;
}

long FrameNumber(const std::string& token, const std::string& where) {
  const char* begin = token.c_str();
  char* end = nullptr;
  errno = 0;
  const long v = std::strtol(begin, &end, 10);
  if (end == begin || *end != '\0' || errno == ERANGE || v < 0)
    throw InputError(where + ": " + Quoted(token) +
                     " (column 1) is not a frame number; expected a non-negative integer");
  return v;
}

}  // namespace

std::string ShortestNumber(double v) {
  std::string text;
  for (int digits = 1; digits <= 17; ++digits) {
    text = FormatNumber(v, digits);
    if (std::strtod(text.c_str(), nullptr) == v) break;
  }
  return text;
}

Eigen::Matrix3d CheckedRotationMatrix(const Eigen::Matrix3d& m, const std::string& where) {
  const double deviation = (m.transpose() * m - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  const double det = m.determinant();
  if (!(deviation <= kPoseRotationTolerance) || det <= 0)
    throw InputError(where + ": the 3x3 part is not a rotation (max |R^T R - I| = " +
                     ShortestNumber(deviation) + ", det = " + ShortestNumber(det) +
                     "); expected an orthonormal matrix with determinant +1 within " +
                     ShortestNumber(kPoseRotationTolerance));
  if (deviation <= kExactEnough) return m;
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(m, Eigen::ComputeFullU | Eigen::ComputeFullV);
  return svd.matrixU() * svd.matrixV().transpose();
}

std::vector<PoseFileLine> ReadPoseFile(const std::string& path, PoseFileFormat format,
                                       const std::string& what, bool both_kitti) {
  const std::string file = what + " " + Quoted(path);
  const std::string data = evaluation_internal::ReadWholeFile(path, file);
  const std::size_t expected = format == PoseFileFormat::kKitti         ? 12
                               : format == PoseFileFormat::kKittiWithId ? 13
                                                                        : 8;
  const char* layout = format == PoseFileFormat::kKitti ? "12 numbers (row-major 3x4 [R | t])"
                       : format == PoseFileFormat::kKittiWithId
                           ? "13 numbers (frame number, row-major 3x4 [R | t])"
                           : "8 numbers (timestamp tx ty tz qx qy qz qw)";
  std::vector<PoseFileLine> out;
  std::istringstream in(data);
  std::string text;
  int line_number = 0;
  while (std::getline(in, text)) {
    ++line_number;
    if (line_number == 1 && text.compare(0, 3, "\xEF\xBB\xBF") == 0) text.erase(0, 3);  // BOM
    if (!text.empty() && text.back() == '\r') text.pop_back();
    const std::size_t first = text.find_first_not_of(" \t");
    if (first == std::string::npos || text[first] == '#') continue;  // blank or comment
    const std::string where = file + ":" + std::to_string(line_number);
    const std::vector<std::string> tokens = Tokens(text);
    if (tokens.size() != expected) {
      // The other KITTI format, when the caller reads it too and the line has its count.
      std::string other;
      if (both_kitti && format == PoseFileFormat::kKitti && tokens.size() == 13)
        other = "; a frame number then 12 numbers is the format kitti-id";
      else if (both_kitti && format == PoseFileFormat::kKittiWithId && tokens.size() == 12)
        other = "; 12 numbers without a frame number are the format kitti";
      throw InputError(where + ": line has " + std::to_string(tokens.size()) +
                       (tokens.size() == 1 ? " number" : " numbers") + "; expected " + layout +
                       other);
    }
    PoseFileLine pose;
    pose.line = line_number;
    pose.frame_id = static_cast<long>(out.size());
    if (format == PoseFileFormat::kTum) {
      pose.timestamp = Number(tokens[0], where, 1, "timestamp (seconds)");
      double v[7];
      for (int k = 0; k < 7; ++k) v[k] = Number(tokens[k + 1], where, k + 2, "pose value");
      const Eigen::Quaterniond q(v[6], v[3], v[4], v[5]);  // w, x, y, z
      const double norm = q.norm();
      if (!(std::abs(norm - 1) <= kPoseRotationTolerance))
        throw InputError(where + ": quaternion (" + tokens[4] + " " + tokens[5] + " " + tokens[6] +
                         " " + tokens[7] + ") has norm " + ShortestNumber(norm) +
                         "; expected a unit quaternion within " +
                         ShortestNumber(kPoseRotationTolerance));
      pose.rotation = CheckedRotationMatrix(q.normalized().toRotationMatrix(), where);
      pose.translation = Eigen::Vector3d(v[0], v[1], v[2]);
      if (!out.empty() && !(pose.timestamp > out.back().timestamp))
        throw InputError(where + ": timestamp " + tokens[0] + " after " +
                         ShortestNumber(out.back().timestamp) +
                         "; expected strictly increasing timestamps");
    } else {
      const int offset = format == PoseFileFormat::kKittiWithId ? 1 : 0;
      if (offset == 1) pose.frame_id = FrameNumber(tokens[0], where);
      Eigen::Matrix<double, 3, 4> m;
      for (int k = 0; k < 12; ++k)
        m(k / 4, k % 4) = Number(tokens[k + offset], where, k + offset + 1, "pose value");
      pose.rotation = CheckedRotationMatrix(m.leftCols<3>(), where);
      pose.translation = m.col(3);
      if (offset == 1 && !out.empty() && pose.frame_id <= out.back().frame_id)
        throw InputError(where + ": frame " + std::to_string(pose.frame_id) + " after frame " +
                         std::to_string(out.back().frame_id) +
                         "; expected strictly increasing frame numbers");
    }
    out.push_back(pose);
  }
  if (out.empty())
    throw InputError(file + ":" + std::to_string(line_number) +
                     ": no pose in the file; expected lines of " + layout);
  return out;
}

}  // namespace openable
