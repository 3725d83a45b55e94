// Private: the physical bounds that every check of a density shares (a
// person's corrections, a VLM's answer, a part's fill), so that they agree.
#pragma once

namespace g2p::detail {

// No material is denser than osmium, 22,590 kg/m^3 (CRC Handbook of
// Chemistry and Physics): anything above this is a typo or a wrong unit.
constexpr double kMaxDensity_kg_m3 = 23000.0;
// Below aerogels and foams nothing is a solid an estimate may claim.
constexpr double kMinSolidDensity_kg_m3 = 10.0;

}  // namespace g2p::detail
