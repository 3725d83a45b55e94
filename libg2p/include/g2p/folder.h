// The output folder: one module owns its layout, its manifest and how it is
// committed. Every command that writes a folder (g2p run, project, refine,
// complete, properties, export, Pipeline::resume) writes it through
// write_pipeline_output (pipeline.h): into a temporary folder beside the
// target, renamed into place at the end, with the same overwrite rules; every
// command that starts from a folder reads it through read_pipeline_folder.
//
// Layout (docs/pipeline.md#the-output-folder):
//   manifest.json        FolderManifest: what the folder holds and how to read its model again
//   views/               view_XX_rgb.png, view_XX_faceid.png, cameras.json (render)
//   segmented/           view_XX_labels_index.png, image_decided.csv (segment)
//   faces.csv, labelled.ply, parts.json, projected/, refine.json (project, refine)
//   overrides.json       a person's corrections, as face selections
//   completed/           the closed parts and completion.json (complete)
//   report.json          densities, structure, masses (properties; with the asset after export)
//   NAME.xml/.urdf/.sdf/.glb, meshes/, run.json, summary.html (export)
//   options.json         a whole run's options (g2p/options_file.h: `g2p run --options` repeats it)
//
//   g2p::Result<g2p::PipelineResult> state = g2p::read_pipeline_folder("out/chair", g2p::Stage::kComplete);
#pragma once

#include <array>
#include <string>
#include <vector>

#include "g2p/identify.h"
#include "g2p/io.h"
#include "g2p/pipeline.h"
#include "g2p/project.h"
#include "g2p/status.h"

namespace g2p {

// The manifest's schema version. 1: project.json and properties.json (before
// 0.14), which are refused with a message naming the version.
constexpr int kFolderVersion = 2;

// manifest.json: what a folder holds (its last stage) and everything needed
// to rebuild the run's state from it: the model file read exactly as the run
// read it, what the object was identified as, and the project options the
// labels were voted with.
struct FolderManifest {
  int version = kFolderVersion;
  std::string written_by;        // "g2p run", "g2p refine", "Pipeline::resume", ...
  Stage stage = Stage::kExport;  // the last stage the folder holds (project ... export)

  // The model: the file and the import options as the run used them (the
  // user's --unit, --height, --longest-side, --up, --keep-axes, --lenient),
  // then the identify step's scale (a normalised mesh given its kind's size).
  std::string model;                         // absolute path
  ImportOptions import;                      // as used; isolate_reader and limits at their defaults
  double kind_scale = 1.0;                   // applied after import (PipelineResult::size_assumed_m > 0)
  std::vector<std::string> import_warnings;  // ImportInfo::warnings as the run ended (a size assumed, ...)
  bool anonymize_names = false;
  bool base_color_only = false;
  std::string materials;  // "materials.json" in the folder, or "" for the paper's table

  Identification identification;
  std::string kind;             // the kind the run acted on ("" = none)
  double size_assumed_m = 0.0;  // > 0: the kind's longest side it assumed, metres

  ProjectOptions project;            // how the labels were voted and partitioned
  std::string asset_name;            // the asset's name ("" before export)
  std::vector<std::string> formats;  // the asset's formats (export)
};

G2P_API std::string folder_manifest_json(const FolderManifest& manifest);
// Reads DIR/manifest.json. A folder of an older version (project.json
// version 1) or of a newer one is refused with a message naming both versions.
G2P_API Result<FolderManifest> read_folder_manifest(const std::string& dir);

// The state a run had after the stage before `first`, rebuilt from a folder
// written by write_pipeline_output: the model read again, the views and
// label maps, the projection (votes rebuilt from the label maps, so soft or
// footprint-weighted votes come back as hard ones, and a note says so), the
// refined labels and parts (faces.csv), the folder's corrections
// (PipelineResult::overrides), and, for `first` after complete, the closed
// parts (completed/) and, after properties, the properties (report.json).
// `first` is lowered to the earliest stage whose input the folder lacks (a
// `g2p run` folder keeps no closed parts unless --save-intermediates), with
// a note in `notes`. `import` supplies what the manifest does not record
// (isolate_reader, limits).
struct FolderState {
  PipelineResult result;
  FolderManifest manifest;
  Stage first = Stage::kRefine;  // the stage to resume at
  std::vector<std::string> notes;
};
G2P_API Result<FolderState> read_pipeline_folder(const std::string& dir, Stage first, const ImportOptions& import = {});

// A labelled object from ground truth instead of a folder: MODEL's faces
// take the class of their material in `truth` (labels.json's entry `key`,
// "" = the file's stem; materials without a class take their neighbours'),
// and the parts they form: the state after refine, without views, for
// Pipeline::resume(state, Stage::kComplete, ...).
G2P_API Result<PipelineResult> labelled_from_truth(const std::string& model_path, const std::string& truth_path,
                                                   const std::string& key, const MaterialTable& table,
                                                   const ImportOptions& import = {});

// labels.json's plausible mass range for entry `key` ("real_mass_kg": [lo,
// hi], kg); NotFound when the entry gives none.
G2P_API Result<std::array<double, 2>> truth_mass_range(const std::string& truth_path, const std::string& key);

}  // namespace g2p
