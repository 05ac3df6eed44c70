// bake_map_set (bake/map_set_bake.h) over the ranks of a session: each rank integrates its rows
// (cluster/bake_partition.h), the root gathers them into whole maps and makes the set. The set is
// the one bake_map_set gives, texel for texel, whatever the number of ranks: a texel's value
// depends on neither the other texels computed nor the thread count (bake/integrator.h), and the
// headers and the albedo normalisation are made once, at the root, from the whole maps.
#pragma once

#include "bake/map_set_bake.h"
#include "cluster/bake_partition.h"
#include "cluster/session.h"

#include <functional>
#include <string>

namespace rsibr::cluster {

struct DistributedBakeTimes {
  double integrate = 0;  // this rank's integration, seconds
  double gather = 0;     // waiting for and receiving the other ranks' rows (root), sending (others)
  long rows = 0;         // rows this rank integrated
};

// Root: the whole set. Other ranks: an empty set. `progress` gets this rank's fraction done.
// A rank whose integration throws sends its error instead of its rows; the root then throws
// std::runtime_error("rank K: <what>") and the other ranks return an empty set, so the job ends
// without a rank left waiting. Collective: every rank of the session calls it with the same inputs.
MapSet bake_map_set_distributed(const Brdf& brdf, const Integrator& integrator, const ViewSet& views,
                                const MapSetBakeOptions& options, const Session& session,
                                const std::function<void(double)>& progress = {},
                                DistributedBakeTimes* times = nullptr);

// The rows of one rank's spans, integrated: the bytes that rank sends (float RGB, the spans' rows in
// order), and back into the maps at the root. Exposed for tests that play every rank in one process.
std::vector<std::uint8_t> integrate_spans(const Brdf& brdf, const Integrator& integrator, const ViewSet& views,
                                          const MapSetBakeOptions& options, const std::vector<RowSpan>& spans,
                                          const std::function<void(double)>& progress = {});
// Throws std::runtime_error when the bytes are not exactly the spans' rows.
void place_spans(const std::uint8_t* bytes, std::size_t n, const std::vector<RowSpan>& spans,
                 std::vector<cv::Mat>& maps);

}  // namespace rsibr::cluster
