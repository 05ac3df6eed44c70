#include "hdr/alignment.h"

#include "core/parallel.h"

#include <opencv2/imgproc.hpp>
#include <opencv2/photo.hpp>

#include "core/vec.h"

#include <algorithm>
#include <cstdint>
#include <cmath>
#include <stdexcept>

namespace rsibr {
namespace {

// A moved bracket accepts its shift only when it removes this much of the disagreement, measured
// on at least this fraction of the frame (a bracket white or black almost everywhere has no
// bitmap to compare, and MTB's shift for it is noise).
constexpr double kAcceptRatio = 0.8;
constexpr double kMinCompared = 0.01;

// Fraction of pixels compared (outside both exclusion bitmaps, inside both coverages) where the
// threshold bitmaps of a and of b moved by `shift` disagree; the compared count in `compared`.
double mismatch(const cv::Mat& tb_a, const cv::Mat& eb_a, const cv::Mat& tb_b, const cv::Mat& eb_b, cv::Point shift,
                int* compared = nullptr) {
  const cv::Mat M = (cv::Mat_<double>(2, 3) << 1, 0, shift.x, 0, 1, shift.y);
  cv::Mat tb, eb;
  cv::warpAffine(tb_b, tb, M, tb_b.size(), cv::INTER_NEAREST, cv::BORDER_CONSTANT, cv::Scalar(0));
  cv::warpAffine(eb_b, eb, M, eb_b.size(), cv::INTER_NEAREST, cv::BORDER_CONSTANT, cv::Scalar(0));
  cv::Mat both = eb & eb_a, diff;
  cv::bitwise_xor(tb, tb_a, diff);
  diff &= both;
  const int n = cv::countNonZero(both);
  if (compared) *compared = n;
  return n > 0 ? double(cv::countNonZero(diff)) / n : 0.0;
}

cv::Mat shifted(const cv::Mat& m, cv::Point s, int border, const cv::Scalar& fill = cv::Scalar()) {
  const cv::Mat M = (cv::Mat_<double>(2, 3) << 1, 0, s.x, 0, 1, s.y);
  cv::Mat out;
  cv::warpAffine(m, out, M, m.size(), cv::INTER_NEAREST, border, fill);
  return out;
}

// The motion that moves a bracket onto the middle one: a rotation by `deg` about the image centre,
// then the shift (pixels, x right, y down).
cv::Mat motion_matrix(cv::Size size, cv::Point2d shift, double deg) {
  cv::Mat M =
      cv::getRotationMatrix2D(cv::Point2f(0.5f * float(size.width - 1), 0.5f * float(size.height - 1)), deg, 1.0);
  M.at<double>(0, 2) += shift.x;
  M.at<double>(1, 2) += shift.y;
  return M;
}

cv::Mat moved(const cv::Mat& m, cv::Point shift, double deg, int border, const cv::Scalar& fill = cv::Scalar()) {
  if (deg == 0) return shifted(m, shift, border, fill);
  cv::Mat out;
  cv::warpAffine(m, out, motion_matrix(m.size(), shift, deg), m.size(), cv::INTER_NEAREST, border, fill);
  return out;
}

// One level of the search: the threshold and exclusion bitmaps (0 / 255) of both images.
struct Level {
  cv::Mat tb_a, eb_a, tb_b, eb_b;
};

// Disagreement of b moved by (shift, deg) with a: the disagreeing fraction of the compared pixels
// (-1 when fewer than `min_compared` of the frame are compared). An integer shift is compared on
// the overlap directly; a rotation warps b's bitmaps.
double level_mismatch(const Level& l, cv::Point shift, double deg, double min_compared) {
  const int W = l.tb_a.cols, H = l.tb_a.rows;
  long n = 0, d = 0;
  if (deg == 0) {
    const int x0 = std::max(0, shift.x), x1 = std::min(W, W + shift.x), y0 = std::max(0, shift.y),
              y1 = std::min(H, H + shift.y);
    if (x1 <= x0 || y1 <= y0) return -1;
    // One pass over the overlap, no temporaries (a fine level is the full frame, searched ~25
    // times per bracket): the non-zero bytes of both = eb_a & eb_b, and of (tb_a ^ tb_b) & both.
    // Rows in parallel on large levels, summed in order.
    const int rows = y1 - y0, cols = x1 - x0;
    std::vector<long> row_n(std::size_t(rows), 0), row_d(std::size_t(rows), 0);
    const auto count_row = [&](int i) {
      const int ya = y0 + i, yb = ya - shift.y;
      const std::uint8_t* ta = l.tb_a.ptr<std::uint8_t>(ya) + x0;
      const std::uint8_t* ea = l.eb_a.ptr<std::uint8_t>(ya) + x0;
      const std::uint8_t* tb = l.tb_b.ptr<std::uint8_t>(yb) + (x0 - shift.x);
      const std::uint8_t* eb = l.eb_b.ptr<std::uint8_t>(yb) + (x0 - shift.x);
      long rn = 0, rd = 0;
      for (int x = 0; x < cols; ++x) {
        const std::uint8_t both = ea[x] & eb[x];
        rn += both != 0;
        rd += ((ta[x] ^ tb[x]) & both) != 0;
      }
      row_n[std::size_t(i)] = rn, row_d[std::size_t(i)] = rd;
    };
    if (long(rows) * cols >= (1L << 16))
      parallel_for_rows(rows, count_row);
    else
      for (int i = 0; i < rows; ++i) count_row(i);
    for (int i = 0; i < rows; ++i) n += row_n[std::size_t(i)], d += row_d[std::size_t(i)];
  } else {
    const cv::Mat M = motion_matrix(l.tb_b.size(), shift, deg);
    cv::Mat tb, eb;
    cv::warpAffine(l.tb_b, tb, M, l.tb_b.size(), cv::INTER_NEAREST, cv::BORDER_CONSTANT, cv::Scalar(0));
    cv::warpAffine(l.eb_b, eb, M, l.eb_b.size(), cv::INTER_NEAREST, cv::BORDER_CONSTANT, cv::Scalar(0));
    const cv::Mat both = eb & l.eb_a;
    n = cv::countNonZero(both);
    d = cv::countNonZero((tb ^ l.tb_a) & both);
  }
  if (double(n) < min_compared * double(W) * double(H)) return -1;
  return double(d) / double(n);
}

// The motion of b onto a, coarse to fine (see alignment.h). `at_edge`: the coarse search's best
// shift lies on the edge of its window (the true one may lie beyond it).
struct Motion {
  cv::Point shift;
  double deg = 0;
  bool at_edge = false;
};

Motion search_motion(const std::vector<Level>& levels) {
  const Level& top = levels.back();
  const int W = top.tb_a.cols, H = top.tb_a.rows;
  // Exhaustive over a quarter of the frame's shorter side at the coarsest level; the nearer of two
  // equal shifts wins (a repeated pattern must not pull the bracket a period away).
  const int R = std::max(2, (std::min(W, H) + 3) / 4);
  Motion m;
  double best = 2;
  for (int dy = -R; dy <= R; ++dy)
    for (int dx = -R; dx <= R; ++dx) {
      const double e = level_mismatch(top, {dx, dy}, 0, 0.25);
      if (e < 0) continue;
      const double cost = e + 1e-4 * std::hypot(dx, dy);
      if (cost < best) best = cost, m.shift = {dx, dy};
    }
  if (best > 1) return m;
  m.at_edge = std::abs(m.shift.x) == R || std::abs(m.shift.y) == R;
  // Small rotations (a handheld camera rolls a little between shots): the step turns the frame's
  // corners by about a pixel; kept only when it lowers the disagreement by 5% or more.
  constexpr double kMaxDeg = 3;
  auto step_deg = [](const Level& l) { return std::atan(1.0 / (0.5 * std::hypot(l.tb_a.cols, l.tb_a.rows))) / kDeg; };
  {
    const double step = step_deg(top), flat = level_mismatch(top, m.shift, 0, 0.25);
    double best_rot = flat;
    Motion r = m;
    for (double deg = -kMaxDeg; deg <= kMaxDeg + 1e-9; deg += step) {
      if (std::abs(deg) < 0.5 * step) continue;
      for (int dy = -2; dy <= 2; ++dy)
        for (int dx = -2; dx <= 2; ++dx) {
          const double e = level_mismatch(top, m.shift + cv::Point(dx, dy), deg, 0.25);
          if (e >= 0 && e < best_rot) best_rot = e, r.shift = m.shift + cv::Point(dx, dy), r.deg = deg;
        }
    }
    if (best_rot < 0.95 * flat) m.shift = r.shift, m.deg = r.deg;
  }
  // Finer levels: the shift doubled, then the best of its neighbours within 2 pixels (a coarse
  // level's smooth bitmaps can misjudge by one of its pixels, two of the next level's), or within 1
  // and one angle step either way when it turns (each a warp of the whole level).
  for (std::size_t k = levels.size() - 1; k-- > 0;) {
    const Level& l = levels[k];
    m.shift *= 2;
    const double step = m.deg == 0 ? 0 : step_deg(l);
    const int reach = m.deg == 0 ? 2 : 1;
    Motion b = m;
    double be = 2;
    for (int a = m.deg == 0 ? 0 : -1; a <= (m.deg == 0 ? 0 : 1); ++a)
      for (int dy = -reach; dy <= reach; ++dy)
        for (int dx = -reach; dx <= reach; ++dx) {
          const double e = level_mismatch(l, m.shift + cv::Point(dx, dy), m.deg + a * step, 0.25);
          if (e >= 0 && e < be) be = e, b.shift = m.shift + cv::Point(dx, dy), b.deg = m.deg + a * step;
        }
    m.shift = b.shift, m.deg = b.deg;
  }
  return m;
}

}  // namespace

const char* to_string(Alignment a) {
  switch (a) {
    case Alignment::off: return "off";
    case Alignment::automatic: return "auto";
    case Alignment::always: return "on";
  }
  return "?";
}

Alignment parse_alignment(const std::string& s) {
  if (s == "off") return Alignment::off;
  if (s == "auto") return Alignment::automatic;
  if (s == "on") return Alignment::always;
  throw std::invalid_argument("alignment '" + s + "': expected auto, on or off");
}

AlignmentResult align_brackets(BracketSet& b, Alignment mode, int max_bits) {
  const std::size_t P = b.size();
  AlignmentResult res;
  res.shifts.assign(P, cv::Point(0, 0));
  res.found.assign(P, cv::Point(0, 0));
  res.rotation_deg.assign(P, 0.0);
  res.beyond_search.assign(P, false);
  res.mismatch_before.assign(P, 0.0);
  res.mismatch_after.assign(P, 0.0);
  if (P < 2 || mode == Alignment::off) return res;
  std::vector<cv::Mat> grey(P);
  const double scale = b.max_code == 255 ? 1.0 : 1.0 / 257.0;
  for (std::size_t j = 0; j < P; ++j) {
    cv::Mat eight;
    b.codes[j].convertTo(eight, CV_8UC3, scale);
    cv::cvtColor(eight, grey[j], cv::COLOR_RGB2GRAY);
  }
  const std::size_t mid = P / 2;
  // Levels: each halves the image, down to a coarsest level of at most 128 pixels on its shorter
  // side (and at least 16).
  int levels = 1;
  while ((std::min(b.rows(), b.cols()) >> (levels - 1)) > 128 && (std::min(b.rows(), b.cols()) >> levels) >= 16)
    ++levels;
  // Under 32 px a side there is nothing to search.
  if (std::min(b.rows(), b.cols()) < 32) return res;
  auto mtb = cv::createAlignMTB(max_bits, 4, true);
  // Per bracket, per level: grey image and coverage, halved with area averaging.
  std::vector<std::vector<cv::Mat>> tb(P), eb(P);
  for (std::size_t j = 0; j < P; ++j) {
    cv::Mat g = grey[j], cov;
    if (j < b.covered.size() && !b.covered[j].empty()) cov = b.covered[j];
    for (int k = 0; k < levels; ++k) {
      if (k > 0) {
        cv::resize(g, g, cv::Size((g.cols + 1) / 2, (g.rows + 1) / 2), 0, 0, cv::INTER_AREA);
        if (!cov.empty()) cv::resize(cov, cov, g.size(), 0, 0, cv::INTER_NEAREST);
      }
      cv::Mat t, e;
      mtb->computeBitmaps(g, t, e);
      if (!cov.empty()) e &= cov;  // padding is no evidence
      tb[j].push_back(t), eb[j].push_back(e);
    }
  }
  for (std::size_t j = 0; j < P; ++j) {
    if (j == mid) continue;
    std::vector<Level> pyr;
    for (std::size_t k = 0; k < std::size_t(levels); ++k) pyr.push_back({tb[mid][k], eb[mid][k], tb[j][k], eb[j][k]});
    const Motion found = search_motion(pyr);
    const cv::Point s = found.shift;
    res.found[j] = s;
    int n0 = 0, n1 = 0;
    res.mismatch_before[j] = mismatch(tb[mid][0], eb[mid][0], tb[j][0], eb[j][0], cv::Point(0, 0), &n0);
    if (s == cv::Point(0, 0) && found.deg == 0) {
      res.mismatch_after[j] = res.mismatch_before[j];
      continue;
    }
    {
      const cv::Mat t = moved(tb[j][0], s, found.deg, cv::BORDER_CONSTANT),
                    e = moved(eb[j][0], s, found.deg, cv::BORDER_CONSTANT);
      res.mismatch_after[j] = mismatch(tb[mid][0], eb[mid][0], t, e, cv::Point(0, 0), &n1);
    }
    // A best shift on the edge of the search window may be short of the true one: not applied.
    if (found.at_edge) {
      res.beyond_search[j] = true;
      continue;
    }
    const double enough = kMinCompared * double(b.rows()) * double(b.cols());
    // Disagreeing pixels before and after: the drop must also stand out of their counting noise
    // (small or mostly white frames give a few dozen, and the search picks the shift that happens
    // to lower them).
    const double d0 = res.mismatch_before[j] * n0, d1 = res.mismatch_after[j] * n1;
    const bool better = double(n0) >= enough && double(n1) >= enough && res.mismatch_before[j] > 0 &&
                        res.mismatch_after[j] <= kAcceptRatio * res.mismatch_before[j] &&
                        d0 - d1 > 4.0 * std::sqrt(d0 + d1) + 20.0;
    if (mode == Alignment::automatic && !b.fitted_sizes && !better) continue;
    res.shifts[j] = s;
    res.rotation_deg[j] = found.deg;
    b.codes[j] = moved(b.codes[j], s, found.deg, cv::BORDER_REPLICATE);
    if (j < b.saturated.size() && !b.saturated[j].empty())
      b.saturated[j] = moved(b.saturated[j], s, found.deg, cv::BORDER_REPLICATE);
    if (b.covered.size() < P) b.covered.resize(P);
    const cv::Mat cov = b.covered[j].empty() ? cv::Mat(b.codes[j].size(), CV_8UC1, cv::Scalar(255)) : b.covered[j];
    b.covered[j] = moved(cov, s, found.deg, cv::BORDER_CONSTANT, cv::Scalar(0));
  }
  return res;
}

}  // namespace rsibr
