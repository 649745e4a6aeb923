#include "OpenABLE/image/robustness.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace openable {

namespace {

// The pixels x in [x0, x1) of row y whose eight windows all lie inside the image (r <= y,
// y + r < h, r <= x, x + r < w): every window is a full box, so its sum is four reads of the
// integral image `sum` at fixed offsets and its size a constant. The same operations as the
// general case of SideWindowLayer (box sums in the same order, a division by the count, the
// first window within 1e-9 of the smallest |q_n - p|), so every output is the same double;
// written without branches over straight rows so that the compiler vectorises it, and compiled
// for AVX-512 and AVX2 too, chosen at load time (GCC's target_clones).
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
__attribute__((target_clones("avx512f", "avx2", "default")))
#endif
void InteriorRow(const double* __restrict in, double* __restrict out,
                 const double* __restrict top,     // integral row y - r
                 const double* __restrict centre,  // integral row y
                 const double* __restrict below,   // integral row y + 1
                 const double* __restrict bottom,  // integral row y + r + 1
                 int r, int x0, int x1) {
  const double half = static_cast<double>((r + 1) * (2 * r + 1));
  const double quarter = static_cast<double>((r + 1) * (r + 1));
  for (int x = x0; x < x1; ++x) {
    const int a = x - r, b = x, c = x + 1, d = x + r + 1;  // integral columns
    const double p = in[x];
    const double q[8] = {(below[d] - top[d] - below[a] + top[a]) / half,              // U
                         (bottom[d] - centre[d] - bottom[a] + centre[a]) / half,      // D
                         (bottom[c] - top[c] - bottom[a] + top[a]) / half,            // L
                         (bottom[d] - top[d] - bottom[b] + top[b]) / half,            // R
                         (below[c] - top[c] - below[a] + top[a]) / quarter,           // NW
                         (below[d] - top[d] - below[b] + top[b]) / quarter,           // NE
                         (bottom[c] - centre[c] - bottom[a] + centre[a]) / quarter,   // SW
                         (bottom[d] - centre[d] - bottom[b] + centre[b]) / quarter};  // SE
    double best = std::abs(q[0] - p), chosen = q[0];
    for (int n = 1; n < 8; ++n) {
      const double dist = std::abs(q[n] - p);
      const bool closer = dist < best - 1e-9;
      best = closer ? dist : best;
      chosen = closer ? q[n] : chosen;
    }
    out[x] = chosen;
  }
}

}  // namespace

cv::Mat1d SideWindowLayer(const cv::Mat1d& image, int r) {
  if (r < 1) throw std::logic_error("SideWindowLayer: radius below 1");
  const int h = image.rows, w = image.cols;
  cv::Mat1d sum;
  cv::integral(image, sum, CV_64F);  // (h + 1) x (w + 1)
  cv::Mat1d out(h, w);
  // Sum and count of rows [y0, y1], columns [x0, x1] clipped to the image.
  auto box = [&](int y0, int y1, int x0, int x1) {
    y0 = std::max(y0, 0), x0 = std::max(x0, 0);
    y1 = std::min(y1, h - 1), x1 = std::min(x1, w - 1);
    const double s = sum(y1 + 1, x1 + 1) - sum(y0, x1 + 1) - sum(y1 + 1, x0) + sum(y0, x0);
    return s / ((y1 - y0 + 1) * (x1 - x0 + 1));
  };
  // Pixels near the border, whose windows are clipped.
  auto general = [&](int y, int x) {
    const double p = image(y, x);
    // Order of Eq. 6: U, D, L, R, NW, NE, SW, SE.
    const double q[8] = {box(y - r, y, x - r, x + r), box(y, y + r, x - r, x + r),
                         box(y - r, y + r, x - r, x), box(y - r, y + r, x, x + r),
                         box(y - r, y, x - r, x),     box(y - r, y, x, x + r),
                         box(y, y + r, x - r, x),     box(y, y + r, x, x + r)};
    int s = 0;
    double best = std::abs(q[0] - p);
    for (int n = 1; n < 8; ++n) {
      const double d = std::abs(q[n] - p);
      if (d < best - 1e-9) best = d, s = n;
    }
    out(y, x) = q[s];
  };
  const int x0 = std::min(r, w), x1 = std::max(x0, w - r);  // interior columns [x0, x1)
  for (int y = 0; y < h; ++y) {
    if (y < r || y + r >= h) {
      for (int x = 0; x < w; ++x) general(y, x);
      continue;
    }
    for (int x = 0; x < x0; ++x) general(y, x);
    InteriorRow(image.ptr<double>(y), out.ptr<double>(y), sum.ptr<double>(y - r),
                sum.ptr<double>(y), sum.ptr<double>(y + 1), sum.ptr<double>(y + r + 1), r, x0, x1);
    for (int x = x1; x < w; ++x) general(y, x);
  }
  return out;
}

cv::Mat SideWindowFusion(const cv::Mat& image, const std::vector<int>& radii) {
  if (image.type() != CV_8UC1 && image.type() != CV_8UC2)
    throw std::logic_error("SideWindowFusion: expected CV_8UC1 or CV_8UC2, got " +
                           cv::typeToString(image.type()));
  if (radii.empty()) return image.clone();
  cv::Mat grey;
  if (image.channels() == 2) {
    cv::extractChannel(image, grey, 0);
  } else {
    grey = image;
  }
  cv::Mat1d cur;
  grey.convertTo(cur, CV_64F);
  for (int r : radii) cur = SideWindowLayer(cur, r);
  cv::Mat1b fused(cur.size());
  for (int y = 0; y < cur.rows; ++y)
    for (int x = 0; x < cur.cols; ++x)
      fused(y, x) = cv::saturate_cast<uchar>(std::floor(cur(y, x) + 0.5));
  if (image.channels() == 1) return fused;
  cv::Mat out = image.clone();
  cv::insertChannel(fused, out, 0);
  return out;
}

