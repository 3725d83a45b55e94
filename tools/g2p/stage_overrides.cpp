#include "stage_overrides.h"

#include <filesystem>
#include <iostream>

#include "commands.h"
#include "common.h"
#include "g2p/identify.h"

namespace g2p::cli {

void add_overrides_flag(CLI::App* cmd, std::string& path) {
  cmd->add_option("--overrides", path,
                  "Corrections to apply (JSON from summary.html's 3D view, docs/pipeline.md#overrides): classes, "
                  "solid/hollow, wall thickness, density, contents per part or face");
}

namespace {

// Parse, check and resolve on the current parts; `apply` changes the labels.
template <typename Apply>
Status apply_file(const std::string& command, const std::string& path, bool carried, int num_faces,
                  const MaterialTable& table, const std::vector<Part>& parts, const std::vector<int>& labels,
                  Apply apply, AppliedOverrides& applied, int& exit_code) {
  auto fail = [&](const Status& s) {
    // read_overrides names the file; the other messages get it here.
    std::string message = s.message();
    if (message.rfind(path, 0) != 0) message = path + ": " + message;
    std::cerr << "g2p " << command << ": error: "
              << (carried ? message.insert(path.size(), " (the folder's corrections)") : "--overrides " + message)
              << "; nothing was written\n";
    exit_code = kExitUsage;
    return s;
  };
  if (!std::filesystem::is_regular_file(path)) return fail(Status::NotFound(path + ": no such file"));
  Result<Overrides> parsed = read_overrides(path, table);
  if (!parsed.ok()) return fail(parsed.status());
  if (!parsed->object.empty()) {  // what the object is: a kind of the object table, checked before anything changes
    Result<std::string> kind = kind_from_text(ObjectTable::shipped(), parsed->object, "\"object\"");
    if (!kind.ok()) return fail(kind.status());
  }
  Result<ResolvedOverrides> resolved = resolve_overrides(*parsed, num_faces, parts, labels, table);
  if (!resolved.ok()) return fail(resolved.status());
  const std::vector<int> before = labels;
  Result<std::vector<std::string>> notes = apply(*resolved);
  if (!notes.ok()) return fail(notes.status());
  for (const std::string& n : *notes) applied.notes.push_back(path + ": " + n);
  // Only a file that moved a face to another class needs the parts closed again.
  applied.changed_classes = applied.changed_classes || labels != before;
  Overrides faces = as_face_selections(*resolved);
  applied.combined.faces_total = faces.faces_total;
  if (applied.combined.model.empty()) applied.combined.model = faces.model;
  if (!faces.object.empty()) {
    applied.combined.object = faces.object;
    applied.notes.push_back(path + ": the object is taken for what \"object\" says, '" + faces.object + "'");
  }
  for (Override& o : faces.entries) applied.combined.entries.push_back(std::move(o));
  return Status::Ok();
}

}  // namespace

Status apply_overrides_file(const std::string& command, const std::string& path, const Mesh& mesh,
                            const MaterialTable& table, FacesFile& faces, AppliedOverrides& applied, int& exit_code,
                            bool carried) {
  return apply_file(
      command, path, carried, mesh.num_faces(), table, faces.parts, faces.labels,
      [&](const ResolvedOverrides& r) -> Result<std::vector<std::string>> {
        if (!r.overrides.changes_labels()) return std::vector<std::string>{};
        Result<FaceGraph> graph = build_face_graph(mesh);
        if (!graph.ok()) return graph.status();
        return apply_class_overrides(r, mesh, *graph, faces.labels, faces.face_part, faces.parts, table);
      },
      applied, exit_code);
}

Status apply_overrides_file(const std::string& command, const std::string& path, const Mesh& mesh,
                            const MaterialTable& table, Projection& projection, AppliedOverrides& applied,
                            int& exit_code, bool carried) {
  return apply_file(
      command, path, carried, mesh.num_faces(), table, projection.parts, projection.labels.label,
      [&](const ResolvedOverrides& r) { return apply_class_overrides(r, mesh, projection, table); }, applied,
      exit_code);
}

void finish_overrides(int num_faces, const std::vector<Part>& parts, const std::vector<int>& labels,
                      const MaterialTable& table, AppliedOverrides& applied) {
  if (applied.empty()) return;
  // Face selections without checks always resolve.
  Result<ResolvedOverrides> r = resolve_overrides(applied.combined, num_faces, parts, labels, table);
  if (r.ok()) applied.resolved = std::make_shared<ResolvedOverrides>(std::move(*r));
}

Status write_overrides(const std::string& dir, const AppliedOverrides& applied, const MaterialTable& table) {
  if (applied.empty()) {  // a folder written again without corrections must not keep old ones
    std::error_code ignored;
    std::filesystem::remove(dir + "/overrides.json", ignored);
    return Status::Ok();
  }
  return write_text_file(dir + "/overrides.json", overrides_json(applied.combined, table));
}

}  // namespace g2p::cli
