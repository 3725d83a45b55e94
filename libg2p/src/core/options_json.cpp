// The import and project options as JSON (core/options_json.h).
#include "core/options_json.h"

#include "g2p/options_file.h"

namespace g2p::detail {

nlohmann::json import_json(const ImportOptions& i) {
  return {{"unit_scale", i.unit_scale}, {"height_m", i.height_m}, {"longest_side_m", i.longest_side_m},
          {"up", to_string(i.up_axis)}, {"z_up", i.z_up},         {"textures", i.load_textures},
          {"strict", i.strict}};
}

Status read_import_json(const nlohmann::json& j, ImportOptions& i) {
  i.unit_scale = j.at("unit_scale").get<double>();
  i.height_m = j.at("height_m").get<double>();
  i.longest_side_m = j.at("longest_side_m").get<double>();
  Result<UpAxis> up = parse_up_axis(j.at("up").get<std::string>());
  if (!up.ok()) return up.status().with_context("import.up");
  i.up_axis = *up;
  i.z_up = j.at("z_up").get<bool>();
  i.load_textures = j.at("textures").get<bool>();
  i.strict = j.at("strict").get<bool>();
  return Status::Ok();
}

nlohmann::json project_json(const ProjectOptions& p) {
  return {{"vote", to_string(p.vote.mode)},
          {"weight_angle", p.vote.weight_by_angle},
          {"weight_footprint", p.vote.weight_by_footprint},
          {"weld", p.weld_tolerance},
          {"min_part_area", p.partition.min_part_area_fraction},
          {"merge_max_confidence", p.partition.merge_max_confidence}};
}

Status read_project_json(const nlohmann::json& j, ProjectOptions& p) {
  Result<VoteMode> vote = parse_vote_mode(j.at("vote").get<std::string>());
  if (!vote.ok()) return vote.status().with_context("project.vote");
  p.vote.mode = *vote;
  p.vote.weight_by_angle = j.at("weight_angle").get<bool>();
  p.vote.weight_by_footprint = j.at("weight_footprint").get<bool>();
  p.weld_tolerance = j.at("weld").get<double>();
  p.partition.min_part_area_fraction = j.at("min_part_area").get<double>();
  p.partition.merge_max_confidence = j.at("merge_max_confidence").get<double>();
  return Status::Ok();
}

}  // namespace g2p::detail
