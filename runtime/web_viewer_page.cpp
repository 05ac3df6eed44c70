#include "runtime/web_viewer_page.h"

#include "core/base64.h"
#include "core/colour.h"
#include "runtime/gpu_map_data.h"
#include "runtime/map_shader.h"

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>

namespace rsibr {
namespace {

template <typename T>
std::string b64(const std::vector<T>& v) {
  std::vector<unsigned char> bytes(v.size() * sizeof(T));
  if (!bytes.empty()) std::memcpy(bytes.data(), v.data(), bytes.size());
  return base64_encode(bytes);
}

std::string escape_html(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '&')
      out += "&amp;";
    else if (c == '<')
      out += "&lt;";
    else if (c == '>')
      out += "&gt;";
    else if (c == '"')
      out += "&quot;";
    else
      out += c;
  }
  return out;
}

// The display transform as a table: node (i, j, k) of n^3 holds the transform of display_encode
// (core/colour.h, unquantised) of radiance 2^(lo + (hi - lo) t) per channel (t = i, j, k over n - 1).
constexpr int kLutSize = 49;  // half-stop nodes; display white (log2 = 0) on a node
constexpr double kLutLog2Lo = -16, kLutLog2Hi = 8;

std::vector<std::uint16_t> display_lut(const std::string& display, const std::string& view) {
  const int n = kLutSize;
  cv::Mat grid(n * n, n, CV_32FC3);
  const auto level = [&](int i) { return float(std::exp2(kLutLog2Lo + (kLutLog2Hi - kLutLog2Lo) * i / (n - 1))); };
  for (int b = 0; b < n; ++b)
    for (int g = 0; g < n; ++g)
      for (int r = 0; r < n; ++r) grid.at<cv::Vec3f>(b * n + g, r) = cv::Vec3f(level(r), level(g), level(b));
  apply_display_transform(grid, display, view);
  std::vector<float> rgba(std::size_t(n) * n * n * 4);
  for (int row = 0; row < n * n; ++row)
    for (int r = 0; r < n; ++r) {
      const cv::Vec3f c = grid.at<cv::Vec3f>(row, r);
      float* o = &rgba[(std::size_t(row) * n + r) * 4];
      for (int k = 0; k < 3; ++k) o[k] = std::clamp(c[k], 0.f, 1.f);
      o[3] = 1.f;
    }
  cv::Mat f(1, int(rgba.size()), CV_32F, rgba.data()), h;
  f.convertTo(h, CV_16F);
  return std::vector<std::uint16_t>(h.ptr<std::uint16_t>(), h.ptr<std::uint16_t>() + rgba.size());
}

