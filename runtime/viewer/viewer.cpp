#include "runtime/viewer/viewer.h"

#include "core/colour.h"
#include "runtime/viewer/display_transform.h"
#include "runtime/viewer/gl_frame.h"
#include "runtime/viewer/gl_map_set.h"
#include "runtime/viewer/gl_mesh.h"
#include "runtime/viewer/gl_window.h"
#include "runtime/viewer/mesh_pass.h"

#include <epoxy/gl.h>
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <imgui.h>
#include <opencv2/imgproc.hpp>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <stdexcept>

namespace rsibr::viewer {

const char* const kViewerKeys =
    "left drag: orbit   wheel: zoom   P: per-pixel / paper   F: singularity fades   D: destination map   "
    "G: globe   S: side by side / wipe   [ ]: exposure -/+ 1/2 stop   R: reset view   Esc: quit";

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// The GL objects of one scene: mesh, map sets, passes and the float frame.
struct Stage {
  const ViewerScene& scene;
  ViewerSettings settings;
  GlMesh mesh;
  std::vector<std::unique_ptr<GlMapSet>> sets;
  MeshPass pass;
  std::unique_ptr<DisplayTransform> display;
  std::unique_ptr<GlFrame> frame;
  double seconds_blend = 0;

  Stage(const ViewerScene& s, const ViewerSettings& st) : scene(s), settings(st), mesh(*s.mesh) {
    if (scene.sets.empty() || scene.sets.size() > 2) throw std::invalid_argument("viewer: one or two map sets");
    rebuild_sets();
    display = std::make_unique<DisplayTransform>(settings.display, settings.view);
  }
  void rebuild_sets() {
    sets.clear();
    for (const MapSet* m : scene.sets)
      sets.push_back(std::make_unique<GlMapSet>(*m, settings.blend, settings.warp, settings.map_size, settings.rings));
  }
  // The float frame for camera (the whole frame's size): one set, or two by wipe / side by side.
  void draw(const Camera& camera) {
    if (!frame || frame->width() != camera.width || frame->height() != camera.height)
      frame = std::make_unique<GlFrame>(camera.width, camera.height);
    frame->bind_and_clear();
    const MeshPassOptions mo{settings.mode, settings.show_weight};
    const auto bounds = scene.mesh->bounds();
    seconds_blend = 0;
    if (sets.size() == 1) {
      pass.draw(camera, bounds, mesh, *sets[0], mo);
    } else if (settings.compare == Compare::SideBySide) {
      // Each half: the same eye and focal length, half the width, principal point at its centre.
      Camera half = camera;
      half.width = camera.width / 2;
      half.cx = camera.cx - 0.5 * (camera.width - half.width);
      pass.draw(half, bounds, mesh, *sets[0], mo, 0, 0);
      Camera right = half;
      right.width = camera.width - half.width;
      right.cx = camera.cx - 0.5 * (camera.width - right.width);
      pass.draw(right, bounds, mesh, *sets[1], mo, half.width, 0);
    } else {
      const int split = std::clamp(int(std::lround(settings.wipe * camera.width)), 0, camera.width);
      glEnable(GL_SCISSOR_TEST);
      glScissor(0, 0, split, camera.height);
      pass.draw(camera, bounds, mesh, *sets[0], mo);
      glScissor(split, 0, camera.width - split, camera.height);
      pass.draw(camera, bounds, mesh, *sets[1], mo);
      glDisable(GL_SCISSOR_TEST);
    }
    if (settings.mode == RenderMode::Paper)
      for (const auto& set : sets) seconds_blend += set->last_blend_seconds();
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
  }
  void present(int window_width, int window_height) const {
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glViewport(0, 0, window_width, window_height);
    glClearColor(0.1f, 0.1f, 0.1f, 1.f);
    glClear(GL_COLOR_BUFFER_BIT);
    display->draw(frame->texture(), settings.exposure, 0, 0, frame->width(), frame->height());
  }
};

}  // namespace

void run_scripted(const ViewerScene& scene, const ViewerSettings& settings, int frames, bool read_back,
                  const std::function<void(const ScriptedFrame&)>& sink, std::string* gl_renderer) {
  if (frames < 1) throw std::invalid_argument("viewer: --orbit needs at least one frame");
  const GlWindow window(settings.camera.width, settings.camera.height, "rsibr view", false);
  if (gl_renderer) *gl_renderer = window.renderer();
  glfwSwapInterval(0);
  Stage stage(scene, settings);
  for (int k = 0; k < frames; ++k) {
    ScriptedFrame f;
    f.index = k;
    f.camera = orbit(settings.camera, settings.pivot, settings.up, k, frames);
    const auto t0 = Clock::now();
    stage.draw(f.camera);
    int fw = 0, fh = 0;
    glfwGetFramebufferSize(window.handle(), &fw, &fh);
    stage.present(fw, fh);
    glFinish();
    f.seconds = since(t0);
    f.seconds_blend = stage.seconds_blend;
    if (read_back) f.rgba = stage.frame->read();
    glfwSwapBuffers(window.handle());
    glfwPollEvents();
    sink(f);
  }
}

