// The batch's asset list: command-line inputs (folders, globs, files), the
// manifest (CSV or JSON Lines, with a row-numbered error for a bad row), and
// unique folder names.
#include <glob.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "core/ascii.h"
#include "core/csv.h"
#include "g2p/batch.h"
#include "g2p/io.h"
#include "g2p/options_file.h"

namespace g2p {
namespace {

namespace fs = std::filesystem;

std::string trim(const std::string& s) {
  const auto begin = s.find_first_not_of(" \t\r\n");
  if (begin == std::string::npos) return "";
  return s.substr(begin, s.find_last_not_of(" \t\r\n") - begin + 1);
}

// One CSV line split into trimmed fields.
Result<std::vector<std::string>> split_csv(const std::string& line) {
  bool closed = true;
  std::vector<std::string> fields = detail::csv_fields(line, &closed);
  if (!closed) return Status::ParseError("a quoted field is not closed");
  for (std::string& f : fields) f = trim(f);
  return fields;
}

Result<double> positive_number(const std::string& s) {
  std::istringstream in(s);
  double value = 0;
  in >> value;
  if (s.empty() || in.fail() || !in.eof() || !(value > 0)) return Status::ParseError("is not a positive number");
  return value;
}

// A manifest row's values as an asset whose options are the columns over the
// row's "options" object (JSON Lines); `where` is "file:line".
Result<BatchAsset> asset_of_row(const std::map<std::string, std::string>& row, nlohmann::json options,
                                const fs::path& manifest_dir, const std::string& where) {
  BatchAsset asset;
  asset.origin = where;
  if (!options.is_object()) options = nlohmann::json::object();
  for (const auto& [column, value] : row) {
    if (value.empty()) continue;
    const std::string bad = where + ": " + column + " '" + value + "'";
    if (column == "path") {
      const fs::path p(value);
      asset.path = p.is_absolute() ? p.string() : (manifest_dir / p).lexically_normal().string();
    } else if (column == "name") {
      asset.name = value;
      options["name"] = value;
    } else if (column == "unit") {
      Result<double> scale = parse_unit(value);
      if (!scale.ok()) return Status::ParseError(bad + ": " + scale.status().message());
      options["import"]["unit_scale"] = *scale;
    } else if (column == "up") {
      Result<UpAxis> up = parse_up_axis(value);
      if (!up.ok()) return Status::ParseError(bad + ": " + up.status().message());
      options["import"]["up"] = to_string(*up);
    } else if (column == "height" || column == "longest_side") {
      Result<double> metres = positive_number(value);
      if (!metres.ok()) return Status::ParseError(bad + " is not a positive number (metres)");
      options["import"][column == "height" ? "height_m" : "longest_side_m"] = *metres;
      options["import"][column == "height" ? "longest_side_m" : "height_m"] = 0.0;
    } else if (column == "segmenter") {
      options["segmenter"]["name"] = value;
    } else if (column == "object") {
      options["object"] = value;
    }
  }
  if (asset.path.empty()) return Status::ParseError(where + ": no path (every row needs the model file)");
  if (!options.empty()) {
    asset.options = options.dump();
    Result<RunOptions> valid = parse_options_file(asset.options, where + ": options");
    if (!valid.ok()) return valid.status();
  }
  return asset;
}

Status check_column(const std::string& column, const std::string& where) {
  const std::vector<std::string>& known = batch_manifest_columns();
  if (column == "path" || std::find(known.begin(), known.end(), column) != known.end()) return Status::Ok();
  std::string list = "path";
  for (const std::string& k : known) list += ", " + k;
  return Status::ParseError(where + ": unknown column '" + column + "' (known: " + list + ")");
}

Result<std::vector<BatchAsset>> read_csv_manifest(std::istream& in, const std::string& file, const fs::path& dir) {
  std::vector<BatchAsset> assets;
  std::vector<std::string> header;
  int number = 0;
  for (std::string line; std::getline(in, line);) {
    ++number;
    const std::string where = file + ":" + std::to_string(number);
    if (trim(line).empty() || trim(line)[0] == '#') continue;
    Result<std::vector<std::string>> fields = split_csv(line);
    if (!fields.ok()) return fields.status().with_context(where);
    if (header.empty()) {
      header = *fields;
      for (std::string& column : header) {
        column = detail::lower_case(column);
        G2P_RETURN_IF_ERROR(check_column(column, where));
      }
      if (std::find(header.begin(), header.end(), "path") == header.end())
        return Status::ParseError(where + ": the header row has no 'path' column");
      continue;
    }
    if (fields->size() != header.size())
      return Status::ParseError(where + ": " + std::to_string(fields->size()) + " fields, the header has " +
                                std::to_string(header.size()));
    std::map<std::string, std::string> row;
    for (std::size_t i = 0; i < header.size(); ++i) row[header[i]] = (*fields)[i];
    Result<BatchAsset> asset = asset_of_row(row, nlohmann::json::object(), dir, where);
    if (!asset.ok()) return asset.status();
    assets.push_back(std::move(*asset));
  }
  if (header.empty()) return Status::ParseError(file + ": no header row (path,name,unit,...)");
  return assets;
}

Result<std::vector<BatchAsset>> read_jsonl_manifest(std::istream& in, const std::string& file, const fs::path& dir) {
  std::vector<BatchAsset> assets;
  int number = 0;
  for (std::string line; std::getline(in, line);) {
    ++number;
    const std::string where = file + ":" + std::to_string(number);
    if (trim(line).empty() || trim(line)[0] == '#') continue;
    const nlohmann::json j = nlohmann::json::parse(line, nullptr, false);
    if (j.is_discarded() || !j.is_object()) return Status::ParseError(where + ": not a JSON object");
    std::map<std::string, std::string> row;
    for (const auto& [key, value] : j.items()) {
      if (key == "options") {
        if (!value.is_object()) return Status::ParseError(where + ": 'options' must be an object of options-file keys");
        continue;
      }
      G2P_RETURN_IF_ERROR(check_column(key, where));
      if (value.is_string()) {
        row[key] = value.get<std::string>();
      } else if (value.is_number()) {
        row[key] = value.dump();
      } else {
        return Status::ParseError(where + ": '" + key + "' must be a string or a number");
      }
    }
    Result<BatchAsset> asset = asset_of_row(row, j.value("options", nlohmann::json::object()), dir, where);
    if (!asset.ok()) return asset.status();
    assets.push_back(std::move(*asset));
  }
  return assets;
}

std::string safe_name(const std::string& name) {
  std::string s = name;
  for (char& c : s)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '.' && c != '_' && c != '-') c = '_';
  if (s.empty() || s[0] == '.') s.insert(s.begin(), '_');
  // The index and the lock live beside the asset folders.
  if (s == "index.json" || s == "index.csv") s = "_" + s;
  return s;
}

// A folder g2p wrote (a batch's output with its index, a run's folder, a
// run's temporary or previous folder): its GLB, OBJ and MJCF files are
// outputs, not models, so a folder scan does not go into it. Without this, a
// batch whose -o lies inside its input folder took its own outputs as models
// on every rerun.
bool is_g2p_output(const fs::path& dir) {
  const std::string name = dir.filename().string();
  if (!name.empty() && name[0] == '.' && name.find(".g2p-") != std::string::npos) return true;
  std::error_code ec;
  for (const char* mark : {"index.json", "run.json", "report.json", "project.json"})
    if (fs::exists(dir / mark, ec)) return true;
  return false;
}

}  // namespace

