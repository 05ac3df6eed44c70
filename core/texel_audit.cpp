#include "core/texel_audit.h"

#include <opencv2/imgproc.hpp>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <memory>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace rsibr {

TexelAudit audit_texels(const cv::Mat& m) {
  if (m.depth() != CV_32F) throw std::logic_error("audit_texels: expected a float image");
  TexelAudit a;
  const int ch = m.channels();
  for (int r = 0; r < m.rows; ++r) {
    const float* p = m.ptr<float>(r);
    for (int i = 0; i < m.cols * ch; ++i) {
      const float x = p[i];
      const bool nan = std::isnan(x), inf = std::isinf(x), huge = !nan && !inf && std::abs(x) > kMaxRadiance;
      a.nan += nan;
      a.inf += inf;
      a.huge += huge;
      a.negative += !nan && !inf && !huge && x < 0;
      if ((nan || inf || huge) && a.first_row < 0) a.first_row = r, a.first_col = i / ch;
    }
  }
  return a;
}

std::string TexelAudit::describe() const {
  std::ostringstream s;
  std::string sep;
  const auto part = [&](long n, const std::string& what) {
    if (n == 0) return;
    s << sep << n << " " << what;
    sep = ", ";
  };
  part(nan, "NaN");
  part(inf, "Inf");
  std::ostringstream beyond;
  beyond << "values beyond " << kMaxRadiance;
  part(huge, beyond.str());
  if (first_row >= 0) s << " (the first at texel column " << first_col << ", row " << first_row << ")";
  return s.str();
}

