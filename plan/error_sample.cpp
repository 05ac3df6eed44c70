#include "plan/error_sample.h"

#include "bake/albedo_table.h"
#include "core/albedo_normalisation.h"
#include "core/sphere_map.h"
#include "core/stopwatch.h"
#include "runtime/blend_engine.h"
#include "runtime/warp.h"

#include <Eigen/Geometry>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <stdexcept>

namespace rsibr {
namespace {

// Counter-based uniform numbers in [0, 1) (SplitMix64 of the key): the same on every platform.
double uniform(std::uint64_t seed, std::uint64_t index) {
  return double(integrator_detail::mix64(seed * 0x9E3779B97F4A7C15ull + index) >> 11) * 0x1.0p-53;
}

Vec2 disc_point(int texel, int size) {
  return sphere_map::disc_from_pixel(Vec2(texel % size, texel / size), size, size);
}

// Whether texel t of a size^2 map is in the disc with normal z >= min_cos (z^2 = 1 - |xy|^2).
bool in_domain(int t, int size, double min_cos) {
  const double r2 = disc_point(t, size).squaredNorm();
  return r2 < 1.0 && 1.0 - r2 >= min_cos * min_cos;
}

}  // namespace

long long disc_texel_count(int size, double min_cos) {
  long long n = 0;
  for (int t = 0; t < size * size; ++t) n += in_domain(t, size, min_cos);
  return n;
}

ErrorSample::ErrorSample(int views, int texels, int size, std::uint64_t seed, double min_cos)
    : ErrorSample(views, texels, size, seed, nullptr, min_cos) {}

ErrorSample::ErrorSample(int views, int texels, int size, std::uint64_t seed, const TexelGuide& guide, double min_cos)
    : ErrorSample(views, texels, size, seed, &guide, min_cos) {}

ErrorSample::ErrorSample(int views, int texels, int size, std::uint64_t seed, const TexelGuide* guide, double min_cos)
    : size_(size), guided_(guide != nullptr) {
  if (views < 1 || texels < 1 || size < 1)
    throw std::invalid_argument("error sample: needs at least one view, one texel and a size >= 1");
  if (!(min_cos >= 0 && min_cos < 1)) throw std::invalid_argument("error sample: min_cos must lie in [0, 1)");
  std::vector<int> disc;
  for (int t = 0; t < size * size; ++t)
    if (in_domain(t, size, min_cos)) disc.push_back(t);
  if (!guide && int(disc.size()) < texels)
    throw std::invalid_argument("error sample: a " + std::to_string(size) + "^2 disc has " +
                                std::to_string(disc.size()) + " texels, fewer than " + std::to_string(texels));
  if (disc.empty()) throw std::invalid_argument("error sample: the disc holds no texel at this size");
  std::uint64_t draw = 0;
  // The views: a Fibonacci lattice of `views` directions under one uniformly random rotation (from a
  // uniform unit quaternion, Shoemake's method). Each view is uniform on the sphere, and together
  // they are spread evenly, which takes out most of the between-view scatter of an error estimate.
  const double u1 = uniform(seed, draw++), u2 = uniform(seed, draw++), u3 = uniform(seed, draw++);
  const Eigen::Quaterniond q(std::sqrt(u1) * std::cos(2.0 * kPi * u3), std::sqrt(1.0 - u1) * std::sin(2.0 * kPi * u2),
                             std::sqrt(1.0 - u1) * std::cos(2.0 * kPi * u2), std::sqrt(u1) * std::sin(2.0 * kPi * u3));
  const Mat3 rotation = q.normalized().toRotationMatrix();
  const double golden = kPi * (3.0 - std::sqrt(5.0));
  for (int k = 0; k < views; ++k) {
    const double z = 1.0 - (2.0 * k + 1.0) / views, phi = golden * k;
    const double s = std::sqrt(std::max(0.0, 1.0 - z * z));
    const Vec3 v = (rotation * Vec3(s * std::cos(phi), s * std::sin(phi), z)).normalized();
    views_.push_back(v);
    frames_.push_back(world_from_view_for(v));
    std::vector<int> picked;
    std::vector<double> weights;
    if (!guide) {
      // `texels` distinct disc texels: a partial Fisher-Yates shuffle.
      std::vector<int> pool = disc;
      for (int i = 0; i < texels; ++i) {
        const std::size_t j =
            std::size_t(i) + std::size_t(uniform(seed, draw++) * double(pool.size() - std::size_t(i)));
        std::swap(pool[std::size_t(i)], pool[std::min(j, pool.size() - 1)]);
        picked.push_back(pool[std::size_t(i)]);
      }
      std::sort(picked.begin(), picked.end());
      weights.assign(picked.size(), 1.0);
    } else {
      const cv::Mat q = (*guide)(k, v, frames_.back());
      if (q.empty() || q.type() != CV_32FC1 || q.rows != q.cols)
        throw std::invalid_argument("error sample: a guide must be a square single-channel float map");
      cv::Mat qs;
      if (q.rows == size)
        qs = q;
      else
        cv::resize(q, qs, cv::Size(size, size), 0, 0, cv::INTER_LINEAR);
      std::vector<double> p(disc.size());
      double total = 0;
      for (std::size_t i = 0; i < disc.size(); ++i) {
        const double qi = qs.at<float>(disc[i] / size, disc[i] % size);
        if (!(qi >= 0) || !std::isfinite(qi))
          throw std::invalid_argument("error sample: a guide holds a negative or non-finite importance");
        p[i] = qi;
        total += qi;
      }
      // The defensive mixture; a guide that is 0 everywhere leaves the uniform draw.
      const double M = double(disc.size()), a = total > 0 ? kGuideShare : 0.0;
      std::vector<double> cdf(disc.size());
      double run = 0;
      for (std::size_t i = 0; i < disc.size(); ++i) {
        p[i] = (1.0 - a) / M + (total > 0 ? a * p[i] / total : 0.0);
        run += p[i];
        cdf[i] = run;
      }
      std::map<std::size_t, int> counts;
      for (int i = 0; i < texels; ++i) {
        const double u = uniform(seed, draw++) * run;
        const std::size_t j = std::size_t(std::upper_bound(cdf.begin(), cdf.end(), u) - cdf.begin());
        ++counts[std::min(j, disc.size() - 1)];
      }
      for (const auto& [j, c] : counts) {  // ascending, since disc is
        picked.push_back(disc[j]);
        weights.push_back(double(c) / (p[j] * M));
      }
    }
    texels_.push_back(std::move(picked));
    weights_.push_back(std::move(weights));
  }
}

Vec3 ErrorSample::normal(int k, int texel) const {
  return (frame(k) * sphere_map::g_normal(disc_point(texel, size_))).normalized();
}

cv::Mat ErrorSample::mask(int k) const {
  cv::Mat m(size_, size_, CV_8UC1, cv::Scalar(0));
  for (int t : texels(k)) m.at<unsigned char>(t / size_, t % size_) = 255;
  return m;
}

ErrorSample ErrorSample::views(int first, int last) const {
  if (!(0 <= first && first < last && last <= view_count()))
    throw std::invalid_argument("error sample: views [" + std::to_string(first) + ", " + std::to_string(last) +
                                ") are not a part of the sample's " + std::to_string(view_count()));
  ErrorSample s;
  s.size_ = size_;
  s.guided_ = guided_;
  s.views_.assign(views_.begin() + first, views_.begin() + last);
  s.frames_.assign(frames_.begin() + first, frames_.begin() + last);
  s.texels_.assign(texels_.begin() + first, texels_.begin() + last);
  s.weights_.assign(weights_.begin() + first, weights_.begin() + last);
  return s;
}

int ErrorSample::count() const {
  int n = 0;
  for (const auto& t : texels_) n += int(t.size());
  return n;
}

std::vector<Vec3> direct_values(const Integrator& integrator, const Brdf& brdf, const IntegratorOptions& options,
                                const ErrorSample& sample, double* seconds) {
  std::vector<Vec3> out;
  out.reserve(std::size_t(sample.count()));
  double total = 0;
  for (int k = 0; k < sample.view_count(); ++k) {
    IntegratorOptions o = options;
    o.texel_mask = sample.mask(k);
    const auto t0 = std::chrono::steady_clock::now();
    const cv::Mat map = integrator.radiance_map(brdf, sample.view(k), sample.frame(k), sample.size(), o);
    total += seconds_since(t0);
    for (int t : sample.texels(k)) {
      const cv::Vec3f& p = map.at<cv::Vec3f>(t / sample.size(), t % sample.size());
      out.emplace_back(p[0], p[1], p[2]);
    }
  }
  if (seconds) *seconds = total;
  return out;
}

namespace {

SampledBlend blend_at_samples(const MapSet& set, const ViewSet& view_set, const ErrorSample& sample,
                              const BlendRule& rule) {
  const BlendEngine engine(set, view_set, rule);
  SampledBlend out;
  for (int k = 0; k < sample.view_count(); ++k) {
    const ViewWeights located = engine.locate(sample.view(k));
    for (int t : sample.texels(k)) {
      double w = 0;
      out.values.push_back(engine.radiance(located, sample.view(k), sample.normal(k, t), &w));
      out.weights.push_back(w);
    }
  }
  return out;
}

}  // namespace

SampledBlend sampled_blend(const Integrator& integrator, const Brdf& brdf, const IntegratorOptions& options,
                           const ViewSet& views, int res, bool normalise_albedo, const ErrorSample& sample,
                           const BlendRule& rule) {
  if (res < 2) throw std::invalid_argument("sampled blend: the map size must be at least 2");
  const std::vector<Vec3>& vs = views.views();
  const CentralDirection kind = brdf.central_direction();
  // The footprints: for every sampled texel and located source, the 2 x 2 bilinear taps around the
  // warped point (the engine's taps are floor(p) and floor(p) + 1 of pixel_from_disc's p). A tap's
  // neighbour is added where p lies within kRound of a texel boundary, so that float rounding in the
  // engine's warp cannot move the footprint onto an unbaked texel; near the rim (where a footprint's
  // taps may fall outside the disc and the engine steps inward) the whole one-texel margin (4 x 4).
  constexpr double kRound = 1e-2;
  std::vector<cv::Mat> masks(vs.size());
  for (int k = 0; k < sample.view_count(); ++k) {
    const Vec3& d = sample.view(k);
    const ViewWeights located = views.locate(d, rule.barycentric);
    for (int t : sample.texels(k)) {
      const Vec3 n = sample.normal(k, t);
      const Vec3 central = kind == CentralDirection::Mirror ? Vec3(2.0 * n.dot(d) * n - d) : n;
      for (int j = 0; j < located.count; ++j) {
        const int i = located.views[std::size_t(j)];
        const Mat3 T = world_from_view_for(vs[std::size_t(i)]);
        const WarpSample w = warp_direction(kind, T.transpose() * central);
        const Vec2 px = sphere_map::pixel_from_disc(w.disc, res, res);
        cv::Mat& m = masks[std::size_t(i)];
        if (m.empty()) m = cv::Mat(res, res, CV_8UC1, cv::Scalar(0));
        const int c0 = int(std::floor(px.x())), r0 = int(std::floor(px.y()));
        const double fx = px.x() - c0, fy = px.y() - r0;
        const bool rim = w.disc.norm() > 1.0 - 3.0 / res;
        const int c_lo = c0 - (rim || fx < kRound ? 1 : 0), c_hi = c0 + 1 + (rim || fx > 1 - kRound ? 1 : 0);
        const int r_lo = r0 - (rim || fy < kRound ? 1 : 0), r_hi = r0 + 1 + (rim || fy > 1 - kRound ? 1 : 0);
        for (int r = std::max(0, r_lo); r <= std::min(res - 1, r_hi); ++r)
          for (int c = std::max(0, c_lo); c <= std::min(res - 1, c_hi); ++c) m.at<unsigned char>(r, c) = 255;
      }
    }
  }
  const std::vector<float> albedo = normalise_albedo ? albedo_table(brdf) : std::vector<float>{};
  const cv::Mat unused(res, res, CV_32FC3, cv::Scalar::all(0));  // shared by the views no texel reads
  MapSet set;
  SampledBlend out;
  const auto t0 = std::chrono::steady_clock::now();
  for (std::size_t i = 0; i < vs.size(); ++i) {
    MapView mv;
    mv.view = vs[i];
    mv.world_from_view = world_from_view_for(vs[i]);
    mv.warp = kind;
    mv.source = MapSource::Computed;
    if (masks[i].empty()) {
      mv.rgb = unused;
    } else {
      IntegratorOptions o = options;
      o.texel_mask = masks[i];
      mv.rgb = integrator.radiance_map(brdf, mv.view, mv.world_from_view, res, o);
      out.texels_baked += cv::countNonZero(masks[i]);
    }
    if (!albedo.empty()) {
      if (!masks[i].empty()) normalise_by_albedo(mv.rgb, albedo);
      mv.albedo = albedo;
    }
    set.views.push_back(std::move(mv));
  }
  out.seconds = seconds_since(t0);
  SampledBlend b = blend_at_samples(set, views, sample, rule);
  out.values = std::move(b.values);
  out.weights = std::move(b.weights);
  return out;
}

BlendErrorMeasure sampled_blend_error(const Integrator& integrator, const Brdf& brdf, const IntegratorOptions& options,
                                      const ViewSet& views, int res, bool normalise_albedo, const ErrorSample& sample,
                                      const std::vector<Vec3>& truth, const BlendErrorOptions& stop,
                                      const ErrorSums& prior) {
  if (stop.step < 1) throw std::invalid_argument("sampled blend error: the step must be at least one view");
  if (truth.size() != std::size_t(sample.count()))
    throw std::invalid_argument("sampled blend error: the truth differs in size from the sample");
  const int K = sample.view_count();
  double truth_norm2 = 0;
  std::size_t i = 0;
  for (int v = 0; v < K; ++v)
    for (double w : sample.weights(v)) truth_norm2 += w * truth[i++].squaredNorm();
  const double bound = stop.stop_above * stop.stop_above * (prior.denominator() + truth_norm2);
  BlendErrorMeasure out;
  SampledBlend all;
  double partial = prior.numerator();
  i = 0;
  while (out.views < K) {
    const int first = out.views, last = std::min(K, first + stop.step);
    std::optional<ErrorSample> piece;
    if (first > 0 || last < K) piece.emplace(sample.views(first, last));
    const SampledBlend b =
        sampled_blend(integrator, brdf, options, views, res, normalise_albedo, piece ? *piece : sample);
    out.seconds += b.seconds;
    std::size_t j = 0;  // b's texel j is the sample's i + j
    for (int v = first; v < last; ++v)
      for (double w : sample.weights(v)) {
        if (b.weights[j] > 0) partial += w * (b.values[j] - truth[i + j]).squaredNorm();
        ++j;
      }
    i += j;
    all.values.insert(all.values.end(), b.values.begin(), b.values.end());
    all.weights.insert(all.weights.end(), b.weights.begin(), b.weights.end());
    out.views = last;
    if (out.views < K && partial > bound) {
      out.at_least = std::sqrt(partial / (prior.denominator() + truth_norm2));
      return out;
    }
  }
  out.sums = prior;
  out.sums.add(sample, all.values, truth, &all.weights);
  out.error = out.sums.estimate();
  return out;
}

SampledBlend sampled_blend(const MapSet& set, const ViewSet& view_set, const ErrorSample& sample,
                           const BlendRule& rule) {
  return blend_at_samples(set, view_set, sample, rule);
}

double relative_rms(const std::vector<Vec3>& values, const std::vector<Vec3>& truth,
                    const std::vector<double>* weights) {
  if (values.size() != truth.size() || (weights && weights->size() != truth.size()))
    throw std::invalid_argument("relative_rms: the vectors differ in size");
  double num = 0, den = 0;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    if (weights && !((*weights)[i] > 0)) continue;
    num += (values[i] - truth[i]).squaredNorm();
    den += truth[i].squaredNorm();
  }
  if (den > 0) return std::sqrt(num / den);
  return num > 0 ? std::numeric_limits<double>::infinity() : 0.0;
}

