#include "compare/map_compare.h"

#include "core/sphere_map.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <stdexcept>

namespace rsibr {
namespace {

std::string part_name(int i) {
  std::ostringstream s;
  s << "view." << std::setw(3) << std::setfill('0') << i;
  return s.str();
}

std::string texel_text(int x, int r) {
  std::ostringstream s;
  s << "(" << x << ", " << r << ")";
  return s.str();
}

std::string size_text(const cv::Mat& m) { return std::to_string(m.cols) + "x" + std::to_string(m.rows); }

// First texel with weight > 0 whose value is not finite, as "(column, row)"; empty when none.
std::string first_non_finite(const cv::Mat& img, const cv::Mat& weight) {
  const int n = img.channels();
  for (int r = 0; r < img.rows; ++r) {
    const float* p = img.ptr<float>(r);
    const float* w = weight.ptr<float>(r);
    for (int x = 0; x < img.cols; ++x) {
      if (!(w[x] > 0)) continue;
      for (int c = 0; c < n; ++c)
        if (!std::isfinite(p[n * x + c])) return texel_text(x, r);
    }
  }
  return "";
}

void check_confidence(const cv::Mat& conf, const std::string& where) {
  for (int r = 0; r < conf.rows; ++r) {
    const float* p = conf.ptr<float>(r);
    for (int x = 0; x < conf.cols; ++x)
      if (!std::isfinite(p[x]) || p[x] < 0)
        throw std::invalid_argument(where + ": confidence at texel " + texel_text(x, r) + " is " +
                                    std::to_string(p[x]) + " (must be finite and >= 0)");
  }
}

double max_weighted(const cv::Mat& img, const cv::Mat& weight) {
  double m = 0;
  for (int r = 0; r < img.rows; ++r) {
    const float* p = img.ptr<float>(r);
    const float* w = weight.ptr<float>(r);
    for (int x = 0; x < img.cols; ++x)
      if (w[x] > 0) m = std::max({m, double(p[3 * x]), double(p[3 * x + 1]), double(p[3 * x + 2])});
  }
  return m;
}

}  // namespace

cv::Mat sphere_map_weight(int width, int height, const cv::Mat& confidence_a, const cv::Mat& confidence_b) {
  cv::Mat w(height, width, CV_32FC1, cv::Scalar(0));
  for (int r = 0; r < height; ++r)
    for (int c = 0; c < width; ++c)
      if (sphere_map::disc_from_pixel(Vec2(c, r), width, height).squaredNorm() < 1.0) w.at<float>(r, c) = 1.f;
  for (const cv::Mat* conf : {&confidence_a, &confidence_b})
    if (!conf->empty()) cv::multiply(w, *conf, w);
  return w;
}

cv::Mat solid_angle_weight(const Layout& layout) {
  const cv::Mat sa = texel_solid_angles(layout);
  cv::Mat w;
  const double count = double(cv::countNonZero(sa > 0));
  sa.convertTo(w, CV_32FC1, count > 0 ? count / (4 * kPi) : 1.0);
  return w;
}

std::vector<std::pair<int, int>> match_views(const MapSet& a, const MapSet& b, const CompareOptions& o) {
  const bool a_smaller = a.views.size() <= b.views.size();
  const MapSet& small = a_smaller ? a : b;
  const MapSet& large = a_smaller ? b : a;
  const std::string& small_name = a_smaller ? o.name_a : o.name_b;
  const std::string& large_name = a_smaller ? o.name_b : o.name_a;
  const double tol = o.view_tolerance_deg * kPi / 180;
  std::vector<std::pair<int, int>> pairs;
  std::vector<int> used(large.views.size(), -1);
  for (std::size_t i = 0; i < small.views.size(); ++i) {
    const MapView& v = small.views[i];
    int best = -1;
    double best_angle = INFINITY;
    for (std::size_t j = 0; j < large.views.size(); ++j) {
      const double ang = angle_between(v.view, large.views[j].view);
      if (ang < best_angle) best_angle = ang, best = int(j);
    }
    std::ostringstream dir;
    dir << std::setprecision(4) << "(" << v.view.x() << ", " << v.view.y() << ", " << v.view.z() << ")";
    if (best < 0 || best_angle > tol) {
      std::ostringstream s;
      s << std::setprecision(3) << small_name << ": " << part_name(int(i)) << " (view " << dir.str()
        << ") has no view in " << large_name << " within " << o.view_tolerance_deg << " degrees (nearest "
        << best_angle * 180 / kPi << " degrees); the sets do not match";
      throw std::invalid_argument(s.str());
    }
    if (used[std::size_t(best)] >= 0)
      throw std::invalid_argument(small_name + ": " + part_name(int(i)) + " and " + part_name(used[std::size_t(best)]) +
                                  " both match " + large_name + "'s " + part_name(best) + "; the sets do not match");
    used[std::size_t(best)] = int(i);
    pairs.emplace_back(a_smaller ? int(i) : best, a_smaller ? best : int(i));
  }
  return pairs;
}

Comparison compare_pairs(std::vector<PairComparison> pairs, const CompareOptions& o) {
  if (pairs.empty()) throw std::invalid_argument(o.name_a + ": nothing to compare");
  double sum_b = 0, sum_a = 0, weight = 0, peak = 0;
  std::vector<std::pair<double, double>> levels;  // (B's channel mean, weight) per weighted texel
  for (const PairComparison& p : pairs) {
    const WeightedImages& im = p.images;
    if (im.a.size() != im.b.size())
      throw std::invalid_argument(o.name_a + ": " + p.name + " is " + size_text(im.a) + " but " + o.name_b + "'s is " +
                                  size_text(im.b) + "; resample one of them first");
    if (im.a.type() != CV_32FC3 || im.b.type() != CV_32FC3 || im.weight.type() != CV_32FC1 ||
        im.weight.size() != im.a.size())
      throw std::invalid_argument(o.name_a + ": " + p.name +
                                  ": images must be RGB float with a float weight of their size");
    check_confidence(im.weight, o.name_a + ": " + p.name + " weight");
    if (const std::string at = first_non_finite(im.a, im.weight); !at.empty())
      throw std::invalid_argument(o.name_a + ": " + p.name + " has a non-finite value at texel " + at);
    if (const std::string at = first_non_finite(im.b, im.weight); !at.empty())
      throw std::invalid_argument(o.name_b + ": " + p.name + " has a non-finite value at texel " + at);
    for (int r = 0; r < im.a.rows; ++r) {
      const float* pa = im.a.ptr<float>(r);
      const float* pb = im.b.ptr<float>(r);
      const float* pw = im.weight.ptr<float>(r);
      for (int x = 0; x < im.a.cols; ++x) {
        if (!(pw[x] > 0)) continue;
        const double w = pw[x];  // double: a weight > 1 times a float near its maximum stays finite
        weight += w;
        levels.emplace_back(std::max(0.0, (double(pb[3 * x]) + pb[3 * x + 1] + pb[3 * x + 2]) / 3), w);
        for (int c = 0; c < 3; ++c) {
          sum_a += w * std::max(0.0, double(pa[3 * x + c]));
          sum_b += w * std::max(0.0, double(pb[3 * x + c]));
        }
      }
    }
    peak = std::max(peak, max_weighted(im.b, im.weight));
  }
  if (!(weight > 0))
    throw std::invalid_argument(o.name_a + ": no texel has a non-zero weight (every confidence is zero?)");
  if (!(o.log_epsilon_fraction > 0)) throw std::invalid_argument("the log epsilon fraction must be positive");

  Comparison out;
  // eps scales with B's typical level: its weighted median (a sun does not move it), else B's
  // mean, else A's, else 1.
  std::sort(levels.begin(), levels.end());
  double median = 0, run = 0;
  for (const auto& [level, w] : levels)
    if ((run += w) >= 0.5 * weight) {
      median = level;
      break;
    }
  const double level = median > 0 ? median : sum_b > 0 ? sum_b / (3 * weight) : sum_a > 0 ? sum_a / (3 * weight) : 1.0;
  out.settings.log_epsilon = o.log_epsilon_fraction * level;
  if (o.psnr_peak > 0) {
    out.settings.psnr_peak = o.psnr_peak;
  } else {
    if (!(peak > 0))
      for (const PairComparison& p : pairs) peak = std::max(peak, max_weighted(p.images.a, p.images.weight));
    out.settings.psnr_peak = peak > 0 ? peak : 1.0;
  }

  ErrorSums before, after;
  for (PairComparison& p : pairs) {
    const ErrorSums s = error_sums(p.images.a, p.images.b, p.images.weight, out.settings);
    try {
      p.before = error_metrics(s, out.settings);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(o.name_a + " against " + o.name_b + ": " + p.name + ": " + e.what());
    }
    before.merge(s);
  }
  out.before = error_metrics(before, out.settings);
  if (o.fit) {
    std::vector<WeightedImages> images;
    for (const PairComparison& p : pairs) images.push_back(p.images);
    GainFitOptions fo = o.fit_options;
    fo.log_epsilon = out.settings.log_epsilon;
    out.fit = fit_gains(images, fo);
  }
  for (PairComparison& p : pairs) {
    if (!out.fit) {
      p.after = p.before;
      continue;
    }
    const ErrorSums s = error_sums(p.images.a, p.images.b, p.images.weight, out.settings, out.fit->gains);
    p.after = error_metrics(s, out.settings);
    after.merge(s);
  }
  out.after = out.fit ? error_metrics(after, out.settings) : out.before;
  out.pairs = std::move(pairs);
  return out;
}

Reframed reframe(const MapView& view, const Mat3& world_from_view) {
  const int w = view.rgb.cols, h = view.rgb.rows;
  // Texel p of the target frame has normal n = world_from_view g_normal(p); in the source frame
  // n_s = source_from_world n, found at the disc point (n_s.x, n_s.y) when n_s.z >= 0.
  const Mat3 source_from_target = view.world_from_view.transpose() * world_from_view;
  cv::Mat map_x(h, w, CV_32FC1), map_y(h, w, CV_32FC1);
  for (int r = 0; r < h; ++r)
    for (int c = 0; c < w; ++c) {
      const Vec2 xy = sphere_map::disc_from_pixel(Vec2(c, r), w, h);
      Vec2 src(-10, -10);  // outside the image: constant border
      if (xy.squaredNorm() < 1.0) {
        const Vec3 n = source_from_target * sphere_map::g_normal(xy);
        if (n.z() >= 0) src = sphere_map::pixel_from_disc(Vec2(n.x(), n.y()), w, h);
      }
      map_x.at<float>(r, c) = float(src.x());
      map_y.at<float>(r, c) = float(src.y());
    }
  Reframed out;
  cv::remap(view.rgb, out.rgb, map_x, map_y, cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(0, 0, 0));
  if (!view.confidence.empty())
    cv::remap(view.confidence, out.confidence, map_x, map_y, cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(0));
  // Valid where every bilinear tap lies on a texel of the source's disc.
  cv::Mat covered;
  cv::remap(sphere_map_weight(w, h), covered, map_x, map_y, cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(0));
  out.valid = cv::Mat(h, w, CV_32FC1);
  for (int r = 0; r < h; ++r)
    for (int c = 0; c < w; ++c) out.valid.at<float>(r, c) = covered.at<float>(r, c) > 0.9999f ? 1.f : 0.f;
  return out;
}

Comparison compare_map_sets(const MapSet& a, const MapSet& b, const CompareOptions& o) {
  if (a.views.empty() || b.views.empty()) throw std::invalid_argument(o.name_a + ": a map set without views");
  if (a.width() != b.width() || a.height() != b.height())
    throw std::invalid_argument(
        o.name_a + ": maps are " + std::to_string(a.width()) + "x" + std::to_string(a.height()) + " but " + o.name_b +
        "'s are " + std::to_string(b.width()) + "x" + std::to_string(b.height()) + "; the sizes must match");
  if (a.views.front().albedo.empty() != b.views.front().albedo.empty() ||
      a.views.front().albedo != b.views.front().albedo)
    throw std::invalid_argument(o.name_a + ": albedo normalisation differs from " + o.name_b +
                                "'s (rsibr.albedo); the texels do not hold the same quantity");
  std::vector<PairComparison> pairs;
  for (const auto& [i, j] : match_views(a, b, o)) {
    const MapView& va = a.views[std::size_t(i)];
    const MapView& vb = b.views[std::size_t(j)];
    PairComparison p;
    p.name = part_name(i);
    p.index_a = i;
    p.index_b = j;
    p.view = va.view;
    p.angle_deg = angle_between(va.view, vb.view) * 180 / kPi;
    if (!va.confidence.empty()) check_confidence(va.confidence, o.name_a + ": " + part_name(i) + " confidence");
    if (!vb.confidence.empty()) check_confidence(vb.confidence, o.name_b + ": " + part_name(j) + " confidence");
    // Frames that differ (a captured view's roll about its axis, or the small tilt of views paired
    // within the tolerance): B is resampled into A's frame; otherwise texels are compared as stored.
    const Mat3 b_from_a = vb.world_from_view.transpose() * va.world_from_view;
    p.frame_angle_deg = Eigen::AngleAxisd(b_from_a).angle() * 180 / kPi;
    if ((vb.world_from_view - va.world_from_view).cwiseAbs().maxCoeff() > 1e-6) {
      const Reframed rb = reframe(vb, va.world_from_view);
      p.b_resampled = true;
      cv::Mat weight = sphere_map_weight(va.rgb.cols, va.rgb.rows, va.confidence, rb.confidence);
      cv::multiply(weight, rb.valid, weight);
      p.images = {va.rgb, rb.rgb, weight};
    } else {
      p.images = {va.rgb, vb.rgb, sphere_map_weight(va.rgb.cols, va.rgb.rows, va.confidence, vb.confidence)};
    }
    pairs.push_back(std::move(p));
  }
  return compare_pairs(std::move(pairs), o);
}

Comparison compare_environments(const EnvMap& a, const EnvMap& b, const CompareOptions& o) {
  if (a.layout.kind() != b.layout.kind())
    throw std::invalid_argument(o.name_a + ": layout " + to_string(a.layout.kind()) + " but " + o.name_b + " is " +
                                to_string(b.layout.kind()) + "; convert one (rsibr convert --to)");
  if (a.pixels.size() != b.pixels.size())
    throw std::invalid_argument(o.name_a + ": " + size_text(a.pixels) + " but " + o.name_b + " is " +
                                size_text(b.pixels) + "; the sizes must match (rsibr convert --size)");
  if (a.pixels.type() != CV_32FC3 || b.pixels.type() != CV_32FC3)
    throw std::invalid_argument(o.name_a + ": environments must have three channels (R, G, B)");
  PairComparison p;
  p.name = "environment";
  p.images = {a.pixels, b.pixels,
              a.layout.kind() == LayoutKind::Sphere ? sphere_map_weight(a.pixels.cols, a.pixels.rows)
                                                    : solid_angle_weight(a.layout)};
  std::vector<PairComparison> pairs;
  pairs.push_back(std::move(p));
  return compare_pairs(std::move(pairs), o);
}

}  // namespace rsibr
