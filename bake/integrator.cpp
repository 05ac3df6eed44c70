#include "bake/integrator.h"

#include "bake/filtered_importance_integrator.h"
#include "bake/mis_integrator.h"
#include "bake/reference_integrator.h"
#include "bake/shading_frame.h"
#include "bake/sh_integrator.h"
#include "core/parallel.h"
#include "core/sphere_map.h"

#include <atomic>
#include <stdexcept>

namespace rsibr {

std::unique_ptr<Integrator> make_integrator(const std::string& method, const EnvMap& env) {
  if (method == "reference") return std::make_unique<ReferenceIntegrator>(env);
  if (method == "mis") return std::make_unique<MisIntegrator>(env);
  if (method == "fis") return std::make_unique<FilteredImportanceIntegrator>(env);
  if (method == "sh") return std::make_unique<ShIntegrator>(env);
  throw std::invalid_argument("unknown integration method '" + method + "' (reference, mis, fis, sh)");
}

namespace integrator_detail {

std::optional<TexelFrame> texel_frame(int c, int r, int size, const Vec3& view, const Mat3& world_from_view) {
  const Vec2 xy = sphere_map::disc_from_pixel(Vec2(c, r), size, size);
  if (!(xy.squaredNorm() < 1.0)) return std::nullopt;  // centre outside the disc: 0
  const shading::Frame frame = shading::Frame::around((world_from_view * sphere_map::g_normal(xy)).normalized());
  const Vec3 wo = frame.to_local(view.normalized());
  if (!(wo.z() > 0)) return std::nullopt;  // viewer on or below the local horizon (the rim): 0
  return TexelFrame{frame, wo};
}

cv::Mat for_each_texel(int size, const Vec3& view, const Mat3& world_from_view, const cv::Mat& mask,
                       const std::function<Vec3(long, const TexelFrame&)>& texel,
                       const std::function<void(int)>& progress) {
  if (size < 1) throw std::invalid_argument("radiance map size must be >= 1");
  if (!mask.empty() && (mask.type() != CV_8UC1 || mask.rows != size || mask.cols != size))
    throw std::invalid_argument("texel mask must be CV_8UC1 of the map's size");
  cv::Mat out(size, size, CV_32FC3, cv::Scalar::all(0));
  const Vec3 v = view.normalized();
  std::atomic<int> rows_done{0};
  parallel_for_rows(size, [&](int r) {
    float* row = out.ptr<float>(r);
    const unsigned char* keep = mask.empty() ? nullptr : mask.ptr<unsigned char>(r);
    for (int c = 0; c < size; ++c) {
      if (keep && !keep[c]) continue;
      const auto t = texel_frame(c, r, size, v, world_from_view);
      if (!t) continue;
      const Vec3 L = texel(long(r) * size + c, *t);
      for (int k = 0; k < 3; ++k) row[3 * c + k] = float(L[k]);
    }
    const int done = ++rows_done;
    if (progress) progress(done);
  });
  return out;
}

}  // namespace integrator_detail
}  // namespace rsibr
