// A triangle mesh (core/mesh.h) in OpenGL buffers: positions and normals (float, world), indices.
#pragma once

#include "core/mesh.h"

#include <epoxy/gl.h>

namespace rsibr::viewer {

class GlMesh {
 public:
  explicit GlMesh(const Mesh& mesh);  // needs a current context
  ~GlMesh();
  GlMesh(const GlMesh&) = delete;
  GlMesh& operator=(const GlMesh&) = delete;
  // Draws every triangle (attribute 0: position, 1: normal) with the program in use.
  void draw() const;
  GLsizei index_count() const { return count_; }

 private:
  GLuint vao_ = 0, buffers_[3] = {0, 0, 0};
  GLsizei count_ = 0;
};

}  // namespace rsibr::viewer
