// Test and bench shoots through a camera that behaves like a consumer one (capture/camera_processing.h:
// raw sensitivities, white balance, a colour matrix with saturation, a tone curve with a toe and a
// shoulder, JPEG at a chosen quality), of a CC0 environment as scene radiance, with the truth a merge
// should recover, and the error measures the HDR tests and bench/hdr_merge.cpp share.
//
// Views: the lat-long environment resized to (views * width) x (views * width / 2); view 0 is the
// width x height window centred on the brightest texel (a sun when there is one, clamped to the
// map), view v the same window moved v * width to the right (wrapping). A neutral patch (a grey
// card: radiance proportional to 1 / (gains * sensitivity), so the camera records equal codes) sits
// in view 0's lower left corner at the median radiance.
//
// Exposure convention: X = L e k (k: electrons per unit radiance-exposure, metered so that the
// median radiance of view 0 records 18% of the full well at e = 1); brackets e_j = ratio^(j - mid).
// Truth per view: the linear output M (g . s . L) k / full_well per unit exposure, i.e. the merge's
// unit X / e when the curve's X = 1 is the output's clip.
#pragma once

#include "capture/camera_processing.h"
#include "capture/sensor_noise.h"
#include "formats/exr_io.h"
#include "hdr/bracket_set.h"
#include "hdr/merge.h"

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

namespace rsibr::testing {

struct ShootSpec {
  std::string env;  // an environment file (lat-long EXR)
  int width = 320, height = 160, views = 3;
  int brackets = 7;
  double step_ev = 2.0;  // between brackets
  int jpeg_quality = 0;  // 0: PNG (lossless 8-bit codes), else JPEG at this quality
  std::uint64_t seed = 1;
  std::string response = "filmic";
  CameraProcessing processing = realistic_processing();
  double full_well = 2e4, read_noise = 3;  // electrons
  bool neutral_patch = true;

