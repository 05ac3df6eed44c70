// The report of a rsibr process run: one self-contained HTML file (no network: pictures are PNG
// data URIs, plots inline SVG, styles inline) built from DIR's step records (pipeline/step_record.h)
// and outputs: timings per step, the lens model and its scores, the response curve (SVG), the
// orientations and their uncertainties, the balls found, the probe (tone-mapped), each grey ball's
// captured and computed maps side by side with heat maps, the comparison's metrics and fitted
// gains, and the turntable frames.
#pragma once

#include "core/base64.h"

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

namespace rsibr {

// Minimal HTML escaping of text (&, <, >, ").
std::string html_escape(const std::string& text);

// An SVG line plot: one polyline per series over shared axes (x, y ranges from the data), with
// axis labels and min/max ticks. Series y values that are not finite are skipped.
struct PlotSeries {
  std::string name, colour;  // colour: CSS
  std::vector<double> x, y;
};
std::string svg_line_plot(const std::vector<PlotSeries>& series, const std::string& x_label, const std::string& y_label,
                          int width = 480, int height = 300);

// Writes `out` atomically from DIR's records (a step without a record gets "not run"; one that
// stopped, DIR/steps/STEP.failed.json, gets its error and what it had found: the pairs of views
// and their pictures, the ball candidates).
// Throws std::runtime_error("<file>: <problem>") when an output a record lists cannot be read.
void write_process_report(const std::filesystem::path& dir, const std::filesystem::path& out,
                          const std::string& photoset);

}  // namespace rsibr
