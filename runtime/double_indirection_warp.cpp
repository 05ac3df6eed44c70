#include "runtime/double_indirection_warp.h"

#include "core/sphere_map.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace rsibr {
namespace {

constexpr std::size_t kCacheTables = 8;
constexpr double kMaxNodes = double(1 << 24);  // 200 MB of nodes per table

int kind_index(CentralDirection kind) { return kind == CentralDirection::Mirror ? 0 : 1; }

// Rows e1, e2, a: an orthonormal frame whose third axis is a (unit).
Mat3 axis_frame(const Vec3& a) {
  const Vec3 helper = std::abs(a.x()) < 0.9 ? Vec3(1, 0, 0) : Vec3(0, 1, 0);
  const Vec3 e1 = (helper - helper.dot(a) * a).normalized();
  const Vec3 e2 = a.cross(e1);
  Mat3 b;
  b.row(0) = e1.transpose();
  b.row(1) = e2.transpose();
  b.row(2) = a.transpose();
  return b;
}

}  // namespace

DoubleIndirectionWarp::DoubleIndirectionWarp(int width, int height, const DoubleIndirectionOptions& options)
    : width_(width), height_(height), options_(options) {
  if (width < 1 || height < 1) throw std::invalid_argument("DoubleIndirectionWarp: size must be positive");
  if (!options.axis.allFinite() || !(options.axis.norm() > 0))
    throw std::invalid_argument("DoubleIndirectionWarp: the axis must be a finite, non-zero direction");
  lon_ = options.longitudes > 0 ? options.longitudes : std::max(width, 3);
  lat_ = options.latitudes > 0 ? options.latitudes : std::max(width / 2 + 1, 3);
  if (lon_ < 3 || lat_ < 3) throw std::invalid_argument("DoubleIndirectionWarp: the table needs at least 3 x 3 nodes");
  if (double(lon_) * double(lat_) > kMaxNodes)
    throw std::invalid_argument("DoubleIndirectionWarp: a table of " + std::to_string(lon_) + " x " +
                                std::to_string(lat_) + " nodes is larger than " + std::to_string(long(kMaxNodes)) +
                                " nodes");
  axis_from_view_ = axis_frame(options.axis.normalized());

  // Screen tables: each texel's central direction (clamped to the disc) as table coordinates.
  const double to_u = lon_ / (2 * kPi), to_v = (lat_ - 1) / kPi;
  for (CentralDirection kind : {CentralDirection::Mirror, CentralDirection::Normal}) {
    std::vector<float>& s = screen_[kind_index(kind)];
    s.resize(std::size_t(width) * std::size_t(height) * 2);
    for (int r = 0; r < height; ++r)
      for (int c = 0; c < width; ++c) {
        Vec2 xy = sphere_map::disc_from_pixel(Vec2(c, r), width, height);
        if (xy.squaredNorm() > 1) xy.normalize();
        const auto [lon, lat] = address(central_direction(kind, xy));
        const std::size_t i = (std::size_t(r) * std::size_t(width) + std::size_t(c)) * 2;
        s[i] = float(lon * to_u);
        s[i + 1] = float(lat * to_v);
      }
  }
  // Node directions, then the tables of the identity swing.
  node_dirs_.resize(std::size_t(lon_) * std::size_t(lat_));
  for (int j = 0; j < lat_; ++j)
    for (int i = 0; i < lon_; ++i)
      node_dirs_[std::size_t(j) * std::size_t(lon_) + std::size_t(i)] =
          direction(2 * kPi * i / lon_, kPi * j / (lat_ - 1));
  for (CentralDirection kind : {CentralDirection::Mirror, CentralDirection::Normal})
    base_[kind_index(kind)] = build(kind, Mat3::Identity());
}

std::pair<double, double> DoubleIndirectionWarp::address(const Vec3& dir) const {
  const Vec3 a = axis_from_view_ * dir.normalized();
  double lon = std::atan2(a.y(), a.x());
  if (lon < 0) lon += 2 * kPi;
  if (lon >= 2 * kPi) lon = 0;  // -0 and a hair below 0 round to 2 pi
  return {lon, std::acos(std::clamp(a.z(), -1.0, 1.0))};
}