  static CameraProcessing realistic_processing() {
    CameraProcessing p;
    p.sensitivity = Vec3(0.55, 1.0, 0.72);
    p.saturation = 1.3;
    return p;
  }
};

struct Shoot {
  std::vector<BracketSet> views;
  std::vector<cv::Mat> truth;    // per view, CV_32FC3: the merge's X / e for a perfect curve
  std::vector<cv::Mat> clipped;  // per view, CV_8UC1: bit c set where channel c clips in the shortest bracket
  cv::Rect patch;                // the neutral patch (view 0)
  std::vector<double> exposures;
  double k = 1;  // electrons per unit L e
};

inline Shoot shoot(const ShootSpec& s) {
  EnvMap env = read_environment(s.env);
  cv::Mat rgb = env.pixels;
  if (rgb.channels() == 4) cv::cvtColor(rgb, rgb, cv::COLOR_RGBA2RGB);
  rgb.convertTo(rgb, CV_32FC3);
  rgb.forEach<cv::Vec3f>([](cv::Vec3f& p, const int*) {
    for (int c = 0; c < 3; ++c) p[c] = std::isfinite(p[c]) && p[c] > 0 ? p[c] : 0.f;  // DWAB ringing
  });
  const int W = s.views * s.width, H = W / 2;
  cv::Mat big;
  cv::resize(rgb, big, cv::Size(W, H), 0, 0, cv::INTER_AREA);
  cv::Point sun(0, 0);
  float brightest = -1;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const cv::Vec3f p = big.at<cv::Vec3f>(y, x);
      if (p[0] + p[1] + p[2] > brightest) brightest = p[0] + p[1] + p[2], sun = {x, y};
    }
  const int y0 = std::clamp(sun.y - s.height / 2, 0, H - s.height);
  std::vector<cv::Mat> L;
  for (int v = 0; v < s.views; ++v) {
    cv::Mat view(s.height, s.width, CV_32FC3);
    for (int y = 0; y < s.height; ++y)
      for (int x = 0; x < s.width; ++x)
        view.at<cv::Vec3f>(y, x) = big.at<cv::Vec3f>(y0 + y, ((sun.x - s.width / 2 + v * s.width + x) % W + W) % W);
    L.push_back(view);
  }
  std::vector<float> grey;
  for (int y = 0; y < s.height; ++y)
    for (int x = 0; x < s.width; ++x) {
      const cv::Vec3f p = L[0].at<cv::Vec3f>(y, x);
      grey.push_back((p[0] + p[1] + p[2]) / 3);
    }
  std::nth_element(grey.begin(), grey.begin() + long(grey.size() / 2), grey.end());
  const double median = std::max(1e-12, double(grey[grey.size() / 2]));
  Shoot out;
  if (s.neutral_patch) {
    out.patch = cv::Rect(s.width / 16, s.height - s.height / 16 - s.height / 6, s.width / 6, s.height / 6);
    const Vec3 gs = s.processing.gains().cwiseProduct(s.processing.sensitivity);
    const Vec3 card = median * gs.maxCoeff() * gs.cwiseInverse();
    L[0](out.patch).setTo(cv::Scalar(card[0], card[1], card[2]));
  }
  out.k = 0.18 * s.full_well / median;
  const SensorNoise noise{out.k, s.full_well, s.read_noise};
  const CameraResponse response(s.response);
  for (int j = 0; j < s.brackets; ++j) out.exposures.push_back(std::pow(2.0, s.step_ev * (j - (s.brackets - 1) / 2.0)));
  for (int v = 0; v < s.views; ++v) {
    std::vector<cv::Mat> codes;
    for (int j = 0; j < s.brackets; ++j) {
      cv::Mat eight;  // 8-bit images: make_brackets takes the code range from the depth
      camera_bracket(L[std::size_t(v)], out.exposures[std::size_t(j)], noise, s.processing, response, 255,
                     s.jpeg_quality, s.seed, std::uint64_t(1 + 64 * v + j))
          .convertTo(eight, CV_8UC3);
      codes.push_back(eight);
    }
    BracketSet b = make_brackets(codes, out.exposures, {}, s.jpeg_quality > 0);
    out.views.push_back(std::move(b));
    cv::Mat t = linear_output(L[std::size_t(v)], s.processing) * (out.k / s.full_well);
    out.truth.push_back(t);
    // Clipped in the shortest bracket: the white-balanced raw or the matrix output reaches 1.
    const Vec3 g = s.processing.gains();
    const double e0 = out.exposures.front();
    cv::Mat clip(s.height, s.width, CV_8UC1, cv::Scalar(0));
    for (int y = 0; y < s.height; ++y)
      for (int x = 0; x < s.width; ++x) {
        const cv::Vec3f l = L[std::size_t(v)].at<cv::Vec3f>(y, x), o = t.at<cv::Vec3f>(y, x);
        unsigned char bits = 0;
        for (int ch = 0; ch < 3; ++ch)
          if (g[ch] * s.processing.sensitivity[ch] * l[ch] * out.k * e0 / s.full_well >= 1 || o[ch] * e0 >= 1)
            bits |= 1 << ch;
        clip.at<unsigned char>(y, x) = bits;
      }
    out.clipped.push_back(clip);
  }
  return out;
}

// ---- error measures (every method's output is known up to one global factor) ----

// The views side by side, one 8-bit BGR image per bracket: what a merge of single images (OpenCV,
// luminance-hdr, pfstools) sees, so it too gets every view.
inline std::vector<cv::Mat> side_by_side_bgr(const Shoot& sh) {
  std::vector<cv::Mat> stack;
  for (std::size_t j = 0; j < sh.exposures.size(); ++j) {
    std::vector<cv::Mat> row;
    for (const auto& b : sh.views) {
      cv::Mat eight, bgr;
      b.codes[j].convertTo(eight, CV_8UC3);
      cv::cvtColor(eight, bgr, cv::COLOR_RGB2BGR);
      row.push_back(bgr);
    }
    cv::Mat h;
    cv::hconcat(row, h);
    stack.push_back(h);
  }
  return stack;
}

inline double luminance(const cv::Vec3f& v) { return 0.2126 * v[0] + 0.7152 * v[1] + 0.0722 * v[2]; }

