#include "runtime/viewer/gl_map_set.h"

#include "runtime/make_warp.h"

#include <algorithm>
#include <chrono>
#include <map>
#include <utility>
#include <stdexcept>
#include <vector>

namespace rsibr::viewer {
namespace {
void nearest(GLenum target) {
  glTexParameteri(target, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTexParameteri(target, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glTexParameteri(target, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(target, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
}
}  // namespace

GlMapSet::GlMapSet(const MapSet& maps, const BlendOptions& blend, const std::string& warp, int map_size, int rings)
    : maps_(maps),
      view_set_(maps.view_set()),
      blend_(blend),
      warp_name_(warp),
      map_size_(map_size > 0 ? map_size : maps.width()) {
  check_blend_inputs(maps, view_set_);
  if (blend.barycentric != Barycentric::Gnomonic)
    throw std::invalid_argument("viewer: the GPU path implements the gnomonic barycentric weights only");
  if (view_set_.triangles().empty())
    throw std::invalid_argument("viewer: the map set's views have no spherical triangle (at least 3 views needed)");
  try {
    warp_ = make_warp({warp, rings, axis_in_views(maps, Vec3(0, 1, 0))}, map_size_, map_size_);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string("viewer: ") + e.what());
  }
  engine_ = std::make_unique<BlendEngine>(maps_, view_set_, blend_);
  const int W = maps.width(), H = maps.height(), N = int(maps.views.size());
  glGenTextures(6, textures_);

  // 0: the maps, RGB + confidence.
  std::vector<float> texels(std::size_t(W) * H * 4 * N);
  for (int i = 0; i < N; ++i) {
    check_blend_source(maps, i);
    const MapView& v = maps.views[std::size_t(i)];
    const bool conf = blend.use_confidence && !v.confidence.empty();
    for (int r = 0; r < H; ++r) {
      const float* s = v.rgb.ptr<float>(r);
      const float* c = conf ? v.confidence.ptr<float>(r) : nullptr;
      float* d = texels.data() + ((std::size_t(i) * H + r) * W) * 4;
      for (int x = 0; x < W; ++x) {
        d[4 * x] = s[3 * x];
        d[4 * x + 1] = s[3 * x + 1];
        d[4 * x + 2] = s[3 * x + 2];
        d[4 * x + 3] = c ? c[x] : 1.f;
      }
    }
  }
  glBindTexture(GL_TEXTURE_2D_ARRAY, textures_[0]);
  glTexImage3D(GL_TEXTURE_2D_ARRAY, 0, GL_RGBA32F, W, H, N, 0, GL_RGBA, GL_FLOAT, texels.data());
  nearest(GL_TEXTURE_2D_ARRAY);

  // 1: per view, rows 0..2 the rows of view_from_world (= the columns of world_from_view), row 0's
  // w the warp (0 mirror, 1 normal); row 3 the unit view vector of the view set.
  std::vector<float> data(std::size_t(N) * 4 * 4, 0.f);
  for (int i = 0; i < N; ++i) {
    const MapView& v = maps.views[std::size_t(i)];
    for (int row = 0; row < 3; ++row)
      for (int k = 0; k < 3; ++k) data[(std::size_t(row) * N + i) * 4 + k] = float(v.world_from_view(k, row));
    data[std::size_t(i) * 4 + 3] = v.warp == CentralDirection::Mirror ? 0.f : 1.f;
    const Vec3& u = view_set_.views()[std::size_t(i)];
    for (int k = 0; k < 3; ++k) data[(std::size_t(3) * N + i) * 4 + k] = float(u[k]);
  }
  glBindTexture(GL_TEXTURE_2D, textures_[1]);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, N, 4, 0, GL_RGBA, GL_FLOAT, data.data());
  nearest(GL_TEXTURE_2D);

  // 2, 3: triangles and their edge planes (unit a x b, b x c, c x a: the margin of locate).
  const auto& tris = view_set_.triangles();
  const auto& views = view_set_.views();
  const int T = int(tris.size());
  std::vector<int> idx;
  std::vector<float> planes(std::size_t(T) * 3 * 4, 0.f);
  for (int t = 0; t < T; ++t) {
    const auto& tri = tris[std::size_t(t)];
    idx.insert(idx.end(), {tri[0], tri[1], tri[2], 0});
    for (int e = 0; e < 3; ++e) {
      const Vec3 n =
          views[std::size_t(tri[std::size_t(e)])].cross(views[std::size_t(tri[std::size_t((e + 1) % 3)])]).normalized();
      for (int k = 0; k < 3; ++k) planes[(std::size_t(e) * T + t) * 4 + k] = float(n[k]);
    }
  }
  glBindTexture(GL_TEXTURE_2D, textures_[2]);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32I, T, 1, 0, GL_RGBA_INTEGER, GL_INT, idx.data());
  nearest(GL_TEXTURE_2D);
  glBindTexture(GL_TEXTURE_2D, textures_[3]);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, T, 3, 0, GL_RGBA, GL_FLOAT, planes.data());
  nearest(GL_TEXTURE_2D);

