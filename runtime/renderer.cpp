#include "runtime/renderer.h"

#include "runtime/blend_engine.h"
#include "runtime/disc_sampler.h"
#include "runtime/make_warp.h"
#include "runtime/warp.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <chrono>
#include <cmath>
#include <stdexcept>

namespace rsibr {

RenderMode render_mode_from_string(const std::string& name) {
  if (name == "paper") return RenderMode::Paper;
  if (name == "per-pixel") return RenderMode::PerPixel;
  throw std::invalid_argument("render: unknown mode '" + name + "' (expected paper or per-pixel)");
}

const char* to_string(RenderMode mode) { return mode == RenderMode::Paper ? "paper" : "per-pixel"; }

namespace {

// Tiles of kTile x kTile pixels, traced in 4 x 4 blocks (one Embree packet of 16 each).
constexpr int kTile = 16;

struct TileGrid {
  int width, height, cols, rows;
  TileGrid(int w, int h) : width(w), height(h), cols((w + kTile - 1) / kTile), rows((h + kTile - 1) / kTile) {}
  int count() const { return cols * rows; }
  // Whether the tile's pixel area meets rect (declared below).
  template <class Rect>
  bool overlaps(int tile, const Rect& rect) const {
    const int x0 = (tile % cols) * kTile, y0 = (tile / cols) * kTile;
    return rect.overlaps(x0 - 0.5, y0 - 0.5, x0 + kTile - 0.5, y0 + kTile - 0.5);
  }
  // The tile's pixels (x, y) in packet order: 4 x 4 blocks, each block row by row. Returns the count.
  int pixels(int tile, int* xs, int* ys) const {
    const int x0 = (tile % cols) * kTile, y0 = (tile / cols) * kTile;
    int n = 0;
    for (int by = 0; by < kTile; by += 4)
      for (int bx = 0; bx < kTile; bx += 4)
        for (int j = 0; j < 16; ++j) {
          const int x = x0 + bx + (j & 3), y = y0 + by + (j >> 2);
          if (x >= width || y >= height) continue;
          xs[n] = x;
          ys[n] = y;
          ++n;
        }
    return n;
  }
};

// A sample's normal difference to a neighbouring pixel's hit: the smaller of the backward and the
// forward one where both pixels hit (so a silhouette or a depth step on one side does not widen the
// footprint), the one that exists otherwise, zero where neither does. a, b: sample indices or -1.
Vec3 smaller_difference(int a, int b, const Vec3& n, const Vec3* normals) {
  const bool ha = a >= 0, hb = b >= 0;
  if (!ha && !hb) return Vec3::Zero();
  const Vec3 da = ha ? Vec3(n - normals[a]) : Vec3::Zero(), db = hb ? Vec3(normals[b] - n) : Vec3::Zero();
  if (ha && hb) return da.squaredNorm() <= db.squaredNorm() ? da : db;
  return ha ? da : db;
}

int spp_side(int spp) {
  const int k = int(std::lround(std::sqrt(double(spp))));
  if (spp < 1 || k * k != spp)
    throw std::invalid_argument("render: spp must be a perfect square (1, 4, 9, ...), not " + std::to_string(spp));
  return k;
}

// The image rectangle (pixel coordinates, mrcal convention) outside which no ray can hit the mesh:
// the bounds of the projected corners of the mesh's bounding box, grown by one pixel for the float
// arithmetic of the rays. A box not entirely in front of the camera gives the whole plane.
struct ImageRect {
  double x0 = -1e300, y0 = -1e300, x1 = 1e300, y1 = 1e300;
  bool contains(double x, double y) const { return x >= x0 && x <= x1 && y >= y0 && y <= y1; }
  bool overlaps(double ax, double ay, double bx, double by) const {
    return ax <= x1 && bx >= x0 && ay <= y1 && by >= y0;
  }
};

ImageRect projected_bounds(const Camera& cam, const Eigen::AlignedBox3f& box) {
  ImageRect r;
  if (box.isEmpty()) return ImageRect{1, 1, 0, 0};  // nothing can be hit
  const Mat3 cam_from_world = cam.world_from_cam.transpose();
  const double scale = (box.max() - box.min()).cast<double>().norm() + (box.center().cast<double>() - cam.eye).norm();
  double x0 = 1e300, y0 = 1e300, x1 = -1e300, y1 = -1e300;
  for (int corner = 0; corner < 8; ++corner) {
    const Vec3 p = box.corner(Eigen::AlignedBox3f::CornerType(corner)).cast<double>();
    const Vec3 q = cam_from_world * (p - cam.eye);
    if (!(q.z() > 1e-6 * scale)) return r;  // (partly) behind the camera: no culling
    const double x = cam.fx * q.x() / q.z() + cam.cx, y = cam.fy * q.y() / q.z() + cam.cy;
    x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
  }
  return ImageRect{x0 - 1, y0 - 1, x1 + 1, y1 + 1};
}

// The samples at offset (ox, oy) of the n pixels (xs, ys): hits[i] and, for traced samples (or every
// sample with all_dirs), dirs[i]. Samples outside `rect` are misses without a ray.
void trace_samples(const RayScene& scene, const Camera& cam, const ImageRect& rect, int n, const int* xs, const int* ys,
                   double ox, double oy, bool all_dirs, Vec3* dirs, RayHit* hits) {
  int index[kTile * kTile];
  Vec3 packed[kTile * kTile];
  RayHit packed_hits[kTile * kTile];
  int m = 0;
  for (int i = 0; i < n; ++i) {
    const double x = xs[i] + ox, y = ys[i] + oy;
    const bool inside = rect.contains(x, y);
    hits[i] = RayHit{};
    if (!inside && !all_dirs) continue;
    dirs[i] = cam.ray_direction(x, y);
    if (!inside) continue;
    index[m] = i;
    packed[m++] = dirs[i];
  }
  if (m > 0) scene.intersect_coherent(cam.eye, packed, m, packed_hits);
  for (int j = 0; j < m; ++j) hits[index[j]] = packed_hits[j];
}

}  // namespace

struct RenderSet {
  const MapSet* maps = nullptr;
  std::unique_ptr<ViewSet> views;
  std::unique_ptr<BlendEngine> engine;
};

struct Renderer::Impl {
  std::unique_ptr<RayScene> scene;
  Eigen::AlignedBox3f bounds;
  std::vector<RenderSet> sets;
  std::unique_ptr<Warp> warp;  // paper mode; nullptr = ExactWarp
  int map_size = 0;
  int spp_k = 1;
};

Renderer::Renderer(const Mesh& mesh, const std::vector<const MapSet*>& sets, const RenderOptions& options)
    : options_(options), impl_(std::make_unique<Impl>()) {
  if (sets.empty()) throw std::invalid_argument("render: no map set");
  impl_->spp_k = spp_side(options.spp);
  for (std::size_t i = 0; i < sets.size(); ++i) {
    if (!sets[i]) throw std::invalid_argument("render: null map set");
    validate(*sets[i]);
    RenderSet s;
    s.maps = sets[i];
    s.views = std::make_unique<ViewSet>(sets[i]->view_set());
    s.engine = std::make_unique<BlendEngine>(*s.maps, *s.views, options.blend);
    if (options.mode == RenderMode::PerPixel) s.engine->prepare_all();  // every view may be hit; checks them now
    impl_->sets.push_back(std::move(s));
  }
  impl_->map_size = options.map_size > 0 ? options.map_size : sets.front()->width();
  if (options.map_size < 0 || impl_->map_size < 2 || impl_->map_size > 16384)
    throw std::invalid_argument("render: map size must be in [2, 16384]");
  if (options.mode == RenderMode::Paper) {
    const int n = impl_->map_size;
    try {
      impl_->warp = make_warp({options.warp, options.rings, axis_in_views(*sets.front(), Vec3(0, 1, 0))}, n, n);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(std::string("render: ") + e.what());
    }
  }
  impl_->scene = std::make_unique<RayScene>(mesh);
  impl_->bounds = mesh.bounds();
}

Renderer::~Renderer() = default;

const RayScene& Renderer::scene() const { return *impl_->scene; }

long long Renderer::trace_only(const Camera& camera) const {
  const TileGrid grid(camera.width, camera.height);
  const RayScene& scene = *impl_->scene;
  const ImageRect rect = projected_bounds(camera, impl_->bounds);
  return tbb::parallel_reduce(
      tbb::blocked_range<int>(0, grid.count()), 0LL,
      [&](const tbb::blocked_range<int>& range, long long hits) {
        int xs[kTile * kTile], ys[kTile * kTile];
        Vec3 dirs[kTile * kTile];
        RayHit rh[kTile * kTile];
        for (int t = range.begin(); t != range.end(); ++t) {
          if (!grid.overlaps(t, rect)) continue;
          const int n = grid.pixels(t, xs, ys);
          trace_samples(scene, camera, rect, n, xs, ys, 0, 0, false, dirs, rh);
          for (int i = 0; i < n; ++i) hits += rh[i].hit;
        }
        return hits;
      },
      [](long long a, long long b) { return a + b; });
}

cv::Mat Renderer::render(const Camera& camera, RenderStats* stats) const {
  cv::Mat out;
  render(camera, out, stats);
  return out;
}

void Renderer::render(const Camera& camera, cv::Mat& out, RenderStats* stats) const {
  const auto t0 = std::chrono::steady_clock::now();
  if (camera.width < 1 || camera.height < 1) throw std::invalid_argument("render: empty image size");
  const RayScene& scene = *impl_->scene;
  const bool paper = options_.mode == RenderMode::Paper;
  const std::size_t nsets = impl_->sets.size();

  // Paper mode: one destination map per set for the camera's central direction.
  // With lod, the destination map is also held as a one-source engine of its own (a normal-warped
  // view along the camera's direction), so that a sample reads it at its footprint's level of detail
  // from the map's MIP pyramid, as per-pixel mode reads the sources.
  struct Dest {
    cv::Mat rgb;
    DiscMap map;
    Mat3 view_from_world;
    MapSet as_set;
    std::unique_ptr<ViewSet> as_views;
    std::unique_ptr<BlendEngine> engine;
    ViewWeights located;
  };
  std::vector<Dest> dests(paper ? nsets : 0);
  if (paper) {
    MapRequest request;
    request.width = request.height = impl_->map_size;
    request.warp = impl_->warp.get();
    for (std::size_t s = 0; s < nsets; ++s) {
      BlendResult b = impl_->sets[s].engine->map(camera.view_direction(), camera.up(), request);
      Dest& d = dests[s];
      d.rgb = b.rgb;
      d.map = DiscMap{&d.rgb, nullptr, b.rgb.cols, b.rgb.rows};
      d.view_from_world = b.world_from_view.transpose();
      if (options_.lod) {
        MapView mv;
        mv.view = b.world_from_view.col(2);
        mv.world_from_view = b.world_from_view;
        mv.warp = CentralDirection::Normal;
        mv.rgb = d.rgb;
        d.as_set.views.push_back(std::move(mv));
        d.as_views = std::make_unique<ViewSet>(std::vector<Vec3>{d.as_set.views.front().view});
        BlendRule one;  // one source: no fade, no confidence; the tap's value, renormalised at the rim
        one.rim_fade = 0;
        one.use_confidence = false;
        d.engine = std::make_unique<BlendEngine>(d.as_set, *d.as_views, one);
        d.located.count = 1;
        d.located.views = {0, -1, -1};
        d.located.weights = {1.0, 0.0, 0.0};
        d.located.inside = true;
      }
    }
  }
  const auto t1 = std::chrono::steady_clock::now();

  out.create(camera.height, camera.width, CV_32FC4);  // kept when its size and type match
  out.setTo(cv::Scalar::all(0));
  const TileGrid grid(camera.width, camera.height);
  const int k = impl_->spp_k;
  const double inv_spp = 1.0 / (k * k);
  const EnvMap* env = options_.environment;
  const ImageRect rect = projected_bounds(camera, impl_->bounds);
  const bool lod = options_.lod;

  struct Counts {
    long long hits = 0, covered = 0;
  };
  const Counts counts = tbb::parallel_reduce(
      tbb::blocked_range<int>(0, grid.count()), Counts{},
      [&](const tbb::blocked_range<int>& range, Counts c) {
        constexpr int N = kTile * kTile;
        int xs[N], ys[N];
        Vec3 dirs[N];
        RayHit rh[N];
        double acc[N][4];
        int hit_count[N];
        std::vector<int> hints(nsets, -1);  // per-set triangle of the last located view (speed only)
        Vec3 normals[N];
        int slot[kTile][kTile];  // lod: the sample index of the tile's pixel (x, y), -1 where it missed
        for (int t = range.begin(); t != range.end(); ++t) {
          if (!env && !grid.overlaps(t, rect)) continue;  // every sample misses: stays 0
          const int n = grid.pixels(t, xs, ys);
          const int tile_x0 = (t % grid.cols) * kTile, tile_y0 = (t / grid.cols) * kTile;
          if (lod)
            for (auto& row : slot) std::fill(row, row + kTile, -1);
          for (int i = 0; i < n; ++i) {
            acc[i][0] = acc[i][1] = acc[i][2] = acc[i][3] = 0;
            hit_count[i] = 0;
          }
          for (int sy = 0; sy < k; ++sy)
            for (int sx = 0; sx < k; ++sx) {
              const double ox = (sx + 0.5) / k - 0.5, oy = (sy + 0.5) / k - 0.5;
              trace_samples(scene, camera, rect, n, xs, ys, ox, oy, env != nullptr, dirs, rh);
              // With lod: every hit's normal first, then each sample's footprint from its neighbours.
              if (lod) {
                for (int i = 0; i < n; ++i) {
                  slot[ys[i] - tile_y0][xs[i] - tile_x0] = rh[i].hit ? i : -1;
                  if (!rh[i].hit) continue;
                  normals[i] = scene.shading_normal(rh[i]);
                  if (scene.geometric_normal(rh[i]).dot(dirs[i]) > 0) normals[i] = -normals[i];
                }
              }
              for (int i = 0; i < n; ++i) {
                const Vec3& d = dirs[i];
                if (!rh[i].hit) {
                  if (env) {
                    float L[kMaxChannels] = {0, 0, 0, 0};
                    sample_bilinear(*env, d, L);
                    if (env->channels() == 1) L[1] = L[2] = L[0];
                    acc[i][0] += L[0];
                    acc[i][1] += L[1];
                    acc[i][2] += L[2];
                    acc[i][3] += 1;
                  }
                  continue;
                }
                ++c.hits;
                ++hit_count[i];
                Vec3 nrm = scene.shading_normal(rh[i]);
                if (scene.geometric_normal(rh[i]).dot(d) > 0) nrm = -nrm;  // back face: two-sided
                const Vec3 v = -d;
                BlendEngine::Footprint fp;
                if (lod) {
                  const int px = xs[i] - tile_x0, py = ys[i] - tile_y0;
                  fp.dn_dx = smaller_difference(px > 0 ? slot[py][px - 1] : -1, px + 1 < kTile ? slot[py][px + 1] : -1,
                                                nrm, normals) /
                             double(k);
                  fp.dn_dy = smaller_difference(py > 0 ? slot[py - 1][px] : -1, py + 1 < kTile ? slot[py + 1][px] : -1,
                                                nrm, normals) /
                             double(k);
                }
                double L[3] = {0, 0, 0};
                for (std::size_t s = 0; s < nsets; ++s) {
                  if (paper && lod) {
                    const Vec3 Ls = dests[s].engine->radiance(dests[s].located, v, nrm, fp);
                    L[0] += Ls.x();
                    L[1] += Ls.y();
                    L[2] += Ls.z();
                  } else if (paper) {
                    const WarpSample ws = warp_direction(CentralDirection::Normal, dests[s].view_from_world * nrm);
                    double Ls[3], conf;
                    if (!sample_disc(dests[s].map, ws.disc, Ls, &conf)) continue;
                    L[0] += Ls[0];
                    L[1] += Ls[1];
                    L[2] += Ls[2];
                  } else {
                    const BlendEngine& engine = *impl_->sets[s].engine;
                    const Vec3 Ls = lod ? engine.radiance(engine.locate(v, &hints[s]), v, nrm, fp)
                                        : engine.radiance(engine.locate(v, &hints[s]), v, nrm);
                    L[0] += Ls.x();
                    L[1] += Ls.y();
                    L[2] += Ls.z();
                  }
                }
                acc[i][0] += L[0];
                acc[i][1] += L[1];
                acc[i][2] += L[2];
                acc[i][3] += 1;
              }
            }
          for (int i = 0; i < n; ++i) {
            float* o = out.ptr<float>(ys[i]) + 4 * xs[i];
            for (int ch = 0; ch < 4; ++ch) o[ch] = float(acc[i][ch] * inv_spp);
            c.covered += hit_count[i] > 0;
          }
        }
        return c;
      },
      [](Counts a, const Counts& b) {
        a.hits += b.hits;
        a.covered += b.covered;
        return a;
      });

  if (stats) {
    stats->samples = (long long)camera.width * camera.height * k * k;
    stats->hits = counts.hits;
    stats->covered_pixels = counts.covered;
    stats->seconds_blend = std::chrono::duration<double>(t1 - t0).count();
    stats->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
}

}  // namespace rsibr
