#include "OpenABLE/odometry/calibration.h"

#include <cmath>
#include <map>
#include <sstream>
#include <vector>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/input_file.h"

namespace openable::odometry {

cv::Matx33d Intrinsics::K() const { return cv::Matx33d(fx, 0, cx, 0, fy, cy, 0, 0, 1); }

void Intrinsics::Check(const std::string& what) const {
  if (!std::isfinite(fx) || !std::isfinite(fy) || !std::isfinite(cx) || !std::isfinite(cy) ||
      fx <= 0 || fy <= 0) {
    std::ostringstream s;
    s << what << ": intrinsics fx " << fx << " fy " << fy << " cx " << cx << " cy " << cy
      << ", expected finite values with fx, fy > 0";
    throw InputError(s.str());
  }
}

KittiCalibration ReadKittiCalibration(const std::string& path, double scale) {
  if (!(scale > 0) || !std::isfinite(scale))
    throw InputError(Quoted(path) + ": scale " + std::to_string(scale) + ", expected > 0");
  std::istringstream in(ReadInputFile(path, "KITTI calibration " + Quoted(path),
                                      "expected a KITTI calib.txt: \"P0: 12 numbers\" per line"));
  std::map<std::string, std::pair<int, cv::Matx34d>> projections;  // name -> (line, P)
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.find_first_not_of(" \t") == std::string::npos) continue;
    const std::string where = Quoted(path) + ":" + std::to_string(number);
    const auto colon = line.find(':');
    if (colon == std::string::npos || colon == 0)
      throw InputError(where + ": expected \"<name>: 12 numbers\"");
    const std::string name = line.substr(0, colon);
    std::istringstream values(line.substr(colon + 1));
    std::vector<double> v;
    std::string token;
    while (values >> token) {
      try {
        std::size_t used = 0;
        const double x = std::stod(token, &used);
        if (used != token.size() || !std::isfinite(x)) throw std::invalid_argument(token);
        v.push_back(x);
      } catch (const std::exception&) {
        throw InputError(where + ": " + Quoted(token) + " is not a finite number");
      }
    }
    if (v.size() != 12)
      throw InputError(where + ": " + name + " has " + std::to_string(v.size()) +
                       " numbers, expected 12 (a row-major 3x4 matrix)");
    projections[name] = {number, cv::Matx34d(v.data())};
  }
  for (const char* name : {"P0", "P1"}) {
    if (!projections.count(name))
      throw InputError(Quoted(path) + ":" + std::to_string(number) + ": no " + name +
                       " line (expected \"" + name + ": 12 numbers\")");
  }
  const auto& [line0, p0] = projections["P0"];
  const auto& [line1, p1] = projections["P1"];
  KittiCalibration c;
  c.left.fx = p0(0, 0) * scale;
  c.left.fy = p0(1, 1) * scale;
  c.left.cx = p0(0, 2) * scale;
  c.left.cy = p0(1, 2) * scale;
  if (c.left.fx <= 0 || c.left.fy <= 0)
    throw InputError(Quoted(path) + ":" + std::to_string(line0) + ": P0 focal lengths must be > 0");
  if (p1(0, 0) <= 0)
    throw InputError(Quoted(path) + ":" + std::to_string(line1) + ": P1(0,0) must be > 0");
  c.baseline = -p1(0, 3) / p1(0, 0);
  if (!(c.baseline > 0))
    throw InputError(Quoted(path) + ":" + std::to_string(line1) + ": baseline -P1(0,3)/P1(0,0) = " +
                     std::to_string(c.baseline) + ", expected > 0 (camera 1 right of camera 0)");
  return c;
}

}  // namespace openable::odometry
