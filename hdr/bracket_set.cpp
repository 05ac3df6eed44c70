#include "hdr/bracket_set.h"

#include "core/parallel.h"
#include "formats/image_codecs.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <exception>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <cmath>
#include <numeric>
#include <optional>
#include <utility>
#include <stdexcept>

namespace rsibr {
namespace {

// Any accepted image -> CV_16UC3 RGB codes; returns the code range of the input depth.
int to_codes(const cv::Mat& in, cv::Mat& out, const std::string& name, bool bgr) {
  if (in.empty()) throw std::runtime_error(name + ": cannot read the image");
  if (in.depth() != CV_8U && in.depth() != CV_16U)
    throw std::runtime_error(name + ": unsupported pixel depth (8-bit or 16-bit integer images only)");
  cv::Mat rgb;
  switch (in.channels()) {
    case 1: cv::cvtColor(in, rgb, cv::COLOR_GRAY2RGB); break;
    case 3:
      if (bgr)
        cv::cvtColor(in, rgb, cv::COLOR_BGR2RGB);
      else
        rgb = in;
      break;
    case 4: cv::cvtColor(in, rgb, bgr ? cv::COLOR_BGRA2RGB : cv::COLOR_RGBA2RGB); break;
    default: throw std::runtime_error(name + ": unsupported channel count " + std::to_string(in.channels()));
  }
  rgb.convertTo(out, CV_16UC3);
  return in.depth() == CV_8U ? 255 : 65535;
}

// By content, not by name: a JPEG starts with its start-of-image marker.
bool is_jpeg_file(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  unsigned char head[2] = {0, 0};
  in.read(reinterpret_cast<char*>(head), 2);
  return in && head[0] == 0xFF && head[1] == 0xD8;
}

std::string size_text(const cv::Mat& m) { return std::to_string(m.cols) + "x" + std::to_string(m.rows); }

// `in` centred on a canvas of `size`: cropped where it is larger, padded with its per-channel
// median code where it is smaller; `covered` is 255 where the canvas holds the file's pixels.
cv::Mat centred(const cv::Mat& in, cv::Size size, cv::Mat& covered) {
  cv::Scalar fill;
  for (int c = 0; c < 3; ++c) {
    cv::Mat ch;
    cv::extractChannel(in, ch, c);
    std::vector<std::uint16_t> v(ch.begin<std::uint16_t>(), ch.end<std::uint16_t>());
    std::nth_element(v.begin(), v.begin() + long(v.size() / 2), v.end());
    fill[c] = v[v.size() / 2];
  }
  cv::Mat out(size, in.type(), fill);
  covered = cv::Mat(size, CV_8UC1, cv::Scalar(0));
  const int ox = (size.width - in.cols) / 2, oy = (size.height - in.rows) / 2;  // where in's (0,0) lands
  const cv::Rect dst = cv::Rect(ox, oy, in.cols, in.rows) & cv::Rect(0, 0, size.width, size.height);
  in(cv::Rect(dst.x - ox, dst.y - oy, dst.width, dst.height)).copyTo(out(dst));
  covered(dst).setTo(255);
  return out;
}

BracketSet assemble(std::vector<cv::Mat> codes, std::vector<int> ranges, std::vector<double> exposures,
                    std::vector<ResolvedExposure> metadata, std::vector<std::string> names, bool fit_sizes = false) {
  const std::size_t n = codes.size();
  if (n == 0) throw std::runtime_error("no brackets");
  bool sizes_differ = false;
  for (std::size_t j = 0; j < n; ++j) {
    if (!(std::isfinite(exposures[j]) && exposures[j] > 0))
      throw std::runtime_error(names[j] + ": exposure must be positive and finite");
    if (codes[j].size() != codes[0].size()) {
      const double dx = std::abs(codes[j].cols - codes[0].cols) / double(std::max(codes[j].cols, codes[0].cols));
      const double dy = std::abs(codes[j].rows - codes[0].rows) / double(std::max(codes[j].rows, codes[0].rows));
      if (!fit_sizes || dx > 0.1 || dy > 0.1)
        throw std::runtime_error(names[j] + ": size " + size_text(codes[j]) + " differs from " + names[0] + " (" +
                                 size_text(codes[0]) + ")" +
                                 (fit_sizes ? ": more than 10% a side, not the same framing"
                                            : "; brackets of different sizes need alignment (rsibr hdr --align auto)"));
      sizes_differ = true;
    }
    if (ranges[j] != ranges[0]) throw std::runtime_error(names[j] + ": bit depth differs from " + names[0]);
  }
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return exposures[a] < exposures[b]; });
  BracketSet s;
  s.max_code = ranges[0];
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t j = order[k];
    if (k > 0 && exposures[j] == s.exposures.back())
      throw std::runtime_error(names[j] + ": same exposure as " + s.files.back() +
                               " (brackets need distinct exposures)");
    s.codes.push_back(std::move(codes[j]));
    s.exposures.push_back(exposures[j]);
    s.metadata.push_back(metadata[j]);
    s.files.push_back(names[j]);
  }
  for (const cv::Mat& c : s.codes) s.file_sizes.push_back(c.size());
  if (sizes_differ) {
    // The middle bracket's frame (the one alignment registers the others to).
    const cv::Size frame = s.codes[n / 2].size();
    s.fitted_sizes = true;
    s.covered.resize(n);
    for (std::size_t k = 0; k < n; ++k) s.codes[k] = centred(s.codes[k], frame, s.covered[k]);
  }
  return s;
}

}  // namespace

