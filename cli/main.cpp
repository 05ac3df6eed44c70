// rsibr: reflection-space image-based rendering from photographed spheres and computed maps.
#include "cli/verbs.h"
#include "core/output_plan.h"

#include <exception>
#include <iostream>
#include <map>
#include <regex>
#include <string>

namespace {

// CLI11's parse errors in the project's words: "<option>: <what is wrong>", one line.
std::string parse_error_text(const CLI::Error& e) {
  const std::string what = e.what();
  static const std::pair<std::regex, const char*> phrasings[] = {
      {std::regex("^(.*): At Most 1 required but received (\\d+)$"), "$1: given $2 times (at most once)"},
      {std::regex("^(.*): At Most (\\d+) required but received (\\d+)$"), "$1: at most $2 values, got $3"},
      {std::regex("^(.*): At least (\\d+) required but received (\\d+)$"), "$1: expected $2 values, got $3"},
      {std::regex("^(.*): (\\d+) required .* missing$"), "$1: expected $2 values"},
      {std::regex("^(\\S+) is required$"), "$1: missing (it is required)"},
      {std::regex("^The following argument was not expected: (.*)$"), "$1: not an option or argument of this verb"},
      {std::regex("^The following arguments were not expected: (.*)$"), "$1: not options or arguments of this verb"},
      {std::regex("^(.*): Value (.*) not in range (.*) to (.*)$"), "$1: expected a value from $3 to $4, got '$2'"},
  };
  for (const auto& [pattern, replacement] : phrasings)
    if (std::regex_match(what, pattern)) return std::regex_replace(what, pattern, replacement);
  return what;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"rsibr: radiance environment maps from photographed spheres and computed lighting\n"
               "integrals, warped and blended in reflection space. 'rsibr <verb> --help' for each verb."};
  app.set_version_flag("--version", std::string("rsibr ") + RSIBR_VERSION);
  app.require_subcommand(1);
  // Parse errors are one line naming the verb, like every other error.
  app.failure_message([](const CLI::App* a, const CLI::Error& e) {
    std::string verb;
    for (const CLI::App* sub : a->get_subcommands()) verb += " " + sub->get_name();
    return "rsibr" + verb + ": error: " + parse_error_text(e) + " (see --help)\n";
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
  // A first word that is neither an option nor a verb: say so (CLI11 would ask for "a subcommand").
  if (argc > 1 && argv[1][0] != '-' && !runners.count(argv[1])) {
    std::string verbs;
    for (const auto& [name, run] : runners) verbs += (verbs.empty() ? "" : ", ") + name;
    std::cerr << "rsibr: error: '" << argv[1] << "' is not a verb (verbs: " << verbs << "; see --help)\n";
    return 2;
  }
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
      std::cerr << "rsibr " << name << ": error: " << rsibr::OutputPlan::naming_targets(e.what()) << "\n";
      return 1;
    }
  }
  return 2;
}
