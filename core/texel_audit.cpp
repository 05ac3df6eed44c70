#include "core/texel_audit.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

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

long sanitize_texels(cv::Mat& m) {
  if (m.depth() != CV_32F) throw std::logic_error("sanitize_texels: expected a float image");
  long changed = 0;
  const int ch = m.channels();
  for (int r = 0; r < m.rows; ++r) {
    float* p = m.ptr<float>(r);
    for (int i = 0; i < m.cols * ch; ++i)
      if (!std::isfinite(p[i]) || p[i] < 0 || p[i] > kMaxRadiance) {
        p[i] = 0.f;
        ++changed;
      }
  }
  return changed;
}

}  // namespace rsibr