BracketSet load_brackets(const PhotoView& view, bool fit_sizes) {
  std::vector<cv::Mat> codes;
  std::vector<int> ranges;
  std::vector<double> exposures;
  std::vector<ResolvedExposure> metadata;
  std::vector<std::string> names;
  std::vector<RawInfo> raw_info;
  std::vector<cv::Mat> raw_saturated;
  std::optional<Vec3> raw_balance;  // the first RAW bracket's, for every other one
  int raw_count = 0;
  for (const BracketPhoto& b : view.brackets) {
    const std::string name = b.file.string();
    cv::Mat c;
    if (is_raw_file(b.file)) {
      RawImage r = read_raw_image(b.file, RawOptions{raw_balance});
      if (!raw_balance) raw_balance = r.info.white_balance;
      // What photoset.yaml leaves out, from the file; the rest (if any) from EXIF.
      BracketPhoto filled = b;
      const bool from_raw = (!b.exposure_s && r.info.exposure_s > 0) || (!b.iso && r.info.iso > 0) ||
                            (!b.aperture && r.info.aperture > 0);
      if (!filled.exposure_s && r.info.exposure_s > 0) filled.exposure_s = r.info.exposure_s;
      if (!filled.iso && r.info.iso > 0) filled.iso = r.info.iso;
      if (!filled.aperture && r.info.aperture > 0) filled.aperture = r.info.aperture;
      metadata.push_back(resolve_exposure(filled));
      if (from_raw) {
        // Where the values came from: photoset.yaml, the RAW file, its EXIF (what LibRaw missed).
        std::string source = (b.exposure_s || b.iso || b.aperture) ? "yaml+raw" : "raw";
        if (metadata.back().source.find("exif") != std::string::npos) source += "+exif";
        metadata.back().source = source;
      }
      c = std::move(r.codes);
      ranges.push_back(65535);
      raw_info.push_back(r.info);
      raw_saturated.push_back(r.saturated);
      ++raw_count;
    } else {
      metadata.push_back(resolve_exposure(b));
      if (is_jpeg_file(b.file) && !jpeg_is_complete(name))
        throw std::invalid_argument(name + ": a truncated JPEG (its image data stops before the end-of-image marker)");
      ranges.push_back(0);  // decoded below, with the view's other images
      raw_info.emplace_back();
      raw_saturated.emplace_back();
    }
    exposures.push_back(metadata.back().relative);
    codes.push_back(std::move(c));
    names.push_back(name);
  }
  // The images (not RAW: LibRaw's files take the first one's white balance, in order) decoded in
  // parallel, each on its own: decoding is most of a view's load. The first error in bracket
  // order is the one reported.
  if (raw_count == 0) {
    std::vector<std::exception_ptr> errors(codes.size());
    parallel_for_rows(int(codes.size()), [&](int j) {
      const std::size_t k = std::size_t(j);
      try {
        ranges[k] =
            to_codes(read_image(names[k], cv::IMREAD_UNCHANGED | cv::IMREAD_ANYDEPTH), codes[k], names[k], true);
      } catch (...) {
        errors[k] = std::current_exception();
      }
    });
    for (const std::exception_ptr& e : errors)
      if (e) std::rethrow_exception(e);
  }
  if (codes.empty()) throw std::runtime_error("view " + view.name + ": no brackets");
  if (raw_count > 0 && raw_count < int(codes.size()))
    throw std::runtime_error("view " + view.name + ": mixes camera RAW files with other images (" +
                             std::to_string(raw_count) + " of " + std::to_string(codes.size()) +
                             " brackets are RAW); give one kind per view");
  // assemble sorts by exposure; keep the RAW records in the same order.
  struct Keyed {
    double exposure;
    RawInfo info;
    cv::Mat saturated;
  };
  std::vector<Keyed> keyed;
  for (std::size_t j = 0; j < raw_info.size(); ++j) keyed.push_back({exposures[j], raw_info[j], raw_saturated[j]});
  BracketSet s = assemble(std::move(codes), std::move(ranges), std::move(exposures), std::move(metadata),
                          std::move(names), fit_sizes);
  if (raw_count > 0) {
    if (s.fitted_sizes)
      throw std::runtime_error("view " + view.name + ": RAW brackets of different sizes (one sensor makes one size)");
    s.raw = true;
    std::stable_sort(keyed.begin(), keyed.end(),
                     [](const Keyed& a, const Keyed& b) { return a.exposure < b.exposure; });
    for (Keyed& k : keyed) s.raw_info.push_back(std::move(k.info)), s.saturated.push_back(std::move(k.saturated));
  }
  for (const std::string& f : s.files) {
    std::string ext = std::filesystem::path(f).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char ch) { return char(std::tolower(ch)); });
    if (ext == ".jpg" || ext == ".jpeg") s.lossy = true;
  }
  return s;
}

BracketSet make_brackets(std::vector<cv::Mat> images, std::vector<double> exposures, std::vector<std::string> names,
                         bool lossy) {
  if (images.size() != exposures.size()) throw std::invalid_argument("make_brackets: one exposure per image");
  for (std::size_t j = names.size(); j < images.size(); ++j) names.push_back("bracket " + std::to_string(j));
  std::vector<cv::Mat> codes(images.size());
  std::vector<int> ranges;
  std::vector<ResolvedExposure> metadata;
  for (std::size_t j = 0; j < images.size(); ++j) {
    ranges.push_back(to_codes(images[j], codes[j], names[j], false));
    ResolvedExposure m;
    m.exposure_s = exposures[j];
    m.relative = exposures[j];
    m.source = "memory";
    metadata.push_back(m);
  }
  BracketSet s =
      assemble(std::move(codes), std::move(ranges), std::move(exposures), std::move(metadata), std::move(names));
  s.lossy = lossy;
  return s;
}

}  // namespace rsibr