const char* const kScript = R"JS(
(function () {
  const D = JSON.parse(document.getElementById('rsibr-data').textContent);
  const api = { ready: false, error: null };
  window.rsibrViewer = api;
  const canvas = document.getElementById('rsibr-canvas');
  const gl = canvas.getContext('webgl2', { antialias: false, preserveDrawingBuffer: true });
  function fail(why) {
    api.error = why;
    document.getElementById('rsibr-live').hidden = true;
    const f = document.getElementById('rsibr-fallback');
    f.hidden = false;
    document.getElementById('rsibr-why').textContent = why;
  }
  if (!gl) { fail('this browser has no WebGL2'); return; }
  if (!gl.getExtension('EXT_color_buffer_float')) { fail('WebGL2 without EXT_color_buffer_float'); return; }
  function bytes(s) { const b = atob(s), u = new Uint8Array(b.length); for (let i = 0; i < b.length; ++i) u[i] = b.charCodeAt(i); return u.buffer; }
  const f32 = s => new Float32Array(bytes(s)), i32 = s => new Int32Array(bytes(s));
  const u16 = s => new Uint16Array(bytes(s)), u32 = s => new Uint32Array(bytes(s));
  function compile(type, src) {
    const s = gl.createShader(type);
    gl.shaderSource(s, src);
    gl.compileShader(s);
    if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(s));
    return s;
  }
  function program(vs, fs) {
    const p = gl.createProgram();
    gl.attachShader(p, compile(gl.VERTEX_SHADER, vs));
    gl.attachShader(p, compile(gl.FRAGMENT_SHADER, fs));
    gl.linkProgram(p);
    if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(p));
    return p;
  }
  function texture(unit, target, internal, w, h, d, format, type, data, linear) {
    const t = gl.createTexture();
    gl.activeTexture(gl.TEXTURE0 + unit);
    gl.bindTexture(target, t);
    gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1);
    if (target === gl.TEXTURE_2D) gl.texImage2D(target, 0, internal, w, h, 0, format, type, data);
    else gl.texImage3D(target, 0, internal, w, h, d, 0, format, type, data);
    const filter = linear ? gl.LINEAR : gl.NEAREST;
    gl.texParameteri(target, gl.TEXTURE_MIN_FILTER, filter);
    gl.texParameteri(target, gl.TEXTURE_MAG_FILTER, filter);
    for (const w of [gl.TEXTURE_WRAP_S, gl.TEXTURE_WRAP_T, gl.TEXTURE_WRAP_R]) gl.texParameteri(target, w, gl.CLAMP_TO_EDGE);
    return t;
  }
  let mesh, display, frame = null;
  try {
    mesh = program(D.vertex_shader, D.fragment_shader);
    display = program(D.display_vertex_shader, D.display_fragment_shader);
  } catch (e) { fail('the shaders do not build: ' + e.message); return; }
  // Units as the desktop viewer binds them (runtime/viewer/mesh_pass.cpp); 6: the display table.
  // Each set's textures, bound to units 0..5 before its draw.
  const sets = D.sets.map(S => {
    const M = S.maps;
    return { S, t: [
      texture(0, gl.TEXTURE_2D_ARRAY, gl.RGBA16F, M.width, M.height, M.views, gl.RGBA, gl.HALF_FLOAT, u16(M.rgba), false),
      texture(1, gl.TEXTURE_2D, gl.RGBA32F, M.views, 4, 1, gl.RGBA, gl.FLOAT, f32(S.view_data), false),
      texture(2, gl.TEXTURE_2D, gl.RGBA32I, S.triangle_count, 1, 1, gl.RGBA_INTEGER, gl.INT, i32(S.triangles), false),
      texture(3, gl.TEXTURE_2D, gl.RGBA32F, S.triangle_count, 3, 1, gl.RGBA, gl.FLOAT, f32(S.edge_planes), false),
      texture(4, gl.TEXTURE_2D, gl.RGBA32F, 1, 1, 1, gl.RGBA, gl.FLOAT, new Float32Array(4), false),
      texture(5, gl.TEXTURE_2D, gl.RGBA32I, Math.max(S.arc_count, 1), 1, 1, gl.RGBA_INTEGER, gl.INT, i32(S.arcs), false)] };
  });
  const kinds = [gl.TEXTURE_2D_ARRAY, gl.TEXTURE_2D, gl.TEXTURE_2D, gl.TEXTURE_2D, gl.TEXTURE_2D, gl.TEXTURE_2D];
  const L = D.display;
  texture(6, gl.TEXTURE_3D, gl.RGBA16F, L.size, L.size, L.size, gl.RGBA, gl.HALF_FLOAT, u16(L.rgba), true);
  gl.useProgram(mesh);
  const um = n => gl.getUniformLocation(mesh, n);
  [['uMaps', 0], ['uViewData', 1], ['uTriangles', 2], ['uEdgePlanes', 3], ['uDest', 4], ['uArcs', 5]].forEach(([n, u]) => gl.uniform1i(um(n), u));
  gl.uniform2i(um('uDestSize'), 1, 1);
  function useSet(k) {
    const { S, t } = sets[k];
    t.forEach((tex, unit) => { gl.activeTexture(gl.TEXTURE0 + unit); gl.bindTexture(kinds[unit], tex); });
    gl.uniform2i(um('uMapSize'), S.maps.width, S.maps.height);
    gl.uniform1i(um('uTriangleCount'), S.triangle_count);
    gl.uniform1i(um('uArcCount'), S.arc_count);
  }
  gl.uniform1i(um('uHint'), -1);
  gl.uniform1f(um('uRimFade'), D.rim_fade);
  gl.uniform1i(um('uShowWeight'), 0);
  gl.uniform2f(um('uOrigin'), 0, 0);
  const vao = gl.createVertexArray();
  gl.bindVertexArray(vao);
  function attribute(loc, data) {
    const b = gl.createBuffer();
    gl.bindBuffer(gl.ARRAY_BUFFER, b);
    gl.bufferData(gl.ARRAY_BUFFER, data, gl.STATIC_DRAW);
    gl.enableVertexAttribArray(loc);
    gl.vertexAttribPointer(loc, 3, gl.FLOAT, false, 0, 0);
  }
  attribute(0, f32(D.mesh.positions));
  attribute(1, f32(D.mesh.normals));
  const ib = gl.createBuffer();
  gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, ib);
  gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, u32(D.mesh.indices), gl.STATIC_DRAW);
  gl.bindVertexArray(null);
  const quad = gl.createVertexArray();

  let cam = D.camera, exposure = D.exposure, wipe = 0.5;
  function makeFrame(w, h) {
    if (frame && frame.w === w && frame.h === h) return;
    const t = gl.createTexture();
    gl.activeTexture(gl.TEXTURE7);
    gl.bindTexture(gl.TEXTURE_2D, t);
    gl.texStorage2D(gl.TEXTURE_2D, 1, gl.RGBA32F, w, h);
    for (const p of [gl.TEXTURE_MIN_FILTER, gl.TEXTURE_MAG_FILTER]) gl.texParameteri(gl.TEXTURE_2D, p, gl.NEAREST);
    const depth = gl.createRenderbuffer();
    gl.bindRenderbuffer(gl.RENDERBUFFER, depth);
    gl.renderbufferStorage(gl.RENDERBUFFER, gl.DEPTH_COMPONENT32F, w, h);
    const fb = gl.createFramebuffer();
    gl.bindFramebuffer(gl.FRAMEBUFFER, fb);
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, t, 0);
    gl.framebufferRenderbuffer(gl.FRAMEBUFFER, gl.DEPTH_ATTACHMENT, gl.RENDERBUFFER, depth);
    frame = { w, h, t, fb };
    canvas.width = w;
    canvas.height = h;
  }
  function draw() {
    makeFrame(cam.width, cam.height);
    const R = cam.world_from_cam;  // row-major world_from_cam = column-major cam_from_world
    const Rt = [R[0], R[3], R[6], R[1], R[4], R[7], R[2], R[5], R[8]];
    const fwd = [R[2], R[5], R[8]], b = D.bounds;
    const along = (b.centre[0] - cam.eye[0]) * fwd[0] + (b.centre[1] - cam.eye[1]) * fwd[1] + (b.centre[2] - cam.eye[2]) * fwd[2];
    const far = Math.max(along + 1.01 * b.radius, 1e-3), near = Math.max(along - 1.01 * b.radius, far * 1e-5);
    gl.bindFramebuffer(gl.FRAMEBUFFER, frame.fb);
    gl.viewport(0, 0, cam.width, cam.height);
    gl.clearColor(0, 0, 0, 0);
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
    gl.enable(gl.DEPTH_TEST);
    gl.depthFunc(gl.LESS);
    gl.disable(gl.CULL_FACE);
    gl.frontFace(gl.CCW);
    gl.useProgram(mesh);
    gl.uniformMatrix3fv(um('uCamFromWorld'), false, R);
    gl.uniformMatrix3fv(um('uWorldFromCam'), false, Rt);
    gl.uniform3fv(um('uEye'), cam.eye);
    gl.uniform4f(um('uIntrinsics'), cam.fx, cam.fy, cam.cx, cam.cy);
    gl.uniform2f(um('uSize'), cam.width, cam.height);
    gl.uniform2f(um('uDepth'), (far + near) / (far - near), -2 * far * near / (far - near));
    gl.bindVertexArray(vao);
    // Two sets: a wipe, the first left of the split, the second right of it (one camera).
    const split = sets.length > 1 ? Math.round(wipe * cam.width) : cam.width;
    for (let k = 0; k < sets.length; ++k) {
      const x0 = k === 0 ? 0 : split, x1 = k === 0 ? split : cam.width;
      if (x1 <= x0) continue;
      useSet(k);
      gl.enable(gl.SCISSOR_TEST);
      gl.scissor(x0, 0, x1 - x0, cam.height);
      gl.drawElements(gl.TRIANGLES, D.mesh.count, gl.UNSIGNED_INT, 0);
      gl.disable(gl.SCISSOR_TEST);
    }
    gl.bindVertexArray(null);
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    gl.viewport(0, 0, cam.width, cam.height);
    gl.disable(gl.DEPTH_TEST);
    gl.useProgram(display);
    const ud = n => gl.getUniformLocation(display, n);
    gl.activeTexture(gl.TEXTURE7);
    gl.bindTexture(gl.TEXTURE_2D, frame.t);
    gl.uniform1i(ud('uFrame'), 7);
    gl.uniform1i(ud('uLut'), 6);
    gl.uniform1f(ud('uScale'), Math.pow(2, exposure) * D.scale);
    gl.uniform2f(ud('uLog2Range'), L.log2_lo, L.log2_hi);
    gl.bindVertexArray(quad);
    gl.drawArrays(gl.TRIANGLES, 0, 3);
    gl.bindVertexArray(null);
    api.ready = true;
  }
  api.setCamera = c => { cam = c; draw(); };
  api.setExposure = s => { exposure = s; draw(); };
  api.setWipe = f => { wipe = Math.min(Math.max(f, 0), 1); draw(); };
  api.radiance = () => {
    gl.bindFramebuffer(gl.FRAMEBUFFER, frame.fb);
    const px = new Float32Array(cam.width * cam.height * 4);
    gl.readPixels(0, 0, cam.width, cam.height, gl.RGBA, gl.FLOAT, px);
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    // Bottom row first in GL: flipped to the image's top row first; RGB scaled back to radiance.
    const out = new Float32Array(px.length), row = cam.width * 4;
    for (let y = 0; y < cam.height; ++y)
      for (let i = 0; i < row; ++i) out[y * row + i] = px[(cam.height - 1 - y) * row + i] * ((i & 3) === 3 ? 1 : D.scale);
    return out;
  };
  api.displayed = () => {
    const px = new Uint8Array(cam.width * cam.height * 4), row = cam.width * 4;
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    gl.readPixels(0, 0, cam.width, cam.height, gl.RGBA, gl.UNSIGNED_BYTE, px);
    const out = new Uint8Array(px.length);
    for (let y = 0; y < cam.height; ++y) out.set(px.subarray((cam.height - 1 - y) * row, (cam.height - y) * row), y * row);
    return out;
  };
  api.camera = () => cam;
  // Orbit about the pivot: the camera's frame as core/camera.h look_at builds it.
  const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
  const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
  const norm = a => { const l = Math.hypot(a[0], a[1], a[2]); return [a[0] / l, a[1] / l, a[2] / l]; };
  function rotate(v, axis, angle) {  // Rodrigues
    const c = Math.cos(angle), s = Math.sin(angle), k = norm(axis), d = k[0] * v[0] + k[1] * v[1] + k[2] * v[2], x = cross(k, v);
    return [0, 1, 2].map(i => v[i] * c + x[i] * s + k[i] * d * (1 - c));
  }
  function lookAt(eye) {
    const z = norm(sub(eye, D.pivot));
    let x = cross(D.up, z);
    if (Math.hypot(x[0], x[1], x[2]) < 1e-9) x = cross([1, 0, 0], z);
    x = norm(x);
    const y = cross(z, x);
    // Camera axes: x right, y down (-y), z forward (-z), as columns of world_from_cam.
    const R = [x[0], -y[0], -z[0], x[1], -y[1], -z[1], x[2], -y[2], -z[2]];
    return Object.assign({}, cam, { eye, world_from_cam: R });
  }
  let drag = null;
  canvas.addEventListener('mousedown', e => { drag = [e.clientX, e.clientY]; });
  window.addEventListener('mouseup', () => { drag = null; });
  window.addEventListener('mousemove', e => {
    if (!drag) return;
    const dx = e.clientX - drag[0], dy = e.clientY - drag[1];
    drag = [e.clientX, e.clientY];
    let off = sub(cam.eye, D.pivot);
    off = rotate(off, D.up, -dx * 0.01);
    const right = cross(D.up, norm(off));
    if (Math.hypot(right[0], right[1], right[2]) > 1e-6) {
      const turned = rotate(off, right, -dy * 0.01);
      const c = (turned[0] * D.up[0] + turned[1] * D.up[1] + turned[2] * D.up[2]) / Math.hypot(turned[0], turned[1], turned[2]);
      if (Math.abs(c) < 0.995) off = turned;
    }
    cam = lookAt([D.pivot[0] + off[0], D.pivot[1] + off[1], D.pivot[2] + off[2]]);
    draw();
  });
  canvas.addEventListener('wheel', e => {
    e.preventDefault();
    const k = Math.exp(0.001 * e.deltaY), off = sub(cam.eye, D.pivot);
    cam = lookAt([D.pivot[0] + k * off[0], D.pivot[1] + k * off[1], D.pivot[2] + k * off[2]]);
    draw();
  }, { passive: false });
  const wiper = document.getElementById('rsibr-wipe');
  if (sets.length > 1) {
    wiper.parentElement.hidden = false;
    wiper.addEventListener('input', () => { wipe = parseFloat(wiper.value); draw(); });
  }
  const slider = document.getElementById('rsibr-exposure'), shown = document.getElementById('rsibr-exposure-value');
  slider.min = Math.floor(exposure) - 12;
  slider.max = Math.ceil(exposure) + 12;
  slider.value = exposure;
  shown.textContent = exposure.toFixed(1);
  slider.addEventListener('input', () => { exposure = parseFloat(slider.value); shown.textContent = exposure.toFixed(1); draw(); });
  draw();
})();
)JS";

