// libFuzzer target: object tables (libg2p/data/objects.json's format, which
// ObjectTable::read takes from a user) and free text matched against the
// shipped table (--object, file and node names), on arbitrary bytes. A table
// that parses must hold only consistent kinds, each found again by its own
// name; any text must match only kinds of the table, and words that match
// nothing must be refused with the nearest kinds named.
#include <cstddef>
#include <cstdint>
#include <string>

#include "g2p/identify.h"
#include "model_invariants.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  g2p::Result<g2p::ObjectTable> table = g2p::ObjectTable::from_json(text, "input");
  if (table.ok()) {
    for (std::size_t i = 0; i < table->kinds().size(); ++i) {
      const g2p::ObjectKind& k = table->kinds()[i];
      if (!(k.height_m[0] > 0 && k.height_m[0] <= k.height_m[1] && k.mass_kg[0] > 0 && k.mass_kg[0] <= k.mass_kg[1]))
        g2p::fuzz::violated("objects: a kind with an empty or non-positive range");
      if (!(k.typical_longest_side_m >= k.longest_side_m[0] && k.typical_longest_side_m <= k.longest_side_m[1]))
        g2p::fuzz::violated("objects: a typical size outside its range");
      if (table->find(k.name) != static_cast<int>(i)) g2p::fuzz::violated("objects: a kind not found by its name");
    }
  }
  const g2p::ObjectTable& shipped = g2p::ObjectTable::shipped();
  if (text.size() > 4096) return 0;  // names and descriptions are short; nearest() is quadratic in the text
  for (const g2p::TextMatch& m : shipped.match(text))
    if (m.kind < 0 || m.kind >= shipped.size()) g2p::fuzz::violated("objects: a match outside the table");
  g2p::Result<std::string> kind = g2p::kind_from_text(shipped, text);
  if (kind.ok() ? shipped.find(*kind) < 0 : kind.status().message().find("nearest") == std::string::npos)
    g2p::fuzz::violated("objects: --object gave no kind of the table, or an error without the nearest kinds");
  return 0;
}
