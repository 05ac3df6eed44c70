// The four warp methods (runtime/make_warp.h) in one run: time per destination map and source-position
// error against the exact warp, for a ring of views around the axis (the double-indirection warp's
// offsets) and for general rotations (its swing tables), and the blend's time per frame with each.
// bench/warp_methods.py runs it and writes the docs/tradeoffs.md section "Warp methods".
//
//   rsibr_warp_methods [--sizes 128,256,512] [--reps 5]      one JSON object per line on stdout
#include "formats/map_set.h"
#include "core/sphere_map.h"
#include "core/view_set.h"
#include "runtime/blend.h"
#include "runtime/blend_engine.h"
#include "runtime/double_indirection_warp.h"
#include "runtime/make_warp.h"
#include "runtime/tessellated_warp.h"
#include "runtime/warp_error.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace rsibr {
namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

Mat3 ring_frame(double elev_deg, double azim_deg) {
  const double e = elev_deg * kPi / 180, a = azim_deg * kPi / 180;
  return world_from_view_for(Vec3(std::cos(e) * std::sin(a), std::sin(e), std::cos(e) * std::cos(a)));
}

struct Method {
  std::string name;
  int knob = 0;  // tessellated: rings; double-indirection: table columns
  std::unique_ptr<Warp> warp;
};

std::vector<Method> methods(int n, const Vec3& axis) {
  std::vector<Method> m;
  m.push_back({"exact", 0, make_warp({"exact"}, n, n)});
  m.push_back({"precomputed", 0, make_warp({"precomputed"}, n, n)});
  for (int rings : {16, 32}) m.push_back({"tessellated", rings, make_warp({"tessellated", rings}, n, n)});
  for (int columns : {n / 2, n, 2 * n})
    m.push_back({"double-indirection", columns, make_warp({"double-indirection", 16, axis, columns}, n, n)});
  return m;
}

// Source frames of one destination frame: `ring` = three views of the destination's ring (rotations
// about world up), otherwise three views 25-40 degrees away in general directions. `frame` varies
// the destination so that no per-frame cache serves a repeat.
std::vector<Mat3> sources_of(bool ring, int frame, Mat3* dest) {
  const double az = 3.0 + 0.37 * frame;
  *dest = ring_frame(20, az);
  std::vector<Mat3> out;
  if (ring) {
    for (double d : {-40.0, 25.0, 65.0}) out.push_back(ring_frame(20, az + d).transpose() * *dest);
  } else {
    const Vec3 v = dest->col(2);
    for (const Vec3& off : {Vec3(0.5, 0.1, 0.2), Vec3(-0.3, -0.5, 0.1), Vec3(0.1, 0.4, -0.6)})
      out.push_back(world_from_view_for((v + off).normalized()).transpose() * *dest);
  }
  return out;
}

// One destination map's warps for the given sources, all disc rows, this thread, in the form the
// blend engine uses (Warp::warp_block: single precision, structure of arrays).
void warp_map(const Warp& w, CentralDirection kind, const std::vector<Mat3>& sources, int n, std::vector<float>& buf) {
  const std::size_t row = std::size_t(n) + 1;
  for (const Mat3& m : sources)
    for (int r = 0; r < n; ++r) {
      const auto [c0, c1] = disc_span(r, n, n);
      if (c0 < c1) w.warp_block(kind, m, n, n, r, c0, c1, buf.data(), buf.data() + row, buf.data() + 2 * row);
    }
}

// A map set of two rings of 8 views (elevations -20 and 20) and the poles, random texels.
MapSet ring_set(int n) {
  MapSet set;
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(0.2f, 1.f);
  std::vector<Mat3> frames;
  for (double elev : {-20.0, 20.0})
    for (int k = 0; k < 8; ++k) frames.push_back(ring_frame(elev, 45.0 * k + (elev > 0 ? 22.5 : 0)));
  for (const Vec3& pole : {Vec3(0, 1, 0), Vec3(0, -1, 0)}) frames.push_back(world_from_view_for(pole));
  for (const Mat3& T : frames) {
    MapView v;
    v.view = T.col(2);
    v.world_from_view = T;
    v.warp = CentralDirection::Mirror;
    v.rgb = cv::Mat(n, n, CV_32FC3);
    for (int r = 0; r < n; ++r)
      for (int c = 0; c < n; ++c) v.rgb.at<cv::Vec3f>(r, c) = cv::Vec3f(u(rng), u(rng), u(rng));
    set.views.push_back(std::move(v));
  }
  return set;
}