// The display pass: a full-frame triangle; radiance x 2^exposure (x the maps' scale) through the
// table at log2, clamped to the table's range; pixels nothing covers show the viewer's grey.
const char* const kDisplayVertex = R"GLSL(#version 300 es
void main() {
  vec2 p = vec2(gl_VertexID == 1 ? 3.0 : -1.0, gl_VertexID == 2 ? 3.0 : -1.0);
  gl_Position = vec4(p, 0.0, 1.0);
}
)GLSL";

const char* const kDisplayFragment = R"GLSL(#version 300 es
precision highp float;
precision highp sampler3D;
uniform sampler2D uFrame;
uniform sampler3D uLut;
uniform float uScale;
uniform vec2 uLog2Range;
out vec4 fragColor;
void main() {
  vec4 c = texelFetch(uFrame, ivec2(gl_FragCoord.xy), 0);
  if (c.a <= 0.0) { fragColor = vec4(0.5, 0.5, 0.5, 1.0); return; }
  vec3 l = log2(max(c.rgb * uScale, vec3(exp2(uLog2Range.x))));
  vec3 t = clamp((l - uLog2Range.x) / (uLog2Range.y - uLog2Range.x), 0.0, 1.0);
  float n = float(textureSize(uLut, 0).x);
  fragColor = vec4(texture(uLut, (t * (n - 1.0) + 0.5) / n).rgb, 1.0);
}
)GLSL";

}  // namespace

