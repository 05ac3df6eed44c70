// rsibr batch: many rsibr command lines from one YAML file (cluster/batch_spec.h), each job on one
// MPI rank under mpirun (job i on rank i mod N), one after another without it. A failed job is
// reported and the others run on; the summary lists every job.
#include "cli/command_line.h"
#include "cli/summary.h"
#include "cli/verbs.h"

#include "cluster/batch_spec.h"
#include "cluster/session.h"
#include "formats/output_plan.h"

#include <nlohmann/json.hpp>

#include <chrono>
#include <filesystem>
#include <iostream>
#include <memory>
#include <stdexcept>

namespace rsibr::cli {
namespace {

struct BatchArgs {
  std::string spec, json;
  bool quiet = false;
};

int run_batch(const BatchArgs& a) {
  namespace fs = std::filesystem;
  const cluster::Session& session = cluster::Session::current();
  const auto t0 = std::chrono::steady_clock::now();
  // The jobs' paths are relative to the spec's folder: every rank works there. The summary's path
  // is the caller's, so it is made absolute first. Its output is checked (at the root) before the
  // spec is read; when any rank cannot start, every rank stops here rather than wait for it.
  const std::string json_target = a.json.empty() || a.json == "-" ? a.json : fs::absolute(a.json).string();
  std::unique_ptr<OutputPlan> outputs;
  std::string json;
  std::vector<cluster::BatchJob> jobs;
  std::exception_ptr failed_to_start;
  try {
    if (session.is_root()) {
      outputs = std::make_unique<OutputPlan>(std::vector<fs::path>{fs::absolute(a.spec)});
      json = outputs->file(json_target);
    }
    jobs = cluster::read_batch_spec(a.spec, verb_names());
  } catch (...) {
    failed_to_start = std::current_exception();
  }
  if (!session.all(!failed_to_start)) {
    if (failed_to_start) std::rethrow_exception(failed_to_start);
    throw std::runtime_error("the root could not start the batch");
  }
  const fs::path folder = fs::absolute(a.spec).parent_path();
  fs::current_path(folder);

  nlohmann::json mine = nlohmann::json::array();
  for (int i : cluster::jobs_of_rank(int(jobs.size()), session.rank(), session.size())) {
    const cluster::BatchJob& job = jobs[std::size_t(i)];
    const auto j0 = std::chrono::steady_clock::now();
    CommandResult result;
    {
      const cluster::ScopedSingleRank one_process;  // the job is a one-process run on this rank
      result = run_command_line(job.args);
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - j0).count();
    nlohmann::json r = {{"index", i + 1},
                        {"name", job.name},
                        {"args", job.args},
                        {"rank", session.rank()},
                        {"exit_code", result.exit_code},
                        {"status", result.exit_code == 0 ? "ok" : "failed"},
                        {"seconds", seconds}};
    if (result.exit_code != 0) r["error"] = result.error;
    if (!a.quiet)
      std::cerr << "rsibr batch: job " << i + 1 << "/" << jobs.size() << " '" << job.name << "' "
                << (result.exit_code == 0 ? "ok" : "failed (exit " + std::to_string(result.exit_code) + ")") << ", "
                << seconds << " s" << (session.size() > 1 ? ", rank " + std::to_string(session.rank()) : "") << "\n";
    mine.push_back(std::move(r));
  }
  const auto gathered = session.gather(cluster::bytes_of(mine.dump()));
  if (!session.is_root()) return 0;

  std::vector<nlohmann::json> results(jobs.size());
  for (const auto& bytes : gathered)
    for (auto& r : nlohmann::json::parse(cluster::text_of(bytes))) results[r["index"].get<std::size_t>() - 1] = r;
  int failed = 0;
  std::string first_failure;
  for (const auto& r : results)
    if (r["status"] != "ok" && failed++ == 0)
      first_failure = "job " + std::to_string(r["index"].get<int>()) + " '" + r["name"].get<std::string>() + "'";
  nlohmann::json j;
  j["spec"] = a.spec;
  j["ranks"] = session.size();
  j["jobs"] = results;
  j["ok"] = int(jobs.size()) - failed;
  j["failed"] = failed;
  j["seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  write_summary(json, j);
  outputs->commit();
  if (!a.quiet || failed)
    std::cerr << "rsibr batch: " << jobs.size() - failed << " of " << jobs.size() << " jobs ok"
              << (failed ? ", " + std::to_string(failed) + " failed (first: " + first_failure + ")" : std::string())
              << "\n";
  return failed ? 1 : 0;
}

}  // namespace

Runner add_batch(CLI::App& app) {
  auto a = std::make_shared<BatchArgs>();
  CLI::App* c = app.add_subcommand("batch", "Run many rsibr commands from a YAML list, over MPI ranks or one by one");
  c->footer(
      "SPEC lists the jobs, each the words after 'rsibr':\n"
      "  jobs:\n"
      "    - name: grey-esplanade\n"
      "      args: [bake, grey.exr, --env, esplanade.exr, --brdf, grey.yaml]\n"
      "    - [process, shoot-a, --out, run-a]\n"
      "Paths in the jobs are relative to SPEC's folder. Under mpirun (a build with MPI) job i runs on rank i mod "
      "N, each job as a one-process run using its rank's share of the machine's cores; without it the jobs run "
      "one after another. A failed job is reported and the others run on; the exit status is 1 when any "
      "failed. --json lists every job: rank, exit code, error line, seconds.");
  c->add_option("spec", a->spec, "Batch spec (YAML)")->required();
  c->add_option("--json", a->json, "Write a JSON summary to FILE ('-' for stdout)");
  c->add_flag("-q,--quiet", a->quiet, "No line per job (failures are still printed by the jobs)");
  return [a] { return run_batch(*a); };
}

}  // namespace rsibr::cli
