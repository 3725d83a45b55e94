// The batch index (OUT/index.json and OUT/index.csv, each replaced atomically)
// and the content hash that decides whether an asset runs again.
#include <algorithm>
#include <cinttypes>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "core/csv.h"
#include "core/file_util.h"
#include "core/json_text.h"
#include "g2p/batch.h"
#include "g2p/pipeline.h"
#include "g2p/version.h"

namespace g2p {
namespace {

namespace fs = std::filesystem;
using detail::csv_field;

constexpr const char* kIndexFormat = "g2p-batch-index";

// FNV-1a, 64 bits: enough to notice a changed file or flag (not a security hash).
class Fnv64 {
 public:
  void add(const char* data, std::size_t n) {
    for (std::size_t i = 0; i < n; ++i) hash_ = (hash_ ^ static_cast<unsigned char>(data[i])) * 0x100000001b3ULL;
  }
  void add(const std::string& s) {
    add(s.data(), s.size());
    add("\0", 1);  // "ab","c" and "a","bc" differ
  }
  std::string hex() const {
    char buffer[17];
    std::snprintf(buffer, sizeof buffer, "%016" PRIx64, hash_);
    return buffer;
  }

 private:
  std::uint64_t hash_ = 0xcbf29ce484222325ULL;
};

Status add_file(Fnv64& hash, const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::IoError(path.string() + ": cannot read");
  std::vector<char> buffer(1 << 16);
  while (in) {
    in.read(buffer.data(), static_cast<std::streamsize>(buffer.size()));
    hash.add(buffer.data(), static_cast<std::size_t>(in.gcount()));
  }
  if (in.bad()) return Status::IoError(path.string() + ": read failed");
  return Status::Ok();
}

nlohmann::json row_json(const BatchRow& r) {
  nlohmann::json stages = nlohmann::json::object();
  for (const auto& [stage, seconds] : r.stage_seconds) stages[stage] = seconds;
  return {{"name", r.name},
          {"status", r.status},
          {"error", r.error},
          {"exit_code", r.exit_code},
          {"input", r.input},
          {"origin", r.origin},
          {"key", r.key},
          {"parts", r.parts},
          {"materials", r.materials},
          {"mass_kg", r.mass_kg},
          {"mass_min_kg", r.mass_min_kg},
          {"mass_max_kg", r.mass_max_kg},
          {"kind", r.kind},
          {"kind_confidence", r.kind_confidence},
          {"mass_in_kind_range", r.mass_in_kind_range},
          {"seconds", r.seconds},
          {"stage_seconds", stages},
          {"warnings", r.warnings},
          {"peak_rss_mib", static_cast<double>(r.peak_rss_bytes) / (1024.0 * 1024.0)},
          {"output", r.output},
          {"finished_at", r.finished_at}};
}

BatchRow row_of_json(const nlohmann::json& j) {
  BatchRow r;
  r.name = j.value("name", "");
  r.status = j.value("status", "");
  r.error = j.value("error", "");
  r.exit_code = j.value("exit_code", 0);
  r.input = j.value("input", "");
  r.origin = j.value("origin", "");
  r.key = j.value("key", "");
  r.parts = j.value("parts", std::size_t{0});
  r.materials = j.value("materials", std::vector<std::string>{});
  r.mass_kg = j.value("mass_kg", 0.0);
  r.mass_min_kg = j.value("mass_min_kg", 0.0);
  r.mass_max_kg = j.value("mass_max_kg", 0.0);
  r.kind = j.value("kind", "");
  r.kind_confidence = j.value("kind_confidence", 0.0);
  r.mass_in_kind_range = j.value("mass_in_kind_range", "");
  r.seconds = j.value("seconds", 0.0);
  if (j.contains("stage_seconds") && j["stage_seconds"].is_object())
    for (const auto& [stage, seconds] : j["stage_seconds"].items())
      if (seconds.is_number()) r.stage_seconds[stage] = seconds.get<double>();
  r.peak_rss_bytes = static_cast<std::size_t>(j.value("peak_rss_mib", 0.0) * 1024.0 * 1024.0);
  if (j.contains("warnings") && j["warnings"].is_array())
    for (const nlohmann::json& w : j["warnings"])
      if (w.is_string()) r.warnings.push_back(w.get<std::string>());
  r.output = j.value("output", "");
  r.finished_at = j.value("finished_at", "");
  return r;
}

std::string number(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.6g", value);
  return buffer;
}

std::string index_csv(const std::vector<BatchRow>& rows) {
  std::ostringstream out;
  out << "name,status,error,exit_code,input,parts,materials,mass_kg,mass_min_kg,mass_max_kg,kind,kind_confidence,"
         "mass_in_kind_range,seconds,peak_rss_mib";
  for (int s = 0; s < kNumStages; ++s) out << ",seconds_" << to_string(static_cast<Stage>(s));
  out << ",warnings,output,key,finished_at\n";
  for (const BatchRow& r : rows) {
    std::string materials;
    for (const std::string& m : r.materials) materials += (materials.empty() ? "" : ";") + m;
    out << csv_field(r.name) << "," << r.status << "," << csv_field(r.error) << "," << r.exit_code << ","
        << csv_field(r.input) << "," << r.parts << "," << csv_field(materials) << "," << number(r.mass_kg) << ","
        << number(r.mass_min_kg) << "," << number(r.mass_max_kg) << "," << csv_field(r.kind) << ","
        << number(r.kind_confidence) << "," << r.mass_in_kind_range << "," << number(r.seconds) << ","
        << number(static_cast<double>(r.peak_rss_bytes) / (1024.0 * 1024.0));
    for (int s = 0; s < kNumStages; ++s) {
      auto it = r.stage_seconds.find(to_string(static_cast<Stage>(s)));
      out << "," << (it == r.stage_seconds.end() ? std::string() : number(it->second));
    }
    std::string warnings;  // one field, the warnings separated by " | "
    for (const std::string& w : r.warnings) warnings += (warnings.empty() ? "" : " | ") + w;
    out << "," << csv_field(warnings) << "," << csv_field(r.output) << "," << r.key << "," << r.finished_at << "\n";
  }
  return out.str();
}

}  // namespace

Result<std::string> batch_asset_key(const BatchAsset& asset, const BatchOptions& options) {
  Fnv64 hash;
  hash.add("g2p-batch-key-2");
  hash.add(version());
  Result<RunOptions> run = batch_asset_options(asset, options);
  if (!run.ok()) return run.status();
  run->pipeline.memory_limit_bytes = 0;  // a limit changes whether a run may start, not what it makes
  hash.add(options_file_json(*run));
  hash.add(asset.name);
  std::error_code ec;
  const fs::path path(asset.path);
  // A missing file, a folder or a FIFO is hashed by its name: its run fails
  // and says why (reading a FIFO here would block).
  if (!fs::is_regular_file(path, ec)) {
    hash.add("not-a-file:" + path.string());
    return hash.hex();
  }
  G2P_RETURN_IF_ERROR(add_file(hash, path));
  // Companions that change the output: an OBJ's .mtl, a glTF's .bin (same stem, same folder).
  std::vector<fs::path> companions;
  const fs::path dir = path.has_parent_path() ? path.parent_path() : fs::path(".");
  for (auto it = fs::directory_iterator(dir, ec); !ec && it != fs::directory_iterator(); it.increment(ec))
    if (it->path().stem() == path.stem() && it->path().filename() != path.filename() && it->is_regular_file(ec))
      companions.push_back(it->path());
  std::sort(companions.begin(), companions.end());
  for (const fs::path& c : companions) {
    hash.add(c.filename().string());
    G2P_RETURN_IF_ERROR(add_file(hash, c));
  }
  return hash.hex();
}

Result<std::vector<BatchRow>> read_batch_index(const std::string& output_dir) {
  const std::string path = (fs::path(output_dir) / "index.json").string();
  std::error_code ec;
  if (!fs::exists(path, ec)) return std::vector<BatchRow>{};
  std::ifstream in(path);
  const nlohmann::json j = nlohmann::json::parse(in, nullptr, false);
  if (j.is_discarded() || !j.is_object() || j.value("format", "") != kIndexFormat || !j.contains("assets") ||
      !j["assets"].is_array())
    return Status::ParseError(path + ": not a g2p batch index; move it away or choose another output folder");
  std::vector<BatchRow> rows;
  for (const nlohmann::json& r : j["assets"])
    if (r.is_object()) rows.push_back(row_of_json(r));
  return rows;
}

Status write_batch_index(const std::string& output_dir, const std::vector<BatchRow>& rows) {
  nlohmann::json assets = nlohmann::json::array();
  for (const BatchRow& r : rows) assets.push_back(row_json(r));
  const nlohmann::json j = {{"format", kIndexFormat}, {"version", 1}, {"g2p", version()}, {"assets", assets}};
  G2P_RETURN_IF_ERROR(
      detail::write_file_atomically((fs::path(output_dir) / "index.json").string(), detail::json_text(j, 2) + "\n"));
  return detail::write_file_atomically((fs::path(output_dir) / "index.csv").string(), index_csv(rows));
}

}  // namespace g2p
