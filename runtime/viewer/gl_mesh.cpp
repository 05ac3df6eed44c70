#include "runtime/viewer/gl_mesh.h"

namespace rsibr::viewer {

GlMesh::GlMesh(const Mesh& mesh) : count_(GLsizei(3 * mesh.triangles.size())) {
  static_assert(sizeof(Eigen::Vector3f) == 3 * sizeof(float) && sizeof(std::array<uint32_t, 3>) == 12);
  glGenVertexArrays(1, &vao_);
  glBindVertexArray(vao_);
  glGenBuffers(3, buffers_);
  glBindBuffer(GL_ARRAY_BUFFER, buffers_[0]);
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(mesh.positions.size() * 12), mesh.positions.data(), GL_STATIC_DRAW);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 12, nullptr);
  glBindBuffer(GL_ARRAY_BUFFER, buffers_[1]);
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(mesh.normals.size() * 12), mesh.normals.data(), GL_STATIC_DRAW);
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 12, nullptr);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, buffers_[2]);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(mesh.triangles.size() * 12), mesh.triangles.data(), GL_STATIC_DRAW);
  glBindVertexArray(0);
}

GlMesh::~GlMesh() {
  glDeleteBuffers(3, buffers_);
  glDeleteVertexArrays(1, &vao_);
}

void GlMesh::draw() const {
  glBindVertexArray(vao_);
  glDrawElements(GL_TRIANGLES, count_, GL_UNSIGNED_INT, nullptr);
  glBindVertexArray(0);
}

}  // namespace rsibr::viewer