// Pixel classes by truth luminance over the unclipped pixels of all views: dark below the 10th
// percentile, bright above the 90th, mid between; clipped: saturated in the shortest bracket;
// excluded: a channel below kGamutFloor of the pixel's luminance (out of, or at the edge of, the
// output gamut, where the camera's matrix output clipped at 0 and no method can recover it).
constexpr double kGamutFloor = 0.02, kColourFloor = 0.05;
enum PixelClass : unsigned char { kExcluded = 0, kDark = 1, kMid = 2, kBright = 3, kClippedClass = 4 };

inline std::vector<cv::Mat> pixel_classes(const Shoot& sh) {
  std::vector<double> lum;
  for (std::size_t v = 0; v < sh.truth.size(); ++v)
    for (int y = 0; y < sh.truth[v].rows; ++y)
      for (int x = 0; x < sh.truth[v].cols; ++x)
        if (!sh.clipped[v].at<unsigned char>(y, x)) lum.push_back(luminance(sh.truth[v].at<cv::Vec3f>(y, x)));
  std::sort(lum.begin(), lum.end());
  const double p10 = lum[lum.size() / 10], p90 = lum[lum.size() * 9 / 10];
  std::vector<cv::Mat> out;
  for (std::size_t v = 0; v < sh.truth.size(); ++v) {
    cv::Mat k(sh.truth[v].size(), CV_8UC1, cv::Scalar(0));
    for (int y = 0; y < k.rows; ++y)
      for (int x = 0; x < k.cols; ++x) {
        const cv::Vec3f t = sh.truth[v].at<cv::Vec3f>(y, x);
        const double l = luminance(t);
        if (sh.clipped[v].at<unsigned char>(y, x))
          k.at<unsigned char>(y, x) = kClippedClass;
        else if (!(t[0] > kGamutFloor * l && t[1] > kGamutFloor * l && t[2] > kGamutFloor * l))
          k.at<unsigned char>(y, x) =
              kExcluded;  // (nearly) outside the output gamut: the camera clipped a channel at 0
        else
          k.at<unsigned char>(y, x) = l < p10 ? kDark : l > p90 ? kBright : kMid;
      }
    out.push_back(k);
  }
  return out;
}

// The global factor: median over mid-tone pixels of truth / estimate luminance.
inline double global_scale(const std::vector<cv::Mat>& est, const Shoot& sh, const std::vector<cv::Mat>& cls) {
  std::vector<double> r;
  for (std::size_t v = 0; v < est.size(); ++v)
    for (int y = 0; y < est[v].rows; ++y)
      for (int x = 0; x < est[v].cols; ++x)
        if (cls[v].at<unsigned char>(y, x) == kMid) {
          const double e = luminance(est[v].at<cv::Vec3f>(y, x));
          if (e > 0 && std::isfinite(e)) r.push_back(luminance(sh.truth[v].at<cv::Vec3f>(y, x)) / e);
        }
  if (r.empty()) return 1;
  std::nth_element(r.begin(), r.begin() + long(r.size() / 2), r.end());
  return r[r.size() / 2];
}

struct ShootErrors {
  double scale = 1;
  double stops[5] = {0, 0, 0, 0, 0};  // RMS log2(scale est / truth) of luminance per class (index PixelClass)
  double colour_stops = 0;            // RMS of log2 of (R/G, B/G) estimate over truth, dark + mid + bright
  double colour_stops_mid = 0;        // the same over mid-tones
  double clipped_at_or_below = 1;     // clipped class: fraction of saturated channels' values <= truth
  double patch_rg = 1, patch_bg = 1;  // the neutral patch's mean R/G and B/G in the estimate
  long non_finite = 0;
};

