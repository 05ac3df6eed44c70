#include "runtime/viewer/mesh_pass.h"

#include "runtime/map_shader.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace rsibr::viewer {

MeshPass::MeshPass()
    : per_pixel_("mesh pass (per pixel)", kMeshVertexShader,
                 std::string("#version 330 core\n#define RSIBR_PAPER 0\n") + kMeshFragmentShader),
      paper_("mesh pass (paper)", kMeshVertexShader,
             std::string("#version 330 core\n#define RSIBR_PAPER 1\n") + kMeshFragmentShader) {
  for (const GlProgram* p : {&per_pixel_, &paper_}) {
    p->use();
    p->set("uMaps", 0);
    p->set("uViewData", 1);
    p->set("uTriangles", 2);
    p->set("uEdgePlanes", 3);
    p->set("uDest", 4);
    p->set("uArcs", 5);
  }
  glUseProgram(0);
}

void MeshPass::draw(const Camera& camera, const Eigen::AlignedBox3f& bounds, const GlMesh& mesh, GlMapSet& set,
                    const MeshPassOptions& options, int x0, int y0) const {
  const bool paper = options.mode == RenderMode::Paper;
  if (paper) set.update_destination(camera.view_direction(), camera.up());

  // Depth range: the bounding sphere along the view axis, near clamped to a small positive value.
  const Vec3 centre = bounds.center().cast<double>();
  const double radius = 0.5 * double(bounds.diagonal().norm());
  const double along = (centre - camera.eye).dot(camera.forward());
  const double far_z = std::max(along + 1.01 * radius, 1e-3);
  const double near_z = std::max(along - 1.01 * radius, far_z * 1e-5);
  // clip.z / clip.w = (A q.z + B) / q.z: -1 at near, +1 at far.
  const double A = (far_z + near_z) / (far_z - near_z), B = -2.0 * far_z * near_z / (far_z - near_z);

  glViewport(x0, y0, camera.width, camera.height);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDisable(GL_CULL_FACE);  // two-sided, as the renderer
  glDisable(GL_BLEND);
  glFrontFace(GL_CCW);
  const GlProgram& program_ = paper ? paper_ : per_pixel_;
  program_.use();
  program_.set("uCamFromWorld", Mat3(camera.world_from_cam.transpose()));
  program_.set("uWorldFromCam", camera.world_from_cam);
  program_.set("uEye", camera.eye);
  glUniform4f(glGetUniformLocation(program_.id(), "uIntrinsics"), float(camera.fx), float(camera.fy), float(camera.cx),
              float(camera.cy));
  program_.set("uSize", Vec2(camera.width, camera.height));
  program_.set("uOrigin", Vec2(x0, y0));
  program_.set("uDepth", Vec2(A, B));
  program_.set("uShowWeight", options.show_weight ? 1 : 0);
  program_.set("uRimFade", float(set.blend_options().rim_fade));
  glUniform2i(glGetUniformLocation(program_.id(), "uMapSize"), set.maps().width(), set.maps().height());
  glUniform2i(glGetUniformLocation(program_.id(), "uDestSize"), set.map_size(), set.map_size());
  program_.set("uTriangleCount", set.triangle_count());
  program_.set("uArcCount", set.arc_count());
  program_.set("uHint", set.view_set().locate(camera.view_direction()).triangle);
  if (paper) program_.set("uDestViewFromWorld", Mat3(set.destination().world_from_view.transpose()));
  set.bind_textures();
  mesh.draw();
  glUseProgram(0);
}

}  // namespace rsibr::viewer
