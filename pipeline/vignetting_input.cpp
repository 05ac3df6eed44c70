#include "pipeline/vignetting_input.h"

#include "calib/lens/photo_optics.h"
#include "pipeline/chessboard_problem.h"

#include <fstream>
#include <optional>
#include <stdexcept>

namespace rsibr {

namespace fs = std::filesystem;

std::vector<fs::path> vignetting_inputs(const PhotoSet& set, const std::string& mode) {
  if (mode == "none") return {};
  if (mode == "auto") {
    if (set.chessboards) return set.chessboards->files;
    // Without boards: the lens database, for the lens the first photo's EXIF names.
    if (!set.views.empty() && !set.views[0].brackets.empty()) return {set.views[0].brackets[0].file};
    return {};
  }
  return {fs::path(mode)};
}

Vignetting photo_set_vignetting(const PhotoSet& set, const std::string& mode, const ResponseCurve& curve,
                                const LensModel& lens, nlohmann::json* report) {
  const auto& in = lens.intrinsics();
  const Vec2 c = in.size() >= 4 ? Vec2(in[2], in[3]) : Vec2(0.5 * (lens.width() - 1), 0.5 * (lens.height() - 1));
  Vignetting v = Vignetting::none(lens.width(), lens.height(), c);
  nlohmann::json rep = {{"mode", mode}};
  if (mode == "none") {
    rep["note"] = "not corrected (--vignetting none)";
  } else if (mode == "auto") {
    if (!set.chessboards) {
      // lensfun's profile of the lens the EXIF names, at its focal length and aperture.
      std::optional<LensfunVignetting> lf;
      if (!set.views.empty() && !set.views[0].brackets.empty()) {
        const fs::path photo = set.views[0].brackets[0].file;
        lf = lensfun_vignetting(read_photo_optics(photo), lens.width(), lens.height());
      }
      if (lf) {
        // lensfun's profiles are about the image centre.
        const Vec2 centre(0.5 * (lens.width() - 1), 0.5 * (lens.height() - 1));
        v = Vignetting::none(lens.width(), lens.height(), centre);
        v.k = lf->k;
        v.source = "lensfun: " + lf->lens;
        rep["estimate"] = {{"lensfun_lens", lf->lens}, {"fit_rms", lf->fit_rms}};
      } else {
        rep["note"] =
            "not corrected: no chessboard images to estimate it from and no lensfun profile for the lens "
            "the EXIF names (give --vignetting FILE)";
      }
    } else {
      std::vector<VignettingBoard> boards;
      try {
        const IntrinsicsProblem p = chessboard_problem(set, set.folder.string());
        for (const ChessboardObservation& b : p.boards)
          for (const fs::path& f : set.chessboards->files)
            if (f.filename().string() == b.name)
              boards.push_back({b.name, read_board_codes(f), b.corners, p.corners_x});
      } catch (const std::invalid_argument& e) {
        rep["note"] = std::string("not corrected: ") + e.what();
      }
      if (!boards.empty()) {
        const VignettingEstimate e = estimate_vignetting(boards, curve, c, lens.width(), lens.height());
        v = e.model;
        rep["estimate"] = {{"degree", e.degree},
                           {"boards", e.boards},
                           {"squares", e.squares},
                           {"rms", e.rms},
                           {"corner_sigma_stops", e.corner_sigma_stops},
                           {"max_r", e.max_r},
                           {"held_out_rms", e.held_out_rms}};
        if (!e.note.empty()) rep["note"] = "not corrected: " + e.note;
      }
    }
  } else {
    std::ifstream f(mode);
    if (!f) throw std::invalid_argument(mode + ": cannot read the vignetting model");
    nlohmann::json j;
    try {
      f >> j;
    } catch (const std::exception& e) {
      throw std::invalid_argument(mode + ": not JSON (" + std::string(e.what()) + ")");
    }
    v = vignetting_from_json(j, mode);
    v.source = "given: " + fs::path(mode).filename().string();
  }
  rep["model"] = vignetting_json(v);
  if (report) *report = rep;
  return v;
}

}  // namespace rsibr