const std::vector<std::string>& batch_manifest_columns() {
  static const std::vector<std::string> columns{"name", "unit", "up", "segmenter", "height", "longest_side", "object"};
  return columns;
}

Result<std::vector<BatchAsset>> read_batch_manifest(const std::string& path) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) return Status::NotFound(path + ": no such manifest file");
  std::ifstream in(path);
  if (!in) return Status::IoError(path + ": cannot read the manifest");
  const fs::path dir = fs::path(path).parent_path();
  const std::string ext = detail::lower_case(fs::path(path).extension().string());
  if (ext == ".jsonl" || ext == ".ndjson") return read_jsonl_manifest(in, path, dir);
  if (ext == ".csv") return read_csv_manifest(in, path, dir);
  return Status::Unsupported(path + ": a manifest is .csv (with a header row) or .jsonl (one JSON object a line)");
}

Result<std::vector<BatchAsset>> list_batch_inputs(const std::vector<std::string>& inputs) {
  std::vector<BatchAsset> assets;
  auto add = [&](const std::string& path) {
    BatchAsset a;
    a.path = path;
    a.origin = path;
    assets.push_back(std::move(a));
  };
  for (const std::string& input : inputs) {
    std::error_code ec;
    if (input.find_first_of("*?[") != std::string::npos && !fs::exists(input, ec)) {
      glob_t matches{};
      const int rc = ::glob(input.c_str(), 0, nullptr, &matches);
      std::vector<std::string> files;
      for (std::size_t i = 0; rc == 0 && i < matches.gl_pathc; ++i)
        if (!fs::is_directory(matches.gl_pathv[i], ec)) files.emplace_back(matches.gl_pathv[i]);
      ::globfree(&matches);
      if (files.empty()) return Status::NotFound(input + ": no file matches this pattern");
      for (const std::string& f : files) add(f);
    } else if (fs::is_directory(input, ec)) {
      std::vector<std::string> files;
      for (auto it = fs::recursive_directory_iterator(input, fs::directory_options::skip_permission_denied, ec);
           !ec && it != fs::recursive_directory_iterator(); it.increment(ec)) {
        if (it->is_directory(ec)) {
          if (is_g2p_output(it->path())) it.disable_recursion_pending();
          continue;
        }
        if (it->is_regular_file(ec) && is_supported_extension(it->path().extension().string()))
          files.push_back(it->path().string());
      }
      if (ec) return Status::IoError(input + ": cannot list the folder: " + ec.message());
      std::sort(files.begin(), files.end());
      for (const std::string& f : files) add(f);
    } else {
      add(input);
    }
  }
  return assets;
}

Status name_batch_assets(std::vector<BatchAsset>& assets) {
  std::map<std::string, const BatchAsset*> explicit_names;
  for (const BatchAsset& a : assets) {
    if (a.name.empty()) continue;
    auto [it, inserted] = explicit_names.emplace(safe_name(a.name), &a);
    if (!inserted)
      return Status::InvalidArgument(a.origin + ": the name '" + a.name + "' is already used by " + it->second->origin);
  }
  std::set<std::string> used;
  for (const auto& entry : explicit_names) used.insert(entry.first);
  for (BatchAsset& a : assets) {
    if (!a.name.empty()) {
      a.name = safe_name(a.name);
      continue;
    }
    const std::string base = safe_name(fs::path(a.path).stem().string());
    std::string name = base;
    for (int n = 2; used.count(name) != 0; ++n) name = base + "-" + std::to_string(n);
    used.insert(name);
    a.name = name;
  }
  return Status::Ok();
}

}  // namespace g2p