namespace {

// One channel (CV_32FC1). With window W of radius r, positive values P and deficits d (-L where
// L < 0), over unnormalised box sums (reflected at the border, which keeps them symmetric:
// y in W(x) exactly when x in W(y)):
//   ask_x = d_x / sum_{y in W(x)} P_y        the share of its window's positive mass x needs
//   q_y   = sum_{x in W(y)} ask_x            what is asked of y, as a fraction of P_y
//   h_y   = min(1, 1 / q_y)                  the fraction of the asks y can honour
//   y gives P_y min(q_y, 1);  x receives ask_x sum_{y in W(x)} P_y h_y
// so what the positives give equals what the deficits receive, texel by texel of the windows, and
// each channel's sum is kept. Deficits left over (their window had too little) try the next,
// doubled radius.
struct Deficit {
  int row, col;
  double amount;
};

// One radius's step over a list of deficits, with the windows' indices reflected as the dense
// step's box filter reflects them (the same sums, in another order). Costs (2r+1)^2 per deficit
// wherever the deficits lie, where the dense step costs the deficits' whole bounding box.
// field: a zeroed buffer of the image's size, handed back zeroed.
void fold_step_sparse(cv::Mat& positive, std::vector<Deficit>& deficits, int radius, double* field) {
  const int rows = positive.rows, cols = positive.cols, w = 2 * radius + 1;
  std::vector<int> window_rows(static_cast<std::size_t>(w)), window_cols(static_cast<std::size_t>(w));
  const auto window = [&](const Deficit& d) {
    for (int k = 0; k < w; ++k) {
      window_rows[std::size_t(k)] = cv::borderInterpolate(d.row - radius + k, rows, cv::BORDER_REFLECT);
      window_cols[std::size_t(k)] = cv::borderInterpolate(d.col - radius + k, cols, cv::BORDER_REFLECT);
    }
  };
  const auto at = [&](int r, int c) { return std::size_t(r) * std::size_t(cols) + std::size_t(c); };
  std::vector<double> ask(deficits.size(), 0.0);
  std::vector<std::size_t> touched;  // indices into field that the asks reached
  for (std::size_t i = 0; i < deficits.size(); ++i) {
    window(deficits[i]);
    double window_positive = 0;
    for (int rr : window_rows) {
      const float* p = positive.ptr<float>(rr);
      for (int cc : window_cols) window_positive += p[cc];
    }
    if (!(window_positive > 0)) continue;
    ask[i] = deficits[i].amount / window_positive;
    for (int rr : window_rows)
      for (int cc : window_cols) {
        double& f = field[at(rr, cc)];
        if (f == 0) touched.push_back(at(rr, cc));
        f += ask[i];
      }
  }
  // field: q_y, then P_y h_y; positive loses P_y min(q_y, 1).
  float* pos = positive.ptr<float>(0);  // continuous: one channel split from the image
  for (std::size_t t : touched) {
    float& pv = pos[t];
    const double q = field[t], p = pv;
    field[t] = q > 1 ? p / q : p;
    pv = float(p - p * std::min(q, 1.0));
  }
  std::vector<Deficit> left;
  for (std::size_t i = 0; i < deficits.size(); ++i) {
    if (ask[i] <= 0) {
      left.push_back(deficits[i]);
      continue;
    }
    window(deficits[i]);
    double supply = 0;
    for (int rr : window_rows)
      for (int cc : window_cols) supply += field[at(rr, cc)];
    const double rest = deficits[i].amount - ask[i] * supply;
    // Rounding leaves crumbs of a deficit that was met in full: dropped, not chased.
    if (rest > 1e-6 * deficits[i].amount) left.push_back({deficits[i].row, deficits[i].col, rest});
  }
  for (std::size_t t : touched) field[t] = 0;
  deficits = std::move(left);
}

// The same step by box filters over the deficits' bounding box grown by 2r: linear in that box,
// whatever the radius, so it serves many deficits at a large radius. Memory: three double planes of
// the box at most (the asks, their box sum turned into what each texel honours in place, and its box
// sum), since a 16K map's box is a gigabyte per plane.
void fold_step_dense(cv::Mat& positive, std::vector<Deficit>& deficits, int radius) {
  cv::Rect box(deficits.front().col, deficits.front().row, 1, 1);
  for (const Deficit& d : deficits) box |= cv::Rect(d.col, d.row, 1, 1);
  const cv::Rect roi =
      cv::Rect(box.x - 2 * radius, box.y - 2 * radius, box.width + 4 * radius, box.height + 4 * radius) &
      cv::Rect(0, 0, positive.cols, positive.rows);
  cv::Mat p = positive(roi);
  const cv::Size window(2 * radius + 1, 2 * radius + 1);
  const auto box_sum = [&](const cv::Mat& in) {
    cv::Mat out;
    cv::boxFilter(in, out, CV_64F, window, cv::Point(-1, -1), false, cv::BORDER_REFLECT);
    return out;
  };
  cv::Mat ask = cv::Mat::zeros(roi.size(), CV_64F);
  {
    const cv::Mat window_positive = box_sum(p);  // float in, double sums
    for (const Deficit& d : deficits) {
      const int r = d.row - roi.y, i = d.col - roi.x;
      if (window_positive.at<double>(r, i) > 0) ask.at<double>(r, i) = d.amount / window_positive.at<double>(r, i);
    }
  }
  cv::Mat honoured = box_sum(ask);  // q_y, then P_y h_y in place
  for (int r = 0; r < roi.height; ++r) {
    double* h = honoured.ptr<double>(r);
    float* pr = p.ptr<float>(r);
    for (int i = 0; i < roi.width; ++i) {
      const double q = h[i], pv = pr[i];
      h[i] = q > 1 ? pv / q : pv;
      pr[i] = float(pv - pv * std::min(q, 1.0));
    }
  }
  const cv::Mat supply = box_sum(honoured);
  honoured.release();
  std::vector<Deficit> left;
  for (const Deficit& d : deficits) {
    const int r = d.row - roi.y, i = d.col - roi.x;
    const double a = ask.at<double>(r, i);
    const double rest = a > 0 ? d.amount - a * supply.at<double>(r, i) : d.amount;
    if (a <= 0 || rest > 1e-6 * d.amount) left.push_back({d.row, d.col, rest});
  }
  deficits = std::move(left);
}

void remove_negative_ringing_channel(cv::Mat& c, FoldMethod method, std::mutex& dense_step) {
  if (!c.isContinuous()) c = c.clone();
  std::vector<Deficit> deficits;
  for (int r = 0; r < c.rows; ++r) {
    float* p = c.ptr<float>(r);
    for (int i = 0; i < c.cols; ++i)
      if (p[i] < 0) {
        deficits.push_back({r, i, -double(p[i])});
        p[i] = 0.f;
      }
  }
  const int largest = std::max(c.rows, c.cols);
  // Zeroed pages come from the system as they are first touched: only those near deficits cost.
  const std::unique_ptr<double, decltype(&std::free)> field(
      static_cast<double*>(std::calloc(std::size_t(c.rows) * std::size_t(c.cols), sizeof(double))), &std::free);
  if (!field) throw std::bad_alloc();
  for (int radius = 1; !deficits.empty(); radius *= 2) {
    if (radius > 2 * largest) break;  // no positive value anywhere can absorb what is left: zeroed
    long r0 = c.rows, r1 = 0, c0 = c.cols, c1 = 0;
    for (const Deficit& d : deficits)
      r0 = std::min<long>(r0, d.row), r1 = std::max<long>(r1, d.row), c0 = std::min<long>(c0, d.col),
      c1 = std::max<long>(c1, d.col);
    const double box = double(std::min<long>(c.rows, r1 - r0 + 1 + 4L * radius)) *
                       double(std::min<long>(c.cols, c1 - c0 + 1 + 4L * radius));
    const double sparse = 3.0 * double(deficits.size()) * double(2 * radius + 1) * double(2 * radius + 1);
    // The dense step allocates its whole box in double, so it pays only for many
    // deficits at large radii; the factor weighs a window texel against a box texel.
    if (method == FoldMethod::Sparse || (method == FoldMethod::Auto && sparse <= 64.0 * box))
      fold_step_sparse(c, deficits, radius, field.get());
    else {
      // One dense step at a time across the channels: each holds three double planes of its box.
      // Isolated: OpenCV's filters run on TBB too, and a thread waiting for them must not pick up
      // another channel's task, which would wait for this very lock.
      const std::lock_guard<std::mutex> lock(dense_step);
      tbb::this_task_arena::isolate([&] { fold_step_dense(c, deficits, radius); });
    }
  }
}

}  // namespace

