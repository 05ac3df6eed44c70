// Each verb registers its subcommand on the app; the callback runs it and returns the exit code.
#pragma once

#include <CLI/CLI.hpp>

#include <functional>

namespace rsibr::cli {

using Runner = std::function<int()>;

Runner add_convert(CLI::App& app);
Runner add_info(CLI::App& app);
Runner add_pattern(CLI::App& app);
Runner add_blend(CLI::App& app);
Runner add_bake(CLI::App& app);
Runner add_batch(CLI::App& app);
Runner add_reference(CLI::App& app);
Runner add_render(CLI::App& app);
Runner add_view(CLI::App& app);
Runner add_hdr(CLI::App& app);
Runner add_compare(CLI::App& app);
Runner add_synth(CLI::App& app);
Runner add_extract(CLI::App& app);
Runner add_calibrate(CLI::App& app);
Runner add_probe(CLI::App& app);
Runner add_orient(CLI::App& app);
Runner add_balls(CLI::App& app);
Runner add_process(CLI::App& app);
Runner add_plan(CLI::App& app);
Runner add_export(CLI::App& app);

}  // namespace rsibr::cli
