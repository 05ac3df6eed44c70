#include "core/ray_scene.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <stdexcept>
#include <string>

namespace rsibr {

struct RayScene::Impl {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
};

namespace {
void check_device(RTCDevice device, const char* what) {
  const RTCError e = rtcGetDeviceError(device);
  if (e != RTC_ERROR_NONE)
    throw std::runtime_error(std::string("Embree: ") + what + " failed (error " + std::to_string(int(e)) + ")");
}
}  // namespace

RayScene::RayScene(const Mesh& mesh) : mesh_(mesh), impl_(std::make_unique<Impl>()) {
  impl_->device = rtcNewDevice(nullptr);
  if (!impl_->device) throw std::runtime_error("Embree: cannot create a device");
  impl_->scene = rtcNewScene(impl_->device);
  // Robust mode: no missed hits on shared edges (watertight), at a small cost.
  rtcSetSceneFlags(impl_->scene, RTC_SCENE_FLAG_ROBUST);
  rtcSetSceneBuildQuality(impl_->scene, RTC_BUILD_QUALITY_HIGH);
  RTCGeometry geom = rtcNewGeometry(impl_->device, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                               3 * sizeof(float), mesh.positions.size()));
  auto* indices = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                 3 * sizeof(unsigned), mesh.triangles.size()));
  check_device(impl_->device, "allocating geometry buffers");
  for (std::size_t i = 0; i < mesh.positions.size(); ++i)
    for (int k = 0; k < 3; ++k) vertices[3 * i + k] = mesh.positions[i][k];
  for (std::size_t i = 0; i < mesh.triangles.size(); ++i)
    for (int k = 0; k < 3; ++k) indices[3 * i + k] = mesh.triangles[i][k];
  rtcCommitGeometry(geom);
  rtcAttachGeometry(impl_->scene, geom);
  rtcReleaseGeometry(geom);
  rtcCommitScene(impl_->scene);
  check_device(impl_->device, "building the scene");
}

RayScene::~RayScene() {
  if (impl_->scene) rtcReleaseScene(impl_->scene);
  if (impl_->device) rtcReleaseDevice(impl_->device);
}

namespace {
void fill_ray(RTCRay& ray, const Vec3& o, const Vec3& d, double t_near, double t_far) {
  ray.org_x = float(o.x());
  ray.org_y = float(o.y());
  ray.org_z = float(o.z());
  ray.dir_x = float(d.x());
  ray.dir_y = float(d.y());
  ray.dir_z = float(d.z());
  ray.tnear = float(t_near);
  ray.tfar = t_far >= double(std::numeric_limits<float>::max()) ? std::numeric_limits<float>::infinity() : float(t_far);
  ray.time = 0;
  ray.mask = 0xFFFFFFFFu;
  ray.id = 0;
  ray.flags = 0;
}
}  // namespace

RayHit RayScene::intersect(const Vec3& origin, const Vec3& direction, double t_near, double t_far) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit rh;
  fill_ray(rh.ray, origin, direction, t_near, t_far);
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(impl_->scene, &context, &rh);
  RayHit out;
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return out;
  out.hit = true;
  out.t = rh.ray.tfar;
  out.triangle = rh.hit.primID;
  out.u = rh.hit.u;
  out.v = rh.hit.v;
  return out;
}

void RayScene::intersect_coherent(const Vec3& origin, const Vec3* directions, int count, RayHit* hits, double t_near,
                                  double t_far) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  const float far =
      t_far >= double(std::numeric_limits<float>::max()) ? std::numeric_limits<float>::infinity() : float(t_far);
  alignas(64) RTCRayHit16 packet;
  alignas(64) int valid[16];
  for (int start = 0; start < count; start += 16) {
    const int n = std::min(16, count - start);
    for (int i = 0; i < 16; ++i) {
      const Vec3& d = directions[start + std::min(i, n - 1)];
      valid[i] = i < n ? -1 : 0;
      packet.ray.org_x[i] = float(origin.x());
      packet.ray.org_y[i] = float(origin.y());
      packet.ray.org_z[i] = float(origin.z());
      packet.ray.dir_x[i] = float(d.x());
      packet.ray.dir_y[i] = float(d.y());
      packet.ray.dir_z[i] = float(d.z());
      packet.ray.tnear[i] = float(t_near);
      packet.ray.tfar[i] = far;
      packet.ray.time[i] = 0;
      packet.ray.mask[i] = 0xFFFFFFFFu;
      packet.ray.id[i] = unsigned(i);
      packet.ray.flags[i] = 0;
      packet.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
      packet.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
    }
    rtcIntersect16(valid, impl_->scene, &context, &packet);
    for (int i = 0; i < n; ++i) {
      RayHit& out = hits[start + i];
      out = RayHit{};
      if (packet.hit.geomID[i] == RTC_INVALID_GEOMETRY_ID) continue;
      out.hit = true;
      out.t = packet.ray.tfar[i];
      out.triangle = packet.hit.primID[i];
      out.u = packet.hit.u[i];
      out.v = packet.hit.v[i];
    }
  }
}

bool RayScene::occluded(const Vec3& origin, const Vec3& direction, double t_near, double t_far) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRay ray;
  fill_ray(ray, origin, direction, t_near, t_far);
  rtcOccluded1(impl_->scene, &context, &ray);
  return ray.tfar < 0;  // Embree sets tfar = -inf on a hit
}

Vec3 RayScene::position(const RayHit& hit) const {
  const auto& tri = mesh_.triangles[hit.triangle];
  const double w0 = 1 - hit.u - hit.v;
  return w0 * mesh_.positions[tri[0]].cast<double>() + hit.u * mesh_.positions[tri[1]].cast<double>() +
         hit.v * mesh_.positions[tri[2]].cast<double>();
}

Vec3 RayScene::geometric_normal(const RayHit& hit) const {
  const auto& tri = mesh_.triangles[hit.triangle];
  const Vec3 p0 = mesh_.positions[tri[0]].cast<double>();
  const Vec3 n = (mesh_.positions[tri[1]].cast<double>() - p0).cross(mesh_.positions[tri[2]].cast<double>() - p0);
  return n.normalized();
}

Vec3 RayScene::shading_normal(const RayHit& hit) const {
  const auto& tri = mesh_.triangles[hit.triangle];
  const double w0 = 1 - hit.u - hit.v;
  const Vec3 n = w0 * mesh_.normals[tri[0]].cast<double>() + hit.u * mesh_.normals[tri[1]].cast<double>() +
                 hit.v * mesh_.normals[tri[2]].cast<double>();
  const double len = n.norm();
  return len > 1e-12 ? Vec3(n / len) : geometric_normal(hit);
}

}  // namespace rsibr
