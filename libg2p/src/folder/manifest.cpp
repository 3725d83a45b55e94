// manifest.json: one writer and one reader for what an output folder holds.
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "core/json_text.h"
#include "core/options_json.h"
#include "folder/manifest.h"
#include "g2p/folder.h"
#include "g2p/options_file.h"

namespace g2p {
namespace {

namespace fs = std::filesystem;

Result<Stage> stage_from(const std::string& name) {
  for (int i = 0; i < kNumStages; ++i)
    if (name == to_string(static_cast<Stage>(i))) return static_cast<Stage>(i);
  return Status::ParseError("unknown stage '" + name + "'");
}

}  // namespace

namespace detail {

FolderManifest folder_manifest(const PipelineResult& r, const PipelineOptions& o, const std::string& written_by) {
  FolderManifest m;
  m.written_by = written_by;
  m.stage = r.last_stage;
  if (!r.model.info.path.empty() && r.model.info.path != "<memory>") {
    std::error_code ec;
    m.model = fs::absolute(r.model.info.path, ec).string();
  }
  m.import = o.import;
  m.kind_scale = r.kind_scale;
  m.import_warnings = r.model.info.warnings;
  m.anonymize_names = o.anonymize_names;
  m.base_color_only = o.base_color_only;
  if (r.table.to_json() != MaterialTable::paper_default().to_json()) m.materials = "materials.json";
  m.identification = r.identification;
  m.kind = r.kind.name;
  m.size_assumed_m = r.size_assumed_m;
  m.project = o.project;
  m.asset_name = r.asset.name;
  if (r.last_stage >= Stage::kExport) m.formats = o.formats;
  return m;
}

}  // namespace detail

std::string folder_manifest_json(const FolderManifest& m) {
  nlohmann::json import = detail::import_json(m.import);
  import["kind_scale"] = m.kind_scale;
  import["warnings"] = m.import_warnings;
  nlohmann::json candidates = nlohmann::json::array();
  for (const KindGuess& g : m.identification.candidates)
    candidates.push_back(
        {{"kind", g.kind}, {"confidence", g.confidence}, {"source", g.source}, {"evidence", g.evidence}});
  const nlohmann::json j = {{"format", "g2p-folder"},
                            {"version", m.version},
                            {"written_by", m.written_by},
                            {"stage", to_string(m.stage)},
                            {"model", m.model},
                            {"import", import},
                            {"anonymize_names", m.anonymize_names},
                            {"base_color_only", m.base_color_only},
                            {"materials", m.materials},
                            {"identification",
                             {{"candidates", candidates},
                              {"notes", m.identification.notes},
                              {"warnings", m.identification.warnings},
                              {"kind", m.kind},
                              {"size_assumed_m", m.size_assumed_m}}},
                            {"project", detail::project_json(m.project)},
                            {"asset", {{"name", m.asset_name}, {"formats", m.formats}}}};
  return detail::json_text(j, 2) + "\n";
}

Result<FolderManifest> read_folder_manifest(const std::string& dir) {
  const std::string path = (fs::path(dir) / "manifest.json").string();
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return Status::NotFound(dir + ": no such folder");
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    if (fs::exists(fs::path(dir) / "project.json", ec) || fs::exists(fs::path(dir) / "properties.json", ec))
      return Status::InvalidArgument(dir +
                                     ": made by an older libg2p (project.json, folder version 1); this one reads "
                                     "version " +
                                     std::to_string(kFolderVersion) + ": run the command that made it again");
    return Status::NotFound(path + ": missing (is " + dir + " a g2p output folder? g2p project or g2p run make one)");
  }
  std::ostringstream text;
  text << in.rdbuf();
  const nlohmann::json j = nlohmann::json::parse(text.str(), nullptr, /*allow_exceptions=*/false);
  if (!j.is_object() || j.value("format", "") != "g2p-folder")
    return Status::ParseError(path + ": not a g2p folder manifest");
  FolderManifest m;
  try {
    m.version = j.at("version").get<int>();
    if (m.version != kFolderVersion)
      return Status::InvalidArgument(
          path + ": folder version " + std::to_string(m.version) + ", and this libg2p reads version " +
          std::to_string(kFolderVersion) +
          (m.version > kFolderVersion ? ": update libg2p" : ": run the command that made it again"));
    m.written_by = j.value("written_by", "");
    Result<Stage> stage = stage_from(j.at("stage").get<std::string>());
    if (!stage.ok()) return stage.status().with_context(path);
    m.stage = *stage;
    m.model = j.at("model").get<std::string>();
    const nlohmann::json& i = j.at("import");
    if (Status s = detail::read_import_json(i, m.import); !s.ok()) return s.with_context(path);
    m.kind_scale = i.at("kind_scale").get<double>();
    m.import_warnings = i.at("warnings").get<std::vector<std::string>>();
    m.anonymize_names = j.at("anonymize_names").get<bool>();
    m.base_color_only = j.at("base_color_only").get<bool>();
    m.materials = j.at("materials").get<std::string>();
    const nlohmann::json& id = j.at("identification");
    for (const nlohmann::json& g : id.at("candidates"))
      m.identification.candidates.push_back(KindGuess{g.at("kind").get<std::string>(), g.at("confidence").get<double>(),
                                                      g.at("source").get<std::string>(),
                                                      g.at("evidence").get<std::string>()});
    m.identification.notes = id.at("notes").get<std::vector<std::string>>();
    m.identification.warnings = id.at("warnings").get<std::vector<std::string>>();
    m.kind = id.at("kind").get<std::string>();
    m.size_assumed_m = id.at("size_assumed_m").get<double>();
    const nlohmann::json& p = j.at("project");
    if (Status s = detail::read_project_json(p, m.project); !s.ok()) return s.with_context(path);
    m.asset_name = j.at("asset").at("name").get<std::string>();
    m.formats = j.at("asset").at("formats").get<std::vector<std::string>>();
  } catch (const nlohmann::json::exception& e) {
    return Status::ParseError(path + ": " + e.what());
  }
  if (!(m.kind_scale > 0.0) || !(m.import.unit_scale >= 0.0) || m.model.empty())
    return Status::ParseError(path + ": the model or its scale is missing");
  return m;
}

}  // namespace g2p
