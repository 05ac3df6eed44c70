#include "pipeline/calibrate_step.h"

#include "calib/lens/intrinsics.h"
#include "calib/lens/photo_optics.h"
#include "core/lens_model.h"
#include "core/progress.h"
#include "hdr/bracket_set.h"
#include "pipeline/chessboard_problem.h"

#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace rsibr {

nlohmann::json run_calibrate_step(const CalibrateStep& st) {
  if (!st.set) throw std::invalid_argument("calibrate: no photo set");
  nlohmann::json j;
  if (st.source == "exif") {
    const BracketSet b = load_brackets(st.set->views[0], true);
    // lensfun's profile of the lens the EXIF names (distortion included), else a pinhole.
    const std::optional<MetadataLens> meta = metadata_lens(st.file, b.cols(), b.rows());
    const PhotoOptics optics = meta ? meta->optics : read_photo_optics(st.file);
    // Why no focal length in pixels: what the EXIF held and what was missing to convert it.
    std::string lensfun_why = meta ? meta->lensfun_why : "the photo's metadata has no FocalLength";
    if (!meta && optics.focal_mm) {
      char mm[32];
      std::snprintf(mm, sizeof mm, "%.3g mm", *optics.focal_mm);
      lensfun_why = "FocalLength " + std::string(mm) +
                    " but no FocalLengthIn35mmFilm, and lensfun knows no crop factor of the camera '" + optics.make +
                    " " + optics.model + "' (its sensor size)";
    }
    const bool from_lensfun = meta && meta->source == "lensfun";
    const std::optional<OpticsLens> guess = meta ? std::optional<OpticsLens>(meta->lens) : std::nullopt;
    if (!guess) {
      // No focal length in the metadata (stripped by an app, a scan): a pinhole of the image's
      // diagonal (a normal lens) to start from; the lens step measures f from the balls' outlines.
      const double f = std::hypot(double(b.cols()), double(b.rows()));
      const LensModel lens = LensModel::pinhole(f, b.cols(), b.rows());
      lens.write(st.out);
      j = {{"source", "outlines"},
           {"model", lens.name()},
           {"intrinsics", lens.intrinsics()},
           {"focal_px", f},
           {"focal_from",
            "none: no usable focal length in the photos' metadata (FocalLengthIn35mmFilm, or "
            "FocalLength of a camera lensfun knows)"},
           {"camera", optics.make + " " + optics.model},
           {"lens", optics.lens},
           {"lensfun", lensfun_why},
           {"assumed",
            "a pinhole: principal point at the image centre, no distortion, the focal length from the "
            "balls' outlines (the lens step)"}};
      return j;
    }
    guess->lens.write(st.out);
    j = {{"source", from_lensfun ? "lensfun" : "exif"},
         {"model", guess->lens.name()},
         {"intrinsics", guess->lens.intrinsics()},
         {"focal_px", guess->focal_px},
         {"focal_sigma_relative", guess->sigma_relative},
         {"focal_from", guess->source},
         {"camera", optics.make + " " + optics.model},
         {"lens", optics.lens},
         {"assumed", from_lensfun ? "lensfun's distortion profile of the lens, its centre at lensfun's"
                                  : "a pinhole: principal point at the image centre, no distortion"}};
    if (!from_lensfun) j["lensfun"] = lensfun_why;
    if (optics.focal_mm) j["focal_mm"] = *optics.focal_mm;
    if (optics.focal_35mm) j["focal_35mm"] = *optics.focal_35mm;
  } else if (st.source != "chessboards") {
    const LensModel lens = LensModel::read(st.file);
    lens.write(st.out);
    j = {{"source", st.file.string()}, {"model", lens.name()}, {"intrinsics", lens.intrinsics()}};
  } else {
    std::vector<std::string> missed;
    Progress bar("calibrate", st.progress);
    const IntrinsicsProblem p = chessboard_problem(*st.set, st.photoset, &missed, [&](double f) { bar.update(f); });
    bar.done();
    const std::vector<std::string>& models = kCalibrateModels;
    int chosen = 0;
    const std::vector<ModelScore> scores = cross_validate_models(p, models, &chosen);
    const IntrinsicsFit fit = fit_intrinsics(p, models[chosen]);
    fit.lens.write(st.out);
    nlohmann::json sc = nlohmann::json::array();
    for (const ModelScore& m : scores)
      sc.push_back({{"model", m.model}, {"held_out_rms_px", m.held_out_rms_px}, {"fit_rms_px", m.fit_rms_px}});
    j = {{"source", "chessboards"},
         {"model", models[chosen]},
         {"intrinsics", fit.lens.intrinsics()},
         {"rms_px", fit.rms_px},
         {"outliers", fit.outliers},
         {"boards_found", p.boards.size()},
         {"boards_missed", missed},
         {"models", sc}};
  }
  return j;
}

}  // namespace rsibr
