// Private: JSON text that never throws on the strings in it.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

namespace g2p::detail {

// j.dump(indent), with any byte sequence that is not UTF-8 (a Latin-1 file
// name, a server's error page) written as U+FFFD instead of throwing
// nlohmann::json's type_error 316 out of a writer.
inline std::string json_text(const nlohmann::json& j, int indent = -1) {
  return j.dump(indent, ' ', false, nlohmann::json::error_handler_t::replace);
}

}  // namespace g2p::detail
