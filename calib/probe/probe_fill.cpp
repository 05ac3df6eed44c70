#include "calib/probe/probe_fill.h"

#include "core/luminance.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace rsibr {

namespace {

// One pyramid level, periodic in x: the mean log colour of the trusted texels under each texel
// (replaced by the pulled colour), their weight (solid angle x trusted), and the weight a fully
// trusted texel would have (alpha = wt / full). Means, not sums, keep float's precision at every level.
struct Level {
  int w = 0, h = 0;
  std::vector<float> p, wt, full;  // p: 3 per texel
};

Level coarser(const Level& f) {
  Level c;
  c.w = (f.w + 1) / 2, c.h = (f.h + 1) / 2;
  c.p.assign(std::size_t(c.w) * c.h * 3, 0.0f);
  c.wt.assign(std::size_t(c.w) * c.h, 0.0f);
  c.full.assign(std::size_t(c.w) * c.h, 0.0f);
  for (int y = 0; y < c.h; ++y)
    for (int x = 0; x < c.w; ++x) {
      double sum[3] = {0, 0, 0}, wt = 0, full = 0;
      for (int dy = 0; dy < 2 && 2 * y + dy < f.h; ++dy)
        for (int dx = 0; dx < 2 && 2 * x + dx < f.w; ++dx) {
          const std::size_t i = std::size_t(2 * y + dy) * f.w + 2 * x + dx;
          wt += f.wt[i], full += f.full[i];
          for (int k = 0; k < 3; ++k) sum[k] += double(f.wt[i]) * f.p[3 * i + k];
        }
      const std::size_t j = std::size_t(y) * c.w + x;
      c.wt[j] = float(wt), c.full[j] = float(full);
      if (wt > 0)
        for (int k = 0; k < 3; ++k) c.p[3 * j + k] = float(sum[k] / wt);
    }
  return c;
}

// Bilinear lookup of a pulled level's colour at texel (x, y) of the level below (a coarse texel i
// covers fine texels 2i and 2i + 1); x wraps around, y is clamped.
void upsampled(const Level& c, int x, int y, float out[3]) {
  const double cx = (x + 0.5) / 2 - 0.5, cy = std::clamp((y + 0.5) / 2 - 0.5, 0.0, double(c.h - 1));
  const int fx0 = int(std::floor(cx)), y0 = int(cy), y1 = std::min(y0 + 1, c.h - 1);
  const int x0 = (fx0 % c.w + c.w) % c.w, x1 = (x0 + 1) % c.w;
  const double fx = cx - fx0, fy = cy - y0;
  for (int k = 0; k < 3; ++k) {
    auto at = [&](int xx, int yy) { return double(c.p[3 * (std::size_t(yy) * c.w + xx) + k]); };
    out[k] =
        float((1 - fy) * ((1 - fx) * at(x0, y0) + fx * at(x1, y0)) + fy * ((1 - fx) * at(x0, y1) + fx * at(x1, y1)));
  }
}

}  // namespace

