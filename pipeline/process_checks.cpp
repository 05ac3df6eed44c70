#include "pipeline/process_checks.h"

#include "bake/brdf_spec.h"
#include "calib/probe/probe.h"
#include "core/colour.h"
#include "core/lens_model.h"
#include "hdr/merged_colour.h"
#include "hdr/photo_set_merge.h"
#include "lights/recovered_probe.h"
#include "pipeline/ball_override.h"
#include "pipeline/pose_input.h"
#include "pipeline/vignetting_input.h"

#include <algorithm>
#include <stdexcept>

namespace rsibr {

namespace fs = std::filesystem;

void check_process_options(const ProcessOptions& o) {
  for (const std::string& f : o.force)
    if (f != "all" && std::find(process_steps().begin(), process_steps().end(), f) == process_steps().end())
      throw std::invalid_argument("--force '" + f +
                                  "': not a step (calibrate, hdr, balls, lens, orient, extract, probe, sources, "
                                  "bake, compare, render, report, all)");
  if (!o.lens.empty() && !fs::is_regular_file(o.lens)) throw std::invalid_argument(o.lens + ": no such file");
  if (!o.mesh.empty() && !fs::is_regular_file(o.mesh)) throw std::invalid_argument(o.mesh + ": no such file");
  if (!o.probe_file.empty() && !fs::is_regular_file(o.probe_file))
    throw std::invalid_argument(o.probe_file + ": no such file");
  if (!o.radiance_dir.empty() && !fs::is_directory(o.radiance_dir))
    throw std::invalid_argument(o.radiance_dir + ": no such folder");
  if (!o.poses.empty()) read_given_poses(o.poses);  // errors before any work
  if (o.vignetting != "auto" && o.vignetting != "none") {
    if (!fs::is_regular_file(o.vignetting)) throw std::invalid_argument(o.vignetting + ": no such file (--vignetting)");
    photo_set_vignetting(PhotoSet{}, o.vignetting, ResponseCurve::identity(255), LensModel::pinhole(100, 64, 64),
                         nullptr);
  }
  if (o.up && !(o.up->norm() > 0 && o.up->allFinite()))
    throw std::invalid_argument("--up: expected a non-zero direction");
  if (!o.input_colour_space.empty() && o.input_colour_space != working_space()) {
    try {
      colour_conversion_matrix(o.input_colour_space, working_space());  // errors before any work
    } catch (const std::runtime_error& e) {
      throw std::invalid_argument(std::string("--input-colorspace: ") + e.what());
    }
  }
  parse_brdf(o.render_brdf);
  chrome_fresnel_from_spec(o.chrome_fresnel, "--chrome-fresnel");  // errors before any work
  if (!o.glossy_brdf.empty()) {
    try {
      parse_brdf(o.glossy_brdf);
    } catch (const std::exception& e) {
      throw std::invalid_argument(std::string("--glossy-brdf: ") + e.what());
    }
  }
}

void check_process_inputs(const ProcessOptions& o, const PhotoSet& set, const fs::path& dir) {
  if (set.views.empty()) throw std::invalid_argument(o.photoset + ": views: none");
  parse_ball_overrides(o.ball_overrides, set);  // errors before any work
  if (o.input_colour_space.empty() && !set.camera_colour_space.empty() && set.camera_colour_space != working_space()) {
    try {
      colour_conversion_matrix(set.camera_colour_space, working_space());
    } catch (const std::runtime_error& e) {
      throw std::invalid_argument(o.photoset + ": camera.colour_space: " + e.what());
    }
  }
  if (fs::exists(dir) && !fs::is_directory(dir)) throw std::invalid_argument(o.out.string() + ": not a folder");
  if (!fs::is_directory(dir.parent_path()))
    throw std::invalid_argument(o.out.string() + ": its parent folder does not exist");
  // No output may land on an input (the photo folder itself must not be DIR).
  if (fs::exists(dir) && fs::equivalent(dir, set.folder))
    throw std::invalid_argument(o.out.string() + ": is the photo set's folder; choose another output folder");
}

}  // namespace rsibr
