// mrcal's C header has no extern "C" guard of its own.
#include "core/lens_model.h"

#include "formats/atomic_file.h"
#include "formats/input_file.h"

extern "C" {
#include <mrcal/mrcal.h>
}

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <mutex>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <sstream>
#include <stdexcept>

namespace rsibr {
namespace {

// The .cameramodel syntax, checked before mrcal sees the text: mrcal 2.2's parser reads past the
// end of some malformed texts and of some comments (found by fuzz/fuzz_camera_model), so only
// well-formed ones reach it, and with their comments blanked out (newlines kept, so line numbers in
// mrcal's messages still match the file).
//   model  := '{' [ string ':' value { ',' string ':' value } [','] ] '}'
//   value  := string | number | '[' [ value { ',' value } [','] ] ']'
//   string := '...' or "..." on one line;  number := [+-] digits [. digits] [(e|E) [+-] digits]
// with blanks and '#' comments (to the end of the line) between tokens, and nothing after '}'.
class CameraModelSyntax {
 public:
  explicit CameraModelSyntax(const std::string& text) : s_(text), blanked_(text) {}

  // "" when the text is well formed, else what is wrong and where.
  std::string problem() {
    try {
      expect('{');
      if (!accept('}')) {
        do {
          if (peek() == '}') break;
          string();
          expect(':');
          value(1);
        } while (accept(','));
        expect('}');
      }
      skip();
      if (i_ != s_.size()) fail("text after the closing '}'");
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "";
  }
  // The text with every comment replaced by blanks, ending in a newline; valid after problem()
  // returned "".
  std::string blanked() const { return blanked_ + "\n"; }

 private:
  [[noreturn]] void fail(const std::string& what) {
    std::size_t line = 1;
    for (std::size_t k = 0; k < i_ && k < s_.size(); ++k) line += s_[k] == '\n';
    throw std::invalid_argument("line " + std::to_string(line) + ": " + what);
  }
  void skip() {
    while (i_ < s_.size()) {
      if (s_[i_] == '#') {
        for (; i_ < s_.size() && s_[i_] != '\n'; ++i_) blanked_[i_] = ' ';
      } else if (s_[i_] == ' ' || s_[i_] == '\t' || s_[i_] == '\n' || s_[i_] == '\r') {
        ++i_;
      } else {
        break;
      }
    }
  }
  char peek() {
    skip();
    return i_ < s_.size() ? s_[i_] : '\0';
  }
  bool accept(char c) {
    if (peek() != c) return false;
    ++i_;
    return true;
  }
  void expect(char c) {
    if (!accept(c)) fail(std::string("expected '") + c + "'");
  }
  void string() {
    const char q = peek();
    if (q != '\'' && q != '"') fail("expected a quoted key or string");
    for (++i_; i_ < s_.size() && s_[i_] != q; ++i_)
      if (s_[i_] == '\n' || s_[i_] == '\\') fail("a string that spans lines or holds a backslash");
    if (i_ >= s_.size()) fail("a string without its closing quote");
    ++i_;
  }
  void digits() {
    const std::size_t start = i_;
    while (i_ < s_.size() && s_[i_] >= '0' && s_[i_] <= '9') ++i_;
    if (i_ == start) fail("expected a number");
  }
  void number() {
    skip();
    if (i_ < s_.size() && (s_[i_] == '+' || s_[i_] == '-')) ++i_;
    digits();
    if (i_ < s_.size() && s_[i_] == '.') {
      ++i_;
      while (i_ < s_.size() && s_[i_] >= '0' && s_[i_] <= '9') ++i_;
    }
    if (i_ < s_.size() && (s_[i_] == 'e' || s_[i_] == 'E')) {
      ++i_;
      if (i_ < s_.size() && (s_[i_] == '+' || s_[i_] == '-')) ++i_;
      digits();
    }
  }
  void value(int depth) {
    if (depth > 4) fail("lists nested too deep");
    const char c = peek();
    if (c == '\'' || c == '"') return string();
    if (c != '[') return number();
    ++i_;
    if (accept(']')) return;
    do {
      if (peek() == ']') break;
      value(depth + 1);
    } while (accept(','));
    expect(']');
  }
  const std::string& s_;
  std::string blanked_;
  std::size_t i_ = 0;
};

mrcal_lensmodel_t lensmodel_of(const std::string& name) {
  mrcal_lensmodel_t m;
  if (!mrcal_lensmodel_from_name(&m, name.c_str()) || !mrcal_lensmodel_type_is_valid(m.type))
    throw std::invalid_argument("unknown or unconfigured mrcal lens model '" + name + "'");
  // mrcal asserts (aborts) on splines it cannot build; refused here with the reason instead.
  if (m.type == MRCAL_LENSMODEL_SPLINED_STEREOGRAPHIC) {
    const auto& c = m.LENSMODEL_SPLINED_STEREOGRAPHIC__config;
    if (c.order != 2 && c.order != 3)
      throw std::invalid_argument("mrcal lens model '" + name + "': a spline's order is 2 or 3");
    if (c.Nx < 4 || c.Ny < 4)
      throw std::invalid_argument("mrcal lens model '" + name + "': a spline needs a grid of at least 4x4 knots");
    if (c.fov_x_deg < 1 || c.fov_x_deg > 359)
      throw std::invalid_argument("mrcal lens model '" + name + "': fov_x_deg must be 1 to 359 degrees");
  }
  return m;
}

std::string name_of(const mrcal_lensmodel_t& m) {
  char buf[256];
  if (!mrcal_lensmodel_name(buf, sizeof buf, &m)) throw std::invalid_argument("mrcal lens model without a name");
  return buf;
}

struct CameraModelFree {
  void operator()(mrcal_cameramodel_t* m) const { mrcal_free_cameramodel(&m); }
};

}  // namespace

LensModel::LensModel(const std::string& name, std::vector<double> intrinsics, int width, int height)
    : intrinsics_(std::move(intrinsics)), width_(width), height_(height) {
  const mrcal_lensmodel_t m = lensmodel_of(name);
  name_ = name_of(m);
  const int n = mrcal_lensmodel_num_params(&m);
  if (int(intrinsics_.size()) != n)
    throw std::invalid_argument(name_ + ": needs " + std::to_string(n) + " intrinsics, got " +
                                std::to_string(intrinsics_.size()));
  for (double v : intrinsics_)
    if (!std::isfinite(v)) throw std::invalid_argument(name_ + ": intrinsics must be finite");
  // Every mrcal model with a core starts with fx, fy, cx, cy: a focal length that is not positive
  // maps every pixel to the same ray (or none), which no later step survives.
  if (mrcal_lensmodel_metadata(&m).has_core && !(intrinsics_[0] > 0 && intrinsics_[1] > 0))
    throw std::invalid_argument(name_ + ": the focal lengths (fx, fy) must be positive");
  if (width <= 0 || height <= 0) throw std::invalid_argument(name_ + ": the image size must be positive");
}

void LensModel::check_name(const std::string& name) { lensmodel_of(name); }

LensModel LensModel::pinhole(double f, int width, int height) {
  return LensModel("LENSMODEL_PINHOLE", {f, f, 0.5 * (width - 1), 0.5 * (height - 1)}, width, height);
}

LensModel LensModel::parse(const std::string& text, const std::string& what) {
  CameraModelSyntax syntax(text);
  if (const std::string problem = syntax.problem(); !problem.empty())
    throw std::invalid_argument(what + ": not a valid mrcal .cameramodel (" + problem + ")");
  const std::string clean = syntax.blanked();
  // mrcal's parser reports problems on stderr; catch that line so the error stays one line that
  // names the file (the CLI contract).
  std::string diagnostic;
  std::unique_ptr<mrcal_cameramodel_t, CameraModelFree> m;
  {
    static std::mutex stderr_mutex;
    std::lock_guard<std::mutex> lock(stderr_mutex);
    std::fflush(stderr);
    FILE* sink = std::tmpfile();
    const int saved = sink ? ::dup(2) : -1;
    if (saved >= 0) ::dup2(::fileno(sink), 2);
    m.reset(mrcal_read_cameramodel_string(clean.c_str(), int(clean.size())));
    if (saved >= 0) {
      std::fflush(stderr);
      ::dup2(saved, 2);
      ::close(saved);
      std::rewind(sink);
      char line[512];
      while (std::fgets(line, sizeof line, sink)) diagnostic = line;
    }
    if (sink) std::fclose(sink);
  }
  while (!diagnostic.empty() && (diagnostic.back() == '\n' || diagnostic.back() == '\r')) diagnostic.pop_back();
  if (!m)
    throw std::invalid_argument(what + ": not a valid mrcal .cameramodel" +
                                (diagnostic.empty() ? std::string() : " (" + diagnostic + ")"));
  const int n = mrcal_lensmodel_num_params(&m->lensmodel);
  LensModel out(name_of(m->lensmodel), std::vector<double>(m->intrinsics, m->intrinsics + n), int(m->imagersize[0]),
                int(m->imagersize[1]));
  std::array<double, 6> rt;
  for (int i = 0; i < 6; ++i) rt[std::size_t(i)] = m->rt_cam_ref[i];
  out.set_rt_cam_ref(rt);
  return out;
}

LensModel LensModel::read(const std::filesystem::path& file) {
  require_regular_file(file);
  std::ifstream in(file, std::ios::binary);
  if (!in) throw std::invalid_argument(file.string() + ": cannot read");
  std::stringstream ss;
  ss << in.rdbuf();
  try {
    return parse(ss.str(), file.string());
  } catch (const std::invalid_argument& e) {
    const std::string msg = e.what();
    if (msg.rfind(file.string(), 0) == 0) throw;
    throw std::invalid_argument(file.string() + ": " + msg);
  }
}

void LensModel::write(const std::filesystem::path& file) const {
  const mrcal_lensmodel_t lm = lensmodel_of(name_);
  const std::size_t bytes = sizeof(mrcal_cameramodel_t) + intrinsics_.size() * sizeof(double);
  std::unique_ptr<mrcal_cameramodel_t, decltype(&std::free)> m(static_cast<mrcal_cameramodel_t*>(std::calloc(1, bytes)),
                                                               &std::free);
  if (!m) throw std::runtime_error(file.string() + ": out of memory");
  for (int i = 0; i < 6; ++i) m->rt_cam_ref[i] = rt_cam_ref_[std::size_t(i)];
  m->imagersize[0] = unsigned(width_);
  m->imagersize[1] = unsigned(height_);
  m->lensmodel = lm;
  for (std::size_t i = 0; i < intrinsics_.size(); ++i) m->intrinsics[i] = intrinsics_[i];
  write_atomically(file, [&](const std::string& tmp) {
    if (!mrcal_write_cameramodel_file(tmp.c_str(), m.get()))
      throw std::runtime_error(file.string() + ": mrcal could not write the camera model");
  });
}

bool LensModel::can_project_behind_camera() const {
  const mrcal_lensmodel_t m = lensmodel_of(name_);
  return mrcal_lensmodel_metadata(&m).can_project_behind_camera;
}

void LensModel::project(const Vec3* cam, int n, Vec2* pixels) const {
  if (n <= 0) return;
  const mrcal_lensmodel_t m = lensmodel_of(name_);
  std::vector<mrcal_point3_t> p(static_cast<std::size_t>(n));
  std::vector<mrcal_point2_t> q(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) p[std::size_t(i)] = {{cam[i].x(), cam[i].y(), cam[i].z()}};
  if (!mrcal_project(q.data(), nullptr, nullptr, p.data(), n, &m, intrinsics_.data()))
    throw std::runtime_error(name_ + ": mrcal_project failed");
  for (int i = 0; i < n; ++i) pixels[i] = Vec2(q[std::size_t(i)].x, q[std::size_t(i)].y);
}

Vec2 LensModel::project(const Vec3& cam) const {
  Vec2 out;
  project(&cam, 1, &out);
  return out;
}

void LensModel::unproject(const Vec2* pixels, int n, Vec3* dirs) const {
  if (n <= 0) return;
  const mrcal_lensmodel_t m = lensmodel_of(name_);
  std::vector<mrcal_point2_t> q(static_cast<std::size_t>(n));
  std::vector<mrcal_point3_t> v(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) q[std::size_t(i)] = {{pixels[i].x(), pixels[i].y()}};
  if (!mrcal_unproject(v.data(), q.data(), n, &m, intrinsics_.data()))
    throw std::runtime_error(name_ + ": mrcal_unproject failed");
  for (int i = 0; i < n; ++i) {
    const auto& w = v[std::size_t(i)];
    dirs[i] = Vec3(w.x, w.y, w.z).normalized();
  }
}

Vec3 LensModel::unproject(const Vec2& pixel) const {
  Vec3 out;
  unproject(&pixel, 1, &out);
  return out;
}

RayTable::RayTable(const LensModel& lens, int step) : step_(step) {
  if (step < 1) throw std::invalid_argument("RayTable: step must be >= 1");
  if (lens.can_project_behind_camera())
    throw std::invalid_argument(lens.name() + ": RayTable needs a model that cannot see behind the camera");
  build(lens, Vec2(-1, -1), Vec2(lens.width(), lens.height()));
}

RayTable::RayTable(const LensModel& lens, int step, const Vec2& lo, const Vec2& hi) : step_(step) {
  if (step < 1) throw std::invalid_argument("RayTable: step must be >= 1");
  if (!(hi.x() >= lo.x() && hi.y() >= lo.y()) || !lo.allFinite() || !hi.allFinite())
    throw std::invalid_argument("RayTable: an empty or non-finite region");
  build(lens, lo, hi);
}

void RayTable::build(const LensModel& lens, const Vec2& lo, const Vec2& hi) {
  // Grid points at x0 + i*step covering [lo, hi] with two border cells (the cubic interpolation
  // reads one point beyond its cell).
  x0_ = lo.x() - 2.0 * step_;
  y0_ = lo.y() - 2.0 * step_;
  cols_ = int(std::ceil((hi.x() - lo.x() + 4.0 * step_) / step_)) + 1;
  rows_ = int(std::ceil((hi.y() - lo.y() + 4.0 * step_) / step_)) + 1;
  std::vector<Vec2> pix(std::size_t(cols_) * std::size_t(rows_));
  for (int r = 0; r < rows_; ++r)
    for (int c = 0; c < cols_; ++c)
      pix[std::size_t(r) * std::size_t(cols_) + std::size_t(c)] = Vec2(x0_ + c * step_, y0_ + r * step_);
  std::vector<Vec3> d(pix.size());
  lens.unproject(pix.data(), int(pix.size()), d.data());
  xy_.resize(pix.size());
  for (std::size_t i = 0; i < d.size(); ++i) {
    if (!(d[i].z() > 0))
      throw std::invalid_argument(lens.name() + ": RayTable: the model cannot unproject pixel (" +
                                  std::to_string(pix[i].x()) + ", " + std::to_string(pix[i].y()) +
                                  ") (distortion not invertible there, or behind the camera)");
    xy_[i] = Vec2(d[i].x() / d[i].z(), d[i].y() / d[i].z());
  }
}

// Catmull-Rom (cubic) interpolation of the grid: exact for quadratics, error O(step^4) where the
// map is smooth (bilinear was 0.013 px at step 8 on the test's OPENCV8 lens).
Vec3 RayTable::direction(double px, double py) const {
  const double gx = std::clamp((px - x0_) / step_, 1.0, cols_ - 2.000001);
  const double gy = std::clamp((py - y0_) / step_, 1.0, rows_ - 2.000001);
  const int c = int(gx), r = int(gy);
  const double fx = gx - c, fy = gy - r;
  auto weights = [](double t, double w[4]) {
    const double t2 = t * t, t3 = t2 * t;
    w[0] = 0.5 * (-t3 + 2 * t2 - t);
    w[1] = 0.5 * (3 * t3 - 5 * t2 + 2);
    w[2] = 0.5 * (-3 * t3 + 4 * t2 + t);
    w[3] = 0.5 * (t3 - t2);
  };
  double wx[4], wy[4];
  weights(fx, wx);
  weights(fy, wy);
  Vec2 xy(0, 0);
  for (int j = 0; j < 4; ++j) {
    const Vec2* row = &xy_[std::size_t(r - 1 + j) * std::size_t(cols_) + std::size_t(c - 1)];
    xy += wy[j] * (wx[0] * row[0] + wx[1] * row[1] + wx[2] * row[2] + wx[3] * row[3]);
  }
  return Vec3(xy.x(), xy.y(), 1.0).normalized();
}

}  // namespace rsibr
