#include "core/mip_pyramid.h"

#include "core/parallel.h"
#include "core/resample.h"

#include <algorithm>
#include <cmath>

namespace rsibr {
namespace {

// Solid angle of the pixel-space rectangle [x0,x1] x [y0,y1] of a "pixel is point" layout (lat-long,
// or one face of a cube, with y relative to the face), in closed form.
double point_layout_rect_solid_angle(const Layout& L, double x0, double x1, double y0, double y1) {
  if (!(x1 > x0) || !(y1 > y0)) return 0.0;
  if (L.kind() == LayoutKind::LatLong) {
    const double dlat = kPi / (L.height() - 1), dlon = 2 * kPi / (L.width() - 1);
    return (std::sin(0.5 * kPi - dlat * y0) - std::sin(0.5 * kPi - dlat * y1)) * (x1 - x0) * dlon;
  }
  // Cube face: coordinates a, b in [-1,1] on the plane at unit distance (reflections and the
  // transposition between image and face axes do not change a rectangle's solid angle).
  const double s = 2.0 / (L.width() - 1);
  auto F = [](double a, double b) { return std::atan2(a * b, std::sqrt(1 + a * a + b * b)); };
  const double a0 = x0 * s - 1, a1 = x1 * s - 1, b0 = y0 * s - 1, b1 = y1 * s - 1;
  return F(a1, b1) - F(a0, b1) - F(a1, b0) + F(a0, b0);
}

}  // namespace

std::optional<Layout> nested_half(const Layout& L) {
  const int W = L.width(), H = L.height();
  switch (L.kind()) {
    case LayoutKind::LatLong:
      if (W % 2 == 1 && H % 2 == 1 && W >= 5 && H >= 3) return Layout(L.kind(), (W + 1) / 2, (H + 1) / 2);
      break;
    case LayoutKind::Cube:
      if (W % 2 == 1 && W >= 3) return Layout::with_size(L.kind(), (W + 1) / 2);
      break;
    case LayoutKind::Octahedral:
      if (W % 4 == 0) return Layout(L.kind(), W / 2, H / 2);
      break;
    case LayoutKind::Sphere:
      if (W % 2 == 0 && H % 2 == 0 && W >= 4 && H >= 4) return Layout(L.kind(), W / 2, H / 2);
      break;
  }
  return std::nullopt;
}

//   L_coarse(c) = sum_k L_fine(k) |cell_k n cell_c| / sum_k |cell_k n cell_c|
// with |.| the exact solid angle. Pixel-is-area layouts nest 2x2 fine cells per coarse cell;
// pixel-is-point layouts put coarse centre c on fine centre 2c, so a coarse cell [2c-1, 2c+1]
// holds one whole fine cell and halves (or quarters) of its neighbours.
EnvMap reduce_nested(const EnvMap& fine) {
  const Layout& F = fine.layout;
  const Layout C = *nested_half(F);
  EnvMap out = EnvMap::zeros(C, fine.channels());
  out.attributes = fine.attributes;
  const int ch = fine.channels();
  const bool point = F.kind() == LayoutKind::LatLong || F.kind() == LayoutKind::Cube;
  const int face_rows = F.kind() == LayoutKind::Cube ? F.width() : F.height();  // fine rows per face
  const int coarse_face_rows = C.kind() == LayoutKind::Cube ? C.width() : C.height();
  parallel_for_rows(C.height(), [&](int r) {
    const int face = r / coarse_face_rows, lr = r % coarse_face_rows;
    float* dst = out.pixels.ptr<float>(r);
    for (int c = 0; c < C.width(); ++c) {
      double acc[kMaxChannels] = {0, 0, 0, 0};
      double wsum = 0;
      auto add = [&](int fc, int flr, double w) {
        if (!(w > 0)) return;
        const float* px = fine.pixels.ptr<float>(face * face_rows + flr) + std::size_t(fc) * ch;
        for (int k = 0; k < ch; ++k) acc[k] += w * px[k];
        wsum += w;
      };
      if (point) {
        const double xmax = F.width() - 1, ymax = face_rows - 1;
        const double cx0 = std::max(0.0, 2.0 * c - 1), cx1 = std::min(xmax, 2.0 * c + 1);
        const double cy0 = std::max(0.0, 2.0 * lr - 1), cy1 = std::min(ymax, 2.0 * lr + 1);
        for (int fy = std::max(0, 2 * lr - 1); fy <= std::min(face_rows - 1, 2 * lr + 1); ++fy)
          for (int fx = std::max(0, 2 * c - 1); fx <= std::min(F.width() - 1, 2 * c + 1); ++fx) {
            const double x0 = std::max(cx0, fx - 0.5), x1 = std::min(cx1, fx + 0.5);
            const double y0 = std::max(cy0, fy - 0.5), y1 = std::min(cy1, fy + 0.5);
            add(fx, fy, point_layout_rect_solid_angle(F, x0, x1, y0, y1));
          }
      } else {
        for (int j = 0; j < 2; ++j)
          for (int i = 0; i < 2; ++i) add(2 * c + i, 2 * lr + j, F.texel_solid_angle(2 * c + i, 2 * lr + j));
      }
      if (wsum > 0)
        for (int k = 0; k < ch; ++k) dst[std::size_t(c) * ch + k] = float(acc[k] / wsum);
    }
  });
  return out;
}

namespace {

bool power_of_two(int n) { return n > 0 && (n & (n - 1)) == 0; }

// Whether halving nests all the way down: 2^m (+1 for pixel-is-point layouts) in each dimension.
bool nests_all_the_way(const Layout& L) {
  switch (L.kind()) {
    case LayoutKind::LatLong: return power_of_two(L.width() - 1) && power_of_two(L.height() - 1);
    case LayoutKind::Cube: return power_of_two(L.width() - 1);
    case LayoutKind::Octahedral:
    case LayoutKind::Sphere: return power_of_two(L.width()) && power_of_two(L.height());
  }
  return false;
}

}  // namespace

MipPyramid::MipPyramid(const EnvMap& base) {
  levels_.push_back(base);
  for (;;) {
    const Layout& top = levels_.back().layout;
    const auto half = nested_half(top);
    if (half && (levels_.size() > 1 || nests_all_the_way(top))) {
      levels_.push_back(reduce_nested(levels_.back()));
      continue;
    }
    // Not nested: resample once to the size nearest to half that nests all the way down
    // (2^m + 1 for pixel-is-point layouts, 2^m for pixel-is-area ones), then reduce exactly.
    const int W = top.width();
    const int p2 = 1 << std::max(1, int(std::lround(std::log2(std::max(2.0, W / 2.0)))));
    std::optional<Layout> next;
    switch (top.kind()) {
      case LayoutKind::LatLong:
        if (W >= 8 && top.height() >= 4) next = Layout(top.kind(), p2 + 1, p2 / 2 + 1);
        break;
      case LayoutKind::Cube:
        if (W >= 4) next = Layout::with_size(top.kind(), p2 + 1);
        break;
      case LayoutKind::Octahedral:
      case LayoutKind::Sphere:
        if (W >= 4) next = Layout::with_size(top.kind(), p2);
        break;
    }
    if (!next || *next == top) break;
    // One area-weighted resample (bilinear reconstruction of the base) to the nesting size.
    levels_.push_back(resample(levels_.back(), *next));
  }
}

void MipPyramid::sample(const Vec3& dir, double lod, float* out) const {
  const int ch = levels_.front().channels();
  lod = std::clamp(std::isfinite(lod) ? lod : 0.0, 0.0, double(levels_.size() - 1));
  const int l0 = int(std::floor(lod));
  const int l1 = std::min(l0 + 1, levels() - 1);
  const float f = float(lod - l0);
  sample_bilinear(levels_[std::size_t(l0)], dir, out);
  if (f == 0.f || l1 == l0) return;
  float upper[kMaxChannels];
  sample_bilinear(levels_[std::size_t(l1)], dir, upper);
  for (int k = 0; k < ch; ++k) out[k] = (1 - f) * out[k] + f * upper[k];
}

double MipPyramid::lod_for_solid_angle(const Vec3& dir, double omega) const {
  const Layout& L = levels_.front().layout;
  const double texel = L.solid_angle_density(L.pixel(dir));
  if (!(texel > 0) || !(omega > 0)) return 0.0;
  return std::max(0.0, 0.5 * std::log2(omega / texel));
}

}  // namespace rsibr
