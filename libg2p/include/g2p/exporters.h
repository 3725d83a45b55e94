// Deprecated name of the export stage's header, kept for one release:
// include "g2p/export.h" instead. (The visibility macro G2P_API, which
// "g2p/export.h" held before, is in "g2p/visibility.h" and included by every
// public header.)
#pragma once

#include "g2p/export.h"
