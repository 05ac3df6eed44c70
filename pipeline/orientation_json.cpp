#include "pipeline/orientation_json.h"

namespace rsibr {

nlohmann::json pair_orientation_json(const std::vector<PairOrientation>& pairs) {
  nlohmann::json out = nlohmann::json::array();
  for (const PairOrientation& p : pairs) {
    nlohmann::json j = {{"views", {p.a, p.b}},
                        {"features", {p.features_a, p.features_b}},
                        {"matched", p.matched},
                        {"matched_under_search", p.gated},
                        {"shared_tracks", p.shared_tracks},
                        {"inliers", p.inliers},
                        {"inliers_by_chance", p.chance_inliers}};
    if (p.search_score > -1)
      j["search"] = {{"score", p.search_score},
                     {"runner_up", p.search_runner_up},
                     {"overlap", p.search_overlap},
                     {"angle_deg", p.search_angle_deg},
                     {"solved_minus_searched_deg", p.solved_vs_search_deg}};
    if (p.agreement.samples > 0)
      j["agreement"] = {{"overlap", p.agreement.overlap},
                        {"median_log2_ratio", p.agreement.median_log2_ratio},
                        {"mismatch_stops", p.agreement.mismatch_stops}};
    out.push_back(j);
  }
  return out;
}

}  // namespace rsibr
