// JSON text for the files and lines the tool writes.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

namespace g2p {

// j.dump(indent), writing any byte sequence that is not UTF-8 (a Latin-1
// material or file name) as U+FFFD instead of throwing out of the command.
inline std::string json_out(const nlohmann::json& j, int indent = 2) {
  return j.dump(indent, ' ', false, nlohmann::json::error_handler_t::replace);
}

}  // namespace g2p
