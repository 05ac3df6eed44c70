#include "calib/orientation/track_refinement.h"

#include "core/parallel.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <stdexcept>

namespace rsibr {

namespace {

// Bilinear log luminance of `face` at texel position (u, v); false when a tap is off the face or
// not valid.
bool sample(const CubeFace& face, double u, double v, double* out) {
  if (!(std::isfinite(u) && std::isfinite(v))) return false;
  const int x0 = static_cast<int>(std::floor(u)), y0 = static_cast<int>(std::floor(v));
  if (x0 < 0 || y0 < 0 || x0 + 1 >= face.size || y0 + 1 >= face.size) return false;
  const unsigned char* m0 = face.valid.ptr<unsigned char>(y0);
  const unsigned char* m1 = face.valid.ptr<unsigned char>(y0 + 1);
  if (!(m0[x0] && m0[x0 + 1] && m1[x0] && m1[x0 + 1])) return false;
  const float* l0 = face.log_luminance.ptr<float>(y0);
  const float* l1 = face.log_luminance.ptr<float>(y0 + 1);
  const double fx = u - x0, fy = v - y0;
  *out = (1 - fy) * ((1 - fx) * l0[x0] + fx * l0[x0 + 1]) + fy * ((1 - fx) * l1[x0] + fx * l1[x0 + 1]);
  return true;
}

// The reference's patch: values on the (2h + 1)^2 grid around a, row by row.
struct Template {
  std::vector<Vec2> offsets;
  std::vector<double> values;
};

std::optional<Template> make_template(const CubeFace& face, const Vec2& a, int h) {
  Template t;
  for (int y = -h; y <= h; ++y)
    for (int x = -h; x <= h; ++x) {
      double val;
      if (!sample(face, a.x() + x, a.y() + y, &val)) return std::nullopt;
      t.values.push_back(val);
      t.offsets.push_back(Vec2(x, y));
    }
  return t;
}

// A view's faces were resampled through the ball as detected; the first solve refined it. A texel
// names a pixel through the detected ball, and the pixel a direction through the refined one.
struct ViewGeometry {
  const CubeFeatureSet* set;
  BallCone detected, refined;
  Mat3 world_from_cam;
};

// The texel on B's face `fb` that shows what A's texel uv on face `fa` shows (exact: both balls'
// reflections, the rotations), or nullopt where either ball does not show it.
std::optional<Vec2> transfer(const ViewGeometry& a, int fa, const Vec2& uv, const ViewGeometry& b, int fb,
                             const LensModel& lens, const BallFeatureOptions& features) {
  const auto pa = ball_pixel_of(lens, a.detected, features, a.set->faces[fa].direction(uv.x(), uv.y()), false);
  if (!pa) return std::nullopt;
  const Vec3 world =
      a.world_from_cam * reflect_off_ball<double>(pa->ray, a.refined.axis, std::sin(a.refined.half_angle)).normalized();
  const auto pb = ball_pixel_of(lens, b.refined, features, b.world_from_cam.transpose() * world, false);
  if (!pb) return std::nullopt;
  const Vec3 db = reflect_off_ball<double>(pb->ray, b.detected.axis, std::sin(b.detected.half_angle)).normalized();
  return b.set->faces[fb].texel(db);
}

struct Alignment {
  Vec2 uv;              // where the template's centre lies on the face
  Eigen::Matrix2d cov;  // of uv, texels^2 (both patches' noise)
};

// Gauss-Newton over (t, gain g, bias b, ramp c) for  g L(m_i + t) + b + c . x_i = T_i,  from t0;
// m_i on `face`, x_i the template's offsets. The ramp takes up a brightness gradient across the
// patch (the mirror's Fresnel changes with the incidence toward the rim), which a shift would
// otherwise absorb.
std::optional<Alignment> align(const Template& tmpl, const std::vector<Vec2>& m, const CubeFace& face, Vec2 t,
                               const Vec2& keypoint, const TrackRefinementOptions& o) {
  const int n = static_cast<int>(m.size());
  std::vector<double> val(n), gx(n), gy(n);
  auto evaluate = [&](const Vec2& shift) {
    for (int i = 0; i < n; ++i) {
      const double u = m[i].x() + shift.x(), v = m[i].y() + shift.y();
      double l, r, up, dn;
      if (!sample(face, u, v, &val[i]) || !sample(face, u - 0.5, v, &l) || !sample(face, u + 0.5, v, &r) ||
          !sample(face, u, v - 0.5, &up) || !sample(face, u, v + 0.5, &dn))
        return false;
      gx[i] = r - l, gy[i] = dn - up;
    }
    return true;
  };
  double gain = 1, bias = 0;
  if (!evaluate(t)) return std::nullopt;
  {
    double mt = 0, mb = 0;
    for (int i = 0; i < n; ++i) mt += tmpl.values[i] / n, mb += val[i] / n;
    bias = mt - mb;
  }
  using Vec6 = Eigen::Matrix<double, 6, 1>;
  using Mat6 = Eigen::Matrix<double, 6, 6>;
  Vec2 ramp = Vec2::Zero();
  auto jacobian = [&](int i) {
    Vec6 j;
    j << gain * gx[i], gain * gy[i], val[i], 1.0, tmpl.offsets[i].x(), tmpl.offsets[i].y();
    return j;
  };
  auto residual = [&](int i) { return gain * val[i] + bias + ramp.dot(tmpl.offsets[i]) - tmpl.values[i]; };
  Mat6 jtj;
  bool converged = false;
  for (int it = 0; it < o.max_iterations; ++it) {
    jtj.setZero();
    Vec6 jtr = Vec6::Zero();
    for (int i = 0; i < n; ++i) {
      const Vec6 j = jacobian(i);
      jtj += j * j.transpose();
      jtr += j * residual(i);
    }
    const Vec6 step = jtj.ldlt().solve(-jtr);
    if (!step.allFinite()) return std::nullopt;
    t += step.head<2>(), gain += step[2], bias += step[3], ramp += step.tail<2>();
    if (!(gain > 0.1 && gain < 10)) return std::nullopt;
    if (!evaluate(t)) return std::nullopt;
    if (step.head<2>().norm() < 1e-4) {
      converged = true;
      break;
    }
  }
  if (!converged) return std::nullopt;
  Alignment out;
  out.uv = m[n / 2] + t;
  if ((out.uv - keypoint).norm() > o.max_shift_texels) return std::nullopt;
  // The residual's variance, the Jacobian at the optimum, the normalised cross-correlation.
  jtj.setZero();
  double ss = 0, mt = 0, mb = 0;
  for (int i = 0; i < n; ++i) {
    const Vec6 j = jacobian(i);
    jtj += j * j.transpose();
    ss += std::pow(residual(i), 2);
    mt += tmpl.values[i] / n, mb += val[i] / n;
  }
  double st = 0, sb = 0, stb = 0;
  for (int i = 0; i < n; ++i) {
    st += std::pow(tmpl.values[i] - mt, 2), sb += std::pow(val[i] - mb, 2);
    stb += (tmpl.values[i] - mt) * (val[i] - mb);
  }
  if (!(st > 0 && sb > 0) || stb / std::sqrt(st * sb) < o.min_ncc) return std::nullopt;
  const Mat6 c = (ss / (n - 6)) * jtj.inverse();
  out.cov = c.topLeftCorner<2, 2>();
  if (!out.cov.allFinite()) return std::nullopt;
  return out;
}

// Faces that may show direction d, the most face-on first.
std::vector<int> faces_facing(const std::vector<CubeFace>& faces, const Vec3& d) {
  std::vector<int> order;
  for (int f = 0; f < static_cast<int>(faces.size()); ++f)
    if (d.dot(faces[f].axis) > 0.5) order.push_back(f);
  std::sort(order.begin(), order.end(), [&](int a, int b) { return d.dot(faces[a].axis) > d.dot(faces[b].axis); });
  return order;
}

// The re-located observation's std dev (radians) from the alignment's covariance at uv on `face`.
std::optional<double> sigma_of(const Eigen::Matrix2d& cov, const CubeFace& face, const Vec2& uv, const LensModel& lens,
                               const BallCone& cone, const BallFeatureOptions& features,
                               const TrackRefinementOptions& o) {
  const auto q0 = ball_pixel_of(lens, cone, features, face.direction(uv.x(), uv.y()));
  const auto qu = ball_pixel_of(lens, cone, features, face.direction(uv.x() + 1, uv.y()), false);
  const auto qv = ball_pixel_of(lens, cone, features, face.direction(uv.x(), uv.y() + 1), false);
  if (!q0 || !qu || !qv) return std::nullopt;
  Eigen::Matrix2d dq;
  dq << qu->pixel - q0->pixel, qv->pixel - q0->pixel;
  const double area = std::abs(dq.determinant());  // pixels per texel
  if (!(area > 0)) return std::nullopt;
  const double lambda = Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(cov).eigenvalues().maxCoeff();
  const Vec3 d = face.direction(uv.x(), uv.y());
  const double per_texel = std::max(angle_between(d, face.direction(uv.x() + 1, uv.y())),
                                    angle_between(d, face.direction(uv.x(), uv.y() + 1)));
  return std::sqrt(std::max(lambda, 0.0) * std::max(1.0, 1 / area) * per_texel * per_texel +
                   std::pow(o.floor_px * q0->radians_per_pixel, 2));
}

}  // namespace

std::vector<DirectionObservation> refine_tracks(const std::vector<CubeFeatureSet>& views,
                                                const std::vector<BallCone>& cones,
                                                const std::vector<BallCone>& refined_cones, const LensModel& lens,
                                                const BallFeatureOptions& features,
                                                const std::vector<Mat3>& world_from_cam,
                                                const std::vector<DirectionObservation>& observations,
                                                const TrackRefinementOptions& options, TrackRefinementReport* report) {
  if (cones.size() != views.size() || refined_cones.size() != views.size() || world_from_cam.size() != views.size())
    throw std::invalid_argument("refine_tracks: views, cones and rotations differ in number");
  std::vector<ViewGeometry> geo;
  for (std::size_t v = 0; v < views.size(); ++v)
    geo.push_back({&views[v], cones[v], refined_cones[v], world_from_cam[v]});
  const std::vector<BallCone>& detected = cones;
  if (options.half_size < 1 || options.max_iterations < 1)
    throw std::invalid_argument("refine_tracks: half_size and max_iterations must be >= 1");
  for (const DirectionObservation& ob : observations)
    if (ob.view < 0 || ob.view >= static_cast<int>(views.size()) || ob.index < 0 ||
        ob.index >= static_cast<int>(views[ob.view].face.size()))
      throw std::invalid_argument("refine_tracks: an observation without its view's feature index");
  std::map<int, std::vector<int>> by_track;
  for (std::size_t i = 0; i < observations.size(); ++i)
    by_track[observations[i].feature].push_back(static_cast<int>(i));
  std::vector<std::vector<int>> tracks;
  for (auto& [id, members] : by_track) tracks.push_back(std::move(members));

  // Per observation: re-located (direction, ray, sigma), kept as detected, or dropped.
  enum class Fate { kept, refined, dropped };
  std::vector<DirectionObservation> out_obs = observations;
  std::vector<Fate> fate(observations.size(), Fate::kept);
  std::vector<double> ratio(observations.size(), 0);
  parallel_for_rows(static_cast<int>(tracks.size()), [&](int k) {
    const std::vector<int>& members = tracks[k];
    // The reference: the sharpest observation whose patch lies in valid texels.
    std::vector<int> order = members;
    std::sort(order.begin(), order.end(), [&](int a, int b) { return observations[a].sigma < observations[b].sigma; });
    std::optional<Template> tmpl;
    int ref = -1;
    for (int i : order) {
      const CubeFeatureSet& a = views[observations[i].view];
      const int idx = observations[i].index;
      tmpl = make_template(a.faces[a.face[idx]], a.face_uv[idx], options.half_size);
      if (tmpl) {
        ref = i;
        break;
      }
    }
    if (!tmpl) return;
    const int va = observations[ref].view;
    const CubeFeatureSet& a = views[va];
    const int fa = a.face[observations[ref].index];
    const Vec2 anchor = a.face_uv[observations[ref].index];
    const double h = options.half_size;
    std::vector<double> sigmas;
    std::vector<int> failed;
    for (int i : members) {
      if (i == ref) continue;
      const DirectionObservation& ob = observations[i];
      const CubeFeatureSet& b = views[ob.view];
      const Vec3 keypoint_dir = b.faces[b.face[ob.index]].direction(b.face_uv[ob.index].x(), b.face_uv[ob.index].y());
      const Vec3 seen =
          world_from_cam[ob.view].transpose() * world_from_cam[va] * a.faces[fa].direction(anchor.x(), anchor.y());
      bool done = false;
      for (int f : faces_facing(b.faces, seen)) {
        const CubeFace& face = b.faces[f];
        // The patch's texels on B's face: exact on the 3 x 3 grid of offsets {-h, 0, h}^2,
        // biquadratic between (an affine map left ~0.07 texel at a 120-px ball's patch corners,
        // which biased the shifts; the cubic terms are ~100x smaller).
        Vec2 grid[3][3];
        bool ok = true;
        for (int j = 0; j < 3 && ok; ++j)
          for (int i = 0; i < 3 && ok; ++i) {
            const auto t =
                transfer(geo[va], fa, anchor + Vec2((i - 1) * h, (j - 1) * h), geo[ob.view], f, lens, features);
            if (t) grid[j][i] = *t;
            ok = t.has_value();
          }
        const auto kp = face.texel(keypoint_dir);
        if (!ok || !kp) continue;
        std::vector<Vec2> m;
        for (const Vec2& x : tmpl->offsets) {
          const auto basis = [](double t) { return Eigen::Vector3d(0.5 * t * (t - 1), 1 - t * t, 0.5 * t * (t + 1)); };
          const Eigen::Vector3d bu = basis(x.x() / h), bv = basis(x.y() / h);
          Vec2 p = Vec2::Zero();
          for (int j = 0; j < 3; ++j)
            for (int i = 0; i < 3; ++i) p += bv[j] * bu[i] * grid[j][i];
          m.push_back(p);
        }
        const auto al = align(*tmpl, m, face, *kp - m[m.size() / 2], *kp, options);
        if (!al) continue;
        const Vec3 r = face.direction(al->uv.x(), al->uv.y());
        const auto px = ball_pixel_of(lens, detected[ob.view], features, r, false);
        const auto s = sigma_of(al->cov, face, al->uv, lens, detected[ob.view], features, options);
        if (!px || !s) continue;
        out_obs[i].direction = r;
        out_obs[i].ray = px->ray;
        out_obs[i].sigma = std::max(*s, 1e-9);
        ratio[i] = *s / ob.sigma;
        fate[i] = Fate::refined;
        sigmas.push_back(*s);
        done = true;
        break;
      }
      if (!done) failed.push_back(i);
    }
    if (sigmas.empty()) return;  // nothing re-located: the track keeps its SIFT observations
    for (int i : failed) fate[i] = Fate::dropped;
    std::nth_element(sigmas.begin(), sigmas.begin() + long(sigmas.size() / 2), sigmas.end());
    out_obs[ref].sigma = sigmas[sigmas.size() / 2];
    ratio[ref] = out_obs[ref].sigma / observations[ref].sigma;
    fate[ref] = Fate::refined;
  });

  std::vector<DirectionObservation> out;
  TrackRefinementReport rep;
  std::vector<double> ratios;
  for (std::size_t i = 0; i < observations.size(); ++i) {
    if (fate[i] == Fate::dropped) {
      ++rep.observations_dropped;
      continue;
    }
    if (fate[i] == Fate::refined) ++rep.observations_refined, ratios.push_back(ratio[i]);
    out.push_back(out_obs[i]);
  }
  for (const std::vector<int>& members : tracks)
    rep.tracks_refined += std::any_of(members.begin(), members.end(), [&](int i) { return fate[i] == Fate::refined; });
  if (!ratios.empty()) {
    std::nth_element(ratios.begin(), ratios.begin() + long(ratios.size() / 2), ratios.end());
    rep.median_sigma_ratio = ratios[ratios.size() / 2];
  }
  if (report) *report = rep;
  return out;
}

}  // namespace rsibr
