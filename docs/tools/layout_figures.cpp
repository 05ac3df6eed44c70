// Figures for docs/conventions.md: every environment-map layout of core/layout.h drawn from the
// library's own direction <-> pixel mappings, the sphere-map coordinates of a radiance map, and
// the icosahedral view-set triangulation.
//
//   layout_figures <output folder>      (docs/tools/make-figures.sh runs it on docs/figures)
//
// Every colour, grid line, dot and label position comes from rsibr::Layout::direction /
// Layout::pixel, rsibr::sphere_map and rsibr::ViewSet, so a figure shows what the code does, not
// what a comment says. Colours: RGB = 0.2 + 0.6 (d+1)/2 of the world direction d ("direction
// coded", toned down so lines and labels stand out), written as is (no display transform).
#include "core/layout.h"
#include "core/patterns.h"
#include "core/sphere_map.h"
#include "core/view_set.h"
#include "formats/image_codecs.h"

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

using namespace rsibr;

namespace {

constexpr int kShift = 4;  // fixed-point bits for sub-pixel drawing
const cv::Scalar kWhite(255, 255, 255), kBlack(0, 0, 0), kGrey(90, 90, 90), kLightGrey(200, 200, 200);
const int kFont = cv::FONT_HERSHEY_SIMPLEX;

Vec3 from_lat_lon(double lat, double lon) {
  return Vec3(std::sin(lon) * std::cos(lat), std::sin(lat), std::cos(lon) * std::cos(lat));
}

// A drawing surface: canvas position of a continuous layout pixel p (integers at texel centres)
// for a layout drawn k times enlarged with its top-left texel corner at `origin`.
struct Panel {
  cv::Point2d origin;
  double k = 1;
  std::function<std::optional<Vec2>(const Vec3&)> pixel;  // layout pixel of a direction, if shown
  cv::Point2d at(const Vec2& p) const { return {origin.x + (p.x() + 0.5) * k, origin.y + (p.y() + 0.5) * k}; }
  std::optional<cv::Point2d> at(const Vec3& d) const {
    const auto p = pixel(d);
    if (!p) return std::nullopt;
    return at(*p);
  }
};

cv::Point fixed(const cv::Point2d& p) {
  return cv::Point(int(std::lround(p.x * (1 << kShift))), int(std::lround(p.y * (1 << kShift))));
}

// Lines are not anti-aliased: AA edges of many short segments multiply the PNG size.
void line(cv::Mat& img, const cv::Point2d& a, const cv::Point2d& b, const cv::Scalar& c, int thick = 1) {
  cv::line(img, fixed(a), fixed(b), c, thick, cv::LINE_8, kShift);
}

void dot(cv::Mat& img, const cv::Point2d& p, double radius, const cv::Scalar& fill) {
  cv::circle(img, fixed(p), int(std::lround((radius + 1.5) * (1 << kShift))), kBlack, -1, cv::LINE_AA, kShift);
  cv::circle(img, fixed(p), int(std::lround(radius * (1 << kShift))), fill, -1, cv::LINE_AA, kShift);
}

// Text with a dark outline, legible on any background. anchor: 0 left, 1 centre, 2 right of p.x;
// p.y is the text's vertical centre.
void text(cv::Mat& img, const std::string& s, cv::Point2d p, double scale = 0.45, const cv::Scalar& c = kWhite,
          int anchor = 0, bool outline = true) {
  int base = 0;
  const cv::Size sz = cv::getTextSize(s, kFont, scale, 1, &base);
  double x = p.x - (anchor == 1 ? sz.width / 2.0 : anchor == 2 ? sz.width : 0.0);
  const cv::Point q(int(std::lround(x)), int(std::lround(p.y + sz.height / 2.0)));
  if (outline) cv::putText(img, s, q, kFont, scale, kBlack, 3, cv::LINE_AA);
  cv::putText(img, s, q, kFont, scale, c, 1, cv::LINE_AA);
}

// Polyline through the canvas positions of a curve of directions; broken where consecutive points
// jump (a seam or fold of the layout) or where the layout shows no direction.
void curve(cv::Mat& img, const Panel& panel, const std::vector<Vec3>& dirs, const cv::Scalar& c, int thick,
           double max_jump) {
  std::optional<cv::Point2d> prev;
  for (const Vec3& d : dirs) {
    const auto q = panel.at(d);
    if (q && prev && cv::norm(*q - *prev) < max_jump) line(img, *prev, *q, c, thick);
    prev = q;
  }
}

std::vector<Vec3> parallel_of(double lat) {
  std::vector<Vec3> v;
  for (int i = 0; i <= 1440; ++i) v.push_back(from_lat_lon(lat, (-180.0 + 0.25 * i) * kDeg));
  return v;
}
std::vector<Vec3> meridian_of(double lon) {
  std::vector<Vec3> v;
  for (int i = 0; i <= 720; ++i) v.push_back(from_lat_lon((-90.0 + 0.25 * i) * kDeg, lon));
  return v;
}
std::vector<Vec3> great_arc(const Vec3& a, const Vec3& b, int n = 200) {
  std::vector<Vec3> v;
  const double ang = angle_between(a, b);
  for (int i = 0; i <= n; ++i) {
    const double t = double(i) / n;
    v.push_back(((std::sin((1 - t) * ang) * a + std::sin(t * ang) * b) / std::sin(ang)).normalized());
  }
  return v;
}

// Lat-long grid every 30 degrees; equator and the meridian through +Z (lon 0) thicker.
void grid(cv::Mat& img, const Panel& panel, double max_jump) {
  for (int lat = -60; lat <= 60; lat += 30)
    curve(img, panel, parallel_of(lat * kDeg), lat == 0 ? kWhite : kLightGrey, lat == 0 ? 2 : 1, max_jump);
  for (int lon = -180; lon < 180; lon += 30)
    curve(img, panel, meridian_of(lon * kDeg), lon == 0 ? kWhite : kLightGrey, lon == 0 ? 2 : 1, max_jump);
}

struct Axis {
  Vec3 d;
  std::string name;
  cv::Scalar colour;  // BGR
};
const std::vector<Axis> kAxes = {
    {Vec3(1, 0, 0), "+X", cv::Scalar(40, 40, 255)},  {Vec3(-1, 0, 0), "-X", cv::Scalar(255, 255, 0)},
    {Vec3(0, 1, 0), "+Y", cv::Scalar(40, 220, 40)},  {Vec3(0, -1, 0), "-Y", cv::Scalar(255, 60, 255)},
    {Vec3(0, 0, 1), "+Z", cv::Scalar(255, 120, 30)}, {Vec3(0, 0, -1), "-Z", cv::Scalar(0, 230, 255)},
};

void axis_dot(cv::Mat& img, const cv::Point2d& p, const Axis& a, const std::string& label, cv::Point2d offset) {
  dot(img, p, 5, a.colour);
  text(img, label.empty() ? a.name : label, p + offset, 0.5, a.colour);
}

// The layout's direction-coded texels, enlarged k times (nearest), as 8-bit BGR; texels without a
// direction (outside a sphere map's disc) are dark grey.
cv::Mat coded(const Layout& layout, int k) {
  const EnvMap env = render_pattern(patterns::direction_coded(), layout, 1);
  cv::Mat out(layout.height(), layout.width(), CV_8UC3);
  for (int r = 0; r < layout.height(); ++r)
    for (int c = 0; c < layout.width(); ++c) {
      const float* p = env.pixels.ptr<float>(r) + 3 * c;
      cv::Vec3b& q = out.at<cv::Vec3b>(r, c);
      if (!layout.direction(Vec2(c, r))) {
        q = cv::Vec3b(45, 45, 45);
        continue;
      }
      // Quantised to steps of 6 (keeps the PNGs small; the bands are ~1 degree wide).
      for (int ch = 0; ch < 3; ++ch)
        q[2 - ch] = cv::saturate_cast<uchar>(6 * std::lround(255.0 * (0.2 + 0.6 * p[ch]) / 6));
    }
  cv::Mat big;
  cv::resize(out, big, cv::Size(), k, k, cv::INTER_NEAREST);
  return big;
}

void save(const std::filesystem::path& dir, const std::string& name, const cv::Mat& img) {
  const auto path = dir / name;
  if (!rsibr::write_image(path.string(), img,
                          {cv::IMWRITE_PNG_COMPRESSION, 9, cv::IMWRITE_PNG_STRATEGY, cv::IMWRITE_PNG_STRATEGY_DEFAULT}))
    throw std::runtime_error(path.string() + ": cannot write");
  std::cout << path.string() << "  " << img.cols << "x" << img.rows << "  " << std::filesystem::file_size(path) / 1024
            << " KiB\n";
}

cv::Mat canvas(int w, int h) { return cv::Mat(h, w, CV_8UC3, cv::Scalar(30, 30, 30)); }

// Name of the world axis a (roughly axis-aligned) vector points along.
std::string axis_name(const Vec3& v) {
  int i;
  v.cwiseAbs().maxCoeff(&i);
  return std::string(v[i] > 0 ? "+" : "-") + "XYZ"[i];
}

// ---------------------------------------------------------------------------------------------
void latlong_figure(const std::filesystem::path& dir) {
  const Layout L(LayoutKind::LatLong, 512, 256);
  const int k = 2, mx = 70, my = 40;
  cv::Mat img = canvas(L.width() * k + 2 * mx, L.height() * k + my + 150);
  coded(L, k).copyTo(img(cv::Rect(mx, my, L.width() * k, L.height() * k)));
  Panel P{{double(mx), double(my)}, double(k), [&](const Vec3& d) { return std::optional<Vec2>(L.pixel(d)); }};
  grid(img, P, 100);
  // Column W-1 lies on the seam too: draw the lon -180 meridian there (Layout::pixel gives column 0).
  line(img, P.at(Vec2(L.width() - 1, 0)), P.at(Vec2(L.width() - 1, L.height() - 1)), kLightGrey);
  // Longitude ticks along the top, latitude ticks on the left, from Layout::pixel.
  for (int lon = -180; lon <= 180; lon += 30) {
    Vec2 p = L.pixel(from_lat_lon(0, lon * kDeg));
    if (lon == -180) p.x() = L.width() - 1;
    text(img, std::to_string(lon), {P.at(p).x, my - 12.0}, 0.4, kLightGrey, 1, false);
  }
  text(img, "lon", {double(mx) - 30, my - 12.0}, 0.4, kLightGrey, 2, false);
  for (int lat = -90; lat <= 90; lat += 30)
    text(img, std::to_string(lat), {mx - 8.0, P.at(L.pixel(from_lat_lon(lat * kDeg, 0.3))).y}, 0.4, kLightGrey, 2,
         false);
  text(img, "lat", {mx - 8.0, my + L.height() * k + 14.0}, 0.4, kLightGrey, 2, false);
  for (const Axis& a : kAxes) {
    auto p = *P.at(a.d);
    std::string label = a.name;
    cv::Point2d off(9, -12);
    if (a.name == "+Y") {
      label = "+Y = whole row 0";
      off = {9, 14};
    }
    if (a.name == "-Y") {
      label = "-Y = whole row H-1";
      off = {9, -14};
    }
    if (a.name == "-Z") {
      label = "-Z (col 0)";
      off = {9, -12};
      axis_dot(img, *P.at(a.d), a, label, off);
      p = P.at(Vec2(L.width() - 1, (L.height() - 1) / 2.0));
      label = "-Z (col W-1)";
      off = {-100, -12};
    }
    axis_dot(img, p, a, label, off);
  }
  // Corner texels.
  const cv::Point2d c00 = P.at(Vec2(0, 0)), c11 = P.at(Vec2(L.width() - 1, L.height() - 1));
  dot(img, c00, 3, kWhite);
  dot(img, c11, 3, kWhite);
  const int ty = my + L.height() * k + 22;
  text(img,
       "Lat-long 512x256 (OpenEXR LatLongMap). World +Y up; view from inside: lon +90 (+X) is LEFT of the centre (+Z).",
       {double(mx), double(ty)}, 0.45);
  text(
      img,
      "pixel (0,0) = lat +90, lon +180;  pixel (W-1,H-1) = lat -90, lon -180.   lat = pi/2 - pi*y/(H-1),  lon = pi - 2pi*x/(W-1)",
      {double(mx), ty + 22.0}, 0.45);
  text(
      img,
      "Pixel is point: columns 0 and W-1 both lie ON the seam (lon +-180, through -Z); rows 0 and H-1 lie ON the poles.",
      {double(mx), ty + 44.0}, 0.45);
  text(img, "Texel (c,r) is centred at continuous pixel (c,r). Grid: 30 deg; thick = equator and lon 0.",
       {double(mx), ty + 66.0}, 0.45);
  text(img, "Colour = 0.2 + 0.6 (d+1)/2 (R from x, G from y, B from z).", {double(mx), ty + 88.0}, 0.45);
  save(dir, "layout_latlong.png", img);
}

// ---------------------------------------------------------------------------------------------
void cube_figures(const std::filesystem::path& dir) {
  const Layout L(LayoutKind::Cube, 128, 768);
  const int n = 128, mx = 40, my = 30;
  // The strip as stored.
  cv::Mat img = canvas(n + mx + 560, 6 * n + 2 * my + 70);
  coded(L, 1).copyTo(img(cv::Rect(mx, my, n, 6 * n)));
  Panel P{{double(mx), double(my)}, 1.0, [&](const Vec3& d) { return std::optional<Vec2>(L.pixel(d)); }};
  grid(img, P, 30);
  const char* face_names[6] = {"+X", "-X", "+Y", "-Y", "+Z", "-Z"};
  for (int f = 0; f < 6; ++f) {
    const double y0 = my + f * n;
    if (f > 0) cv::line(img, {mx - 6, int(y0)}, {mx + n + 6, int(y0)}, kBlack, 1);
    // Orientation of the face, measured from Layout::direction.
    const Vec2 c(n / 2.0 - 0.5, f * n + n / 2.0 - 0.5);
    const Vec3 d0 = *L.direction(c), dr = *L.direction(c + Vec2(8, 0)) - d0, dd = *L.direction(c + Vec2(0, 8)) - d0;
    text(img, std::to_string(f), {mx - 10.0, y0 + n / 2.0}, 0.5, kWhite, 2);
    const double tx = mx + n + 16;
    text(
        img,
        std::string("face ") + face_names[f] + ": rows " + std::to_string(f * n) + ".." + std::to_string(f * n + n - 1),
        {tx, y0 + 30}, 0.5);
    text(img, "image right = " + axis_name(dr) + ",  image down = " + axis_name(dd) + ",  up = " + axis_name(-dd),
         {tx, y0 + 56}, 0.45);
    const Vec3 corner = *L.direction(Vec2(0, f * n));
    char buf[96];
    std::snprintf(buf, sizeof buf, "texel (0,%d) = (%+.0f,%+.0f,%+.0f) (a cube corner)", f * n, corner.x(), corner.y(),
                  corner.z());
    text(img, buf, {tx, y0 + 80}, 0.45, kLightGrey);
    dot(img, P.at(Vec2(0, f * n)), 2.5, kWhite);
  }
  for (const Axis& a : kAxes) axis_dot(img, *P.at(a.d), a, "", {8, -10});
  text(img, "Cube 128 x 768 (OpenEXR CubeMap): faces +X,-X,+Y,-Y,+Z,-Z stacked top to bottom, W x 6W.",
       {double(mx), double(my + 6 * n + 20)}, 0.42);
  text(img, "Pixel is point: a face's edge texels lie ON the cube's edges (a direction on an edge is stored",
       {double(mx), double(my + 6 * n + 40)}, 0.42);
  text(img, "in both faces). Faces are stored as seen from inside. White dots: each face's first texel.",
       {double(mx), double(my + 6 * n + 60)}, 0.42);
  save(dir, "layout_cube.png", img);

  // The same texels unfolded into a cross as seen from inside (+Y up, looking at +Z: +X left).
  struct Cell {
    Vec3 fwd, up;
    int col, row;
    const char* name;
  };
  const std::vector<Cell> cells = {
      {Vec3(0, 1, 0), Vec3(0, 0, -1), 1, 0, "+Y"}, {Vec3(1, 0, 0), Vec3(0, 1, 0), 0, 1, "+X"},
      {Vec3(0, 0, 1), Vec3(0, 1, 0), 1, 1, "+Z"},  {Vec3(-1, 0, 0), Vec3(0, 1, 0), 2, 1, "-X"},
      {Vec3(0, 0, -1), Vec3(0, 1, 0), 3, 1, "-Z"}, {Vec3(0, -1, 0), Vec3(0, 0, 1), 1, 2, "-Y"}};
  const int s = 160, ox = 20, oy = 30;
  cv::Mat cross = canvas(4 * s + 2 * ox, 3 * s + oy + 100);
  const cv::Mat strip = coded(L, 1);
  auto cell_dir = [&](const Cell& c, double a, double b) { return (c.fwd + a * c.fwd.cross(c.up) + b * c.up).eval(); };
  for (const Cell& c : cells)
    for (int j = 0; j < s; ++j)
      for (int i = 0; i < s; ++i) {
        const Vec3 d = cell_dir(c, 2.0 * (i + 0.5) / s - 1.0, 1.0 - 2.0 * (j + 0.5) / s);
        const Vec2 p = L.pixel(d);  // nearest stored texel
        const int pc = std::clamp(int(std::lround(p.x())), 0, n - 1),
                  pr = std::clamp(int(std::lround(p.y())), 0, 6 * n - 1);
        cross.at<cv::Vec3b>(oy + c.row * s + j, ox + c.col * s + i) = strip.at<cv::Vec3b>(pr, pc);
      }
  Panel C{{0, 0}, 1.0, [&](const Vec3& d) -> std::optional<Vec2> {
            for (const Cell& c : cells) {
              const double f = d.dot(c.fwd);
              const Vec3 r = c.fwd.cross(c.up);
              if (f <= 0 || std::abs(d.dot(r)) > f * (1 + 1e-9) || std::abs(d.dot(c.up)) > f * (1 + 1e-9)) continue;
              const double a = d.dot(r) / f, b = d.dot(c.up) / f;
              return Vec2(ox + c.col * s + (a + 1) * s / 2 - 0.5, oy + c.row * s + (1 - b) * s / 2 - 0.5);
            }
            return std::nullopt;
          }};
  grid(cross, C, 30);
  for (const Cell& c : cells) {
    cv::rectangle(cross, {ox + c.col * s, oy + c.row * s}, {ox + c.col * s + s - 1, oy + c.row * s + s - 1}, kBlack, 1);
    text(cross, std::string("face ") + c.name, {ox + c.col * s + 6.0, oy + c.row * s + s - 14.0}, 0.42, kWhite);
  }
  for (const Axis& a : kAxes) axis_dot(cross, *C.at(a.d), a, "", {8, -10});
  // Each face's stored first texel (column 0 of its row block): where it lands in the cross.
  for (int f = 0; f < 6; ++f) {
    const Vec3 d = *L.direction(Vec2(0.5, f * n + 0.5));  // just inside the corner, so the face is unambiguous
    const auto q = C.at(d);
    if (!q) continue;
    dot(cross, *q, 3, kWhite);
    const bool right = q->x - ox - std::floor((q->x - ox) / s) * s > s / 2;
    const bool low = q->y - oy - std::floor((q->y - oy) / s) * s > s / 2;
    text(cross, "(0," + std::to_string(f * n) + ")", *q + cv::Point2d(right ? -6 : 6, low ? -10 : 10), 0.38, kWhite,
         right ? 2 : 0);
  }
  const double ty = oy + 3 * s + 20;
  text(cross, "Cube 128 x 768 unfolded as seen from INSIDE (+Y up, looking at +Z: +X to the left).", {double(ox), ty},
       0.42);
  text(cross, "Each cell shows the stored texels (nearest). White dots: each face's stored first texel",
       {double(ox), ty + 20}, 0.42);
  text(cross, "(0, 128 f). Every face is stored as seen from inside (no mirror); the stored +Y and -Y",
       {double(ox), ty + 40}, 0.42);
  text(cross, "faces are rotated 180 deg from these cells (both: right = +X). Grid: 30 deg.", {double(ox), ty + 60},
       0.42);
  save(dir, "layout_cube_cross.png", cross);
}

// ---------------------------------------------------------------------------------------------
void octahedral_figure(const std::filesystem::path& dir) {
  const Layout L(LayoutKind::Octahedral, 256, 256);
  const int k = 2, mx = 40, my = 40, side = 256 * k;
  cv::Mat img = canvas(side + 2 * mx + 380, side + 2 * my);
  coded(L, k).copyTo(img(cv::Rect(mx, my, side, side)));
  Panel P{{double(mx), double(my)}, double(k), [&](const Vec3& d) { return std::optional<Vec2>(L.pixel(d)); }};
  grid(img, P, 60);
  // The folds u = 0 and v = 0 (texel edges, N even) as thin dashed black lines.
  for (int i = 0; i < side; i += 8) {
    line(img, {mx + side / 2.0, my + double(i)}, {mx + side / 2.0, my + i + 4.0}, kBlack);
    line(img, {mx + double(i), my + side / 2.0}, {mx + i + 4.0, my + side / 2.0}, kBlack);
  }
  for (const Axis& a : kAxes) {
    if (a.name == "-Y") {
      const Vec2 corners[4] = {{0, 0}, {255, 0}, {0, 255}, {255, 255}};
      for (const Vec2& c : corners) {
        const Vec2 p(c.x() == 0 ? -0.5 : 255.5, c.y() == 0 ? -0.5 : 255.5);  // the image corners
        axis_dot(img, P.at(p), a, "-Y", {c.x() == 0 ? 8.0 : -30.0, c.y() == 0 ? 14.0 : -14.0});
      }
      continue;
    }
    cv::Point2d off(9, -12);
    if (a.name == "+Z") off = {9, 14};
    if (a.name == "+X") off = {-30, -14};
    axis_dot(img, *P.at(a.d), a, a.name == "+Y" ? "+Y (centre)" : a.name, off);
  }
  const double tx = mx + side + 20;
  double ty = my + 10;
  auto say = [&](const std::string& s, const cv::Scalar& c = kWhite) {
    text(img, s, {tx, ty}, 0.45, c);
    ty += 22;
  };
  say("Octahedral 256 x 256 (seed 004, square form)");
  say("+Y centre; image right = +X, image up = -Z");
  say("inner diamond |u|+|v| <= 1: upper hemisphere");
  say("corners: lower hemisphere, folded out; all");
  say("  four image corners are -Y");
  say("thick diamond |u|+|v| = 1: the equator");
  say("  (octahedron edges, along texel diagonals)");
  say("dashed u = 0, v = 0: octahedron edges x = 0,");
  say("  z = 0 (on texel edges because N is even)");
  say("each image edge folds at its midpoint:");
  say("  (1, v) and (1, -v) are one direction");
  ty += 8;
  say("(u,v) in [-1,1]^2, v up, |d|_1 = |x|+|y|+|z|:", kLightGrey);
  say("  y >= 0: u = x/|d|_1,  v = -z/|d|_1", kLightGrey);
  say("  y < 0:  (u,v) -> ((1-|v|) sgn u, (1-|u|) sgn v)", kLightGrey);
  say("texel (c,r) centre (pixel is area):", kLightGrey);
  say("  u = (2c+1)/N - 1,  v = 1 - (2r+1)/N", kLightGrey);
  ty += 8;
  say("Grid: 30 deg lat/lon; thick: equator, lon 0.");
  save(dir, "layout_octahedral.png", img);
}

// ---------------------------------------------------------------------------------------------
void sphere_figure(const std::filesystem::path& dir) {
  const Layout L(LayoutKind::Sphere, 256, 256);
  const int k = 2, mx = 40, my = 40, side = 256 * k;
  cv::Mat img = canvas(side + 2 * mx + 330, side + 2 * my);
  coded(L, k).copyTo(img(cv::Rect(mx, my, side, side)));
  Panel P{{double(mx), double(my)}, double(k), [&](const Vec3& d) { return std::optional<Vec2>(L.pixel(d)); }};
  grid(img, P, 60);
  for (const Axis& a : kAxes) {
    cv::Point2d off(9, -12);
    std::string label = a.name;
    if (a.name == "+Z") label = "+Z (centre)";
    if (a.name == "-Z") {
      label = "-Z = the whole rim (drawn at (x,y) = (0,-1))";
      off = {-150, 16};
    }
    if (a.name == "-X") off = {-32, -12};
    axis_dot(img, *P.at(a.d), a, label, off);
  }
  const cv::Point2d corner = P.at(Vec2(-0.5, -0.5));
  text(img, "texels outside the disc: no direction", corner + cv::Point2d(6, 12), 0.42, kLightGrey);
  const double tx = mx + side + 20;
  double ty = my + 10;
  auto say = [&](const std::string& s, const cv::Scalar& c = kWhite) {
    text(img, s, {tx, ty}, 0.45, c);
    ty += 22;
  };
  say("Sphere (mirror ball) 256 x 256:");
  say("an orthographic mirror ball seen from +Z");
  say("(view frame = world frame here)");
  say("image right = +X, image up = +Y");
  say("centre = +Z (towards the viewer)");
  say("rim = -Z (straight behind the ball)");
  ty += 10;
  say("texel p holds direction g_mirror(p):", kLightGrey);
  say("  x = (2c+1)/W - 1,  y = 1 - (2r+1)/H", kLightGrey);
  say("  z = sqrt(1 - x^2 - y^2)", kLightGrey);
  say("  d = (2xz, 2yz, 2z^2 - 1)", kLightGrey);
  say("radius sqrt(1/2) (through +-X, +-Y):", kLightGrey);
  say("  directions perpendicular to +Z", kLightGrey);
  say("equal-area: d(omega) = 4 dx dy", kLightGrey);
  ty += 10;
  say("Grid: 30 deg lat/lon; thick: equator, lon 0.");
  save(dir, "layout_sphere.png", img);
}

// ---------------------------------------------------------------------------------------------
// Sphere-map coordinates of one radiance map (view frame), on an 8x8-texel map drawn large.
void sphere_coords_figure(const std::filesystem::path& dir) {
  const int n = 8, k = 56, mx = 90, my = 60, side = n * k;
  const Layout L(LayoutKind::Sphere, n, n);
  cv::Mat img = canvas(side + mx + 500, side + my + 90);
  Panel P{{double(mx), double(my)}, double(k), [&](const Vec3& d) { return std::optional<Vec2>(L.pixel(d)); }};
  // Texels: direction-coded g_mirror of the centre (view frame), grey where the centre is outside.
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c) {
      const auto d = L.direction(Vec2(c, r));
      cv::Scalar col(45, 45, 45);
      if (d)
        col = cv::Scalar(255 * (0.2 + 0.3 * (d->z() + 1)), 255 * (0.2 + 0.3 * (d->y() + 1)),
                         255 * (0.2 + 0.3 * (d->x() + 1)));
      cv::rectangle(img, cv::Rect(mx + c * k, my + r * k, k, k), col, -1);
      cv::rectangle(img, cv::Rect(mx + c * k, my + r * k, k + 1, k + 1), kGrey, 1);
      dot(img, P.at(Vec2(c, r)), 2, d ? kWhite : kGrey);
    }
  // Unit disc = the silhouette (the rim: mirror direction -v), and the circle where the mirror
  // direction is perpendicular to v (radius sqrt(1/2)).
  const cv::Point2d centre = P.at(sphere_map::pixel_from_disc(Vec2(0, 0), n, n));
  auto circle = [&](double rho, const cv::Scalar& col, int thick) {
    cv::circle(img, fixed(centre), int(std::lround(rho * side / 2.0 * (1 << kShift))), col, thick, cv::LINE_AA, kShift);
  };
  circle(1.0, kWhite, 2);
  circle(std::sqrt(0.5), kLightGrey, 1);
  // Axes x (right) and y (up) through the centre.
  const cv::Point2d xe = P.at(sphere_map::pixel_from_disc(Vec2(1.15, 0), n, n));
  const cv::Point2d ye = P.at(sphere_map::pixel_from_disc(Vec2(0, 1.15), n, n));
  cv::arrowedLine(img, fixed(centre), fixed(xe), kWhite, 2, cv::LINE_AA, kShift, 0.04);
  cv::arrowedLine(img, fixed(centre), fixed(ye), kWhite, 2, cv::LINE_AA, kShift, 0.04);
  text(img, "x", xe + cv::Point2d(6, 0), 0.6);
  text(img, "y", ye + cv::Point2d(8, 4), 0.6);
  dot(img, centre, 5, cv::Scalar(255, 120, 30));
  text(img, "(0,0): n = r = +z = v", centre + cv::Point2d(-8, 18), 0.45, kWhite, 2);
  const cv::Point2d rim = P.at(sphere_map::pixel_from_disc(Vec2(0, -1), n, n));
  dot(img, rim, 4, cv::Scalar(0, 230, 255));
  text(img, "rim |(x,y)| = 1: r = -z = -v", rim + cv::Point2d(12, -12), 0.45, kWhite, 0);
  const cv::Point2d q = P.at(sphere_map::pixel_from_disc(Vec2(0, std::sqrt(0.5)), n, n));
  text(img, "|(x,y)| = sqrt(1/2): r perpendicular to v", q + cv::Point2d(0, -12), 0.42, kWhite, 1);
  const cv::Point2d q2 = P.at(sphere_map::pixel_from_disc(Vec2(0.55, -0.45), n, n));
  text(img, "n = g_normal, r = g_mirror", q2, 0.42, kLightGrey, 1);
  // s along the bottom, t on the left (t up).
  const double by = my + side + 8;
  for (int i = 0; i <= 4; ++i) {
    const double s = i / 4.0;
    const double px = mx + s * side;
    cv::line(img, {int(px), int(by)}, {int(px), int(by) + 6}, kLightGrey, 1);
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.2g", s);
    text(img, std::string("s=") + buf, {px, by + 18}, 0.42, kLightGrey, 1, false);
    std::snprintf(buf, sizeof buf, "x=%+.1f", 2 * s - 1);
    text(img, buf, {px, by + 38}, 0.42, kLightGrey, 1, false);
    const double py = my + (1 - s) * side;
    cv::line(img, {mx - 6, int(py)}, {mx, int(py)}, kLightGrey, 1);
    std::snprintf(buf, sizeof buf, "%.2g", s);
    text(img, std::string("t=") + buf, {mx - 10.0, py - 8}, 0.42, kLightGrey, 2, false);
    std::snprintf(buf, sizeof buf, "y=%+.1f", 2 * s - 1);
    text(img, buf, {mx - 10.0, py + 8}, 0.42, kLightGrey, 2, false);
  }
  cv::arrowedLine(img, {mx + side / 2 - 40, int(by) + 58}, {mx + side / 2 + 40, int(by) + 58}, kWhite, 1, cv::LINE_AA,
                  0, 0.2);
  text(img, "s", {mx + side / 2 + 48.0, by + 58}, 0.5);
  // First texel.
  const cv::Point2d t00 = P.at(Vec2(0, 0));
  text(img, "texel (c=0, r=0)", t00 + cv::Point2d(-26, -k / 2.0 - 24), 0.42);
  text(img, "s = 1/16, t = 15/16", t00 + cv::Point2d(-26, -k / 2.0 - 8), 0.42);
  const double tx = mx + side + 70;
  double ty = my + 10;
  auto say = [&](const std::string& s, const cv::Scalar& c = kWhite) {
    text(img, s, {tx, ty}, 0.45, c);
    ty += 22;
  };
  say("Sphere-map coordinates of a radiance map");
  say("(an 8x8 map; view frame: x right, y up,");
  say(" z from the ball's centre to the viewer = v)");
  ty += 8;
  say("(s,t) in [0,1]^2: s right, t UP", kLightGrey);
  say("texel (c, r), row 0 at the top, centre (dots):", kLightGrey);
  say("  s = (c + 0.5)/W,  t = 1 - (r + 0.5)/H", kLightGrey);
  say("x = 2s - 1,  y = 2t - 1", kLightGrey);
  say("g_normal = (x, y, sqrt(1 - x^2 - y^2))", kLightGrey);
  say("g_mirror = (2xz, 2yz, 2z^2 - 1)", kLightGrey);
  say("g_mirror^-1(r) = g_normal^-1((r+z)/|r+z|)", kLightGrey);
  say("  (the paper's /|r+z|^2 is a misprint)", kLightGrey);
  say("grey texels (centre outside the disc):", kLightGrey);
  say("  no direction, zero weight", kLightGrey);
  ty += 8;
  say("texel p of view v: radiance leaving a surface");
  say("with normal world_from_view * g_normal(p)");
  say("toward a viewer at infinity along v;");
  say("world_from_view = [x_view y_view v] (paper's T)");
  ty += 8;
  say("colour: mirror direction, view frame", kLightGrey);
  save(dir, "sphere_map_coordinates.png", img);
}

