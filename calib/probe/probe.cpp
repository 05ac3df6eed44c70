#include "calib/probe/probe.h"

#include "formats/exr_io.h"
#include "core/parallel.h"
#include "core/sphere_map.h"
#include "core/luminance.h"
#include "core/resolution_mask.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace rsibr {

namespace {

// Views one probe texel's lookups are held for (on the stack).
constexpr std::size_t kMaxProbeViews = 256;

// One view's bilinear lookup at mirror direction r (view frame): the trusted taps' value and
// confidence, and the clipped taps' weight and value.
struct Lookup {
  Vec3 value = Vec3::Zero();
  double confidence = 0, weight = 0;  // weight: the trusted taps' bilinear weight
  Vec3 clipped_value = Vec3::Zero();
  double clipped = 0, clipped_weight = 0;
  bool near_clipped = false;  // a trusted tap lies within the registration error of the view's own clipped texels
};

// `near`: empty, or CV_8UC1 of the map's size, non-zero within the registration error of a clipped texel.
Lookup look_up(const MapView& mv, const cv::Mat& near, const Vec3& r) {
  Lookup out;
  const Vec2 px = sphere_map::pixel_from_disc(sphere_map::g_mirror_inv(r), mv.rgb.cols, mv.rgb.rows);
  const int x0 = static_cast<int>(std::floor(px.x())), y0 = static_cast<int>(std::floor(px.y()));
  if (x0 < 0 || y0 < 0 || x0 + 1 >= mv.rgb.cols || y0 + 1 >= mv.rgb.rows) return out;
  const double fx = px.x() - x0, fy = px.y() - y0;
  const double tw[4] = {(1 - fx) * (1 - fy), fx * (1 - fy), (1 - fx) * fy, fx * fy};
  const int tx[4] = {x0, x0 + 1, x0, x0 + 1}, ty[4] = {y0, y0, y0 + 1, y0 + 1};
  for (int k = 0; k < 4; ++k) {
    const cv::Vec3f p = mv.rgb.at<cv::Vec3f>(ty[k], tx[k]);
    const Vec3 c(p[0], p[1], p[2]);
    // A tap without confidence gives nothing; the rest are renormalised (bilinear within the trusted texels).
    if (const float cf = mv.confidence.at<float>(ty[k], tx[k]); cf > 0) {
      out.value += tw[k] * c;
      out.confidence += tw[k] * cf;
      out.weight += tw[k];
      out.near_clipped |= !near.empty() && near.at<unsigned char>(ty[k], tx[k]) != 0;
    } else if (!mv.clipped.empty()) {
      if (const float cl = mv.clipped.at<float>(ty[k], tx[k]); cl > 0 && c.allFinite()) {
        out.clipped_value += tw[k] * c;
        out.clipped += tw[k] * cl;
        out.clipped_weight += tw[k];
      }
    }
  }
  if (out.clipped_weight > 0) {
    // A clipped tap's value is a lower bound, far above its neighbours' for a sun: renormalising
    // over the trusted taps would fill the sun with sky. The whole lookup counts as clipped.
    out.clipped_value /= out.clipped_weight;
    out.value = Vec3::Zero();
    out.confidence = out.weight = 0;
    out.near_clipped = false;
    return out;
  }
  if (out.weight > 0) out.value /= out.weight;
  return out;
}

}  // namespace

