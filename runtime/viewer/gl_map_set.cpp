#include "runtime/viewer/gl_map_set.h"

#include "runtime/gpu_map_data.h"
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
  const GpuMapData d = gpu_map_data(maps, view_set_, blend);
  try {
    warp_ = make_warp({warp, rings, axis_in_views(maps, Vec3(0, 1, 0))}, map_size_, map_size_);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string("viewer: ") + e.what());
  }
  engine_ = std::make_unique<BlendEngine>(maps_, view_set_, blend_);
  glGenTextures(6, textures_);
  // 0: the maps; 1: view data; 2, 3: triangles and their edge planes; 5: boundary arcs
  // (runtime/gpu_map_data.h).
  glBindTexture(GL_TEXTURE_2D_ARRAY, textures_[0]);
  glTexImage3D(GL_TEXTURE_2D_ARRAY, 0, GL_RGBA32F, d.width, d.height, d.views, 0, GL_RGBA, GL_FLOAT, d.maps.data());
  nearest(GL_TEXTURE_2D_ARRAY);
  glBindTexture(GL_TEXTURE_2D, textures_[1]);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, d.views, 4, 0, GL_RGBA, GL_FLOAT, d.view_data.data());
  nearest(GL_TEXTURE_2D);
  glBindTexture(GL_TEXTURE_2D, textures_[2]);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32I, d.triangle_count, 1, 0, GL_RGBA_INTEGER, GL_INT, d.triangles.data());
  nearest(GL_TEXTURE_2D);
  glBindTexture(GL_TEXTURE_2D, textures_[3]);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, d.triangle_count, 3, 0, GL_RGBA, GL_FLOAT, d.edge_planes.data());
  nearest(GL_TEXTURE_2D);
  arc_count_ = d.arc_count;
  glBindTexture(GL_TEXTURE_2D, textures_[5]);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32I, std::max(arc_count_, 1), 1, 0, GL_RGBA_INTEGER, GL_INT, d.arcs.data());
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
