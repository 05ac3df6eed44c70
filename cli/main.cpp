// rsibr: reflection-space image-based rendering from photographed spheres and computed maps.
#include "cli/verbs.h"

#include <exception>
#include <iostream>
#include <map>

int main(int argc, char** argv) {
  CLI::App app{"rsibr: radiance environment maps from photographed spheres and computed lighting\n"
               "integrals, warped and blended in reflection space. 'rsibr <verb> --help' for each verb."};
  app.set_version_flag("--version", std::string("rsibr ") + RSIBR_VERSION);
  app.require_subcommand(1);
  // Parse errors are one line naming the verb, like every other error.
  app.failure_message([](const CLI::App* a, const CLI::Error& e) {
    std::string verb;
    for (const CLI::App* sub : a->get_subcommands()) verb += " " + sub->get_name();
    return "rsibr" + verb + ": error: " + e.what() + " (see --help)\n";
  });
  std::map<std::string, rsibr::cli::Runner> runners;
  runners["convert"] = rsibr::cli::add_convert(app);
  runners["info"] = rsibr::cli::add_info(app);
  runners["pattern"] = rsibr::cli::add_pattern(app);
  runners["blend"] = rsibr::cli::add_blend(app);
  runners["bake"] = rsibr::cli::add_bake(app);
  runners["reference"] = rsibr::cli::add_reference(app);
  runners["render"] = rsibr::cli::add_render(app);
  runners["view"] = rsibr::cli::add_view(app);
  runners["hdr"] = rsibr::cli::add_hdr(app);
  runners["compare"] = rsibr::cli::add_compare(app);
  runners["synth"] = rsibr::cli::add_synth(app);
  runners["extract"] = rsibr::cli::add_extract(app);
  runners["calibrate"] = rsibr::cli::add_calibrate(app);
  runners["probe"] = rsibr::cli::add_probe(app);
  runners["orient"] = rsibr::cli::add_orient(app);
  runners["process"] = rsibr::cli::add_process(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  for (auto& [name, run] : runners) {
    if (!app.got_subcommand(name)) continue;
    try {
      return run();
    } catch (const std::exception& e) {
      std::cerr << "rsibr " << name << ": error: " << e.what() << "\n";
      return 1;
    }
  }
  return 2;
}
