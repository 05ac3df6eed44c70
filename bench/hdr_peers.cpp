// HDR merge against the peers: the shoots of the consumer-camera model (tests/hdr/camera_shoot.h:
// raw sensitivities, white balance, a saturating colour matrix, a filmic tone curve with a toe and
// a shoulder, JPEG at a chosen quality) with their truth, written as files for the command-line
// peers (luminance-hdr-cli, pfstools), and the in-process methods (rsibr's automatic curve and
// merge, OpenCV's Debevec and Robertson) measured on the same codes; bench/hdr_peers.py runs it and
// the peers and writes the docs/tradeoffs.md section "HDR merge: against the peers".
//
//   rsibr_hdr_peers --env E --jpeg Q --seed S --write DIR
//       DIR/bracket_<j>.png and .tif: bracket j of every view side by side (view v at x = v * width),
//       8-bit RGB, the codes every method sees (for JPEG the decoded codes, stored losslessly);
//       DIR/shoot.json: exposures, view size, the settings.
//   rsibr_hdr_peers --env E --jpeg Q --seed S --out JSON [--score NAME=FILE.exr ...] [--opencv ...]
//       regenerates the same shoot (deterministic in the seed), runs rsibr and OpenCV on it, reads
//       each peer's float RGB OpenEXR (the same side-by-side layout), and writes every method's errors.
//
// Errors (camera_shoot.h shoot_errors): each output is known up to one global factor, fitted per
// method per shoot as a single scalar for all three channels (median of truth / estimate
// luminance over mid-tone pixels; never a per-channel gain). Per pixel class of truth luminance
// (dark below the 10th percentile, bright above the 90th, mid between, clipped: saturated in the
// shortest bracket): RMS log2 of the luminance ratio; colour: RMS log2 of R/G and B/G against
// the truth's. For the clipped class the same log2 luminance ratio is reported with the fraction
// of saturated channel values at or below the truth (a lower bound should be).
#include "bench/measure.h"
#include "formats/atomic_file.h"
#include "formats/truth_image.h"
#include "hdr/camera_shoot.h"
#include "hdr/merge.h"
#include "hdr/noise_model.h"
#include "hdr/response_recovery.h"
#include "formats/image_codecs.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/photo.hpp>

#include <filesystem>
#include <fstream>
#include <iostream>

