#include "runtime/viewer/display_transform.h"

#include "core/colour.h"

#include <stdexcept>

namespace rsibr::viewer {
namespace OCIO = OCIO_NAMESPACE;

namespace {
const char* const kVertex = R"GLSL(#version 330 core
void main() {  // one triangle covering the viewport
  vec2 p = vec2(gl_VertexID == 1 ? 3.0 : -1.0, gl_VertexID == 2 ? 3.0 : -1.0);
  gl_Position = vec4(p, 0.0, 1.0);
}
)GLSL";

void check_names(const OCIO::ConstConfigRcPtr& config, const std::string& display, const std::string& view) {
  bool known = false;
  for (int i = 0; i < config->getNumDisplays(); ++i) known |= display == config->getDisplay(i);
  if (!known) throw std::runtime_error("unknown display '" + display + "' in the OpenColorIO config");
  known = false;
  for (int i = 0; i < config->getNumViews(display.c_str()); ++i) known |= view == config->getView(display.c_str(), i);
  if (!known) throw std::runtime_error("unknown view '" + view + "' for display '" + display + "'");
}
}  // namespace

std::vector<std::string> DisplayTransform::views(const std::string& display) {
  const auto config = colour_config();
  const std::string d = display.empty() ? std::string(config->getDefaultDisplay()) : display;
  std::vector<std::string> out;
  for (int i = 0; i < config->getNumViews(d.c_str()); ++i) out.emplace_back(config->getView(d.c_str(), i));
  return out;
}

DisplayTransform::DisplayTransform(const std::string& display, const std::string& view) {
  const auto config = colour_config();
  display_ = display.empty() ? std::string(config->getDefaultDisplay()) : display;
  view_ = view.empty() ? std::string(config->getDefaultView(display_.c_str())) : view;
  check_names(config, display_, view_);
  const auto processor =
      config->getProcessor(working_space().c_str(), display_.c_str(), view_.c_str(), OCIO::TRANSFORM_DIR_FORWARD);
  const auto gpu = processor->getDefaultGPUProcessor();
  OCIO::GpuShaderDescRcPtr desc = OCIO::GpuShaderDesc::CreateShaderDesc();
  desc->setLanguage(OCIO::GPU_LANGUAGE_GLSL_1_3);
  desc->setFunctionName("OCIODisplay");
  desc->setResourcePrefix("ocio_");
  gpu->extractGpuShaderInfo(desc);
  if (desc->getNumUniforms() > 0)
    throw std::runtime_error("display transform '" + view_ + "' has dynamic properties (not supported)");

  const std::string fragment = std::string("#version 330 core\n") + desc->getShaderText() + R"GLSL(
uniform sampler2D uFrame;
uniform float uGain;
uniform vec2 uOrigin;
out vec4 fragColor;
void main() {
  vec4 s = texelFetch(uFrame, ivec2(gl_FragCoord.xy - uOrigin), 0);
  if (!(s.a > 0.0)) { fragColor = vec4(0.2, 0.2, 0.2, 1.0); return; }
  vec3 rgb = s.rgb / s.a * uGain;
  rgb = mix(rgb, vec3(0.0), isnan(rgb));  // as display_encode: NaN -> 0
  fragColor = vec4(clamp(OCIODisplay(vec4(rgb, 1.0)).rgb, 0.0, 1.0), 1.0);
}
)GLSL";
  program_ = GlProgram("display transform (OCIO " + view_ + ")", kVertex, fragment);
  program_.use();
  program_.set("uFrame", 0);
  int unit = 1;
  for (unsigned i = 0; i < desc->getNumTextures(); ++i, ++unit) {
    const char *tex = nullptr, *sampler = nullptr;
    unsigned w = 0, h = 0;
    OCIO::GpuShaderDesc::TextureType channel;
    OCIO::Interpolation interp;
    desc->getTexture(i, tex, sampler, w, h, channel, interp);
    const float* values = nullptr;
    desc->getTextureValues(i, values);
    const bool red = channel == OCIO::GpuShaderDesc::TEXTURE_RED_CHANNEL;
    const GLenum target = h > 1 ? GL_TEXTURE_2D : GL_TEXTURE_1D;
    Lut lut{target, 0, sampler};
    glGenTextures(1, &lut.texture);
    glActiveTexture(GLenum(GL_TEXTURE0 + unit));
    glBindTexture(target, lut.texture);
    const GLenum filter = interp == OCIO::INTERP_NEAREST ? GL_NEAREST : GL_LINEAR;
    glTexParameteri(target, GL_TEXTURE_MIN_FILTER, filter);
    glTexParameteri(target, GL_TEXTURE_MAG_FILTER, filter);
    glTexParameteri(target, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(target, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    if (h > 1)
      glTexImage2D(target, 0, red ? GL_R32F : GL_RGB32F, GLsizei(w), GLsizei(h), 0, red ? GL_RED : GL_RGB, GL_FLOAT,
                   values);
    else
      glTexImage1D(target, 0, red ? GL_R32F : GL_RGB32F, GLsizei(w), 0, red ? GL_RED : GL_RGB, GL_FLOAT, values);
    program_.set(sampler, unit);
    luts_.push_back(lut);
  }
  for (unsigned i = 0; i < desc->getNum3DTextures(); ++i, ++unit) {
    const char *tex = nullptr, *sampler = nullptr;
    unsigned edge = 0;
    OCIO::Interpolation interp;
    desc->get3DTexture(i, tex, sampler, edge, interp);
    const float* values = nullptr;
    desc->get3DTextureValues(i, values);
    Lut lut{GL_TEXTURE_3D, 0, sampler};
    glGenTextures(1, &lut.texture);
    glActiveTexture(GLenum(GL_TEXTURE0 + unit));
    glBindTexture(GL_TEXTURE_3D, lut.texture);
    const GLenum filter = interp == OCIO::INTERP_NEAREST ? GL_NEAREST : GL_LINEAR;
    glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MIN_FILTER, filter);
    glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MAG_FILTER, filter);
    for (GLenum wrap : {GL_TEXTURE_WRAP_S, GL_TEXTURE_WRAP_T, GL_TEXTURE_WRAP_R})
      glTexParameteri(GL_TEXTURE_3D, wrap, GL_CLAMP_TO_EDGE);
    glTexImage3D(GL_TEXTURE_3D, 0, GL_RGB32F, GLsizei(edge), GLsizei(edge), GLsizei(edge), 0, GL_RGB, GL_FLOAT, values);
    program_.set(sampler, unit);
    luts_.push_back(lut);
  }
  glActiveTexture(GL_TEXTURE0);
  glUseProgram(0);
  glGenVertexArrays(1, &vao_);
}

DisplayTransform::~DisplayTransform() {
  for (const Lut& l : luts_) glDeleteTextures(1, &l.texture);
  glDeleteVertexArrays(1, &vao_);
}

void DisplayTransform::draw(GLuint frame_texture, float exposure_stops, int x0, int y0, int width, int height) const {
  glViewport(x0, y0, width, height);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_BLEND);
  program_.use();
  program_.set("uGain", float(std::exp2(double(exposure_stops))));
  program_.set("uOrigin", Vec2(x0, y0));
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_2D, frame_texture);
  int unit = 1;
  for (const Lut& l : luts_) {
    glActiveTexture(GLenum(GL_TEXTURE0 + unit++));
    glBindTexture(l.target, l.texture);
  }
  glActiveTexture(GL_TEXTURE0);
  glBindVertexArray(vao_);
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glBindVertexArray(0);
  glUseProgram(0);
}

}  // namespace rsibr::viewer
