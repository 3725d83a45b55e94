// Private: where the files libg2p ships beside its code are found (the
// segmentation network, the region classifier, the object detector).
#pragma once

#include <string>

namespace g2p::detail {

// A shipped model file by name, searched in $G2P_MODEL_DIR, the source tree's
// libg2p/data/models (builds that are not installed) and the installed
// share/g2p/models, in that order; "" when none holds it.
std::string shipped_model_file(const std::string& name);

}  // namespace g2p::detail
