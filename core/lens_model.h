// A camera lens model (intrinsics and image size), a thin wrapper over mrcal's C API: every mrcal
// lens model (LENSMODEL_PINHOLE, LENSMODEL_OPENCV4/5/8/12, LENSMODEL_STEREOGRAPHIC,
// LENSMODEL_SPLINED_STEREOGRAPHIC_..., CAHVOR), read and written as mrcal's `.cameramodel` text
// so mrcal's own tools can inspect the files.
//
// Frames (docs/conventions.md): the camera frame is mrcal/OpenCV's, x right, y down, z forward.
// Pixels follow mrcal: (0, 0) is the centre of the top-left pixel. Intrinsics are mrcal's vector
// for the model: the core (fx, fy, cx, cy) first where the model has one, then the distortions.
// The extrinsics of a .cameramodel (rt_cam_ref, mrcal's Rodrigues rotation then translation) are
// carried through unchanged; rsibr keeps poses elsewhere and writes zeros by default.
#pragma once

#include "core/vec.h"

#include <array>
#include <filesystem>
#include <string>
#include <vector>

namespace rsibr {

class LensModel {
 public:
  // `name` is mrcal's configured model name, e.g. "LENSMODEL_OPENCV8" or
  // "LENSMODEL_SPLINED_STEREOGRAPHIC_order=3_Nx=16_Ny=12_fov_x_deg=100". Throws
  // std::invalid_argument for an unknown name, an intrinsics vector of the wrong length, a
  // non-finite value, a focal length that is not positive, a spline mrcal cannot build (order 2
  // or 3, at least 4x4 knots, fov_x_deg 1 to 359) or a non-positive image size.
  LensModel(const std::string& name, std::vector<double> intrinsics, int width, int height);

  // Throws std::invalid_argument("mrcal lens model '<name>': <problem>") for a name the
  // constructor would refuse (the model's configuration, before mrcal is asked to use it).
  static void check_name(const std::string& name);

  // A pinhole model with focal length f (pixels) and the principal point at the image centre.
  static LensModel pinhole(double f, int width, int height);

  // .cameramodel text or file; errors are std::invalid_argument("<what>: <problem>").
  static LensModel read(const std::filesystem::path& file);
  static LensModel parse(const std::string& text, const std::string& what = "cameramodel");
  // Writes atomically (formats/atomic_file.h) through mrcal_write_cameramodel_file. Throws
  // std::runtime_error("<file>: <problem>").
  void write(const std::filesystem::path& file) const;

  const std::string& name() const { return name_; }
  const std::vector<double>& intrinsics() const { return intrinsics_; }
  int width() const { return width_; }
  int height() const { return height_; }
  // mrcal's rt_cam_ref (6 numbers), carried through read and write.
  const std::array<double, 6>& rt_cam_ref() const { return rt_cam_ref_; }
  void set_rt_cam_ref(const std::array<double, 6>& rt) { rt_cam_ref_ = rt; }
  // Whether the model can represent points at or behind the image plane (z <= 0).
  bool can_project_behind_camera() const;

  // Pixel of a camera-frame point (any length). Undefined (but finite where mrcal is) for points
  // outside the model's field of view; callers check with in_image().
  Vec2 project(const Vec3& cam) const;
  // Several points at once (one mrcal call).
  void project(const Vec3* cam, int n, Vec2* pixels) const;
  // Unit camera-frame direction of the ray through a pixel (mrcal_unproject: an iterative solve
  // for distorted models; about 1e-9 px round trip inside the image).
  Vec3 unproject(const Vec2& pixel) const;
  void unproject(const Vec2* pixels, int n, Vec3* dirs) const;

  // Inside the image: pixel centres span [0, width-1] x [0, height-1], pixels cover half a pixel
  // more on every side.
  bool in_image(const Vec2& p, double margin = 0) const {
    return p.x() >= -0.5 + margin && p.y() >= -0.5 + margin && p.x() <= width_ - 0.5 - margin &&
           p.y() <= height_ - 0.5 - margin;
  }

  bool operator==(const LensModel& o) const {
    return name_ == o.name_ && intrinsics_ == o.intrinsics_ && width_ == o.width_ && height_ == o.height_ &&
           rt_cam_ref_ == o.rt_cam_ref_;
  }

 private:
  std::string name_;
  std::vector<double> intrinsics_;
  int width_ = 0, height_ = 0;
  std::array<double, 6> rt_cam_ref_{};
};

// A table of unit ray directions for fast unprojection of many sub-pixel positions: directions are
// mrcal_unproject'ed on a grid every `step` pixels (covering the image with a two-cell border) and
// interpolated by Catmull-Rom splines in normalised coordinates (x/z, y/z). Models that see behind the camera
// are not supported (throws std::invalid_argument): their normalised coordinates are unbounded.
// Accuracy (tests/capture/lens_model_test.cpp): the interpolated ray reprojects to within 1e-3 px
// of its pixel for an OPENCV8 lens with 8% barrel distortion at step 8.
//
// A table over a part of the image (pixels lo to hi, e.g. around one ball) costs its area instead of
// the whole image's and is made for any model, as long as every ray of its grid is in front of the
// camera (else it throws std::invalid_argument, and the caller unprojects exactly).
class RayTable {
 public:
  RayTable(const LensModel& lens, int step = 8);
  RayTable(const LensModel& lens, int step, const Vec2& lo, const Vec2& hi);
  Vec3 direction(double px, double py) const;  // unit, camera frame

 private:
  void build(const LensModel& lens, const Vec2& lo, const Vec2& hi);
  int step_, cols_ = 0, rows_ = 0;
  double x0_ = 0, y0_ = 0;
  std::vector<Vec2> xy_;  // normalised (x/z, y/z) at the grid points
};

}  // namespace rsibr
