// Committing an output folder: checked before any work, written beside its
// final place and renamed into it.
#include "folder/commit.h"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <string>

#include "core/file_util.h"
#include "g2p/pipeline.h"

namespace g2p {
namespace fs = std::filesystem;

namespace detail {

bool is_g2p_folder(const fs::path& folder) {
  std::error_code ec;
  for (const char* mark : {"manifest.json", "run.json", "report.json", "project.json"})
    if (fs::exists(folder / mark, ec)) return true;
  return false;
}

// `-o ../X` run from inside X names X itself, whose parent is where the
// temporary and previous folders go.
fs::path final_folder(const std::string& dir) {
  std::error_code ec;
  fs::path target = fs::weakly_canonical(fs::absolute(dir, ec), ec);
  if (ec) target = fs::absolute(fs::path(dir), ec).lexically_normal();
  return target.filename().empty() ? target.parent_path() : target;
}

}  // namespace detail

namespace {

// Whether `inner` is `folder` or lies below it (both absolute and normal).
bool lies_inside(const fs::path& inner, const fs::path& folder) {
  auto i = inner.begin();
  for (auto f = folder.begin(); f != folder.end(); ++f, ++i)
    if (i == inner.end() || *i != *f) return false;
  return true;
}

// What an existing folder may hold for --overwrite to replace it.
Status check_replaceable(const fs::path& folder, const OutputOptions& output) {
  std::error_code ec;
  if (!output.input_path.empty()) {
    const fs::path input = fs::weakly_canonical(fs::absolute(output.input_path, ec), ec);
    if (!ec && lies_inside(input, folder))
      return Status::InvalidArgument(folder.string() + ": holds the model being run (" + input.string() +
                                     "), which replacing the folder would delete; write the output elsewhere");
  }
  const fs::path cwd = fs::weakly_canonical(fs::current_path(ec), ec);
  if (!ec && lies_inside(cwd, folder))
    return Status::InvalidArgument(folder.string() +
                                   ": is or holds the working directory, which replacing it would delete; "
                                   "write the output elsewhere");
  if (fs::is_empty(folder, ec) || detail::is_g2p_folder(folder)) return Status::Ok();
  return Status::InvalidArgument(folder.string() +
                                 ": exists and is not a g2p output folder (no manifest.json), so it is not "
                                 "replaced; choose a new folder");
}

}  // namespace

Status check_output_folder(const std::string& dir, const OutputOptions& output) {
  if (dir.empty()) return Status::InvalidArgument("no output folder given");
  std::error_code ec;
  const fs::path final_dir = detail::final_folder(dir);
  if (fs::exists(final_dir, ec) && !fs::is_directory(final_dir, ec))
    return Status::InvalidArgument(final_dir.string() + ": exists and is not a folder");
  if (fs::exists(final_dir, ec) && !output.overwrite)
    return Status::InvalidArgument(final_dir.string() + ": exists; choose another folder or allow overwriting");
  if (fs::exists(final_dir, ec)) G2P_RETURN_IF_ERROR(check_replaceable(final_dir, output));
  fs::path above = final_dir.parent_path();
  while (!above.empty() && !fs::exists(above, ec) && above != above.parent_path()) above = above.parent_path();
  if (!fs::is_directory(above, ec))
    return Status::InvalidArgument(above.string() + ": is not a folder, so " + final_dir.string() + " cannot be made");
  // Permissions alone do not tell (root, read-only mounts, pseudo file
  // systems): make and remove an empty folder where the output will go.
  std::string probe = (above / ".g2p-probe-XXXXXX").string();
  if (::mkdtemp(probe.data()) == nullptr)
    return Status::IoError(above.string() + ": cannot write here (" + std::strerror(errno) + "), so " +
                           final_dir.string() + " cannot be made");
  fs::remove(probe, ec);
  return Status::Ok();
}

namespace detail {

Status commit_folder(const std::string& dir, const OutputOptions& output,
                     const std::function<Status(const std::string& tmp, const fs::path& final_dir)>& fill) {
  std::error_code ec;
  const fs::path final_dir = final_folder(dir);
  G2P_RETURN_IF_ERROR(check_output_folder(dir, output));
  const fs::path parent = final_dir.parent_path();
  G2P_RETURN_IF_ERROR(ensure_directory(parent.string()));
  const std::string tag = "." + final_dir.filename().string() + ".g2p-" + std::to_string(::getpid());
  const fs::path tmp = parent / (tag + ".tmp");
  const fs::path old = parent / (tag + ".old");
  fs::remove_all(tmp, ec);
  Status s = ensure_directory(tmp.string());
  if (s.ok()) s = fill(tmp.string(), final_dir);
  if (s.ok() && fs::exists(final_dir)) {
    fs::rename(final_dir, old, ec);
    if (ec) s = Status::IoError(final_dir.string() + ": cannot move the previous output aside: " + ec.message());
  }
  if (s.ok()) {
    fs::rename(tmp, final_dir, ec);
    if (ec) {
      s = Status::IoError(final_dir.string() + ": cannot move the new output into place: " + ec.message());
      std::error_code back;
      if (fs::exists(old)) {
        fs::rename(old, final_dir, back);  // the previous output stays as it was
        if (back) s = Status::IoError(s.message() + "; the previous output is kept at " + old.string());
      }
    }
  }
  if (!s.ok()) {
    fs::remove_all(tmp, ec);
    return s;
  }
  fs::remove_all(old, ec);
  return Status::Ok();
}

}  // namespace detail

}  // namespace g2p