double fill_unseen(EnvMap& env, const cv::Mat& trusted, const cv::Mat& fill, double floor) {
  if (env.layout.kind() != LayoutKind::LatLong || env.pixels.type() != CV_32FC3)
    throw std::invalid_argument("fill_unseen: a 3-channel lat-long map is expected");
  const int W = env.pixels.cols, H = env.pixels.rows;
  for (const cv::Mat* m : {&trusted, &fill})
    if (m->type() != CV_8UC1 || m->rows != H || m->cols != W)
      throw std::invalid_argument("fill_unseen: masks must be 8-bit, one channel, of the map's size");
  const int to_fill = cv::countNonZero(fill);
  if (to_fill == 0) return 0.0;
  // The floor: `floor` x the trusted texels' median luminance (log of 0 is no colour).
  std::vector<float> lum;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x)
      if (trusted.at<uchar>(y, x)) {
        const cv::Vec3f c = env.pixels.at<cv::Vec3f>(y, x);
        lum.push_back(float(luminance(Vec3(c[0], c[1], c[2]))));
      }
  if (lum.empty()) throw std::invalid_argument("fill_unseen: no trusted texel to fill from");
  std::nth_element(lum.begin(), lum.begin() + long(lum.size() / 2), lum.end());
  const double lo = std::max(double(lum[lum.size() / 2]) * floor, 1e-30);

  // Columns 0 and W - 1 are one direction: the pyramid holds the P = W - 1 distinct columns,
  // periodic in x, so a hole across the seam sees both of its sides.
  const int P = W - 1;
  Level base;
  base.w = P, base.h = H;
  base.p.assign(std::size_t(P) * H * 3, 0.0f);
  base.wt.assign(std::size_t(P) * H, 0.0f);
  base.full.assign(std::size_t(P) * H, 0.0f);
  for (int y = 0; y < H; ++y) {
    const double a =
        env.layout.texel_solid_angle(1, y);  // an inner column's (the seam's two halves are one texel here)
    for (int x = 0; x < P; ++x) {
      const std::size_t i = std::size_t(y) * P + x;
      base.full[i] = float(a);
      if (!trusted.at<uchar>(y, x)) continue;
      const cv::Vec3f c = env.pixels.at<cv::Vec3f>(y, x);
      base.wt[i] = float(a);
      for (int k = 0; k < 3; ++k) base.p[3 * i + k] = float(std::log(std::max(double(c[k]), lo)));
    }
  }
  std::vector<Level> levels;
  levels.push_back(std::move(base));
  while (levels.back().w > 1 || levels.back().h > 1) levels.push_back(coarser(levels.back()));

  // Pull: the top is the trusted texels' mean; each finer level blends its own mean with the coarser
  // level's by its known share (p becomes the level's colour).
  for (std::size_t n = levels.size(); n-- > 0;) {
    Level& l = levels[n];
    for (int y = 0; y < l.h; ++y)
      for (int x = 0; x < l.w; ++x) {
        const std::size_t i = std::size_t(y) * l.w + x;
        // The top level's colour is its own mean (something is trusted, so its weight is not 0).
        const float alpha = n + 1 == levels.size() ? 1.0f
                            : l.full[i] > 0        ? std::clamp(l.wt[i] / l.full[i], 0.0f, 1.0f)
                                                   : 0.0f;
        float up[3] = {0, 0, 0};
        if (n + 1 < levels.size()) upsampled(levels[n + 1], x, y, up);
        for (int k = 0; k < 3; ++k) {
          l.p[3 * i + k] = alpha * l.p[3 * i + k] + (1 - alpha) * up[k];
        }
      }
  }

  const Level& l0 = levels.front();
  double filled = 0, total = 0;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const double a = env.layout.texel_solid_angle(x, y);
      total += a;
      if (!fill.at<uchar>(y, x)) continue;
      filled += a;
      const std::size_t i = std::size_t(y) * P + x % P;
      env.pixels.at<cv::Vec3f>(y, x) =
          cv::Vec3f(std::exp(l0.p[3 * i]), std::exp(l0.p[3 * i + 1]), std::exp(l0.p[3 * i + 2]));
    }
  // A pole row is one direction: its filled texels take their mean.
  for (const int y : {0, H - 1}) {
    cv::Vec3d sum(0, 0, 0);
    int n = 0;
    for (int x = 0; x < W; ++x)
      if (fill.at<uchar>(y, x)) sum += cv::Vec3d(env.pixels.at<cv::Vec3f>(y, x)), ++n;
    if (n == 0) continue;
    for (int x = 0; x < W; ++x)
      if (fill.at<uchar>(y, x)) env.pixels.at<cv::Vec3f>(y, x) = cv::Vec3f(sum / n);
  }
  return total > 0 ? filled / total : 0.0;
}

}  // namespace rsibr
