// Private: how a folder is committed: written beside its final place and
// renamed into it, so that it never holds a half-written or mixed result.
#pragma once

#include <filesystem>
#include <functional>
#include <string>

#include "g2p/pipeline.h"

namespace g2p::detail {

// The files whose presence marks a folder as g2p's (an --overwrite may
// replace it): manifest.json, and an older version's run.json, report.json
// and project.json.
bool is_g2p_folder(const std::filesystem::path& folder);

// The output folder as an absolute path with "..", "." and links resolved.
std::filesystem::path final_folder(const std::string& dir);

// Checks `dir` (check_output_folder), calls fill(tmp, final) on a new empty
// temporary folder beside it and, if that succeeds, renames it into place,
// replacing the previous folder only then. On any failure the temporary
// folder is removed and `dir` is as it was.
Status commit_folder(const std::string& dir, const OutputOptions& output,
                     const std::function<Status(const std::string& tmp, const std::filesystem::path& final_dir)>& fill);

}  // namespace g2p::detail
