#include "cluster/batch_spec.h"

#include "formats/yaml_spec.h"

#include <algorithm>
#include <set>
#include <stdexcept>

namespace rsibr::cluster {
namespace {

std::vector<std::string> words_of(const YAML::Node& node, const std::string& path) {
  if (!node.IsSequence() || node.size() == 0) spec_fail(path, "must be a non-empty list of words");
  std::vector<std::string> words;
  for (std::size_t i = 0; i < node.size(); ++i) {
    if (!node[i].IsScalar()) spec_fail(path + "[" + std::to_string(i) + "]", "must be a word (a string)");
    words.push_back(node[i].as<std::string>());
  }
  return words;
}

}  // namespace

std::vector<BatchJob> read_batch_spec(const std::filesystem::path& file, const std::vector<std::string>& verbs) {
  try {
    const YAML::Node root = load_yaml_file(file);
    const YamlMap top(root, "batch", {"jobs"});
    const YAML::Node jobs = top.get("jobs");
    if (!jobs.IsSequence() || jobs.size() == 0) spec_fail(top.at("jobs"), "must be a non-empty list of jobs");
    std::vector<BatchJob> out;
    std::set<std::string> names;
    for (std::size_t i = 0; i < jobs.size(); ++i) {
      const std::string path = top.at("jobs") + "[" + std::to_string(i) + "]";
      BatchJob job;
      job.name = "job " + std::to_string(i + 1);
      if (jobs[i].IsMap()) {
        const YamlMap m(jobs[i], path, {"name", "args"});
        if (auto name = m.optional_string("name")) job.name = *name;
        job.args = words_of(m.get("args"), m.at("args"));
      } else {
        job.args = words_of(jobs[i], path);
      }
      const std::string& verb = job.args.front();
      if (verb == "batch" || verb == "view")
        spec_fail(path, "'" + verb + "' cannot run in a batch (a batch job is a bake, a process run, ...)");
      if (std::find(verbs.begin(), verbs.end(), verb) == verbs.end())
        spec_fail(path, "'" + verb + "' is not a verb of rsibr");
      if (!names.insert(job.name).second) spec_fail(path, "a second job named '" + job.name + "'");
      out.push_back(std::move(job));
    }
    return out;
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what(), name = file.string();
    if (what.rfind(name, 0) == 0) throw;  // already names the file
    throw std::invalid_argument(name + ": " + what);
  }
}

std::vector<int> jobs_of_rank(int jobs, int rank, int ranks) {
  if (ranks < 1 || rank < 0 || rank >= ranks) throw std::invalid_argument("batch: rank outside the job");
  std::vector<int> mine;
  for (int i = rank; i < jobs; i += ranks) mine.push_back(i);
  return mine;
}

}  // namespace rsibr::cluster