long remove_negative_ringing(cv::Mat& m, FoldMethod method) {
  if (m.depth() != CV_32F) throw std::logic_error("remove_negative_ringing: expected a float image");
  long negative = 0;
  for (int r = 0; r < m.rows; ++r) {
    const float* p = m.ptr<float>(r);
    for (int i = 0; i < m.cols * m.channels(); ++i) negative += p[i] < 0;
  }
  if (negative == 0) return 0;
  std::vector<cv::Mat> channels;
  cv::split(m, channels);
  // Channels are independent: one task each (their dense steps take turns).
  std::mutex dense_step;
  tbb::parallel_for(std::size_t(0), channels.size(),
                    [&](std::size_t k) { remove_negative_ringing_channel(channels[k], method, dense_step); });
  cv::merge(channels, m);
  return negative;
}

long sanitize_texels(cv::Mat& m) {
  if (m.depth() != CV_32F) throw std::logic_error("sanitize_texels: expected a float image");
  long changed = 0;
  const int ch = m.channels();
  for (int r = 0; r < m.rows; ++r) {
    float* p = m.ptr<float>(r);
    for (int i = 0; i < m.cols * ch; ++i)
      if (!std::isfinite(p[i]) || p[i] > kMaxRadiance) {
        p[i] = 0.f;
        ++changed;
      }
  }
  return changed + remove_negative_ringing(m);
}

}  // namespace rsibr