int run(const std::vector<int>& sizes, int reps) {
  for (int n : sizes) {
    std::vector<float> buf(3 * (std::size_t(n) + 1));
    Mat3 dest0;
    sources_of(true, 0, &dest0);
    const Vec3 axis = dest0.transpose() * Vec3(0, 1, 0);
    const std::vector<Method> ms = methods(n, axis);
    for (bool ring : {true, false})
      for (CentralDirection kind : {CentralDirection::Mirror, CentralDirection::Normal})
        for (const Method& m : ms) {
          Mat3 dest;
          const std::vector<Mat3> src = sources_of(ring, 0, &dest);
          const testing::WarpError e = testing::compare_to_exact(*m.warp, kind, src, n, 0.1);
          const double max_t = e.max_texels, rms_t = e.rms_texels;
          // Frames: each a new destination (caches never serve a repeat); the best of `reps` passes.
          const int frames = std::max(2, 4 * 256 * 256 / (n * n));
          double best = INFINITY;
          int frame = 1;
          for (int rep = 0; rep < reps; ++rep) {
            const auto t0 = Clock::now();
            for (int f = 0; f < frames; ++f) warp_map(*m.warp, kind, sources_of(ring, frame++, &dest), n, buf);
            best = std::min(best, since(t0) / frames);
          }
          std::printf(
              "{\"what\": \"warp\", \"size\": %d, \"case\": \"%s\", \"kind\": \"%s\", \"warp\": \"%s\", "
              "\"knob\": %d, \"seconds_per_map\": %.6g, \"max_texels\": %.5g, \"rms_texels\": %.5g}\n",
              n, ring ? "ring" : "general", to_string(kind), m.name.c_str(), m.knob, best, max_t, rms_t);
          std::fflush(stdout);
        }
    // The blend (all threads) to destinations on the upper ring of a two-ring set, with each warp,
    // through one engine (its sources laid out once, as the renderer and the viewer hold it).
    const MapSet set = ring_set(n);
    const ViewSet views = set.view_set();
    const BlendEngine engine(set, views);
    engine.prepare_all();
    const std::vector<Method> bm = methods(n, axis_in_views(set, Vec3(0, 1, 0)));
    for (const Method& m : bm) {
      BlendOptions o;
      o.width = o.height = n;
      o.warp = m.warp.get();
      const int frames = std::max(2, 8 * 256 * 256 / (n * n));
      double best = INFINITY;
      int frame = 0;
      for (int rep = 0; rep < reps; ++rep) {
        const auto t0 = Clock::now();
        for (int f = 0; f < frames; ++f) engine.map(ring_frame(20, 5.0 + 1.3 * frame++).col(2), Vec3(0, 1, 0), o);
        best = std::min(best, since(t0) / frames);
      }
      std::printf("{\"what\": \"blend\", \"size\": %d, \"warp\": \"%s\", \"knob\": %d, \"seconds_per_frame\": %.6g}\n",
                  n, m.name.c_str(), m.knob, best);
      std::fflush(stdout);
    }
  }
  return 0;
}

std::vector<int> parse_ints(const char* text) {
  std::vector<int> out;
  std::stringstream s(text);
  std::string item;
  while (std::getline(s, item, ',')) out.push_back(std::stoi(item));
  return out;
}

}  // namespace
}  // namespace rsibr

int main(int argc, char** argv) {
  std::vector<int> sizes = {128, 256, 512};
  int reps = 5;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--sizes") && i + 1 < argc)
      sizes = rsibr::parse_ints(argv[++i]);
    else if (!std::strcmp(argv[i], "--reps") && i + 1 < argc)
      reps = std::stoi(argv[++i]);
    else {
      std::fprintf(stderr, "usage: rsibr_warp_methods [--sizes 128,256,512] [--reps 5]\n");
      return 2;
    }
  }
  return rsibr::run(sizes, reps);
}
