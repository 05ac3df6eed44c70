#include "runtime/tessellated_warp.h"

#include "core/sphere_map.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace rsibr {
namespace {

constexpr std::size_t kCacheFrames = 8;

}  // namespace

TessellatedWarp::TessellatedWarp(int width, int height, const TessellationOptions& options)
    : width_(width), height_(height), options_(options) {
  if (width < 1 || height < 1) throw std::invalid_argument("TessellatedWarp: size must be positive");
  if (options.rings < 1 || options.segments < 3)
    throw std::invalid_argument("TessellatedWarp: needs at least 1 ring and 3 segments");
  const int R = options.rings, S = options.segments;
  // Vertex 0 is the centre; vertex 1 + (k-1)*S + j is ring k >= 1, segment j.
  vertices_.push_back(Vec2(0, 0));
  for (int k = 1; k <= R; ++k) {
    const double rho = std::sin(0.5 * kPi * k / R);
    for (int j = 0; j < S; ++j) {
      const double a = 2 * kPi * j / S;
      vertices_.push_back(rho * Vec2(std::cos(a), std::sin(a)));
    }
  }
  auto vid = [&](int k, int j) { return k == 0 ? 0 : 1 + (k - 1) * S + ((j % S) + S) % S; };
  cells_ = R * S;
  cell_vertices_.resize(std::size_t(cells_));
  for (int k = 0; k < R; ++k)
    for (int j = 0; j < S; ++j)
      cell_vertices_[std::size_t(k * S + j)] = {vid(k, j), vid(k + 1, j), vid(k, j + 1), vid(k + 1, j + 1)};

  texels_.resize(std::size_t(width) * std::size_t(height));
  for (int r = 0; r < height; ++r)
    for (int c = 0; c < width; ++c) {
      const Vec2 xy = sphere_map::disc_from_pixel(Vec2(c, r), width, height);
      const double rho = std::min(1.0, xy.norm());
      const double t = std::asin(rho) * 2.0 * R / kPi;  // ring parameter, 0..R
      double a = std::atan2(xy.y(), xy.x());
      if (a < 0) a += 2 * kPi;
      const double s = a * S / (2 * kPi);  // segment parameter, 0..S
      const int k = std::clamp(int(std::floor(t)), 0, R - 1);
      const int j = std::clamp(int(std::floor(s)), 0, S - 1);
      const float u = float(std::clamp(t - k, 0.0, 1.0)), v = float(std::clamp(s - j, 0.0, 1.0));
      Corners& C = texels_[std::size_t(r) * std::size_t(width) + std::size_t(c)];
      C.cell = k * S + j;
      C.v = cell_vertices_[std::size_t(C.cell)];
      C.w = {(1 - u) * (1 - v), u * (1 - v), (1 - u) * v, u * v};
    }
}

std::shared_ptr<const TessellatedWarp::Frame> TessellatedWarp::frame(CentralDirection kind, const Mat3& m) const {
  {
    std::shared_lock<std::shared_mutex> lock(mutex_);
    for (const auto& f : cache_)
      if (f->kind == kind && f->source_from_dest == m) return f;
  }
  std::unique_lock<std::shared_mutex> lock(mutex_);
  for (const auto& f : cache_)  // another thread may have built it meanwhile
    if (f->kind == kind && f->source_from_dest == m) return f;
  auto f = std::make_shared<Frame>();
  f->kind = kind;
  f->source_from_dest = m;
  f->samples.resize(vertices_.size());
  for (std::size_t i = 0; i < vertices_.size(); ++i)
    f->samples[i] = warp_direction(kind, m * central_direction(kind, vertices_[i]));
  f->safe.resize(std::size_t(cells_));
  for (int cell = 0; cell < cells_; ++cell) {
    const auto& v = cell_vertices_[std::size_t(cell)];
    Vec2 lo = f->samples[std::size_t(v[0])].disc, hi = lo;
    double rim = 1.0;
    for (int i : v) {
      lo = lo.cwiseMin(f->samples[std::size_t(i)].disc);
      hi = hi.cwiseMax(f->samples[std::size_t(i)].disc);
      rim = std::min(rim, f->samples[std::size_t(i)].rim);
    }
    const bool safe = (hi - lo).maxCoeff() <= options_.max_spread && rim >= options_.min_rim;
    f->safe[std::size_t(cell)] = safe;
    f->exact_cells += !safe;
  }
  if (cache_.size() >= kCacheFrames) cache_.erase(cache_.begin());
  cache_.push_back(f);
  return f;
}

int TessellatedWarp::exact_cells(CentralDirection kind, const Mat3& source_from_dest) const {
  return frame(kind, source_from_dest)->exact_cells;
}

void TessellatedWarp::warp_row(CentralDirection kind, const Mat3& source_from_dest, int width, int height, int row,
                               int c_begin, int c_end, WarpSample* out) const {
  if (width != width_ || height != height_)
    throw std::invalid_argument("TessellatedWarp: built for " + std::to_string(width_) + "x" + std::to_string(height_) +
                                ", asked for " + std::to_string(width) + "x" + std::to_string(height));
  const auto f = frame(kind, source_from_dest);
  const Corners* row_texels = texels_.data() + std::size_t(row) * std::size_t(width);
  for (int c = c_begin; c < c_end; ++c) {
    const Corners& C = row_texels[c];
    WarpSample& o = out[c - c_begin];
    if (!f->safe[std::size_t(C.cell)]) {
      const Vec2 xy = sphere_map::disc_from_pixel(Vec2(c, row), width, height);
      o = warp_direction(kind, source_from_dest * central_direction(kind, xy));
      continue;
    }
    Vec2 disc = Vec2::Zero();
    double rim = 0;
    for (int i = 0; i < 4; ++i) {
      const WarpSample& s = f->samples[std::size_t(C.v[std::size_t(i)])];
      disc += double(C.w[std::size_t(i)]) * s.disc;
      rim += double(C.w[std::size_t(i)]) * s.rim;
    }
    // Interpolated points stay in the source disc (a chord of the rim can bulge past it).
    const double n2 = disc.squaredNorm();
    if (n2 > 1.0) disc /= std::sqrt(n2);
    o = {disc, rim};
  }
}

}  // namespace rsibr
