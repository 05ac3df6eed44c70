#include "capture/chessboard.h"

#include "capture/sensor_noise.h"
#include "core/parallel.h"

#include <cmath>
#include <stdexcept>

namespace rsibr {
namespace {

constexpr double kBlack = 0.06, kWhite = 0.9, kBackground = 0.3;

double board_reflectance(double u, double v, int corners, double spacing) {
  const double half = 0.5 * (corners + 1);
  const double a = u / spacing + half, b = v / spacing + half;  // in squares from the board's corner
  if (a < -1 || b < -1 || a > corners + 2 || b > corners + 2) return kBackground;
  if (a < 0 || b < 0 || a >= corners + 1 || b >= corners + 1) return kWhite;  // border
  return ((int(std::floor(a)) + int(std::floor(b))) % 2 == 0) ? kBlack : kWhite;
}

}  // namespace

ChessboardShot render_chessboard(const LensModel& lens, const RayTable& rays, const SynthChessboards& boards, int index,
                                 std::uint64_t seed, int supersampling) {
  const int n = boards.corners;
  const double s = boards.spacing_m;
  const double f = lens.intrinsics().empty() ? 500 : lens.intrinsics()[0];
  const double board_w = (n + 3) * s;
  ChessboardShot shot;
  NoiseRng rng(seed, (0xB0A5ull << 32) + std::uint64_t(index));
  for (int attempt = 0;; ++attempt) {
    if (attempt == 1000) throw std::runtime_error("chessboard: no pose keeps the board in the image");
    const double distance = f * board_w / (0.5 * lens.width()) * (0.9 + 0.3 * rng.uniform());
    const double deg = kPi / 180;
    const Mat3 R = (Eigen::AngleAxisd((rng.uniform() * 2 - 1) * 15 * deg, Vec3::UnitZ()) *
                    Eigen::AngleAxisd((rng.uniform() * 2 - 1) * 25 * deg, Vec3::UnitY()) *
                    Eigen::AngleAxisd((rng.uniform() * 2 - 1) * 25 * deg, Vec3::UnitX()))
                       .toRotationMatrix();
    const Vec3 centre((rng.uniform() * 2 - 1) * 0.25 * distance * lens.width() / f,
                      (rng.uniform() * 2 - 1) * 0.25 * distance * lens.height() / f, distance);
    std::vector<Vec3> pts;
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        pts.push_back(R * Vec3((i + 1 - 0.5 * (n + 1)) * s, (j + 1 - 0.5 * (n + 1)) * s, 0) + centre);
    std::vector<Vec2> px(pts.size());
    lens.project(pts.data(), int(pts.size()), px.data());
    const double margin = 2 * f * s / distance;
    bool inside = true;
    for (const Vec2& p : px) inside = inside && lens.in_image(p, margin);
    if (!inside) continue;
    shot.cam_from_board = R;
    shot.board_centre_cam = centre;
    shot.corners = px;
    break;
  }
  // Ray-plane intersection: the board plane through c with normal m = R z; t = (c.m) / (d.m).
  const Vec3 m = shot.cam_from_board.col(2), c = shot.board_centre_cam;
  const Mat3 board_from_cam = shot.cam_from_board.transpose();
  shot.reflectance.create(lens.height(), lens.width(), CV_32FC1);
  const int ss = supersampling;
  parallel_for_rows(lens.height(), [&](int y) {
    for (int x = 0; x < lens.width(); ++x) {
      integrator_detail::TexelRng prng(seed ^ (0xC4E55ull << 20) ^ std::uint64_t(index),
                                       std::uint64_t(y) * std::uint64_t(lens.width()) + std::uint64_t(x));
      double sum = 0;
      for (int j = 0; j < ss; ++j)
        for (int i = 0; i < ss; ++i) {
          const Vec3 d = rays.direction(x - 0.5 + (i + prng.uniform()) / ss, y - 0.5 + (j + prng.uniform()) / ss);
          const double dm = d.dot(m);
          double r = kBackground;
          if (std::abs(dm) > 1e-12) {
            const double t = c.dot(m) / dm;
            if (t > 0) {
              const Vec3 q = board_from_cam * (t * d - c);
              r = board_reflectance(q.x(), q.y(), n, s);
            }
          }
          sum += r;
        }
      shot.reflectance.at<float>(y, x) = float(sum / (ss * ss));
    }
  });
  return shot;
}

}  // namespace rsibr
