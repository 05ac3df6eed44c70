#include "formats/atomic_folder.h"

#include "formats/file_error.h"
#include "formats/written_file_check.h"

#include "core/text.h"

#include <unistd.h>

#include <fstream>
#include <stdexcept>

namespace rsibr {
namespace {

// Absolute, normal, without a trailing separator ("out/" -> "/.../out").
std::filesystem::path normal_folder(const std::filesystem::path& folder) {
  std::filesystem::path p = std::filesystem::absolute(folder).lexically_normal();
  if (p.filename().empty() && p.has_parent_path()) p = p.parent_path();
  return p;
}

}  // namespace

void check_output_folder(const std::filesystem::path& folder, const std::vector<std::filesystem::path>& inputs) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (folder.empty()) throw std::invalid_argument("the output folder name is empty");
  const fs::path parent = normal_folder(folder).parent_path();
  if (!fs::is_directory(parent, ec))
    throw std::invalid_argument(folder.string() + ": the folder " + parent.string() + " does not exist");
  if (fs::exists(folder, ec) && !fs::is_directory(folder, ec))
    throw std::invalid_argument(folder.string() + ": exists and is not a folder");
  for (const auto& input : inputs)
    if (fs::exists(folder, ec) && fs::equivalent(input, folder, ec))
      throw std::invalid_argument(folder.string() + ": output would overwrite the input");
}

std::filesystem::path file_in_folder(const std::filesystem::path& folder, const std::string& file_name) {
  namespace fs = std::filesystem;
  if (file_name.empty() || file_name == "." || file_name == ".." || file_name.find('/') != std::string::npos ||
      file_name.find('\0') != std::string::npos)
    throw std::invalid_argument(folder.string() + ": '" + quoted_for_message(file_name) +
                                "' is not a file name inside the output folder");
  const fs::path path = folder / file_name;
  std::error_code ec1, ec2;
  const fs::path parent = fs::weakly_canonical(normal_folder(path).parent_path(), ec1);
  const fs::path expected = fs::weakly_canonical(normal_folder(folder), ec2);
  if (ec1 || ec2 || parent != expected)
    throw std::invalid_argument(folder.string() + ": '" + quoted_for_message(file_name) +
                                "' lies outside the output folder");
  return path;
}

void write_folder_atomically(const std::filesystem::path& folder, const FolderContents& files) {
  namespace fs = std::filesystem;
  check_output_folder(folder);
  for (const auto& [name, bytes] : files) file_in_folder(folder, name);
  const fs::path target = normal_folder(folder);
  std::string staging_name = ".";
  staging_name += target.filename().string();
  staging_name += ".tmp";
  staging_name += std::to_string(::getpid());
  const fs::path staging = target.parent_path() / staging_name;
  std::error_code ec;
  const bool existed = fs::exists(target, ec);
  try {
    fs::remove_all(staging, ec);
    fs::create_directory(staging);
    for (const auto& [name, bytes] : files) {
      std::ofstream out(staging / name, std::ios::binary);
      out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
      out.close();
      if (!out) throw FileError((target / name).string(), "cannot write", {}, FileRole::Output);
      check_written_file(staging / name, target / name, bytes.empty());
    }
    if (!existed) {
      fs::rename(staging, target);
    } else {
      for (const auto& [name, bytes] : files) fs::rename(staging / name, target / name);
      fs::remove(staging);
    }
  } catch (const fs::filesystem_error& e) {
    fs::remove_all(staging, ec);
    throw FileError(folder.string(), e.code().message(), {}, FileRole::Output);
  } catch (...) {
    fs::remove_all(staging, ec);
    throw;
  }
}

}  // namespace rsibr
