#include "core/lensfun_lens.h"

#include <lensfun/lensfun.h>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <mutex>
#include <stdexcept>
#include <vector>

namespace rsibr {
namespace {

constexpr double kFullFrameDiagonalMm = 43.266615305567875;  // hypot(36, 24)
constexpr double kSimpleModelPx = 0.05;  // a simpler model is kept when it is this close to lensfun everywhere

struct Sample {
  Eigen::Vector2d x;  // the ray's point on the z = 1 plane
  Eigen::Vector2d t;  // lensfun's distorted pixel, (d - c) / f
};

std::string model_text(const lfLensCalibDistortion& d) {
  char buf[160];
  switch (d.Model) {
    case LF_DIST_MODEL_POLY3: std::snprintf(buf, sizeof buf, "poly3 k1=%g", d.Terms[0]); break;
    case LF_DIST_MODEL_POLY5: std::snprintf(buf, sizeof buf, "poly5 k1=%g k2=%g", d.Terms[0], d.Terms[1]); break;
    case LF_DIST_MODEL_PTLENS:
      std::snprintf(buf, sizeof buf, "ptlens a=%g b=%g c=%g", d.Terms[0], d.Terms[1], d.Terms[2]);
      break;
    default: std::snprintf(buf, sizeof buf, "model %d", int(d.Model)); break;
  }
  return std::string(buf) + " at " + std::to_string(int(std::lround(d.Focal))) + " mm";
}

Eigen::Vector2d distorted(lfModifier* mod, const Eigen::Vector2d& u) {
  alignas(16) float r[2] = {0, 0};
  lf_modifier_apply_geometry_distortion(mod, float(u.x()), float(u.y()), 1, 1, r);
  return {double(r[0]), double(r[1])};
}

// The rational radial factor num / den of OPENCV8 at rho = r^2 (k: mrcal's k1 k2 k3 k4 k5 k6).
void rational(const double* k, double rho, double& num, double& den) {
  num = 1 + rho * (k[0] + rho * (k[1] + rho * k[2]));
  den = 1 + rho * (k[3] + rho * (k[4] + rho * k[5]));
}

// OPENCV8's radial factor fitted to the samples with `den_terms` (1..3) denominator terms, k[3 +
// den_terms..5] held at 0: the linearised form t den = x num by least squares, then
// Levenberg-Marquardt on the true residual x num / den - t. False when it does not converge to
// finite values.
bool fit_rational(const std::vector<Sample>& samples, int den_terms, Eigen::Matrix<double, 6, 1>& k) {
  const int np = 3 + den_terms, n = int(samples.size());
  Eigen::MatrixXd A(2 * n, np);
  Eigen::VectorXd b(2 * n);
  for (int i = 0; i < n; ++i) {
    const Sample& s = samples[std::size_t(i)];
    const double rho = s.x.squaredNorm(), p[3] = {rho, rho * rho, rho * rho * rho};
    for (int a = 0; a < 2; ++a) {
      for (int q = 0; q < 3; ++q) A(2 * i + a, q) = s.x[a] * p[q];
      for (int q = 0; q < den_terms; ++q) A(2 * i + a, 3 + q) = -s.t[a] * p[q];
      b[2 * i + a] = s.t[a] - s.x[a];
    }
  }
  const Eigen::VectorXd k0 = A.colPivHouseholderQr().solve(b);
  k.setZero();
  k.head(np) = k0;
  auto cost = [&](const Eigen::Matrix<double, 6, 1>& kk) {
    double c2 = 0;
    for (const Sample& s : samples) {
      double num, den;
      rational(kk.data(), s.x.squaredNorm(), num, den);
      c2 += (s.x * (num / den) - s.t).squaredNorm();
    }
    return std::isfinite(c2) ? c2 : 1e300;
  };
  double lambda = 1e-6, current = cost(k);
  for (int it = 0; it < 40; ++it) {
    Eigen::MatrixXd H = Eigen::MatrixXd::Zero(np, np);
    Eigen::VectorXd g = Eigen::VectorXd::Zero(np);
    for (const Sample& s : samples) {
      const double rho = s.x.squaredNorm(), p[3] = {rho, rho * rho, rho * rho * rho};
      double num, den;
      rational(k.data(), rho, num, den);
      for (int a = 0; a < 2; ++a) {
        Eigen::VectorXd jr(np);
        for (int q = 0; q < 3; ++q) jr[q] = s.x[a] * p[q] / den;
        for (int q = 0; q < den_terms; ++q) jr[3 + q] = -s.x[a] * num * p[q] / (den * den);
        H += jr * jr.transpose();
        g += jr * (s.x[a] * num / den - s.t[a]);
      }
    }
    bool improved = false;
    for (int tries = 0; tries < 12 && !improved; ++tries) {
      Eigen::MatrixXd Hd = H;
      Hd.diagonal() *= 1 + lambda;
      Eigen::Matrix<double, 6, 1> next = k;
      next.head(np) -= Hd.ldlt().solve(g);
      const double c2 = next.allFinite() ? cost(next) : 1e300;
      if (c2 < current) {
        improved = true;
        const bool converged = current - c2 < 1e-12 * current;
        k = next;
        current = c2;
        lambda = std::max(1e-9, lambda * 0.3);
        if (converged) return k.allFinite();
      } else {
        lambda *= 10;
      }
    }
    if (!improved) break;
  }
  return k.allFinite();
}

}  // namespace

const lfDatabase* lensfun_database() {
  static std::once_flag once;
  static lfDatabase* db = nullptr;
  std::call_once(once, [] {
    db = lf_db_new();
    if (db && lf_db_load(db) != LF_NO_ERROR) {
      lf_db_destroy(db);
      db = nullptr;
    }
  });
  return db;
}

std::optional<LensfunLens> lensfun_lens(const std::string& make, const std::string& model, const std::string& lens_name,
                                        double focal_mm, int width, int height, std::string* why) {
  if (width <= 0 || height <= 0) throw std::invalid_argument("lensfun_lens: the image size must be positive");
  if (!(focal_mm > 0) || !std::isfinite(focal_mm))
    throw std::invalid_argument("lensfun_lens: the focal length must be positive");
  auto fail = [&](const std::string& w) -> std::optional<LensfunLens> {
    if (why) *why = w;
    return std::nullopt;
  };
  const lfDatabase* db = lensfun_database();
  if (!db) return fail("lensfun's database could not be loaded");
  if (lens_name.empty()) return fail("the photo names no lens (EXIF LensModel)");
  const lfCamera** cams = make.empty() && model.empty() ? nullptr : lf_db_find_cameras(db, make.c_str(), model.c_str());
  const lfCamera* cam = cams && cams[0] ? cams[0] : nullptr;
  const lfLens** lenses = lf_db_find_lenses_hd(db, cam, nullptr, lens_name.c_str(), 0);
  std::optional<LensfunLens> out;
  std::string problem;
  if (!cam) {
    problem = "lensfun does not know the camera '" + make + " " + model + "' (its crop factor)";
  } else if (!lenses || !lenses[0]) {
    problem = "lensfun does not know the lens '" + lens_name + "'";
  } else if (lenses[0]->Type != LF_RECTILINEAR) {
    problem = "lensfun's profile of '" + lens_name + "' is not rectilinear (fisheye lenses are not supported)";
  } else {
    const lfLens* lens = lenses[0];
    lfLensCalibDistortion dc;
    if (!lf_lens_interpolate_distortion(lens, float(focal_mm), &dc) || dc.Model == LF_DIST_MODEL_NONE) {
      problem = "lensfun has no distortion profile of '" + lens_name + "'";
    } else {
      LensfunLens L;
      L.focal_mm = focal_mm;
      L.crop_factor = cam->CropFactor;
      const std::string lmaker = lens->Maker ? lf_mlstr_get(lens->Maker) : "",
                        lmodel = lens->Model ? lf_mlstr_get(lens->Model) : "";
      L.lens_name = lmodel.rfind(lmaker, 0) == 0 ? lmodel : lmaker + " " + lmodel;
      L.camera = std::string(lf_mlstr_get(cam->Maker)) + " " + lf_mlstr_get(cam->Model);
      L.profile = model_text(dc);
      // The paraxial focal length: lensfun's real focal where the profile has one, else nominal.
      double paraxial_mm = focal_mm;
      lfLensCalibRealFocal rf;
      if (lf_lens_interpolate_real_focal(lens, float(focal_mm), &rf) && rf.RealFocal > 0) paraxial_mm = rf.RealFocal;
      const double f = paraxial_mm * L.crop_factor * std::hypot(double(width), double(height)) / kFullFrameDiagonalMm;
      L.focal_px = f;

      lfModifier* mod = lf_modifier_new(lens, L.crop_factor, width, height);
      const int flags = lf_modifier_initialize(mod, lens, LF_PF_F32, float(focal_mm), 8.0f, 1.0f, 1.0f, lens->Type,
                                               LF_MODIFY_DISTORTION, 0);
      if (!(flags & LF_MODIFY_DISTORTION)) {
        problem = "lensfun cannot apply the distortion profile of '" + lens_name + "'";
      } else {
        // The distortion centre: the mapping's fixed point, from the image centre (lensfun's
        // default; a profile with a centre offset moves it).
        Eigen::Vector2d c(0.5 * (width - 1), 0.5 * (height - 1));
        auto jacobian = [&](const Eigen::Vector2d& u) {
          Eigen::Matrix2d J;
          const double h = 0.5;
          J.col(0) = (distorted(mod, u + Eigen::Vector2d(h, 0)) - distorted(mod, u - Eigen::Vector2d(h, 0))) / (2 * h);
          J.col(1) = (distorted(mod, u + Eigen::Vector2d(0, h)) - distorted(mod, u - Eigen::Vector2d(0, h))) / (2 * h);
          return J;
        };
        const Eigen::Vector2d c0 = c;
        for (int it = 0; it < 8; ++it) {
          const Eigen::Vector2d g = distorted(mod, c) - c;
          if (g.norm() < 1e-4) break;
          const Eigen::Matrix2d A = jacobian(c) - Eigen::Matrix2d::Identity();
          if (std::abs(A.determinant()) < 1e-6) break;
          c -= A.inverse() * g;
        }
        if (!c.allFinite() || (c - c0).norm() > 0.05 * std::hypot(double(width), double(height))) c = c0;
        const Eigen::Matrix2d J = jacobian(c);
        const double m = 0.5 * (J(0, 0) + J(1, 1));  // lensfun's magnification at the centre

        // Samples over an enlarged frame of the corrected image, kept where they land in the photo
        // (with a margin) and where the radial mapping still increases (no fold-over).
        std::vector<Sample> samples;
        const int nx = 64, ny = 48;
        const double spread = 1.6;
        for (int j = 0; j < ny; ++j)
          for (int i = 0; i < nx; ++i) {
            const Eigen::Vector2d u =
                c + spread * Eigen::Vector2d((i / double(nx - 1) - 0.5) * width, (j / double(ny - 1) - 0.5) * height);
            const Eigen::Vector2d d = distorted(mod, u);
            if (!d.allFinite() || d.x() < -2 || d.y() < -2 || d.x() > width + 1 || d.y() > height + 1) continue;
            const Eigen::Vector2d v = u - c;
            if (v.norm() > 1e-9) {
              const Eigen::Vector2d d2 = distorted(mod, c + 1.01 * v);
              if (!((d2 - c).norm() > (d - c).norm())) continue;
            }
            samples.push_back({v * m / f, (d - c) / f});
          }
        if (samples.size() < 50) {
          problem = "lensfun's mapping of '" + lens_name + "' leaves too little of the photo to fit";
        } else {
          double rho_max = 0;
          for (const Sample& s : samples) rho_max = std::max(rho_max, s.x.squaredNorm());
          // Errors in pixels of a model through mrcal's own projection.
          auto errors = [&](const LensModel& lm, double& rms, double& mx) {
            double s2 = 0;
            mx = 0;
            for (const Sample& s : samples) {
              const Vec2 p = lm.project(Vec3(s.x.x(), s.x.y(), 1));
              const double e = (Eigen::Vector2d(p.x(), p.y()) - (c + f * s.t)).norm();
              s2 += e * e;
              mx = std::max(mx, std::isfinite(e) ? e : 1e30);
            }
            rms = std::sqrt(s2 / double(samples.size()));
          };
          // OPENCV5, radial part (p1 = p2 = 0): x rho k1 + x rho^2 k2 + x rho^3 k3 = t - x.
          const int n = int(samples.size());
          Eigen::MatrixXd A(2 * n, 3);
          Eigen::VectorXd b(2 * n);
          for (int i = 0; i < n; ++i) {
            const Sample& s = samples[std::size_t(i)];
            const double rho = s.x.squaredNorm();
            for (int a = 0; a < 2; ++a) {
              A.row(2 * i + a) << s.x[a] * rho, s.x[a] * rho * rho, s.x[a] * rho * rho * rho;
              b[2 * i + a] = s.t[a] - s.x[a];
            }
          }
          const Eigen::Vector3d k5 = A.colPivHouseholderQr().solve(b);
          LensModel best("LENSMODEL_OPENCV5", {f, f, c.x(), c.y(), k5[0], k5[1], 0, 0, k5[2]}, width, height);
          double rms = 0, mx = 0;
          errors(best, rms, mx);
          if (mx > kSimpleModelPx) {
            // OPENCV8's rational radial factor, with 1, 2 or 3 denominator terms, each without a
            // pole over the field: the fewest terms that come within kSimpleModelPx of lensfun
            // everywhere (the full [3/3] form is often degenerate, numerator and denominator
            // nearly cancelling), else the closest.
            for (int den_terms = 1; den_terms <= 3 && mx > kSimpleModelPx; ++den_terms) {
              Eigen::Matrix<double, 6, 1> k;
              if (!fit_rational(samples, den_terms, k)) continue;
              bool pole = false;
              for (int i = 0; i <= 100 && !pole; ++i) {
                double num, den;
                rational(k.data(), 1.2 * rho_max * i / 100.0, num, den);
                pole = !(den > 0.2) || !(num > 0);
              }
              if (pole) continue;
              LensModel l8("LENSMODEL_OPENCV8", {f, f, c.x(), c.y(), k[0], k[1], 0, 0, k[2], k[3], k[4], k[5]}, width,
                           height);
              double rms8 = 0, mx8 = 0;
              errors(l8, rms8, mx8);
              if (mx8 < mx) {
                best = l8;
                rms = rms8;
                mx = mx8;
              }
            }
          }
          L.lens = best;
          L.fit_rms_px = rms;
          L.fit_max_px = mx;
          out = L;
        }
      }
      lf_modifier_destroy(mod);
    }
  }
  lf_free(lenses);
  lf_free(cams);
  if (!out) return fail(problem);
  return out;
}

std::optional<LensfunVignetting> lensfun_vignetting(const std::string& make, const std::string& model,
                                                    const std::string& lens_name, double focal_mm, double aperture,
                                                    int width, int height, double distance_m) {
  if (width <= 0 || height <= 0) throw std::invalid_argument("lensfun_vignetting: the image size must be positive");
  if (!(focal_mm > 0) || !(aperture > 0) || lens_name.empty()) return std::nullopt;
  const lfDatabase* db = lensfun_database();
  if (!db) return std::nullopt;
  const lfCamera** cams = lf_db_find_cameras(db, make.c_str(), model.c_str());
  const lfCamera* cam = cams && cams[0] ? cams[0] : nullptr;
  const lfLens** lenses = lf_db_find_lenses_hd(db, cam, nullptr, lens_name.c_str(), 0);
  std::optional<LensfunVignetting> out;
  if (lenses && lenses[0]) {
    const lfLens* lens = lenses[0];
    lfLensCalibVignetting calib;
    const float crop = cam ? cam->CropFactor : lens->CropFactor;
    if (lf_lens_interpolate_vignetting(lens, float(focal_mm), float(aperture), float(distance_m), &calib) && crop > 0) {
      // lensfun's correction of a flat field of ones is 1 / v: sampled on a grid of rows, fitted.
      lfModifier* mod = lf_modifier_new(lens, crop, width, height);
      const int flags = lf_modifier_initialize(mod, lens, LF_PF_F32, float(focal_mm), float(aperture),
                                               float(distance_m), 1.0f, lens->Type, LF_MODIFY_VIGNETTING, 0);
      if (flags & LF_MODIFY_VIGNETTING) {
        const double cx = 0.5 * (width - 1), cy = 0.5 * (height - 1);
        const double rc = std::hypot(std::max(cx, width - 1 - cx), std::max(cy, height - 1 - cy));
        const int step = std::max(1, std::min(width, height) / 64);
        Eigen::Matrix3d AtA = Eigen::Matrix3d::Zero();
        Eigen::Vector3d Atb = Eigen::Vector3d::Zero();
        std::vector<std::pair<double, double>> samples;  // (r^2, v)
        std::vector<float> row(std::size_t(width) * 3);
        for (int y = 0; y < height; y += step) {
          std::fill(row.begin(), row.end(), 1.0f);
          lf_modifier_apply_color_modification(mod, row.data(), 0.0f, float(y), width, 1, LF_CR_3(RED, GREEN, BLUE),
                                               int(row.size() * sizeof(float)));
          for (int x = 0; x < width; x += step) {
            const double g = row[std::size_t(x) * 3 + 1];
            if (!(g > 0) || !std::isfinite(g)) continue;
            const double r2 = (std::pow(x - cx, 2) + std::pow(y - cy, 2)) / (rc * rc), v = 1.0 / g;
            const Eigen::Vector3d a(r2, r2 * r2, r2 * r2 * r2);
            AtA += a * a.transpose();
            Atb += a * (v - 1);
            samples.push_back({r2, v});
          }
        }
        const Eigen::Vector3d k = AtA.ldlt().solve(Atb);
        if (k.allFinite() && !samples.empty()) {
          LensfunVignetting lv;
          lv.k = {k[0], k[1], k[2]};
          const std::string maker = lens->Maker ? lf_mlstr_get(lens->Maker) : "",
                            model = lens->Model ? lf_mlstr_get(lens->Model) : "";
          lv.lens = model.rfind(maker, 0) == 0 ? model : maker + " " + model;  // models usually start with the maker
          double s2 = 0;
          for (const auto& [r2, v] : samples) {
            const double fit = 1 + r2 * (k[0] + r2 * (k[1] + r2 * k[2]));
            s2 += std::pow(fit / v - 1, 2);
          }
          lv.fit_rms = std::sqrt(s2 / double(samples.size()));
          out = lv;
        }
      }
      lf_modifier_destroy(mod);
    }
  }
  lf_free(lenses);
  lf_free(cams);
  return out;
}

}  // namespace rsibr