inline ShootErrors shoot_errors(const std::vector<cv::Mat>& est, const Shoot& sh) {
  const std::vector<cv::Mat> cls = pixel_classes(sh);
  ShootErrors e;
  e.scale = global_scale(est, sh, cls);
  double se[5] = {0, 0, 0, 0, 0}, n[5] = {0, 0, 0, 0, 0}, ce = 0, cn = 0, cem = 0, cnm = 0;
  long below = 0, clipped_values = 0;
  for (std::size_t v = 0; v < est.size(); ++v)
    for (int y = 0; y < est[v].rows; ++y)
      for (int x = 0; x < est[v].cols; ++x) {
        const cv::Vec3f a = est[v].at<cv::Vec3f>(y, x), t = sh.truth[v].at<cv::Vec3f>(y, x);
        const int k = cls[v].at<unsigned char>(y, x);
        bool finite = true;
        for (int c = 0; c < 3; ++c) finite = finite && std::isfinite(a[c]);
        if (!finite) {
          ++e.non_finite;
          continue;
        }
        if (k == kClippedClass) {
          // The lower bound is for the channels that saturated (the others are estimates).
          const int bits = sh.clipped[v].at<unsigned char>(y, x);
          for (int c = 0; c < 3; ++c)
            if (bits & (1 << c)) below += e.scale * a[c] <= t[c], ++clipped_values;
          continue;
        }
        if (k == kExcluded) continue;
        // Tone: the log2 luminance ratio. Colour: log2 of R/G and B/G against the truth's, each
        // channel floored at kColourFloor of the truth luminance (a channel much weaker than the
        // pixel's luminance is mostly noise, in every method; an estimate at or below 0 counts as
        // the floor, not as minus infinity).
        const double lt = luminance(t), f = kColourFloor * lt;
        const double d = std::log2(std::max(1e-3 * lt, e.scale * luminance(a)) / lt);
        se[k] += d * d, n[k] += 1;
        double la[3], ltc[3];
        for (int c = 0; c < 3; ++c) la[c] = std::log2(std::max(0.0, e.scale * a[c]) + f), ltc[c] = std::log2(t[c] + f);
        const double rg = (la[0] - la[1]) - (ltc[0] - ltc[1]);
        const double bg = (la[2] - la[1]) - (ltc[2] - ltc[1]);
        ce += rg * rg + bg * bg, cn += 2;
        if (k == kMid) cem += rg * rg + bg * bg, cnm += 2;
      }
  for (int k = 1; k < 4; ++k) e.stops[k] = std::sqrt(se[k] / std::max(1.0, n[k]));
  e.colour_stops = std::sqrt(ce / std::max(1.0, cn));
  e.colour_stops_mid = std::sqrt(cem / std::max(1.0, cnm));
  e.clipped_at_or_below = clipped_values ? double(below) / double(clipped_values) : 1.0;
  if (sh.patch.area() > 0) {
    // Its interior: JPEG's 4:2:0 chroma and 8x8 blocks carry the surroundings' colour a few pixels in.
    const cv::Rect inner(sh.patch.x + 4, sh.patch.y + 4, sh.patch.width - 8, sh.patch.height - 8);
    const cv::Scalar m = cv::mean(est[0](inner));
    e.patch_rg = m[0] / m[1];
    e.patch_bg = m[2] / m[1];
  }
  return e;
}

// The variance channel's calibration: 1.4826 MAD of (scale est - truth) / (scale sqrt(var)) over the
// unclipped pixels of every channel with var > 0 (1 when the variance is honest).
inline double normalised_spread(const std::vector<MergedImage>& m, const Shoot& sh, double scale) {
  std::vector<double> z;
  const std::vector<cv::Mat> cls = pixel_classes(sh);
  for (std::size_t v = 0; v < m.size(); ++v)
    for (int y = 0; y < m[v].radiance.rows; ++y)
      for (int x = 0; x < m[v].radiance.cols; ++x) {
        const int k = cls[v].at<unsigned char>(y, x);
        if (k == kExcluded || k == kClippedClass || m[v].flags.at<unsigned char>(y, x)) continue;
        const cv::Vec3f a = m[v].radiance.at<cv::Vec3f>(y, x), var = m[v].variance.at<cv::Vec3f>(y, x),
                        t = sh.truth[v].at<cv::Vec3f>(y, x);
        for (int c = 0; c < 3; ++c)
          if (var[c] > 0) z.push_back((scale * a[c] - t[c]) / (scale * std::sqrt(double(var[c]))));
      }
  if (z.empty()) return 0;
  std::nth_element(z.begin(), z.begin() + long(z.size() / 2), z.end());
  const double med = z[z.size() / 2];
  for (double& d : z) d = std::abs(d - med);
  std::nth_element(z.begin(), z.begin() + long(z.size() / 2), z.end());
  return 1.4826 * z[z.size() / 2];
}

}  // namespace rsibr::testing
