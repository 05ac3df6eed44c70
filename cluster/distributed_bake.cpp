#include "cluster/distributed_bake.h"

#include "cluster/bake_partition.h"
#include "core/stopwatch.h"

#include <chrono>
#include <cstring>
#include <stdexcept>

namespace rsibr::cluster {
namespace {

// A rank's message: one status byte (1 = rows follow, 0 = an error text follows), then the payload.
std::vector<std::uint8_t> message(bool ok, const std::vector<std::uint8_t>& payload) {
  std::vector<std::uint8_t> m;
  m.reserve(payload.size() + 1);
  m.push_back(ok ? 1 : 0);
  m.insert(m.end(), payload.begin(), payload.end());
  return m;
}

}  // namespace

std::vector<std::uint8_t> integrate_spans(const Brdf& brdf, const Integrator& integrator, const ViewSet& views,
                                          const MapSetBakeOptions& options, const std::vector<RowSpan>& spans,
                                          const std::function<void(double)>& progress) {
  const int res = options.res;
  const std::size_t row_bytes = std::size_t(res) * 3 * sizeof(float);
  long total_rows = 0;
  for (const RowSpan& s : spans) total_rows += s.row_end - s.row_begin;
  std::vector<std::uint8_t> bytes(std::size_t(total_rows) * row_bytes);
  std::size_t at = 0;
  long rows_before = 0;
  for (const RowSpan& s : spans) {
    const Vec3& v = views.views().at(std::size_t(s.view));
    IntegratorOptions io = options.integrator;
    io.texel_mask = cv::Mat(res, res, CV_8UC1, cv::Scalar(0));
    io.texel_mask.rowRange(s.row_begin, s.row_end).setTo(255);
    std::function<void(int)> rows;
    // The masked-out rows are visited too (and cost nothing): count only this span's.
    const long before = rows_before;
    if (progress && total_rows > 0)
      rows = [&, before](int done) {
        progress(std::min(1.0, double(before + done * (s.row_end - s.row_begin) / res) / total_rows));
      };
    const cv::Mat map = integrator.radiance_map(brdf, v, world_from_view_for(v), res, io, rows);
    for (int r = s.row_begin; r < s.row_end; ++r, at += row_bytes)
      std::memcpy(bytes.data() + at, map.ptr(r), row_bytes);
    rows_before += s.row_end - s.row_begin;
  }
  return bytes;
}

void place_spans(const std::uint8_t* bytes, std::size_t n, const std::vector<RowSpan>& spans,
                 std::vector<cv::Mat>& maps) {
  std::size_t at = 0;
  for (const RowSpan& s : spans) {
    cv::Mat& map = maps.at(std::size_t(s.view));
    const std::size_t row_bytes = std::size_t(map.cols) * map.elemSize();
    for (int r = s.row_begin; r < s.row_end; ++r, at += row_bytes) {
      if (at + row_bytes > n) throw std::runtime_error("bake: a rank sent fewer rows than it was given");
      std::memcpy(map.ptr(r), bytes + at, row_bytes);
    }
  }
  if (at != n) throw std::runtime_error("bake: a rank sent more rows than it was given");
}

MapSet bake_map_set_distributed(const Brdf& brdf, const Integrator& integrator, const ViewSet& views,
                                const MapSetBakeOptions& options, const Session& session,
                                const std::function<void(double)>& progress, DistributedBakeTimes* times) {
  if (session.size() == 1) {
    const auto t0 = std::chrono::steady_clock::now();
    MapSet set = bake_map_set(brdf, integrator, views, options, progress);
    if (times) *times = {seconds_since(t0), 0.0, long(views.views().size()) * options.res};
    return set;
  }
  if (options.res < 1)
    throw std::invalid_argument("bake: the map size must be at least 1, not " + std::to_string(options.res));
  const int n_views = int(views.views().size());
  const auto mine = rows_of_rank(n_views, options.res, session.rank(), session.size());
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<std::uint8_t> sent;
  try {
    sent = message(true, integrate_spans(brdf, integrator, views, options, mine, progress));
  } catch (const std::exception& e) {
    sent = message(false, bytes_of(e.what()));
  }
  const auto t1 = std::chrono::steady_clock::now();
  const auto received = session.gather(sent);
  if (times) {
    times->integrate = std::chrono::duration<double>(t1 - t0).count();
    times->gather = seconds_since(t1);
    times->rows = 0;
    for (const RowSpan& s : mine) times->rows += s.row_end - s.row_begin;
  }
  if (!session.is_root()) return {};
  std::vector<cv::Mat> maps(static_cast<std::size_t>(n_views));
  for (cv::Mat& m : maps) m = cv::Mat(options.res, options.res, CV_32FC3, cv::Scalar::all(0));
  for (int r = 0; r < session.size(); ++r) {
    const auto& m = received[std::size_t(r)];
    if (m.empty()) throw std::runtime_error("rank " + std::to_string(r) + ": sent nothing");
    if (m[0] != 1) throw std::runtime_error("rank " + std::to_string(r) + ": " + std::string(m.begin() + 1, m.end()));
    place_spans(m.data() + 1, m.size() - 1, rows_of_rank(n_views, options.res, r, session.size()), maps);
  }
  return computed_map_set(brdf, integrator, views, options, std::move(maps));
}

}  // namespace rsibr::cluster
