#include "g2p/version.h"

namespace g2p {

const char* version() { return G2P_VERSION_STRING; }

}  // namespace g2p
