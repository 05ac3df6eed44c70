// A batch: many rsibr command lines (bakes, process runs, ...) in one YAML file, run by `rsibr
// batch`, spread over MPI ranks (each job on one rank) or one after another on one process.
//
//   jobs:
//     - name: grey-esplanade          # optional; default "job N" (N from 1)
//       args: [bake, grey.exr, --env, esplanade.exr, --brdf, grey.yaml]
//     - [process, shoot-a, --out, run-a]   # a job may be its words alone
//
// args are the words after "rsibr"; paths in them are relative to the spec's folder. The first
// word is a verb other than batch and view.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace rsibr::cluster {

struct BatchJob {
  std::string name;
  std::vector<std::string> args;
};

// Throws std::invalid_argument("<file>: <key path>: <problem>") for a spec that does not read: not
// YAML, no jobs, a job without args, a word that is not a string, a first word that is not one of
// `verbs` (or is batch or view), two jobs of one name.
std::vector<BatchJob> read_batch_spec(const std::filesystem::path& file, const std::vector<std::string>& verbs);

// The jobs of `rank`: job i runs on rank i mod ranks (in the spec's order).
std::vector<int> jobs_of_rank(int jobs, int rank, int ranks);

}  // namespace rsibr::cluster