namespace rsibr {
namespace {

using bench::Clock;
using bench::seconds_since;

// A side-by-side RGB float image back into views.
std::vector<cv::Mat> split_views(const cv::Mat& rgb, const testing::Shoot& sh) {
  std::vector<cv::Mat> out;
  const int W = sh.views.front().cols(), H = sh.views.front().rows();
  for (std::size_t v = 0; v < sh.views.size(); ++v) out.push_back(rgb(cv::Rect(int(v) * W, 0, W, H)).clone());
  return out;
}

// The clipped class: RMS log2(scale lum(est) / lum(truth)) (floored as shoot_errors floors).
double clipped_stops(const std::vector<cv::Mat>& est, const testing::Shoot& sh, double scale) {
  const std::vector<cv::Mat> cls = testing::pixel_classes(sh);
  double se = 0, n = 0;
  for (std::size_t v = 0; v < est.size(); ++v)
    for (int y = 0; y < est[v].rows; ++y)
      for (int x = 0; x < est[v].cols; ++x) {
        if (cls[v].at<unsigned char>(y, x) != testing::kClippedClass) continue;
        const cv::Vec3f a = est[v].at<cv::Vec3f>(y, x);
        if (!(std::isfinite(a[0]) && std::isfinite(a[1]) && std::isfinite(a[2]))) continue;
        const double lt = testing::luminance(sh.truth[v].at<cv::Vec3f>(y, x));
        if (!(lt > 0)) continue;
        const double d = std::log2(std::max(1e-3 * lt, scale * testing::luminance(a)) / lt);
        se += d * d, n += 1;
      }
  return n > 0 ? std::sqrt(se / n) : 0.0;
}

// Per channel: the median over mid-tone pixels of scale est_c / truth_c (1, 1, 1 for a method
// without a colour cast; a diagnostic only: the errors never use a per-channel gain).
std::vector<double> channel_cast(const std::vector<cv::Mat>& est, const testing::Shoot& sh, double scale) {
  const std::vector<cv::Mat> cls = testing::pixel_classes(sh);
  std::vector<double> out;
  for (int c = 0; c < 3; ++c) {
    std::vector<double> r;
    for (std::size_t v = 0; v < est.size(); ++v)
      for (int y = 0; y < est[v].rows; ++y)
        for (int x = 0; x < est[v].cols; ++x) {
          const double a = est[v].at<cv::Vec3f>(y, x)[c], t = sh.truth[v].at<cv::Vec3f>(y, x)[c];
          if (cls[v].at<unsigned char>(y, x) == testing::kMid && std::isfinite(a) && t > 0) r.push_back(scale * a / t);
        }
    if (r.empty()) {
      out.push_back(0);
      continue;
    }
    std::nth_element(r.begin(), r.begin() + long(r.size() / 2), r.end());
    out.push_back(r[r.size() / 2]);
  }
  return out;
}

nlohmann::json errors_json(const std::vector<cv::Mat>& est, const testing::Shoot& sh) {
  const testing::ShootErrors e = testing::shoot_errors(est, sh);
  return {{"scale", e.scale},
          {"dark", e.stops[testing::kDark]},
          {"mid", e.stops[testing::kMid]},
          {"bright", e.stops[testing::kBright]},
          {"clipped", clipped_stops(est, sh, e.scale)},
          {"clipped_at_or_below", e.clipped_at_or_below},
          {"colour", e.colour_stops},
          {"colour_mid", e.colour_stops_mid},
          {"patch_rg", e.patch_rg},
          {"patch_bg", e.patch_bg},
          {"channel_cast", channel_cast(est, sh, e.scale)},
          {"non_finite", e.non_finite}};
}

testing::ShootSpec spec_of(const std::string& env, int jpeg, unsigned seed) {
  testing::ShootSpec s;
  s.env = env;
  s.jpeg_quality = jpeg;
  s.seed = seed;
  return s;
}

// OpenCV's calibration and merge on the side-by-side brackets. `samples`, `lambda`: CalibrateDebevec's.
cv::Mat opencv_merge(const std::vector<cv::Mat>& stack, const std::vector<float>& times, bool robertson, int samples,
                     float lambda) {
  cv::Mat response, hdr;
  if (robertson) {
    cv::createCalibrateRobertson()->process(stack, response, times);
    cv::createMergeRobertson()->process(stack, hdr, times, response);
  } else {
    cv::createCalibrateDebevec(samples, lambda)->process(stack, response, times);
    cv::createMergeDebevec()->process(stack, hdr, times, response);
  }
  cv::cvtColor(hdr, hdr, cv::COLOR_BGR2RGB);
  return hdr;
}

int run(int argc, char** argv) {
  CLI::App app{"HDR merge against the peers: synthetic consumer-camera brackets with truth"};
  std::string env, write_dir, out_path;
  int jpeg = 0;
  unsigned seed = 1;
  std::vector<std::string> score, opencv_debevec;
  app.add_option("--env", env, "Truth radiance (a CC0 lat-long environment)")->required()->check(CLI::ExistingFile);
  app.add_option("--jpeg", jpeg, "JPEG quality (0: PNG, lossless codes)")->check(CLI::Range(0, 100));
  app.add_option("--seed", seed, "Noise seed");
  app.add_option("--write", write_dir, "Write the brackets and shoot.json into this folder and stop");
  app.add_option("--out", out_path, "JSON output: every method's errors and time");
  app.add_option("--score", score, "NAME=FILE.exr: a peer's merge of the written brackets (repeatable)");
  app.add_option("--opencv-debevec", opencv_debevec,
                 "SAMPLES,LAMBDA of an OpenCV CalibrateDebevec run (repeatable; default 70,10: OpenCV's own)");
  CLI11_PARSE(app, argc, argv);
  if (write_dir.empty() == out_path.empty()) {
    std::cerr << "rsibr_hdr_peers: give exactly one of --write and --out\n";
    return 2;
  }

  const auto t_shoot = Clock::now();
  const testing::Shoot sh = testing::shoot(spec_of(env, jpeg, seed));
  const double shoot_s = seconds_since(t_shoot);
  const std::vector<cv::Mat> stack = testing::side_by_side_bgr(sh);
  const std::vector<float> times(sh.exposures.begin(), sh.exposures.end());

  if (!write_dir.empty()) {
    std::filesystem::create_directories(write_dir);
    for (std::size_t j = 0; j < stack.size(); ++j)
      for (const char* ext : {".png", ".tif"}) {  // the same codes; luminance-hdr-cli reads TIFF, not PNG
        const std::string path = write_dir + "/bracket_" + std::to_string(j) + ext;
        if (!rsibr::write_image(path, stack[j])) {
          std::cerr << path << ": cannot write\n";
          return 1;
        }
      }
    nlohmann::json s = {{"env", std::filesystem::path(env).filename().string()},
                        {"jpeg_quality", jpeg},
                        {"seed", seed},
                        {"exposures", sh.exposures},
                        {"views", sh.views.size()},
                        {"view_width", sh.views.front().cols()},
                        {"view_height", sh.views.front().rows()},
                        {"width", stack.front().cols},
                        {"height", stack.front().rows},
                        {"max_code", 255},
                        {"shoot_seconds", shoot_s}};
    std::ofstream(write_dir + "/shoot.json") << s.dump(1) << "\n";
    return 0;
  }

  nlohmann::json methods = nlohmann::json::array();
  // rsibr: the automatic curve (model and channels by held-out error, saturation measured), the
  // noise model estimated from every view, the inverse-variance merge of each view.
  {
    std::vector<const BracketSet*> views;
    for (const auto& b : sh.views) views.push_back(&b);
    const auto t0 = Clock::now();
    const ResponseRecovery rec = recover_response(views);
    const NoiseModel noise = estimate_noise(views, rec.curve);
    std::vector<cv::Mat> est;
    for (const auto& b : sh.views) est.push_back(merge_brackets(b, rec.curve, noise).radiance);
    const double t = seconds_since(t0);
    methods.push_back({{"method", "rsibr"},
                       {"settings", "automatic: " + rec.chosen},
                       {"chosen", rec.chosen},
                       {"near_tie", rec.near_tie},
                       {"seconds", t},
                       {"errors", errors_json(est, sh)}});
  }
  if (opencv_debevec.empty()) opencv_debevec = {"70,10"};
  for (const std::string& s : opencv_debevec) {
    int samples = 70;
    float lambda = 10;
    if (std::sscanf(s.c_str(), "%d,%f", &samples, &lambda) != 2 || samples < 10 || !(lambda > 0)) {
      std::cerr << "rsibr_hdr_peers: --opencv-debevec " << s << ": expected SAMPLES,LAMBDA\n";
      return 2;
    }
    const auto t0 = Clock::now();
    const cv::Mat hdr = opencv_merge(stack, times, false, samples, lambda);
    const double t = seconds_since(t0);
    methods.push_back({{"method", "OpenCV Debevec"},
                       {"settings", "CalibrateDebevec samples " + std::to_string(samples) + ", lambda " +
                                        s.substr(s.find(',') + 1) + " + MergeDebevec"},
                       {"seconds", t},
                       {"errors", errors_json(split_views(hdr, sh), sh)}});
  }
  {
    const auto t0 = Clock::now();
    const cv::Mat hdr = opencv_merge(stack, times, true, 0, 0);
    const double t = seconds_since(t0);
    methods.push_back({{"method", "OpenCV Robertson"},
                       {"settings", "CalibrateRobertson (30 iterations, threshold 0.01) + MergeRobertson"},
                       {"seconds", t},
                       {"errors", errors_json(split_views(hdr, sh), sh)}});
  }
  for (const std::string& s : score) {
    const auto eq = s.find('=');
    if (eq == std::string::npos) {
      std::cerr << "rsibr_hdr_peers: --score " << s << ": expected NAME=FILE\n";
      return 2;
    }
    const std::string name = s.substr(0, eq), path = s.substr(eq + 1);
    cv::Mat img = read_truth_image(path);  // float R, G, B OpenEXR; throws "<path>: ..."
    if (img.type() != CV_32FC3 || img.cols != stack.front().cols || img.rows != stack.front().rows) {
      std::cerr << path << ": not a " << stack.front().cols << "x" << stack.front().rows << " float RGB image\n";
      return 1;
    }
    methods.push_back({{"method", name}, {"errors", errors_json(split_views(img, sh), sh)}});
  }
  nlohmann::json out = {{"env", std::filesystem::path(env).filename().string()},
                        {"jpeg_quality", jpeg},
                        {"seed", seed},
                        {"exposures", sh.exposures},
                        {"methods", methods}};
  write_text_atomically(out_path, out.dump(1) + "\n");
  return 0;
}

}  // namespace
}  // namespace rsibr

int main(int argc, char** argv) {
  try {
    return rsibr::run(argc, argv);
  } catch (const std::exception& e) {
    std::cerr << "rsibr_hdr_peers: " << e.what() << "\n";
    return 1;
  }
}
