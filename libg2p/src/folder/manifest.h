// Private: the manifest of a run's result.
#pragma once

#include <string>

#include "g2p/folder.h"

namespace g2p::detail {

// What `r`, run with `o`, holds, for manifest.json.
FolderManifest folder_manifest(const PipelineResult& r, const PipelineOptions& o, const std::string& written_by);

}  // namespace g2p::detail