Vec3 DoubleIndirectionWarp::direction(double lon, double lat) const {
  return axis_from_view_.transpose() *
         Vec3(std::sin(lat) * std::cos(lon), std::sin(lat) * std::sin(lon), std::cos(lat));
}

double DoubleIndirectionWarp::twist(const Mat3& source_from_dest) const {
  return split(source_from_dest).offset * 2 * kPi / lon_;
}

// M' = B M B^T = S Rz(delta): delta = 2 atan2(q_z, q_w) is the twist of M' about z (its quaternion
// with the x and y parts dropped); S = M' Rz(-delta), expressed back in the view frame for the table.
DoubleIndirectionWarp::Split DoubleIndirectionWarp::split(const Mat3& m) const {
  const Mat3 mp = axis_from_view_ * m * axis_from_view_.transpose();
  const Eigen::Quaterniond q(mp);
  const double delta = 2 * std::atan2(q.z(), q.w());
  Mat3 rz;
  rz << std::cos(delta), -std::sin(delta), 0, std::sin(delta), std::cos(delta), 0, 0, 0, 1;
  const Mat3 swing_axis = mp * rz.transpose();
  Split s;
  s.offset = delta * lon_ / (2 * kPi);
  s.twist_only = (swing_axis - Mat3::Identity()).cwiseAbs().maxCoeff() <= 1e-9;
  s.swing = axis_from_view_.transpose() * swing_axis * axis_from_view_;
  return s;
}

bool DoubleIndirectionWarp::offset_only(const Mat3& source_from_dest) const {
  return split(source_from_dest).twist_only;
}

std::shared_ptr<const DoubleIndirectionWarp::Table> DoubleIndirectionWarp::build(CentralDirection kind,
                                                                                 const Mat3& swing) const {
  auto t = std::make_shared<Table>();
  t->kind = kind;
  t->swing = swing;
  t->nodes.resize(node_dirs_.size());
  for (std::size_t k = 0; k < node_dirs_.size(); ++k) {
    const WarpSample w = warp_direction(kind, swing * node_dirs_[k]);
    t->nodes[k] = {float(w.disc.x()), float(w.disc.y()), float(w.rim)};
  }
  t->safe.resize(std::size_t(lat_ - 1) * std::size_t(lon_));
  for (int j = 0; j + 1 < lat_; ++j)
    for (int i = 0; i < lon_; ++i) {
      const int i1 = i + 1 == lon_ ? 0 : i + 1;
      const Node* corner[4] = {&t->nodes[std::size_t(j * lon_ + i)], &t->nodes[std::size_t(j * lon_ + i1)],
                               &t->nodes[std::size_t((j + 1) * lon_ + i)], &t->nodes[std::size_t((j + 1) * lon_ + i1)]};
      float lo_x = corner[0]->x, hi_x = lo_x, lo_y = corner[0]->y, hi_y = lo_y, rim = corner[0]->rim;
      for (const Node* n : corner) {
        lo_x = std::min(lo_x, n->x), hi_x = std::max(hi_x, n->x);
        lo_y = std::min(lo_y, n->y), hi_y = std::max(hi_y, n->y);
        rim = std::min(rim, n->rim);
      }
      // The normal warp is continuous across its rim (normals facing away go to the nearest rim
      // point) and jumps only straight behind, which the spread catches; the mirror warp's
      // coordinates jump across the whole rim near its singular direction.
      const bool safe = std::max(hi_x - lo_x, hi_y - lo_y) <= options_.max_spread &&
                        (kind == CentralDirection::Normal || rim >= options_.min_rim);
      t->safe[std::size_t(j * lon_ + i)] = safe;
      t->exact_cells += !safe;
    }
  return t;
}

std::shared_ptr<const DoubleIndirectionWarp::Table> DoubleIndirectionWarp::table(CentralDirection kind,
                                                                                 const Split& s) const {
  if (s.twist_only) return base_[kind_index(kind)];
  std::lock_guard<std::mutex> lock(mutex_);
  for (const auto& t : cache_)
    if (t->kind == kind && t->swing == s.swing) return t;
  auto t = build(kind, s.swing);
  ++built_;
  if (cache_.size() >= kCacheTables) cache_.erase(cache_.begin());
  cache_.push_back(t);
  return t;
}

