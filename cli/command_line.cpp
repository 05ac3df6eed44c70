#include "cli/command_line.h"

#include "cli/option_checks.h"
#include "cli/verbs.h"
#include "cluster/session.h"
#include "formats/file_error.h"
#include "formats/output_plan.h"

#include <opencv2/core.hpp>
#include <tbb/global_control.h>

#include <exception>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <regex>

namespace rsibr::cli {
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

std::map<std::string, Runner> add_verbs(CLI::App& app) {
  std::map<std::string, Runner> runners;
  runners["convert"] = add_convert(app);
  runners["info"] = add_info(app);
  runners["pattern"] = add_pattern(app);
  runners["blend"] = add_blend(app);
  runners["bake"] = add_bake(app);
  runners["batch"] = add_batch(app);
  runners["reference"] = add_reference(app);
  runners["render"] = add_render(app);
  runners["view"] = add_view(app);
  runners["hdr"] = add_hdr(app);
  runners["compare"] = add_compare(app);
  runners["synth"] = add_synth(app);
  runners["extract"] = add_extract(app);
  runners["calibrate"] = add_calibrate(app);
  runners["probe"] = add_probe(app);
  runners["orient"] = add_orient(app);
  runners["balls"] = add_balls(app);
  runners["process"] = add_process(app);
  runners["plan"] = add_plan(app);
  runners["export"] = add_export(app);
  return runners;
}

}  // namespace

std::vector<std::string> verb_names() {
  CLI::App app;
  std::vector<std::string> names;
  for (const auto& [name, run] : add_verbs(app)) names.push_back(name);
  return names;
}

CommandResult run_command_line(const std::vector<std::string>& args) {
  const cluster::Session& session = cluster::Session::current();
  const bool speaks = session.is_root();  // under mpirun only the root prints errors
  auto fail = [&](int code, const std::string& line) {
    if (speaks) std::cerr << line << "\n";
    return CommandResult{code, line};
  };
  CLI::App app{
      "rsibr: radiance environment maps from photographed spheres and computed lighting\n"
      "integrals, warped and blended in reflection space. 'rsibr <verb> --help' for each verb."};
  app.set_version_flag("--version", std::string("rsibr ") + RSIBR_VERSION);
  app.require_subcommand(1);
  int threads = 0;
  app.add_option("--threads", threads,
                 "Worker threads (default: this machine's cores, shared among the MPI ranks on it)")
      ->check(CLI::Range(1, 4096));
  std::string parse_failure;
  // Parse errors are one line naming the verb, like every other error.
  app.failure_message([&parse_failure](const CLI::App* a, const CLI::Error& e) {
    std::string verb;
    for (const CLI::App* sub : a->get_subcommands()) verb += " " + sub->get_name();
    parse_failure = "rsibr" + verb + ": error: " + parse_error_text(e) + " (see --help)";
    return parse_failure + "\n";
  });
  std::map<std::string, Runner> runners = add_verbs(app);
  require_finite_numbers(app);
  // A first word that is neither an option nor a verb: say so (CLI11 would ask for "a subcommand").
  if (!args.empty() && !args[0].empty() && args[0][0] != '-' && !runners.count(args[0])) {
    std::string verbs;
    for (const auto& [name, run] : runners) verbs += (verbs.empty() ? "" : ", ") + name;
    return fail(2, "rsibr: error: '" + args[0] + "' is not a verb (verbs: " + verbs + "; see --help)");
  }
  std::vector<std::string> words{"rsibr"};
  words.insert(words.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& w : words) argv.push_back(w.data());
  try {
    app.parse(int(argv.size()), argv.data());
  } catch (const CLI::ParseError& e) {
    // CLI11's own exit codes (100 and up, one per kind of parse error) become 2: the command is refused.
    if (!speaks) return {e.get_exit_code() == 0 ? 0 : 2, ""};
    const int code = app.exit(e) == 0 ? 0 : 2;
    return {code, code == 0 ? std::string() : parse_failure};
  }
  std::optional<tbb::global_control> thread_limit;
  if (threads > 0 || session.size() > 1)
    thread_limit.emplace(tbb::global_control::max_allowed_parallelism,
                         std::size_t(threads > 0 ? threads : session.default_threads()));
  for (auto& [name, run] : runners) {
    if (!app.got_subcommand(name)) continue;
    if (session.size() > 1 && name != "bake" && name != "batch")
      return fail(2, "rsibr " + name + ": error: runs as one process, not over " + std::to_string(session.size()) +
                         " MPI ranks (only bake and batch are split over ranks; run it without mpirun)");
    // Exit status (docs/user-guide.md, Common behaviour): 2 the command is refused (the command
    // line, or an input that is missing, unreadable or inconsistent: the caller's to fix); 1 the
    // work failed (a solve that does not converge, a ball not found, anything else); 4 an output
    // could not be written (a full disk, a folder gone); 70 an internal error (a broken invariant
    // or a library's own assertion: a bug to report, never the input's fault).
    const std::string who = "rsibr " + name + ": error: ";
    try {
      return {run(), ""};
    } catch (const FileError& e) {
      return fail(e.role() == FileRole::Input ? 2 : 4, who + OutputPlan::naming_targets(e.what()));
    } catch (const std::invalid_argument& e) {
      return fail(2, who + OutputPlan::naming_targets(e.what()));
    } catch (const std::out_of_range& e) {  // std::stod on a user's 1e999 as well as a bad .at()
      return fail(1, who + OutputPlan::naming_targets(e.what()));
    } catch (const std::length_error& e) {
      return fail(1, who + OutputPlan::naming_targets(e.what()));
    } catch (const std::logic_error& e) {
      return fail(70, who + "internal error (please report it): " + OutputPlan::naming_targets(e.what()));
    } catch (const cv::Exception& e) {
      return fail(70, who + "internal error (please report it): OpenCV's " + e.func + " refused its input: " + e.err);
    } catch (const std::exception& e) {
      return fail(1, who + OutputPlan::naming_targets(e.what()));
    }
  }
  return {2, ""};
}

}  // namespace rsibr::cli
