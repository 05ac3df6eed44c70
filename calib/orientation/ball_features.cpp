#include "calib/orientation/ball_features.h"

#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <optional>
#include <stdexcept>

namespace rsibr {

namespace {

// The reflected direction of pixel q (camera frame), or nullopt off the ball.
std::optional<Vec3> reflected(const LensModel& lens, const Vec3& centre, const Vec2& q) {
  const Vec3 d = lens.unproject(q);
  const double b = d.dot(centre), c = centre.squaredNorm() - 1.0;
  const double disc = b * b - c;
  if (!(disc > 0)) return std::nullopt;
  const Vec3 n = (b - std::sqrt(disc)) * d - centre;
  return (d - 2 * d.dot(n) * n).normalized();
}

}  // namespace

BallFeatures ball_features(const cv::Mat& image, const LensModel& lens, const BallCone& cone,
                           const BallFeatureOptions& options) {
  if (image.type() != CV_32FC3 || image.cols != lens.width() || image.rows != lens.height())
    throw std::invalid_argument("ball features: the image must be float RGB of the lens model's size");
  const Vec3 axis = cone.axis.normalized();
  const Vec3 centre = axis / std::sin(cone.half_angle);
  // Mask: pixels whose ray is within max_radius_fraction of the cone's angle.
  cv::Mat mask(image.rows, image.cols, CV_8UC1, cv::Scalar(0));
  cv::Mat lum(image.rows, image.cols, CV_32FC1);
  cv::transform(image, lum, cv::Matx13f(1.f / 3, 1.f / 3, 1.f / 3));
  cv::max(lum, 0.0, lum);
  double lo = 1e300, hi = -1e300;
  const double limit = options.max_radius_fraction * cone.half_angle;
  // The ball's bounding box in pixels, from its outline.
  const std::vector<Vec2> outline = cone_outline(cone, lens, 64);
  double x0 = 1e9, x1 = -1e9, y0 = 1e9, y1 = -1e9;
  for (const Vec2& p : outline)
    x0 = std::min(x0, p.x()), x1 = std::max(x1, p.x()), y0 = std::min(y0, p.y()), y1 = std::max(y1, p.y());
  const int cx0 = std::max(0, int(std::floor(x0))), cx1 = std::min(image.cols - 1, int(std::ceil(x1)));
  const int cy0 = std::max(0, int(std::floor(y0))), cy1 = std::min(image.rows - 1, int(std::ceil(y1)));
  const double eps = std::max(1e-3 * cv::mean(lum)[0], 1e-30);
  cv::Mat lg(image.rows, image.cols, CV_32FC1, cv::Scalar(0));
  for (int y = cy0; y <= cy1; ++y)
    for (int x = cx0; x <= cx1; ++x) {
      if (angle_between(lens.unproject(Vec2(x, y)), axis) > limit) continue;
      mask.at<unsigned char>(y, x) = 255;
      const double v = std::log(lum.at<float>(y, x) + eps);
      lg.at<float>(y, x) = static_cast<float>(v);
      lo = std::min(lo, v), hi = std::max(hi, v);
    }
  BallFeatures out;
  if (!(hi > lo)) return out;
  cv::Mat u8;
  lg.convertTo(u8, CV_8U, 255.0 / (hi - lo), -lo * 255.0 / (hi - lo));
  u8.setTo(0, mask == 0);
  cv::Ptr<cv::SIFT> sift = cv::SIFT::create(options.max_features, 3, options.contrast_threshold);
  std::vector<cv::KeyPoint> kps;
  cv::Mat desc;
  sift->detectAndCompute(u8, mask, kps, desc);
  const double cos_cam = std::cos(options.camera_mask_deg * kPi / 180);
  for (std::size_t i = 0; i < kps.size(); ++i) {
    const Vec2 q(kps[i].pt.x, kps[i].pt.y);
    const auto r = reflected(lens, centre, q);
    const auto rx = reflected(lens, centre, q + Vec2(0.5, 0)), ry = reflected(lens, centre, q + Vec2(0, 0.5));
    if (!r || !rx || !ry) continue;
    if (r->dot(-axis) > cos_cam) continue;  // the camera's own reflection
    const double per_px = 2 * std::max(angle_between(*r, *rx), angle_between(*r, *ry));
    out.directions.push_back(*r);
    out.sigma.push_back(std::max(options.sigma_px * per_px, 1e-6));
    out.pixels.push_back(q);
    out.rays.push_back(lens.unproject(q).normalized());
    out.descriptors.push_back(desc.row(static_cast<int>(i)));
  }
  return out;
}

std::vector<DirectionObservation> match_ball_features(const std::vector<BallFeatures>& views, int* features,
                                                      double ratio, const MatchGuess& guess,
                                                      std::vector<PairMatches>* pairs) {
  if (!guess.world_from_cam.empty() && guess.world_from_cam.size() != views.size())
    throw std::invalid_argument("match_ball_features: a rotation guess must be given for every view or none");
  if (pairs) pairs->clear();
  // Union-find over (view, index).
  std::vector<int> offset(views.size() + 1, 0);
  for (std::size_t v = 0; v < views.size(); ++v)
    offset[v + 1] = offset[v] + static_cast<int>(views[v].directions.size());
  std::vector<int> parent(offset.back());
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](int a) {
    while (parent[a] != a) a = parent[a] = parent[parent[a]];
    return a;
  };
  cv::BFMatcher matcher(cv::NORM_L2);
  for (std::size_t a = 0; a < views.size(); ++a)
    for (std::size_t b = a + 1; b < views.size(); ++b) {
      PairMatches pm{int(a), int(b), views[a].descriptors.rows, views[b].descriptors.rows, 0, false};
      const bool gated = !guess.world_from_cam.empty() && guess.world_from_cam[a] && guess.world_from_cam[b];
      if (views[a].descriptors.rows < (gated ? 1 : 2) || views[b].descriptors.rows < (gated ? 1 : 2)) {
        if (pairs) pairs->push_back(pm);
        continue;
      }
      pm.gated = gated;
      std::vector<std::pair<int, int>> kept;  // (index in a, index in b)
      if (gated) {
        // Under the guess: a's feature i and b's feature j pair when each is the other's nearest
        // descriptor inside the gate, gated_ratio times nearer than the second nearest there (a
        // lone candidate passes).
        const Mat3 b_from_a = guess.world_from_cam[b]->transpose() * *guess.world_from_cam[a];
        const double cos_gate = std::cos(guess.gate_deg * kPi / 180);
        cv::Mat dist;
        cv::batchDistance(views[a].descriptors, views[b].descriptors, dist, CV_32F, cv::noArray(), cv::NORM_L2);
        const int na = dist.rows, nb = dist.cols;
        constexpr float kNone = std::numeric_limits<float>::max();
        std::vector<int> best_a(na, -1), best_b(nb, -1);
        std::vector<float> d1a(na, kNone), d2a(na, kNone), d1b(nb, kNone), d2b(nb, kNone);
        auto offer = [](float x, int k, int& best, float& d1, float& d2) {
          if (x < d1)
            d2 = d1, d1 = x, best = k;
          else if (x < d2)
            d2 = x;
        };
        for (int i = 0; i < na; ++i) {
          const Vec3 d = b_from_a * views[a].directions[std::size_t(i)];
          for (int j = 0; j < nb; ++j)
            if (d.dot(views[b].directions[std::size_t(j)]) > cos_gate) {
              const float x = dist.at<float>(i, j);
              offer(x, j, best_a[i], d1a[i], d2a[i]);
              offer(x, i, best_b[j], d1b[j], d2b[j]);
            }
        }
        const float gr = static_cast<float>(guess.gated_ratio);
        for (int i = 0; i < na; ++i) {
          const int j = best_a[i];
          if (j >= 0 && best_b[j] == i && (d2a[i] == kNone || d1a[i] < gr * d2a[i]) &&
              (d2b[j] == kNone || d1b[j] < gr * d2b[j]))
            kept.push_back({i, j});
        }
      }
      // Unguided: the mutual nearest descriptors over the whole sphere that pass the ratio test;
      // under a guess, those the gate did not already pair (a wrong guess keeps them).
      if (views[a].descriptors.rows >= 2 && views[b].descriptors.rows >= 2) {
        std::vector<char> used_a(views[a].descriptors.rows, 0), used_b(views[b].descriptors.rows, 0);
        for (const auto& [i, j] : kept) used_a[i] = used_b[j] = 1;
        std::vector<std::vector<cv::DMatch>> ab, ba;
        matcher.knnMatch(views[a].descriptors, views[b].descriptors, ab, 2);
        matcher.knnMatch(views[b].descriptors, views[a].descriptors, ba, 2);
        std::vector<int> best_ba(views[b].descriptors.rows, -1);
        for (const auto& m : ba)
          if (m.size() == 2 && m[0].distance < ratio * m[1].distance) best_ba[m[0].queryIdx] = m[0].trainIdx;
        for (const auto& m : ab)
          if (m.size() == 2 && m[0].distance < ratio * m[1].distance && best_ba[m[0].trainIdx] == m[0].queryIdx &&
              !used_a[m[0].queryIdx] && !used_b[m[0].trainIdx])
            kept.push_back({m[0].queryIdx, m[0].trainIdx});
      }
      for (const auto& [i, j] : kept) parent[find(offset[a] + i)] = find(offset[b] + j);
      pm.matched = static_cast<int>(kept.size());
      if (pairs) pairs->push_back(pm);
    }
  // Tracks: roots seen by >= 2 views, numbered in order of first appearance.
  std::map<int, std::vector<std::pair<int, int>>> tracks;
  for (std::size_t v = 0; v < views.size(); ++v)
    for (int i = 0; i < static_cast<int>(views[v].directions.size()); ++i)
      tracks[find(offset[v] + i)].push_back({int(v), i});
  std::vector<DirectionObservation> obs;
  int id = 0;
  for (const auto& [root, members] : tracks) {
    std::vector<char> seen(views.size(), 0);
    int distinct = 0;
    for (const auto& [v, i] : members) distinct += !seen[v], seen[v] = 1;
    if (distinct < 2) continue;
    std::fill(seen.begin(), seen.end(), 0);
    for (const auto& [v, i] : members) {
      if (seen[v]) continue;
      seen[v] = 1;
      obs.push_back({v, id, views[v].directions[i], views[v].sigma[i],
                     i < static_cast<int>(views[v].rays.size()) ? views[v].rays[i] : Vec3::Zero(), i});
    }
    ++id;
  }
  if (features) *features = id;
  return obs;
}

}  // namespace rsibr