int DoubleIndirectionWarp::exact_cells(CentralDirection kind, const Mat3& source_from_dest) const {
  return table(kind, split(source_from_dest))->exact_cells;
}

int DoubleIndirectionWarp::tables_built() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return built_;
}

// float32, as the table: u in [0, 2 columns) (a screen longitude plus a wrapped offset, each in
// [0, columns), wraps with one subtraction), v in [0, rows - 1]. Raw pointers and the sizes as
// arguments, inlined: the row loop keeps them in registers.
inline bool DoubleIndirectionWarp::interpolate(const Node* nodes, const unsigned char* safe, int columns, int rows,
                                               float u, float v, WarpSample& o) {
  if (u >= float(columns)) u -= float(columns);
  const int i = std::min(int(u), columns - 1), j = std::min(int(v), rows - 2);
  const float fu = u - float(i), fv = v - float(j);
  const int i1 = i + 1 == columns ? 0 : i + 1;
  const int k = j * columns + i;
  if (!safe[k]) return false;
  const Node &a = nodes[k], &b = nodes[k - i + i1], &c = nodes[k + columns], &d = nodes[k + columns - i + i1];
  const float w00 = (1 - fu) * (1 - fv), w10 = fu * (1 - fv), w01 = (1 - fu) * fv, w11 = fu * fv;
  Vec2 disc(w00 * a.x + w10 * b.x + w01 * c.x + w11 * d.x, w00 * a.y + w10 * b.y + w01 * c.y + w11 * d.y);
  // Interpolated points stay in the source disc (a chord of the rim can bulge past it).
  const double n2 = disc.squaredNorm();
  if (n2 > 1.0) disc /= std::sqrt(n2);
  o = {disc, double(w00 * a.rim + w10 * b.rim + w01 * c.rim + w11 * d.rim)};
  return true;
}

// The offset in table columns, wrapped into [0, columns).
float DoubleIndirectionWarp::wrapped(double u) const {
  const float w = float(u - lon_ * std::floor(u / lon_));
  return w < float(lon_) ? w : 0.f;
}

WarpSample DoubleIndirectionWarp::lookup(CentralDirection kind, const Mat3& source_from_dest, double lon,
                                         double lat) const {
  const Split s = split(source_from_dest);
  WarpSample o;
  const float v = float(std::clamp(lat, 0.0, kPi) * (lat_ - 1) / kPi);
  const auto t = table(kind, s);
  if (interpolate(t->nodes.data(), t->safe.data(), lon_, lat_, wrapped(lon * lon_ / (2 * kPi) + s.offset), v, o))
    return o;
  return warp_direction(kind, source_from_dest * direction(lon, lat));
}

void DoubleIndirectionWarp::warp_row(CentralDirection kind, const Mat3& source_from_dest, int width, int height,
                                     int row, int c_begin, int c_end, WarpSample* out) const {
  if (width != width_ || height != height_)
    throw std::invalid_argument("DoubleIndirectionWarp: built for " + std::to_string(width_) + "x" +
                                std::to_string(height_) + ", asked for " + std::to_string(width) + "x" +
                                std::to_string(height));
  const Split s = split(source_from_dest);
  const auto t = table(kind, s);
  const float* screen = screen_[kind_index(kind)].data() + (std::size_t(row) * std::size_t(width)) * 2;
  const float offset = wrapped(s.offset);
  const Node* nodes = t->nodes.data();
  const unsigned char* safe = t->safe.data();
  const int columns = lon_, rows = lat_;
  for (int c = c_begin; c < c_end; ++c) {
    WarpSample& o = out[c - c_begin];
    if (interpolate(nodes, safe, columns, rows, screen[2 * c] + offset, screen[2 * c + 1], o)) continue;
    const Vec2 xy = sphere_map::disc_from_pixel(Vec2(c, row), width, height);
    o = warp_direction(kind, source_from_dest * central_direction(kind, xy));
  }
}

}  // namespace rsibr
