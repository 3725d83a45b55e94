// Private: where the files libg2p ships beside its code are found (the
// segmentation network, the region classifier, the object detector).
#pragma once

#include <string>

namespace g2p::detail {

// A shipped model file by name, searched in $G2P_MODEL_DIR, then share/g2p/models
// relative to the loaded libg2p (an install tree wherever it was unpacked: a
// prefix, a distribution package, a throwaway root), the source tree's
// libg2p/data/models (builds that are not installed; left out with
// -DG2P_BUILD_TREE_PATHS=OFF, as distribution packages build) and the
// configured install prefix's share/g2p/models, in that order; "" when none holds it.
std::string shipped_model_file(const std::string& name);

}  // namespace g2p::detail