  // 5: the boundary arcs of a set that does not surround the sphere: the triangle edges no other
  // triangle shares (core/view_set.h's covered-region boundary), with their triangle.
  std::vector<int> arcs;
  if (!view_set_.surrounds()) {
    std::map<std::pair<int, int>, int> edges;  // undirected edge -> count
    for (const auto& tri : tris)
      for (int e = 0; e < 3; ++e) {
        const int a = tri[std::size_t(e)], b = tri[std::size_t((e + 1) % 3)];
        ++edges[{std::min(a, b), std::max(a, b)}];
      }
    for (int t = 0; t < T; ++t)
      for (int e = 0; e < 3; ++e) {
        const int a = tris[std::size_t(t)][std::size_t(e)], b = tris[std::size_t(t)][std::size_t((e + 1) % 3)];
        if (edges[{std::min(a, b), std::max(a, b)}] == 1) arcs.insert(arcs.end(), {a, b, t, 0});
      }
  }
  arc_count_ = int(arcs.size() / 4);
  if (arcs.empty()) arcs.assign(4, 0);
  glBindTexture(GL_TEXTURE_2D, textures_[5]);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32I, std::max(arc_count_, 1), 1, 0, GL_RGBA_INTEGER, GL_INT, arcs.data());
  nearest(GL_TEXTURE_2D);

  // 4: the destination map (paper mode), allocated here, filled per frame.
  glBindTexture(GL_TEXTURE_2D, textures_[4]);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, map_size_, map_size_, 0, GL_RGBA, GL_FLOAT, nullptr);
  nearest(GL_TEXTURE_2D);
  glBindTexture(GL_TEXTURE_2D, 0);
}

GlMapSet::~GlMapSet() { glDeleteTextures(6, textures_); }

void GlMapSet::set_rim_fade(double rim_fade) {
  if (rim_fade == blend_.rim_fade) return;
  blend_.rim_fade = rim_fade;
  engine_ = std::make_unique<BlendEngine>(maps_, view_set_, blend_);
}

const BlendResult& GlMapSet::update_destination(const Vec3& view, const Vec3& up) {
  const auto t0 = std::chrono::steady_clock::now();
  MapRequest request;
  request.width = request.height = map_size_;
  request.warp = warp_.get();
  engine_->map(view, up, request, destination_);  // the last frame's images reused
  cv::Mat rgba(map_size_, map_size_, CV_32FC4);
  const cv::Mat parts[] = {destination_.rgb, destination_.weight};
  const int from_to[] = {0, 0, 1, 1, 2, 2, 3, 3};
  cv::mixChannels(parts, 2, &rgba, 1, from_to, 4);
  glBindTexture(GL_TEXTURE_2D, textures_[4]);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, map_size_, map_size_, GL_RGBA, GL_FLOAT, rgba.data);
  glBindTexture(GL_TEXTURE_2D, 0);
  blend_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return destination_;
}

void GlMapSet::bind_textures() const {
  const GLenum targets[6] = {GL_TEXTURE_2D_ARRAY, GL_TEXTURE_2D, GL_TEXTURE_2D,
                             GL_TEXTURE_2D,       GL_TEXTURE_2D, GL_TEXTURE_2D};
  for (int i = 0; i < 6; ++i) {
    glActiveTexture(GLenum(GL_TEXTURE0 + i));
    glBindTexture(targets[i], textures_[i]);
  }
  glActiveTexture(GL_TEXTURE0);
}

}  // namespace rsibr::viewer
