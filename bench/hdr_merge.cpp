// HDR merge: accuracy against truth and speed, each against OpenCV (CalibrateDebevec +
// MergeDebevec) and Debevec hat weighting measured in the same run (issue "HDR merge", item 6).
// bench/hdr_merge.py runs it and writes the docs/performance.md and docs/tradeoffs.md sections.
//
// Truth: a CC0 environment (esplanade: a sun) resized to --width x --height, as scene radiance L.
// Capture: the test synthesizer (tests/hdr/bracket_synth.h): X = L e k, Poisson shot noise
// (full well 20000 e-), Gaussian read noise, 7 brackets two stops apart, a film-like S-shaped
// response per channel, 8-bit codes (OpenCV's MergeDebevec takes 8-bit only).
// Error: each method's output is known up to a global factor; it is fitted per method (median of
// truth / estimate over mid-tone pixels), then RMS of (estimate - truth) / truth luminance over
// the three channels, per region of truth luminance:
// shadows (below the 10th percentile), mid-tones, highlights (above the 90th), over pixels that
// are not clipped in every bracket; SNR in the darkest decade [p0.1, 10 p0.1] of truth luminance.
// Speed: the brackets tiled to --big-width x --big-height (24 MP), best of --repeats.
#include "bench/measure.h"
#include "hdr/bracket_synth.h"
#include "hdr/merge.h"
#include "hdr/noise_model.h"
#include "hdr/response_recovery.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/photo.hpp>
#include <tbb/info.h>

#include <sys/resource.h>

#include <fstream>
#include <iostream>