namespace {

// The texel loop of assemble_probe, for the set and, with `folds`, for the set without each view in
// turn: out[0] all views, out[1 + v] without view v (its env only). Every view's lookups are made
// once per subsample and summed per output, skipping the left-out view, in view order: each output
// is what assemble_probe of its views gives, bit for bit. A fold whose subsampling or resolution
// masks would differ from the whole set's (the left-out view was the finest, or the only one of its
// resolution) is left empty here (`done` false) for the caller to assemble on its own.
std::vector<Probe> assemble(const MapSet& set, const ProbeOptions& options, bool folds, std::vector<char>* done) {
  if (set.views.empty()) throw std::invalid_argument("probe: no views");
  if (set.views.size() > kMaxProbeViews)
    throw std::invalid_argument("probe: " + std::to_string(set.views.size()) + " views; at most " +
                                std::to_string(kMaxProbeViews) + " are assembled into one probe");
  for (std::size_t v = 0; v < set.views.size(); ++v) {
    const MapView& mv = set.views[v];
    if (mv.confidence.empty() || mv.rgb.type() != CV_32FC3)
      throw std::invalid_argument("probe: view." + std::to_string(v) +
                                  " has no confidence channel (not a captured map)");
    if (!mv.clipped.empty() && (mv.clipped.type() != CV_32FC1 || mv.clipped.size() != mv.rgb.size()))
      throw std::invalid_argument("probe: view." + std::to_string(v) +
                                  " has a clipped channel of the wrong type or size");
  }
  if (options.width < 4 || options.width % 2) throw std::invalid_argument("probe: width must be even and >= 4");
  const Layout layout(LayoutKind::LatLong, options.width, options.width / 2);
  const std::size_t nv = set.views.size(), outputs = folds ? 1 + nv : 1;
  std::vector<Probe> out(outputs);
  for (std::size_t e = 0; e < outputs; ++e) {
    out[e].env = EnvMap::zeros(layout, 3);
    out[e].env.attributes["source"] = "probe";
  }
  Probe& probe = out.front();
  probe.weight = cv::Mat(layout.height(), layout.width(), CV_32FC1, cv::Scalar(0));
  probe.clipped = cv::Mat(layout.height(), layout.width(), CV_32FC1, cv::Scalar(0));
  probe.lower_bound = cv::Mat(layout.height(), layout.width(), CV_32FC3, cv::Scalar::all(0));
  // The finest map's texel angle (4 / size radians) against the probe's (latitude step).
  const double probe_texel = kPi / (layout.height() - 1);
  auto subsamples = [&](std::size_t skip) {
    int map_size = 0;
    for (std::size_t v = 0; v < nv; ++v)
      if (v != skip) map_size = std::max(map_size, std::min(set.views[v].rgb.cols, set.views[v].rgb.rows));
    const double map_texel = 4.0 / std::max(map_size, 1);
    return std::clamp(int(std::ceil(probe_texel / map_texel - 1e-9)), 1, 4);
  };
  const int k = subsamples(nv);
  // Views measured at different resolutions (core/resolution_mask.h): each lookup's confidence is
  // scaled by s_i = m_i + 1 - max_j m_j, the views' authored masks at the lookup's level of detail
  // (the probe's subsample spacing in the view's map texels), so the sharpest views give the detail
  // wherever they fully cover. Views of one resolution: s_i = 1.
  std::vector<double> detail;
  for (std::size_t v = 0; v < nv; ++v) {
    try {
      detail.push_back(native_detail_level(set.views[v]));
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument("probe: view." + std::to_string(v) + ": " + e.what());
    }
  }
  const bool mixed = mixed_resolution(detail);
  // The folds made in this pass: those whose subsampling and mixing are the whole set's.
  std::vector<char> in_pass(outputs, 1);
  for (std::size_t v = 0; folds && v < nv; ++v) {
    std::vector<double> rest = detail;
    rest.erase(rest.begin() + long(v));
    in_pass[1 + v] = nv >= 2 && subsamples(v) == k && mixed_resolution(rest) == mixed;
  }
  if (done) *done = in_pass;
  std::vector<std::unique_ptr<MaskPyramid>> masks(nv);
  std::vector<double> lod(nv, 0.0);
  if (mixed)
    for (std::size_t v = 0; v < nv; ++v) {
      masks[v] = resolution_mask(set.views[v].confidence, detail[v]);
      const double spacing = probe_texel / k, texel = 4.0 / std::max(1, set.views[v].rgb.cols);
      lod[v] = spacing > texel ? std::log2(spacing / texel) : 0.0;
    }
  // Per view, its clipped texels grown by the registration error (registration_deg; a map texel
  // spans 4 / size radians), for the vote below.
  std::vector<cv::Mat> near(nv);
  for (std::size_t v = 0; v < nv; ++v) {
    const MapView& mv = set.views[v];
    if (mv.clipped.empty() || !(options.registration_deg > 0)) continue;
    cv::Mat mask = mv.clipped > 0.0f;
    if (cv::countNonZero(mask) == 0) continue;
    const int radius = int(std::ceil(options.registration_deg * kPi / 180 * std::max(mv.rgb.cols, mv.rgb.rows) / 4));
    cv::dilate(mask, near[v], cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * radius + 1, 2 * radius + 1)));
  }
  std::vector<double> row_area(layout.height(), 0.0), row_covered(layout.height(), 0.0),
      row_clipped(layout.height(), 0.0);
  struct Sums {
    Vec3 sum = Vec3::Zero(), bound = Vec3::Zero();
    double wsum = 0, csum = 0, wnear = 0;
  };
  parallel_for_rows(layout.height(), [&](int row) {
    std::vector<Sums> acc(outputs);
    for (int col = 0; col < layout.width(); ++col) {
      const auto centre = layout.texel_direction(col, row);
      if (!centre) continue;
      const double area = std::sqrt(std::max(0.0, 1.0 - centre->y() * centre->y()));  // cos(latitude)
      row_area[row] += area;
      std::fill(acc.begin(), acc.end(), Sums{});
      for (int a = 0; a < k; ++a)
        for (int b = 0; b < k; ++b) {
          const auto w = k == 1 ? centre : layout.direction(Vec2(col - 0.5 + (b + 0.5) / k, row - 0.5 + (a + 0.5) / k));
          if (!w) continue;
          Lookup looks[kMaxProbeViews];
          float m[kMaxProbeViews];
          Vec3 f[kMaxProbeViews];
          // The largest mask value and the runner-up's: the largest without any one view.
          float m_max = 0.0f, m_second = 0.0f;
          std::size_t m_arg = nv;
          for (std::size_t v = 0; v < nv; ++v) {
            const MapView& mv = set.views[v];
            const Vec3 r = mv.world_from_view.transpose() * *w;
            looks[v] = look_up(mv, near[v], r);
            m[v] = 0.0f;
            if (mixed && looks[v].confidence > 0) {
              const Vec2 px = sphere_map::pixel_from_disc(sphere_map::g_mirror_inv(r), mv.rgb.cols, mv.rgb.rows);
              m[v] = masks[v]->sample(px, lod[v]);
              if (m[v] > m_max || m_arg == nv)
                m_second = m_max, m_max = m[v], m_arg = v;
              else
                m_second = std::max(m_second, m[v]);
            }
            f[v] = Vec3::Ones();
            if (options.fresnel && (looks[v].confidence > 0 || looks[v].clipped > 0))
              f[v] = options.fresnel->eval(std::sqrt(std::clamp(0.5 * (1 + r.normalized().z()), 0.0, 1.0)))
                         .cwiseMax(Vec3::Constant(1e-6));
          }
          for (std::size_t e = 0; e < outputs; ++e) {
            if (!in_pass[e]) continue;
            const std::size_t skip = e == 0 ? nv : e - 1;
            const float mm = skip == m_arg ? m_second : m_max;
            Sums& s = acc[e];
            for (std::size_t v = 0; v < nv; ++v) {
              if (v == skip) continue;
              Lookup l = looks[v];
              if (mixed) l.confidence *= m[v] + 1.0f - mm;
              if (l.confidence > 0) {
                s.sum += l.confidence * l.value.cwiseQuotient(f[v]);
                s.wsum += l.confidence;
                if (l.near_clipped) s.wnear += l.confidence;
              }
              if (l.clipped > 0) {
                s.csum += l.clipped;
                s.bound = s.bound.cwiseMax(l.clipped_value.cwiseQuotient(f[v]));
              }
            }
          }
        }
      for (std::size_t e = 0; e < outputs; ++e) {
        if (!in_pass[e]) continue;
        Sums& s = acc[e];
        s.wsum /= k * k, s.csum /= k * k, s.sum /= k * k, s.wnear /= k * k;
        // A trusted estimate below a lower bound other views saw there contradicts them (a sun
        // smeared over the stretched rim of a view that saw it unclipped): the lower bound wins when
        // its views outweigh the trusted ones (else one view's misregistered clipped pixels would
        // clip the sky the others saw). A trusted lookup within the registration error of its own
        // view's clipped texels does not vote against it: that view saw the light clipped too, a
        // little elsewhere (a sun a few texels wide in every view, the views registered a degree or
        // two apart, would otherwise be outvoted everywhere and vanish from the probe;
        // docs/tradeoffs.md, "Measured choices in the code").
        if (s.wsum >= options.min_weight && s.csum > s.wsum - s.wnear && luminance(s.sum / s.wsum) < luminance(s.bound))
          s.wsum = 0;
        if (s.wsum < options.min_weight) {
          if (e == 0 && s.csum >= options.min_weight) {
            probe.clipped.at<float>(row, col) = static_cast<float>(s.csum);
            probe.lower_bound.at<cv::Vec3f>(row, col) =
                cv::Vec3f(float(s.bound.x()), float(s.bound.y()), float(s.bound.z()));
            row_clipped[row] += area;
          }
          continue;
        }
        const Vec3 l = s.sum / s.wsum;
        out[e].env.pixels.at<cv::Vec3f>(row, col) = cv::Vec3f(float(l.x()), float(l.y()), float(l.z()));
        if (e == 0) {
          probe.weight.at<float>(row, col) = static_cast<float>(s.wsum);
          row_covered[row] += area;
        }
      }
    }
  });
  double a = 0, c = 0, cl = 0;
  for (int r = 0; r < layout.height(); ++r) a += row_area[r], c += row_covered[r], cl += row_clipped[r];
  probe.covered_fraction = a > 0 ? c / a : 0;
  probe.clipped_fraction = a > 0 ? cl / a : 0;
  return out;
}

}  // namespace

Probe assemble_probe(const MapSet& set, const ProbeOptions& options) {
  return std::move(assemble(set, options, false, nullptr).front());
}

std::vector<EnvMap> assemble_probe_folds(const MapSet& set, const ProbeOptions& options) {
  std::vector<char> done;
  std::vector<Probe> all = assemble(set, options, true, &done);
  std::vector<EnvMap> out;
  for (std::size_t v = 0; v < set.views.size(); ++v) {
    if (done[1 + v]) {
      out.push_back(std::move(all[1 + v].env));
      continue;
    }
    MapSet rest;
    for (std::size_t u = 0; u < set.views.size(); ++u)
      if (u != v) rest.views.push_back(set.views[u]);
    out.push_back(rest.views.empty() ? EnvMap{} : assemble_probe(rest, options).env);
  }
  return out;
}

void write_probe(const std::string& path, const EnvMap& env, const cv::Mat& confidence, const cv::Mat& flags) {
  cv::Mat f;
  flags.convertTo(f, CV_32F);
  write_environment(path, env, {}, {{"confidence", confidence}, {"flags", f}});
}

}  // namespace rsibr