namespace {

// Orbit state of the interactive camera: eye = pivot + distance * direction(yaw, pitch) about up.
struct OrbitCamera {
  Vec3 pivot, up, right0, back0;  // back0: from the pivot toward the initial eye (unit)
  double yaw = 0, pitch = 0, distance = 1, vfov = 40;
  Camera camera(int width, int height) const {
    const double cp = std::cos(pitch);
    const Vec3 dir = (cp * (std::cos(yaw) * back0 + std::sin(yaw) * right0) + std::sin(pitch) * up).normalized();
    return look_at(pivot + distance * dir, pivot, up, vfov, width, height);
  }
};

struct Input {
  double scroll = 0;
};

void scroll_callback(GLFWwindow* w, double, double dy) {
  if (auto* in = static_cast<Input*>(glfwGetWindowUserPointer(w))) in->scroll += dy;
}

// The source views on a small globe seen from the current camera: front views filled, back views
// hollow, the located triangle's views highlighted with their weights.
void draw_globe(const ViewSet& views, const ViewWeights& located, const Camera& cam) {
  const float size = 170.f, R = 0.45f * size;
  const ImVec2 p0 = ImGui::GetCursorScreenPos();
  ImGui::InvisibleButton("globe", ImVec2(size, size));
  ImDrawList* dl = ImGui::GetWindowDrawList();
  const ImVec2 c(p0.x + 0.5f * size, p0.y + 0.5f * size);
  dl->AddCircle(c, R, IM_COL32(160, 160, 160, 255), 64);
  const Vec3 right = cam.world_from_cam.col(0), up = cam.up(), toward = cam.view_direction();
  auto project = [&](const Vec3& v) { return ImVec2(c.x + R * float(v.dot(right)), c.y - R * float(v.dot(up))); };
  for (const auto& T : views.triangles())
    for (int e = 0; e < 3; ++e) {
      const Vec3 &a = views.views()[std::size_t(T[std::size_t(e)])],
                 &b = views.views()[std::size_t(T[std::size_t((e + 1) % 3)])];
      if (a.dot(toward) > 0 && b.dot(toward) > 0) dl->AddLine(project(a), project(b), IM_COL32(90, 90, 110, 255));
    }
  for (std::size_t i = 0; i < views.views().size(); ++i) {
    const Vec3& v = views.views()[i];
    if (v.dot(toward) >= 0)
      dl->AddCircleFilled(project(v), 3.f, IM_COL32(200, 200, 200, 255));
    else
      dl->AddCircle(project(v), 3.f, IM_COL32(110, 110, 110, 255));
  }
  for (int k = 0; k < located.count; ++k) {
    const Vec3& v = views.views()[std::size_t(located.views[std::size_t(k)])];
    const ImVec2 q = project(v);
    dl->AddCircleFilled(q, 3.f + 6.f * float(located.weights[std::size_t(k)]), IM_COL32(255, 170, 40, 255));
    char label[16];
    std::snprintf(label, sizeof label, "%.2f", located.weights[std::size_t(k)]);
    dl->AddText(ImVec2(q.x + 6, q.y - 6), IM_COL32(255, 220, 120, 255), label);
  }
  dl->AddCircle(c, 4.f, IM_COL32(80, 200, 255, 255));  // the current view direction
}

std::string describe(const MapSet& m) {
  const MapView& v = m.views.front();
  std::string warps = to_string(v.warp), sources = to_string(v.source);
  for (const MapView& w : m.views) {
    if (w.warp != v.warp) warps = "mixed";
    if (w.source != v.source) sources = "mixed";
  }
  return std::to_string(m.views.size()) + " views, " + std::to_string(m.width()) + "x" + std::to_string(m.height()) +
         ", warp " + warps + ", " + sources;
}

}  // namespace

