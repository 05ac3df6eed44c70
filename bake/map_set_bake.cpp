#include "bake/map_set_bake.h"

#include "bake/albedo_table.h"
#include "core/albedo_normalisation.h"

#include <atomic>
#include <stdexcept>

namespace rsibr {

std::vector<BakeFrame> frames_of(const ViewSet& views) {
  std::vector<BakeFrame> frames;
  for (const Vec3& v : views.views()) frames.push_back({v, world_from_view_for(v)});
  return frames;
}

MapSet bake_map_set(const Brdf& brdf, const Integrator& integrator, const ViewSet& views,
                    const MapSetBakeOptions& options, const std::function<void(double)>& progress) {
  return bake_map_set(brdf, integrator, frames_of(views), options, progress);
}

MapSet bake_map_set(const Brdf& brdf, const Integrator& integrator, const std::vector<BakeFrame>& frames,
                    const MapSetBakeOptions& options, const std::function<void(double)>& progress) {
  if (frames.empty()) throw std::invalid_argument("bake: no view to bake");
  if (options.res < 1)
    throw std::invalid_argument("bake: the map size must be at least 1, not " + std::to_string(options.res));
  const double total_rows = double(frames.size()) * options.res;
  std::atomic<long> rows_before{0};
  std::vector<cv::Mat> radiance;
  for (const BakeFrame& f : frames) {
    const long before = rows_before.load();
    std::function<void(int)> rows;
    if (progress) rows = [&](int done) { progress((before + done) / total_rows); };
    radiance.push_back(integrator.radiance_map(brdf, f.view, f.world_from_view, options.res, options.integrator, rows));
    rows_before += options.res;
  }
  return computed_map_set(brdf, integrator, frames, options, std::move(radiance));
}

MapSet computed_map_set(const Brdf& brdf, const Integrator& integrator, const ViewSet& views,
                        const MapSetBakeOptions& options, std::vector<cv::Mat> radiance) {
  return computed_map_set(brdf, integrator, frames_of(views), options, std::move(radiance));
}

MapSet computed_map_set(const Brdf& brdf, const Integrator& integrator, const std::vector<BakeFrame>& frames,
                        const MapSetBakeOptions& options, std::vector<cv::Mat> radiance) {
  if (radiance.size() != frames.size())
    throw std::invalid_argument("bake: " + std::to_string(radiance.size()) + " maps for " +
                                std::to_string(frames.size()) + " views");
  const std::string method = integrator.name();
  const std::vector<float> albedo = options.normalise_albedo ? albedo_table(brdf) : std::vector<float>{};
  const bool stochastic = method == "mis" || method == "fis";
  const IntegratorOptions& io = options.integrator;
  MapSet set;
  for (std::size_t i = 0; i < radiance.size(); ++i) {
    if (radiance[i].type() != CV_32FC3 || radiance[i].rows != options.res || radiance[i].cols != options.res)
      throw std::invalid_argument("bake: map " + std::to_string(i) + " is not CV_32FC3 of the map size");
    MapView mv;
    mv.view = frames[i].view;
    mv.world_from_view = frames[i].world_from_view;
    mv.warp = brdf.central_direction();
    mv.source = MapSource::Computed;
    mv.material = brdf.spec();
    mv.attributes["version"] = RSIBR_VERSION;
    if (!options.environment_name.empty()) mv.attributes["environment"] = options.environment_name;
    mv.attributes["method"] = method;
    mv.attributes["samples"] = stochastic ? std::to_string(io.samples) : "n/a";
    mv.attributes["seed"] = stochastic ? std::to_string(io.seed) : "n/a";
    if (method == "reference")
      mv.attributes["referenceWidth"] = io.reference_width > 0 ? std::to_string(io.reference_width) : "full";
    mv.rgb = std::move(radiance[i]);
    if (!albedo.empty()) {
      normalise_by_albedo(mv.rgb, albedo);
      mv.albedo = albedo;
    }
    set.views.push_back(std::move(mv));
  }
  return set;
}

}  // namespace rsibr