uint64_t NoiseState(int seed, int stream, int frame) {
  auto mix = [](uint64_t z) {  // splitmix64's finaliser
    z += 0x9E3779B97F4A7C15ull;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  };
  uint64_t z = mix(static_cast<uint64_t>(static_cast<uint32_t>(seed)));
  z = mix(z ^ static_cast<uint64_t>(static_cast<uint32_t>(stream)));
  z = mix(z ^ static_cast<uint64_t>(static_cast<uint32_t>(frame)));
  return z == 0 ? 1 : z;  // cv::RNG replaces a zero state
}

cv::Mat AddNoise(const cv::Mat& frame, const NoiseOptions& o, uint64_t state) {
  const int type = frame.type();
  if (type != CV_32FC1 && type != CV_32FC2 && type != CV_32FC3)
    throw std::logic_error("AddNoise: expected CV_32FC1, C2 or C3, got " + cv::typeToString(type));
  cv::Mat out = frame.clone();
  // Channels that are intensities: all but a stereo frame's disparity (channel 1).
  const int cn = frame.channels(), noisy = cn == 2 ? 1 : cn;
  cv::RNG rng(state);
  const double sd = std::sqrt(std::max(0.0, o.gaussian));
  const float gain = static_cast<float>(1.0 + o.overexposure);
  for (int y = 0; y < out.rows; ++y) {
    float* row = out.ptr<float>(y);
    for (int x = 0; x < out.cols; ++x) {
      float* px = row + x * cn;
      for (int c = 0; c < noisy; ++c) {
        float v = px[c];
        if (o.overexposure > 0) v *= gain;
        if (sd > 0) v += static_cast<float>(rng.gaussian(sd));
        px[c] = std::min(1.f, std::max(0.f, v));
      }
      if (o.salt_pepper > 0 && rng.uniform(0.0, 1.0) < o.salt_pepper) {
        const float v = rng.uniform(0, 2) == 0 ? 0.f : 1.f;
        for (int c = 0; c < noisy; ++c) px[c] = v;
      }
    }
  }
  return out;
}

cv::Mat MakeNightLike(const cv::Mat& frame, const NightOptions& o, uint64_t state) {
  const int type = frame.type();
  if (type != CV_32FC1 && type != CV_32FC3)
    throw std::logic_error("MakeNightLike: expected CV_32FC1 or CV_32FC3, got " +
                           cv::typeToString(type));
  cv::RNG rng(state);
  const int w = frame.cols, h = frame.rows, cn = frame.channels();
  // 1. Viewpoint: scale >= 1 so that the reflected border stays small.
  const double scale = 1.0 + rng.uniform(0.0, o.zoom);
  const double angle = rng.uniform(-o.rotation, o.rotation);
  const double dx = rng.uniform(-o.shift, o.shift) * w, dy = rng.uniform(-o.shift, o.shift) * h;
  cv::Mat m = cv::getRotationMatrix2D(cv::Point2f(w / 2.0f, h / 2.0f), angle, scale);
  m.at<double>(0, 2) += dx;
  m.at<double>(1, 2) += dy;
  cv::Mat moved;
  cv::warpAffine(frame, moved, m, frame.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT_101);
  // 2-4. Light field, tone curve, colour cast.
  const double gains[3] = {o.gain_b, o.gain_g, o.gain_r};
  cv::Mat out(frame.size(), type);
  double total = 0;
  for (int y = 0; y < h; ++y) {
    const double top = o.sky_height * h;  // t: 1 above top / 2, 0 below top
    const double t = top > 0 ? std::min(1.0, std::max(0.0, 2.0 * (1.0 - y / top))) : 0.0;
    const float* in = moved.ptr<float>(y);
    float* px = out.ptr<float>(y);
    for (int x = 0; x < w; ++x) {
      double u = w > 1 ? static_cast<double>(x) / (w - 1) : 1.0;
      if (o.from_left) u = 1.0 - u;
      const double light = o.ambient + (1.0 - o.ambient) * ((1.0 - o.side) + o.side * u);
      for (int c = 0; c < cn; ++c) {
        const double day = std::min(1.0, std::max(0.0, static_cast<double>(in[x * cn + c])));
        const double sky = 1.0 - (1.0 - o.sky_floor) * t * day;
        double v = std::pow(day * light * sky, o.gamma);
        if (cn == 3) v *= gains[c];
        px[x * cn + c] = static_cast<float>(v);
        total += v;
      }
    }
  }
  // 5-7. Automatic gain, noise, glare, clipping.
  const double mean = total / (static_cast<double>(w) * h * cn);
  const double gain = mean > 1e-12 ? o.target_mean / mean : 1.0;
  const double floor = o.glare * o.target_mean;
  for (int y = 0; y < h; ++y) {
    float* px = out.ptr<float>(y);
    for (int i = 0; i < w * cn; ++i) {
      const double v = px[i] * gain;
      const double sd = std::sqrt(o.shot * o.shot * v / o.target_mean + o.read * o.read);
      const double noisy = v + rng.gaussian(1.0) * sd;
      px[i] = static_cast<float>(std::min(1.0, std::max(0.0, (noisy + floor) / (1.0 + o.glare))));
    }
  }
  return out;
}

}  // namespace openable