void ErrorSums::add(const ErrorSample& sample, const std::vector<Vec3>& values, const std::vector<Vec3>& truth,
                    const std::vector<double>* blend_weights) {
  const std::size_t n = std::size_t(sample.count());
  if (values.size() != n || truth.size() != n || (blend_weights && blend_weights->size() != n))
    throw std::invalid_argument("sample_error: the vectors differ in size from the sample");
  std::size_t i = 0;
  for (int k = 0; k < sample.view_count(); ++k) {
    double num = 0, den = 0;
    for (double w : sample.weights(k)) {
      if (!blend_weights || (*blend_weights)[i] > 0) {
        num += w * (values[i] - truth[i]).squaredNorm();
        den += w * truth[i].squaredNorm();
      }
      ++i;
    }
    num_.push_back(num);
    den_.push_back(den);
  }
}

double ErrorSums::numerator() const { return std::accumulate(num_.begin(), num_.end(), 0.0); }
double ErrorSums::denominator() const { return std::accumulate(den_.begin(), den_.end(), 0.0); }

ErrorEstimate ErrorSums::estimate() const {
  auto ratio = [](double a, double b) {
    if (b > 0) return std::sqrt(a / b);
    return a > 0 ? std::numeric_limits<double>::infinity() : 0.0;
  };
  const int K = views();
  const double N = numerator(), D = denominator();
  ErrorEstimate e;
  e.value = ratio(N, D);
  if (K < 2 || !std::isfinite(e.value)) return e;
  // Jackknife: sigma^2 = (K - 1) / K sum_k (R_(-k) - mean R_(-k))^2.
  std::vector<double> loo(static_cast<std::size_t>(K));
  double mean = 0;
  for (int k = 0; k < K; ++k) {
    loo[std::size_t(k)] = ratio(N - num_[std::size_t(k)], D - den_[std::size_t(k)]);
    if (!std::isfinite(loo[std::size_t(k)])) {
      e.sigma = std::numeric_limits<double>::infinity();
      return e;
    }
    mean += loo[std::size_t(k)] / K;
  }
  double ss = 0;
  for (double r : loo) ss += (r - mean) * (r - mean);
  e.sigma = std::sqrt(double(K - 1) / K * ss);
  return e;
}

