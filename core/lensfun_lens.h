// A lens from the lensfun database (Debian's liblensfun, its profiles in liblensfun-data-v1),
// found by the names a photo's EXIF gives (camera make and model, lens model), as an mrcal model.
//
// lensfun describes distortion as a mapping of pixels: for each pixel of the corrected
// (rectilinear) image, where it lies in the photo. Its models (ptlens, poly3, poly5) are radial
// about the distortion centre and keep the scale at its normalising radius, not at the centre, so
// the corrected image's focal length is not the lens's. Here the mapping is sampled over the whole
// photo through lensfun's own modifier (none of its normalisation conventions are copied) and an
// OpenCV model of mrcal fitted to it, with the paraxial focal length (the EXIF focal length, or
// lensfun's real focal length where the profile gives one) as fx = fy:
//   x_u = (u - c) * m / f     (the ray's tangent plane point; m = lensfun's magnification at c)
//   d   = c + f * D(x_u)      (D: OPENCV5's radial terms, else OPENCV8's rational ones)
// Linear least squares for OPENCV5; for OPENCV8 the linearised rational form refined by
// Levenberg-Marquardt, with 1, 2 or 3 denominator terms and no pole in the field. The simplest
// model that reproduces lensfun within 0.05 px everywhere wins, else the closest. ptlens's odd
// powers of the radius are not in any OpenCV model: its fit is within about 0.1 px on a 648 px
// frame (scaling with the resolution); poly3 and poly5 are represented exactly.
// Rectilinear lenses only (mrcal's OpenCV models cannot represent a fisheye's field of view).
#pragma once

#include "core/lens_model.h"

#include <array>
#include <optional>
#include <string>

struct lfDatabase;

namespace rsibr {

// The database, loaded once (thread-safe); nullptr when lensfun cannot load it.
const lfDatabase* lensfun_database();

struct LensfunLens {
  LensModel lens = LensModel::pinhole(1, 2, 2);  // the image's size; centre: lensfun's distortion centre
  double focal_px = 0;                           // paraxial, pixels (fx = fy)
  double focal_mm = 0;                           // the focal length it was evaluated at (nominal)
  double crop_factor = 0;                        // the camera's (lensfun), else the lens's calibration crop
  std::string lens_name;                         // lensfun's name for the lens
  std::string camera;                            // lensfun's name for the camera (empty: not in the database)
  std::string profile;                           // e.g. "ptlens a=0.00644 b=-0.01245 c=-0.0348 at 18 mm"
  double fit_rms_px = 0, fit_max_px = 0;         // the model against lensfun's mapping over the photo
};

// Nullopt (with *why set when given) when the database lacks the lens or its distortion at that
// focal length, the lens is not rectilinear, or no crop factor is known. Throws
// std::invalid_argument for a non-positive size or focal length.
std::optional<LensfunLens> lensfun_lens(const std::string& make, const std::string& model, const std::string& lens,
                                        double focal_mm, int width, int height, std::string* why = nullptr);

// lensfun's vignetting of the lens (found as above) at its focal length and aperture, focused at
// `distance_m`, as the polynomial of hdr/vignetting.h (v = 1 + k1 r^2 + k2 r^4 + k3 r^6, r = 1 at
// the farthest corner, the image centre as its centre): fitted by least squares to lensfun's own
// correction of a flat field, so none of lensfun's coordinate conventions (normalisation, crop
// factors) are copied here. fit_rms: the fit's RMS relative error over the frame. Nullopt when
// lensfun lacks the lens or its vignetting, or the focal length or aperture is not positive.
struct LensfunVignetting {
  std::array<double, 3> k{0, 0, 0};
  std::string lens;  // lensfun's name for it
  double fit_rms = 0;
};
std::optional<LensfunVignetting> lensfun_vignetting(const std::string& make, const std::string& model,
                                                    const std::string& lens, double focal_mm, double aperture,
                                                    int width, int height, double distance_m = 1.0);

}  // namespace rsibr