int run_interactive(const ViewerScene& scene, const ViewerSettings& initial) {
  const GlWindow window(initial.camera.width, initial.camera.height, "rsibr view", true);
  const std::string renderer = window.renderer();
  GLFWwindow* w = window.handle();
  Input input;
  glfwSetWindowUserPointer(w, &input);
  glfwSetScrollCallback(w, scroll_callback);  // before ImGui, which chains to it
  glfwSwapInterval(1);

  Stage stage(scene, initial);
  ViewerSettings& s = stage.settings;
  const auto reset = [&] {
    OrbitCamera o;
    o.pivot = initial.pivot;
    o.up = initial.up.normalized();
    const Vec3 back = initial.camera.eye - initial.pivot;
    o.distance = std::max(back.norm(), 1e-6);
    Vec3 b = back / o.distance;
    o.pitch = std::asin(std::clamp(b.dot(o.up), -0.99, 0.99));
    Vec3 flat = b - b.dot(o.up) * o.up;
    if (flat.norm() < 1e-9) flat = world_from_view_for(o.up).col(0);
    o.back0 = flat.normalized();
    o.right0 = o.up.cross(o.back0).normalized();
    o.vfov = initial.vfov_deg;
    return o;
  };
  OrbitCamera orbit_cam = reset();

  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGui::GetIO().IniFilename = nullptr;  // no imgui.ini next to the user's files
  ImGui_ImplGlfw_InitForOpenGL(w, true);
  ImGui_ImplOpenGL3_Init("#version 330 core");

  bool show_dest = false, show_globe = true;
  GLuint dest_texture = 0;
  glGenTextures(1, &dest_texture);
  const std::vector<std::string> views = DisplayTransform::views(s.display);
  const char* modes[] = {"per pixel (GPU shader)", "paper (CPU engine, one map per frame)"};
  const char* warps[] = {"exact", "precomputed", "tessellated", "double-indirection"};
  double last_x = 0, last_y = 0, frame_seconds = 0, smoothed = 0;
  bool dragging = false;

  while (!glfwWindowShouldClose(w)) {
    glfwPollEvents();
    ImGuiIO& io = ImGui::GetIO();
    double mx, my;
    glfwGetCursorPos(w, &mx, &my);
    const bool down = glfwGetMouseButton(w, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS;
    if (down && dragging) {
      orbit_cam.yaw -= 0.01 * (mx - last_x);
      orbit_cam.pitch = std::clamp(orbit_cam.pitch + 0.01 * (my - last_y), -1.55, 1.55);
    }
    dragging = down && (dragging || !io.WantCaptureMouse);
    last_x = mx;
    last_y = my;
    if (!io.WantCaptureMouse && input.scroll != 0) orbit_cam.distance *= std::pow(0.9, input.scroll);
    input.scroll = 0;
    bool rebuild = false;
    if (!io.WantCaptureKeyboard) {
      if (ImGui::IsKeyPressed(GLFW_KEY_ESCAPE)) glfwSetWindowShouldClose(w, GLFW_TRUE);
      if (ImGui::IsKeyPressed(GLFW_KEY_P))
        s.mode = s.mode == RenderMode::PerPixel ? RenderMode::Paper : RenderMode::PerPixel;
      if (ImGui::IsKeyPressed(GLFW_KEY_F)) s.show_weight = !s.show_weight;
      if (ImGui::IsKeyPressed(GLFW_KEY_D)) show_dest = !show_dest;
      if (ImGui::IsKeyPressed(GLFW_KEY_G)) show_globe = !show_globe;
      if (ImGui::IsKeyPressed(GLFW_KEY_S)) s.compare = s.compare == Compare::Wipe ? Compare::SideBySide : Compare::Wipe;
      if (ImGui::IsKeyPressed(GLFW_KEY_LEFT_BRACKET)) s.exposure -= 0.5f;
      if (ImGui::IsKeyPressed(GLFW_KEY_RIGHT_BRACKET)) s.exposure += 0.5f;
      if (ImGui::IsKeyPressed(GLFW_KEY_R)) orbit_cam = reset();
    }

    int fw = 0, fh = 0;
    glfwGetFramebufferSize(w, &fw, &fh);
    if (fw < 2 || fh < 2) continue;  // minimised
    const Camera cam = orbit_cam.camera(fw, fh);
    const auto t0 = Clock::now();
    stage.draw(cam);
    stage.present(fw, fh);
    glFinish();
    frame_seconds = since(t0);
    smoothed = smoothed > 0 ? 0.9 * smoothed + 0.1 * frame_seconds : frame_seconds;

    ImGui_ImplOpenGL3_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    ImGui::NewFrame();
    ImGui::SetNextWindowPos(ImVec2(10, 10), ImGuiCond_FirstUseEver);
    ImGui::SetNextWindowSize(ImVec2(400, 0), ImGuiCond_FirstUseEver);
    ImGui::SetNextWindowBgAlpha(0.85f);
    ImGui::Begin("rsibr view");
    ImGui::TextWrapped("%s", kViewerKeys);
    ImGui::Separator();
    for (std::size_t i = 0; i < stage.sets.size(); ++i) {
      const GlMapSet& set = *stage.sets[i];
      const std::string header = std::string(stage.sets.size() > 1 ? (i == 0 ? "left: " : "right: ") : "maps: ") +
                                 (i < scene.names.size() ? scene.names[i] : "?");
      if (!ImGui::CollapsingHeader(header.c_str(), i == 0 ? ImGuiTreeNodeFlags_DefaultOpen : 0)) continue;
      ImGui::Text("  %s", describe(set.maps()).c_str());
      const std::string& material = set.maps().views.front().material;
      if (!material.empty()) ImGui::TextWrapped("  material: %s", material.c_str());
      const ViewWeights located = set.view_set().locate(cam.view_direction(), s.blend.barycentric);
      ImGui::Text("  triangle %d%s", located.triangle, located.inside ? "" : " (outside the set: nearest)");
      for (int k = 0; k < located.count; ++k) {
        const Vec3& v = set.view_set().views()[std::size_t(located.views[std::size_t(k)])];
        ImGui::Text("    view %3d (%+.3f %+.3f %+.3f)  w = %.4f", located.views[std::size_t(k)], v.x(), v.y(), v.z(),
                    located.weights[std::size_t(k)]);
      }
      if (show_globe && i == 0) draw_globe(set.view_set(), located, cam);
    }
    ImGui::Separator();
    int mode = s.mode == RenderMode::PerPixel ? 0 : 1;
    if (ImGui::Combo("mode", &mode, modes, 2)) s.mode = mode == 0 ? RenderMode::PerPixel : RenderMode::Paper;
    int warp = int(std::find(std::begin(warps), std::end(warps), s.warp) - std::begin(warps));
    if (ImGui::Combo("warp (paper)", &warp, warps, IM_ARRAYSIZE(warps))) {
      s.warp = warps[warp];
      rebuild = true;
    }
    float fade = float(s.blend.rim_fade);
    if (ImGui::SliderFloat("rim fade", &fade, 0.f, 1.f, "%.2f")) {
      s.blend.rim_fade = fade;
      for (auto& set : stage.sets) set->set_rim_fade(fade);
    }
    ImGui::SliderFloat("exposure", &s.exposure, -10.f, 10.f, "%.1f stops");
    int view_index = int(std::find(views.begin(), views.end(), stage.display->view()) - views.begin());
    if (ImGui::BeginCombo("display", stage.display->view().c_str())) {
      for (int i = 0; i < int(views.size()); ++i)
        if (ImGui::Selectable(views[std::size_t(i)].c_str(), i == view_index)) {
          stage.display = std::make_unique<DisplayTransform>(s.display, views[std::size_t(i)]);
        }
      ImGui::EndCombo();
    }
    if (stage.sets.size() > 1) {
      bool side = s.compare == Compare::SideBySide;
      if (ImGui::Checkbox("side by side", &side)) s.compare = side ? Compare::SideBySide : Compare::Wipe;
      if (!side) ImGui::SliderFloat("wipe", &s.wipe, 0.f, 1.f, "%.2f");
    }
    ImGui::Checkbox("singularity fades (sum of weights)", &s.show_weight);
    ImGui::Checkbox("source views globe", &show_globe);
    ImGui::Checkbox("destination sphere map", &show_dest);
    if (show_dest) {
      GlMapSet& set = *stage.sets[0];
      if (s.mode != RenderMode::Paper) set.update_destination(cam.view_direction(), cam.up());
      const cv::Mat bgr = display_encode(set.destination().rgb, s.exposure, s.display, stage.display->view());
      cv::Mat rgba;
      cv::cvtColor(bgr, rgba, cv::COLOR_BGR2RGBA);
      glBindTexture(GL_TEXTURE_2D, dest_texture);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
      glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
      glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, rgba.cols, rgba.rows, 0, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data);
      ImGui::Image(reinterpret_cast<ImTextureID>(static_cast<intptr_t>(dest_texture)), ImVec2(160, 160));
    }
    ImGui::Separator();
    ImGui::Text("frame %.2f ms (%.1f fps), CPU blend %.2f ms", 1e3 * smoothed, smoothed > 0 ? 1.0 / smoothed : 0.0,
                1e3 * stage.seconds_blend);
    ImGui::Text("%dx%d, %s", fw, fh, renderer.c_str());
    ImGui::End();
    if (stage.sets.size() > 1 && s.compare == Compare::Wipe) {  // the wipe's edge
      const float x = s.wipe * io.DisplaySize.x;                // window coordinates
      ImGui::GetBackgroundDrawList()->AddLine(ImVec2(x, 0), ImVec2(x, io.DisplaySize.y), IM_COL32(255, 255, 255, 160));
    }
    ImGui::Render();
    glViewport(0, 0, fw, fh);
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
    glfwSwapBuffers(w);
    if (rebuild) stage.rebuild_sets();
  }
  glDeleteTextures(1, &dest_texture);
  ImGui_ImplOpenGL3_Shutdown();
  ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext();
  return 0;
}

}  // namespace rsibr::viewer
