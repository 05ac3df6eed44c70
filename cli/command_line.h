// One rsibr command line, parsed and run: what main() does, and what `rsibr batch` does per job.
#pragma once

#include <string>
#include <vector>

namespace rsibr::cli {

struct CommandResult {
  int exit_code = 0;
  std::string error;  // the one line printed on standard error when the command failed ("" when it did not)
};

// args: the words after "rsibr" (a verb and its options, or a global option such as --help).
// Prints what the verb prints; an error is one line on standard error. Exit status 2: the command
// is refused (a command line that does not parse, an option value or an input file that is
// missing, unreadable or inconsistent); 1: the work failed (an output, a solve, anything else). Under more than one MPI rank only `bake` and `batch` run
// (cluster/session.h), and only the root prints errors.
CommandResult run_command_line(const std::vector<std::string>& args);

// The verbs, in alphabetical order.
std::vector<std::string> verb_names();

}  // namespace rsibr::cli
