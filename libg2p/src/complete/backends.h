// Private: factories of the built-in completers, registered in completer_registry().
#pragma once

#include <memory>

#include "g2p/complete.h"

namespace g2p {

std::unique_ptr<Completer> make_partition_completer();
std::unique_ptr<Completer> make_external_completer();

}  // namespace g2p