ErrorEstimate sample_error(const ErrorSample& sample, const std::vector<Vec3>& values, const std::vector<Vec3>& truth,
                           const std::vector<double>* blend_weights) {
  ErrorSums sums;
  sums.add(sample, values, truth, blend_weights);
  return sums.estimate();
}

TexelGuide squared_radiance_guide(const Integrator& integrator, const Brdf& brdf, const IntegratorOptions& options,
                                  int guide_size) {
  if (guide_size < 2) throw std::invalid_argument("error sample: a guide's size must be at least 2");
  return [&integrator, &brdf, options, guide_size](int, const Vec3& view, const Mat3& frame) {
    IntegratorOptions o = options;
    o.texel_mask = cv::Mat();
    const cv::Mat rgb = integrator.radiance_map(brdf, view, frame, guide_size, o);
    cv::Mat q(guide_size, guide_size, CV_32FC1, cv::Scalar(0));
    for (int r = 0; r < guide_size; ++r)
      for (int c = 0; c < guide_size; ++c) {
        const cv::Vec3f& p = rgb.at<cv::Vec3f>(r, c);
        const float v = p[0] * p[0] + p[1] * p[1] + p[2] * p[2];
        q.at<float>(r, c) = std::isfinite(v) && v > 0 ? v : 0.0f;
      }
    return q;
  };
}

}  // namespace rsibr
