// OpenGL shader programs: compile and link from GLSL text, errors as exceptions carrying the
// driver's log; uniform setters by name. Needs a current context (runtime/viewer/gl_window.h).
#pragma once

#include "core/vec.h"

#include <epoxy/gl.h>

#include <string>

namespace rsibr::viewer {

class GlProgram {
 public:
  GlProgram() = default;
  // Throws std::runtime_error("<name>: <stage> shader: <log>") when compiling or linking fails.
  GlProgram(const std::string& name, const std::string& vertex_source, const std::string& fragment_source);
  ~GlProgram();
  GlProgram(GlProgram&& other) noexcept;
  GlProgram& operator=(GlProgram&& other) noexcept;
  GlProgram(const GlProgram&) = delete;
  GlProgram& operator=(const GlProgram&) = delete;

  GLuint id() const { return id_; }
  void use() const { glUseProgram(id_); }
  // Setters for the program in use; a uniform the linker removed (unused) is ignored.
  void set(const char* name, int value) const;
  void set(const char* name, float value) const;
  void set(const char* name, const Vec2& value) const;
  void set(const char* name, const Vec3& value) const;
  void set(const char* name, const Mat3& value) const;  // column-major upload of the 3x3 matrix

 private:
  GLuint id_ = 0;
};

}  // namespace rsibr::viewer