namespace rsibr {
namespace {

using bench::Clock;
using bench::seconds_since;

double luminance(const cv::Vec3d& v) { return 0.2126 * v[0] + 0.7152 * v[1] + 0.0722 * v[2]; }

struct Regions {
  cv::Mat label;    // 0 excluded, 1 shadows, 2 mid-tones, 3 highlights
  cv::Mat darkest;  // 1 in the darkest decade
};

Regions regions(const cv::Mat& truth, const cv::Mat& clipped_everywhere) {
  std::vector<double> lum;
  for (int r = 0; r < truth.rows; ++r)
    for (int x = 0; x < truth.cols; ++x)
      if (!clipped_everywhere.at<unsigned char>(r, x) && luminance(truth.at<cv::Vec3d>(r, x)) > 0)
        lum.push_back(luminance(truth.at<cv::Vec3d>(r, x)));
  std::vector<double> s = lum;
  std::sort(s.begin(), s.end());
  auto pct = [&](double p) { return s[std::min(s.size() - 1, std::size_t(p * double(s.size())))]; };
  const double p10 = pct(0.10), p90 = pct(0.90), lo = std::max(pct(0.001), 1e-30);
  Regions g;
  g.label = cv::Mat(truth.size(), CV_8UC1, cv::Scalar(0));
  g.darkest = cv::Mat(truth.size(), CV_8UC1, cv::Scalar(0));
  for (int r = 0; r < truth.rows; ++r)
    for (int x = 0; x < truth.cols; ++x) {
      const double l = luminance(truth.at<cv::Vec3d>(r, x));
      if (clipped_everywhere.at<unsigned char>(r, x) || !(l > 0)) continue;
      g.label.at<unsigned char>(r, x) = l < p10 ? 1 : (l > p90 ? 3 : 2);
      g.darkest.at<unsigned char>(r, x) = (l >= lo && l <= 10 * lo) ? 1 : 0;
    }
  return g;
}

// Median of truth / estimate in channel c over mid-tone pixels.
double median_ratio(const cv::Mat& est, const cv::Mat& truth, const Regions& g, int c) {
  std::vector<double> ratios;
  for (int r = 0; r < truth.rows; r += 2)
    for (int x = 0; x < truth.cols; x += 2)
      if (g.label.at<unsigned char>(r, x) == 2) {
        const double e = est.at<cv::Vec3f>(r, x)[c];
        if (e > 0 && std::isfinite(e)) ratios.push_back(truth.at<cv::Vec3d>(r, x)[c] / e);
      }
  if (ratios.empty()) return 1.0;
  std::nth_element(ratios.begin(), ratios.begin() + long(ratios.size() / 2), ratios.end());
  return ratios[ratios.size() / 2];
}

// Errors of `est` (CV_32FC3 RGB) against truth after fitting the global factor on mid-tones
// (green's), or with per_channel a factor per channel (a white balance: the channels' relative
// scales are not observable from brackets, see the section's text).
nlohmann::json errors(const cv::Mat& est, const cv::Mat& truth, const Regions& g, bool per_channel) {
  double scales[3];
  for (int c = 0; c < 3; ++c) scales[c] = median_ratio(est, truth, g, per_channel ? c : 1);
  const double scale = scales[1];
  double se[4] = {0, 0, 0, 0}, n[4] = {0, 0, 0, 0}, sig = 0, noise = 0;
  long bad = 0;
  for (int r = 0; r < truth.rows; ++r)
    for (int x = 0; x < truth.cols; ++x) {
      const int k = g.label.at<unsigned char>(r, x);
      if (!k) continue;
      const double lum = luminance(truth.at<cv::Vec3d>(r, x));
      for (int c = 0; c < 3; ++c) {
        const double t = truth.at<cv::Vec3d>(r, x)[c];
        const double e = double(est.at<cv::Vec3f>(r, x)[c]) * scales[c];
        if (!std::isfinite(e)) {
          ++bad;
          continue;
        }
        if (lum > 0) se[k] += (e - t) * (e - t) / (lum * lum), n[k] += 1;
        if (g.darkest.at<unsigned char>(r, x)) sig += t * t, noise += (e - t) * (e - t);
      }
    }
  return {{"shadows", std::sqrt(se[1] / std::max(1.0, n[1]))},
          {"midtones", std::sqrt(se[2] / std::max(1.0, n[2]))},
          {"highlights", std::sqrt(se[3] / std::max(1.0, n[3]))},
          {"snr_darkest_decade_db", 10 * std::log10(sig / std::max(noise, 1e-300))},
          {"non_finite", bad},
          {"scale", scale}};
}

nlohmann::json errors(const cv::Mat& est, const cv::Mat& truth, const Regions& g) {
  nlohmann::json j = errors(est, truth, g, false);
  j["per_channel"] = errors(est, truth, g, true);
  return j;
}

std::vector<cv::Mat> to_bgr8(const BracketSet& b) {
  std::vector<cv::Mat> out;
  for (const cv::Mat& c : b.codes) {
    cv::Mat eight, bgr;
    c.convertTo(eight, CV_8UC3);
    cv::cvtColor(eight, bgr, cv::COLOR_RGB2BGR);
    out.push_back(bgr);
  }
  return out;
}

cv::Mat opencv_merge(const std::vector<cv::Mat>& bgr, const std::vector<float>& times, const cv::Mat& response) {
  cv::Mat hdr;
  cv::createMergeDebevec()->process(bgr, hdr, times, response);
  cv::cvtColor(hdr, hdr, cv::COLOR_BGR2RGB);
  return hdr;
}

double cpu_seconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) + 1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

// Best wall time of `repeats` runs, and the CPU time (all threads) of that run: on a shared
// machine the wall time depends on the load, the CPU time much less.
struct Timing {
  double wall = 1e300, cpu = 0;
};
template <class F>
Timing best_of(int repeats, F&& f) {
  Timing best;
  for (int i = 0; i < repeats; ++i) {
    const double c0 = cpu_seconds();
    const auto t0 = Clock::now();
    f();
    const double wall = seconds_since(t0);
    if (wall < best.wall) best = {wall, cpu_seconds() - c0};
  }
  return best;
}

int run(int argc, char** argv) {
  CLI::App app{"HDR merge accuracy and speed against OpenCV"};
  std::string env_path, out_path;
  int width = 1536, height = 1024, big_w = 6000, big_h = 4000, repeats = 3, cv_repeats = 2;
  unsigned seed = 7;
  app.add_option("--env", env_path, "Truth radiance (a CC0 environment)")->required();
  app.add_option("--out", out_path, "JSON output")->required();
  app.add_option("--width", width);
  app.add_option("--height", height);
  app.add_option("--big-width", big_w);
  app.add_option("--big-height", big_h);
  app.add_option("--repeats", repeats);
  app.add_option("--cv-repeats", cv_repeats);
  app.add_option("--seed", seed);
  CLI11_PARSE(app, argc, argv);

  nlohmann::json out;
  out["threads"] = tbb::info::default_concurrency();
  const EnvMap env = bench::load_sanitized(env_path);
  cv::Mat truth;
  cv::resize(env.pixels, truth, cv::Size(width, height), 0, 0, cv::INTER_AREA);
  truth.convertTo(truth, CV_64FC3);
  // Exposures: the middle bracket puts the median luminance at X = 0.18.
  std::vector<double> lum;
  for (int r = 0; r < truth.rows; r += 4)
    for (int x = 0; x < truth.cols; x += 4) lum.push_back(luminance(truth.at<cv::Vec3d>(r, x)));
  std::nth_element(lum.begin(), lum.begin() + long(lum.size() / 2), lum.end());
  const double e_mid = 0.18 / lum[lum.size() / 2];
  const auto e = testing::exposure_series(e_mid / 64, 4.0, 7);
  testing::BracketCamera cam;
  cam.max_code = 255;
  cam.read_sigma = 5e-4;
  cam.response = testing::s_curve;
  out["scene"] = {{"env", std::filesystem::path(env_path).filename().string()},
                  {"width", width},
                  {"height", height},
                  {"exposures", e},
                  {"full_well", cam.full_well},
                  {"read_sigma", cam.read_sigma},
                  {"bits", 8}};
  const auto t_syn = Clock::now();
  const BracketSet b = make_brackets(testing::synthesize(truth, e, cam, seed), e);
  std::cerr << "synthesized " << b.size() << " brackets in " << seconds_since(t_syn) << " s\n";

  // Ours: recovery (model by held-out error), noise estimate, merge.
  auto t0 = Clock::now();
  const ResponseRecovery rec = recover_response(b);
  const double t_recover = seconds_since(t0);
  t0 = Clock::now();
  const NoiseModel noise = estimate_noise(b, rec.curve, default_saturation_code(255));
  const double t_noise = seconds_since(t0);
  t0 = Clock::now();
  const MergedImage ours = merge_brackets(b, rec.curve, noise);
  const double t_merge = seconds_since(t0);
  cv::Mat clipped_everywhere = (ours.flags & kClipped) != 0;
  const Regions g = regions(truth, clipped_everywhere);
  nlohmann::json cands = nlohmann::json::array();
  for (const auto& c : rec.candidates)
    cands.push_back({{"model", c.model},
                     {"shared", c.shared},
                     {"complexity", c.complexity},
                     {"held_out_error", c.held_out_error},
                     {"tied", c.tied},
                     {"parameters", c.parameters}});
  out["response"] = {{"chosen", rec.chosen},
                     {"candidates", cands},
                     {"seconds", t_recover},
                     {"margin_sigmas", rec.margin_sigmas},
                     {"warning", rec.warning}};
  out["noise"] = {{"shot", noise.shot},
                  {"read", noise.read},
                  {"true_shot", cam.shot()},
                  {"true_read", cam.read()},
                  {"seconds", t_noise}};
  out["clipped_pixels"] = ours.clipped;
  out["ghost_pixels"] = ours.ghost;

  nlohmann::json methods = nlohmann::json::array();
  methods.push_back({{"method", "rsibr: inverse-variance merge (" + rec.curve.model + " curve, estimated noise)"},
                     {"errors", errors(ours.radiance, truth, g)},
                     {"seconds", t_merge}});
  t0 = Clock::now();
  const cv::Mat hat = merge_hat_weighted(b, rec.curve);
  methods.push_back({{"method", "Debevec hat weighting (same curve)"},
                     {"errors", errors(hat, truth, g)},
                     {"seconds", seconds_since(t0)}});
  // The true curve: how much of the error is the curve's.
  const ResponseCurve true_curve = ResponseCurve::sampled("true", 255, 256, [&](int c, double u) {
    double lo = 0, hi = 1;
    for (int i = 0; i < 60; ++i) {
      const double mid = 0.5 * (lo + hi);
      (cam.response(c, mid) < u ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
  });
  // What a neutral records: the true curves' radiance at the middle code, over green's.
  out["true_middle_code_ratio"] = {true_curve.linear(0, 127.5) / true_curve.linear(1, 127.5), 1.0,
                                   true_curve.linear(2, 127.5) / true_curve.linear(1, 127.5)};
  NoiseModel true_noise;
  for (int c = 0; c < 3; ++c)
    true_noise.shot[std::size_t(c)] = cam.shot(), true_noise.read[std::size_t(c)] = cam.read();
  methods.push_back({{"method", "rsibr merge with the true curve and noise"},
                     {"errors", errors(merge_brackets(b, true_curve, true_noise).radiance, truth, g)},
                     {"seconds", nullptr}});
  methods.push_back({{"method", "Debevec hat weighting, true curve"},
                     {"errors", errors(merge_hat_weighted(b, true_curve), truth, g)},
                     {"seconds", nullptr}});
  // OpenCV: CalibrateDebevec (its defaults: 70 samples, lambda 10, random) + MergeDebevec.
  const std::vector<cv::Mat> bgr = to_bgr8(b);
  std::vector<float> times(e.begin(), e.end());
  cv::Mat cv_response;
  t0 = Clock::now();
  cv::createCalibrateDebevec()->process(bgr, cv_response, times);
  const double t_cv_cal = seconds_since(t0);
  t0 = Clock::now();
  const cv::Mat cv_hdr = opencv_merge(bgr, times, cv_response);
  const double t_cv_merge = seconds_since(t0);
  methods.push_back({{"method", "OpenCV CalibrateDebevec + MergeDebevec"},
                     {"errors", errors(cv_hdr, truth, g)},
                     {"seconds", t_cv_merge},
                     {"calibrate_seconds", t_cv_cal}});
  out["accuracy"] = methods;
  std::cerr << "accuracy done\n";

  // Speed: 7 x 24 MP, tiled from the brackets.
  std::vector<cv::Mat> big;
  for (const cv::Mat& c : b.codes) {
    cv::Mat tiled;
    cv::repeat(c, (big_h + c.rows - 1) / c.rows, (big_w + c.cols - 1) / c.cols, tiled);
    big.push_back(tiled(cv::Rect(0, 0, big_w, big_h)).clone());
  }
  BracketSet bb;
  bb.codes = big;
  bb.exposures = b.exposures;
  bb.metadata = b.metadata;
  bb.files = b.files;
  bb.max_code = 255;
  MergedImage mm;
  const Timing t_ours = best_of(repeats, [&] { mm = merge_brackets(bb, rec.curve, noise); });
  const Timing t_noise_big = best_of(1, [&] { (void)estimate_noise(bb, rec.curve, default_saturation_code(255)); });
  cv::Mat hb;
  const Timing t_hat = best_of(repeats, [&] { hb = merge_hat_weighted(bb, rec.curve); });
  const std::vector<cv::Mat> big_bgr = to_bgr8(bb);
  cv::Mat cvb;
  const Timing t_cv = best_of(cv_repeats, [&] { cv::createMergeDebevec()->process(big_bgr, cvb, times, cv_response); });
  double load[3] = {0, 0, 0};
  getloadavg(load, 3);
  out["speed"] = {{"width", big_w},
                  {"height", big_h},
                  {"brackets", int(bb.size())},
                  {"rsibr_merge_s", t_ours.wall},
                  {"rsibr_merge_cpu_s", t_ours.cpu},
                  {"rsibr_noise_estimate_s", t_noise_big.wall},
                  {"rsibr_noise_estimate_cpu_s", t_noise_big.cpu},
                  {"hat_merge_s", t_hat.wall},
                  {"hat_merge_cpu_s", t_hat.cpu},
                  {"opencv_merge_debevec_s", t_cv.wall},
                  {"opencv_merge_debevec_cpu_s", t_cv.cpu},
                  {"repeats", repeats},
                  {"opencv_repeats", cv_repeats},
                  {"load_average_1min", load[0]}};
  std::ofstream(out_path) << out.dump(1) << "\n";
  std::cerr << "ours " << t_ours.wall << " s (cpu " << t_ours.cpu << "), hat " << t_hat.wall << " s (cpu " << t_hat.cpu
            << "), OpenCV " << t_cv.wall << " s (cpu " << t_cv.cpu << "), load " << load[0] << "\n";
  return 0;
}

}  // namespace
}  // namespace rsibr

int main(int argc, char** argv) { return rsibr::run(argc, argv); }
