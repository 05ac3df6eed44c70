#include "hdr/bracket_set.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <cmath>
#include <numeric>
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
    case 3: if (bgr) cv::cvtColor(in, rgb, cv::COLOR_BGR2RGB); else rgb = in; break;
    case 4: cv::cvtColor(in, rgb, bgr ? cv::COLOR_BGRA2RGB : cv::COLOR_RGBA2RGB); break;
    default: throw std::runtime_error(name + ": unsupported channel count " + std::to_string(in.channels()));
  }
  rgb.convertTo(out, CV_16UC3);
  return in.depth() == CV_8U ? 255 : 65535;
}

BracketSet assemble(std::vector<cv::Mat> codes, std::vector<int> ranges, std::vector<double> exposures,
                    std::vector<ResolvedExposure> metadata, std::vector<std::string> names) {
  const std::size_t n = codes.size();
  if (n == 0) throw std::runtime_error("no brackets");
  for (std::size_t j = 0; j < n; ++j) {
    if (!(std::isfinite(exposures[j]) && exposures[j] > 0))
      throw std::runtime_error(names[j] + ": exposure must be positive and finite");
    if (codes[j].size() != codes[0].size())
      throw std::runtime_error(names[j] + ": size " + std::to_string(codes[j].cols) + "x" + std::to_string(codes[j].rows) +
                               " differs from " + names[0] + " (" + std::to_string(codes[0].cols) + "x" +
                               std::to_string(codes[0].rows) + ")");
    if (ranges[j] != ranges[0]) throw std::runtime_error(names[j] + ": bit depth differs from " + names[0]);
  }
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return exposures[a] < exposures[b]; });
  BracketSet s;
  s.max_code = ranges[0];
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t j = order[k];
    if (k > 0 && exposures[j] == s.exposures.back())
      throw std::runtime_error(names[j] + ": same exposure as " + s.files.back() + " (brackets need distinct exposures)");
    s.codes.push_back(std::move(codes[j]));
    s.exposures.push_back(exposures[j]);
    s.metadata.push_back(metadata[j]);
    s.files.push_back(names[j]);
  }
  return s;
}

}  // namespace

BracketSet load_brackets(const PhotoView& view) {
  std::vector<cv::Mat> codes;
  std::vector<int> ranges;
  std::vector<double> exposures;
  std::vector<ResolvedExposure> metadata;
  std::vector<std::string> names;
  for (const BracketPhoto& b : view.brackets) {
    const std::string name = b.file.string();
    metadata.push_back(resolve_exposure(b));
    exposures.push_back(metadata.back().relative);
    cv::Mat c;
    ranges.push_back(to_codes(cv::imread(name, cv::IMREAD_UNCHANGED | cv::IMREAD_ANYDEPTH), c, name, true));
    codes.push_back(std::move(c));
    names.push_back(name);
  }
  if (codes.empty()) throw std::runtime_error("view " + view.name + ": no brackets");
  BracketSet s = assemble(std::move(codes), std::move(ranges), std::move(exposures), std::move(metadata), std::move(names));
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
  BracketSet s = assemble(std::move(codes), std::move(ranges), std::move(exposures), std::move(metadata), std::move(names));
  s.lossy = lossy;
  return s;
}

}  // namespace rsibr
