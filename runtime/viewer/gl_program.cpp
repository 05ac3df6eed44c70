#include "runtime/viewer/gl_program.h"

#include <stdexcept>
#include <utility>
#include <vector>

namespace rsibr::viewer {
namespace {
GLuint compile(const std::string& name, GLenum stage, const std::string& source) {
  const GLuint s = glCreateShader(stage);
  const char* text = source.c_str();
  glShaderSource(s, 1, &text, nullptr);
  glCompileShader(s);
  GLint ok = 0;
  glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    GLint len = 0;
    glGetShaderiv(s, GL_INFO_LOG_LENGTH, &len);
    std::vector<char> log(std::size_t(std::max(len, 1)), '\0');
    glGetShaderInfoLog(s, len, nullptr, log.data());
    glDeleteShader(s);
    throw std::runtime_error(name + ": " + (stage == GL_VERTEX_SHADER ? "vertex" : "fragment") +
                             " shader: " + log.data());
  }
  return s;
}
GLint location(GLuint program, const char* name) { return glGetUniformLocation(program, name); }
}  // namespace

GlProgram::GlProgram(const std::string& name, const std::string& vertex_source, const std::string& fragment_source) {
  const GLuint vs = compile(name, GL_VERTEX_SHADER, vertex_source);
  GLuint fs = 0;
  try {
    fs = compile(name, GL_FRAGMENT_SHADER, fragment_source);
  } catch (...) {
    glDeleteShader(vs);
    throw;
  }
  id_ = glCreateProgram();
  glAttachShader(id_, vs);
  glAttachShader(id_, fs);
  glLinkProgram(id_);
  glDeleteShader(vs);
  glDeleteShader(fs);
  GLint ok = 0;
  glGetProgramiv(id_, GL_LINK_STATUS, &ok);
  if (!ok) {
    GLint len = 0;
    glGetProgramiv(id_, GL_INFO_LOG_LENGTH, &len);
    std::vector<char> log(std::size_t(std::max(len, 1)), '\0');
    glGetProgramInfoLog(id_, len, nullptr, log.data());
    glDeleteProgram(id_);
    id_ = 0;
    throw std::runtime_error(name + ": link: " + log.data());
  }
}

GlProgram::~GlProgram() {
  if (id_) glDeleteProgram(id_);
}
GlProgram::GlProgram(GlProgram&& other) noexcept : id_(std::exchange(other.id_, 0)) {}
GlProgram& GlProgram::operator=(GlProgram&& other) noexcept {
  if (this != &other) {
    if (id_) glDeleteProgram(id_);
    id_ = std::exchange(other.id_, 0);
  }
  return *this;
}

void GlProgram::set(const char* name, int value) const { glUniform1i(location(id_, name), value); }
void GlProgram::set(const char* name, float value) const { glUniform1f(location(id_, name), value); }
void GlProgram::set(const char* name, const Vec2& v) const {
  glUniform2f(location(id_, name), float(v.x()), float(v.y()));
}
void GlProgram::set(const char* name, const Vec3& v) const {
  glUniform3f(location(id_, name), float(v.x()), float(v.y()), float(v.z()));
}
void GlProgram::set(const char* name, const Mat3& m) const {
  float f[9];
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r) f[3 * c + r] = float(m(r, c));
  glUniformMatrix3fv(location(id_, name), 1, GL_FALSE, f);
}

}  // namespace rsibr::viewer