// ---------------------------------------------------------------------------------------------
void viewset_figure(const std::filesystem::path& dir, const ViewSet& set, const std::string& name,
                    const std::string& title) {
  const Layout L(LayoutKind::LatLong, 1024, 512);
  const int mx = 60, my = 36;
  cv::Mat img = canvas(L.width() + 2 * mx, L.height() + my + 80);
  Panel P{{double(mx), double(my)}, 1.0, [&](const Vec3& d) { return std::optional<Vec2>(L.pixel(d)); }};
  const auto& tris = set.triangles();
  // Background: the triangle each texel falls in (ViewSet::locate), pastel colours.
  for (int r = 0; r < L.height(); ++r)
    for (int c = 0; c < L.width(); ++c) {
      const auto w = set.locate(*L.direction(Vec2(c, r)));
      const unsigned h = unsigned(w.triangle) * 2654435761u;
      const cv::Vec3b col(uchar(90 + (h >> 8) % 100), uchar(90 + (h >> 16) % 100), uchar(90 + (h >> 24) % 100));
      img.at<cv::Vec3b>(my + r, mx + c) = w.inside ? col : cv::Vec3b(40, 40, 40);
    }
  // Faint 30-degree grid, then triangle edges as great-circle arcs.
  grid(img, P, 200);
  for (const auto& t : tris)
    for (int e = 0; e < 3; ++e) {
      const int a = t[std::size_t(e)], b = t[std::size_t((e + 1) % 3)];
      if (a < b) curve(img, P, great_arc(set.views()[std::size_t(a)], set.views()[std::size_t(b)]), kBlack, 2, 200);
    }
  const bool small = set.views().size() <= 12;
  if (small)
    for (std::size_t t = 0; t < tris.size(); ++t) {
      const Vec3 c = (set.views()[std::size_t(tris[t][0])] + set.views()[std::size_t(tris[t][1])] +
                      set.views()[std::size_t(tris[t][2])])
                         .normalized();
      text(img, "T" + std::to_string(t), *P.at(c) + cv::Point2d(0, 16), 0.4, kLightGrey, 1);
    }
  for (std::size_t i = 0; i < set.views().size(); ++i) {
    const Vec3& v = set.views()[i];
    const auto p = *P.at(v);
    dot(img, p, small ? 5 : 3, kWhite);
    if (small) {
      // The unnormalised icosahedron vertex: components 0, +-1, +-phi.
      const double scale = std::sqrt(1.0 + 0.25 * (1 + std::sqrt(5.0)) * (1 + std::sqrt(5.0)));
      std::string label = std::to_string(i) + " (";
      for (int k = 0; k < 3; ++k) {
        const double c = v[k] * scale;
        label += std::abs(c) < 1e-6 ? "0"
                                    : std::string(c > 0 ? "+" : "-") + (std::abs(std::abs(c) - 1) < 1e-6 ? "1" : "phi");
        label += k < 2 ? "," : ")";
      }
      text(img, label, p + cv::Point2d(8, -11), 0.42, kWhite);
    }
    if (std::abs(v.y()) > 0.999999 || std::abs(std::abs(std::atan2(v.x(), v.z())) - kPi) < 1e-9) {
      // On a pole or the seam: the point also appears at the other end.
      if (std::abs(v.y()) < 0.999999) dot(img, P.at(Vec2(L.width() - 1, L.pixel(v).y())), small ? 5 : 3, kWhite);
    }
  }
  for (int lon = -180; lon <= 180; lon += 60) {
    Vec2 p = L.pixel(from_lat_lon(0, lon * kDeg));
    if (lon == -180) p.x() = L.width() - 1;
    text(img, std::to_string(lon), {P.at(p).x, my - 12.0}, 0.4, kLightGrey, 1, false);
  }
  for (int lat = -60; lat <= 60; lat += 30)
    text(img, std::to_string(lat), {mx - 8.0, P.at(L.pixel(from_lat_lon(lat * kDeg, 0.3))).y}, 0.4, kLightGrey, 2,
         false);
  text(img, "+Z", *P.at(Vec3(0, 0, 1)) + cv::Point2d(0, 14), 0.4, kLightGrey, 1);
  const double ty = my + L.height() + 20;
  text(img, title, {double(mx), ty}, 0.45);
  text(img,
       std::to_string(set.views().size()) + " views, " + std::to_string(tris.size()) +
           " triangles: convex hull of the unit view vectors (qhull), counter-clockwise seen from outside, sorted.",
       {double(mx), ty + 22}, 0.45);
  text(img, "Drawn in lat-long (lon 0 = +Z at the centre, +X left of it); background: ViewSet::locate's triangle.",
       {double(mx), ty + 44}, 0.45, kLightGrey);
  save(dir, name, img);
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const std::filesystem::path dir = argc > 1 ? argv[1] : "docs/figures";
    std::filesystem::create_directories(dir);
    latlong_figure(dir);
    cube_figures(dir);
    octahedral_figure(dir);
    sphere_figure(dir);
    sphere_coords_figure(dir);
    viewset_figure(dir, ViewSet::icosahedron(), "viewset_icosahedron.png",
                   "Icosahedral view set (the paper's default): views = cyclic permutations of (0, +-1, +-phi), "
                   "normalised; index = ViewSet order.");
    viewset_figure(dir, ViewSet::geodesic(1), "viewset_geodesic42.png",
                   "Geodesic view set 42 (one subdivision: edge midpoints pushed to the sphere).");
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "layout_figures: " << e.what() << "\n";
    return 1;
  }
}