std::string web_viewer_page(const WebViewerPage& page) {
  if (!page.maps || !page.mesh) throw std::invalid_argument("web viewer: a map set and a mesh are required");
  // Half floats hold up to 65504: brighter sets are divided by one power of two (both sides of a
  // wipe share the frame and its display scale).
  std::vector<const MapSet*> sets{page.maps};
  if (page.maps2) sets.push_back(page.maps2);
  std::vector<GpuMapData> gpu;
  float peak = 0;
  for (const MapSet* m : sets) {
    gpu.push_back(gpu_map_data(*m, m->view_set(), page.blend));
    for (std::size_t i = 0; i < gpu.back().maps.size(); ++i)
      if (i % 4 != 3) peak = std::max(peak, gpu.back().maps[i]);
  }
  const double scale = peak > 6e4f ? std::exp2(std::ceil(std::log2(double(peak) / 6e4))) : 1.0;
  nlohmann::json jsets = nlohmann::json::array();
  for (const GpuMapData& d : gpu) {
    cv::Mat scaled(1, int(d.maps.size()), CV_32F), h;
    for (std::size_t i = 0; i < d.maps.size(); ++i)
      scaled.ptr<float>()[i] = i % 4 == 3 ? d.maps[i] : float(d.maps[i] / scale);
    scaled.convertTo(h, CV_16F);
    const std::vector<std::uint16_t> half(h.ptr<std::uint16_t>(), h.ptr<std::uint16_t>() + d.maps.size());
    jsets.push_back({{"maps", {{"width", d.width}, {"height", d.height}, {"views", d.views}, {"rgba", b64(half)}}},
                     {"view_data", b64(d.view_data)},
                     {"triangles", b64(d.triangles)},
                     {"triangle_count", d.triangle_count},
                     {"edge_planes", b64(d.edge_planes)},
                     {"arcs", b64(d.arcs)},
                     {"arc_count", d.arc_count}});
  }

  const Mesh& mesh = *page.mesh;
  std::vector<float> pos, nrm;
  for (std::size_t i = 0; i < mesh.positions.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      pos.push_back(mesh.positions[i][k]);
      nrm.push_back(i < mesh.normals.size() ? mesh.normals[i][k] : 0.f);
    }
  std::vector<std::uint32_t> idx;
  for (const auto& t : mesh.triangles) idx.insert(idx.end(), t.begin(), t.end());
  const Eigen::AlignedBox3f box = mesh.bounds();
  const Vec3 centre = box.center().cast<double>();

  const Camera& c = page.camera;
  std::vector<double> R;
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) R.push_back(c.world_from_cam(r, k));
  nlohmann::json j;
  j["sets"] = jsets;
  j["scale"] = scale;
  j["rim_fade"] = page.blend.rim_fade;
  j["mesh"] = {{"positions", b64(pos)}, {"normals", b64(nrm)}, {"indices", b64(idx)}, {"count", idx.size()}};
  j["bounds"] = {{"centre", {centre.x(), centre.y(), centre.z()}}, {"radius", 0.5 * double(box.diagonal().norm())}};
  j["camera"] = {{"width", c.width},
                 {"height", c.height},
                 {"fx", c.fx},
                 {"fy", c.fy},
                 {"cx", c.cx},
                 {"cy", c.cy},
                 {"eye", {c.eye.x(), c.eye.y(), c.eye.z()}},
                 {"world_from_cam", R}};
  j["pivot"] = {page.pivot.x(), page.pivot.y(), page.pivot.z()};
  j["up"] = {page.up.x(), page.up.y(), page.up.z()};
  j["exposure"] = page.exposure;
  j["display"] = {{"size", kLutSize},
                  {"log2_lo", kLutLog2Lo},
                  {"log2_hi", kLutLog2Hi},
                  {"rgba", b64(display_lut(page.display, page.display_view))}};
  j["vertex_shader"] = webgl2_vertex_shader();
  j["fragment_shader"] = webgl2_fragment_shader();
  j["display_vertex_shader"] = kDisplayVertex;
  j["display_fragment_shader"] = kDisplayFragment;
  // "</" inside a script element would end it: JSON escapes '/' here.
  std::string data = j.dump();
  for (std::size_t p = 0; (p = data.find("</", p)) != std::string::npos; p += 3) data.replace(p, 2, "<\\/");

  std::string html = "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>" +
                     escape_html(page.title) +
                     "</title>\n<style>body{font-family:sans-serif;margin:1em;background:#222;color:#ddd}"
                     "canvas{display:block;cursor:grab;max-width:100%}.rsibr-controls{margin:.5em 0}</style>"
                     "</head>\n<body>\n<h1>" +
                     escape_html(page.title) + "</h1>\n<div id=\"rsibr-live\"><canvas id=\"rsibr-canvas\" width=\"" +
                     std::to_string(c.width) + "\" height=\"" + std::to_string(c.height) +
                     "\"></canvas>\n<div class=\"rsibr-controls\">Drag to orbit, wheel to zoom. Exposure <input "
                     "type=\"range\" id=\"rsibr-exposure\" min=\"-12\" max=\"12\" step=\"0.1\"> <span "
                     "id=\"rsibr-exposure-value\"></span> stops<span hidden> | " +
                     escape_html(page.names[0]) + " &#8592; wipe &#8594; " + escape_html(page.names[1]) +
                     " <input type=\"range\" id=\"rsibr-wipe\" min=\"0\" max=\"1\" step=\"0.01\" "
                     "value=\"0.5\"></span></div></div>\n<div id=\"rsibr-fallback\" "
                     "hidden><p>The live view needs WebGL2: <span id=\"rsibr-why\"></span>.</p>" +
                     page.fallback_html + "</div>\n<script type=\"application/json\" id=\"rsibr-data\">" + data +
                     "</script>\n<script>" + kScript + "</script>\n</body></html>\n";
  return html;
}

}  // namespace rsibr
