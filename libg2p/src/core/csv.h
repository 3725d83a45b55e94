// Private: RFC 4180 CSV fields, for the files libg2p writes and reads
// (faces.csv, the batch index and manifest).
#pragma once

#include <string>
#include <vector>

namespace g2p::detail {

// Quotes a field holding a comma, a quote or a line break ("a ""b""").
std::string csv_field(const std::string& s);

// Splits one CSV record (no line breaks inside fields). `closed`, when given,
// is set to false if a quoted field is not closed by the end of the line.
std::vector<std::string> csv_fields(const std::string& line, bool* closed = nullptr);

}  // namespace g2p::detail
