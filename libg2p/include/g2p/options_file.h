// A run's options as a file: every choice a user makes for `g2p run` (import,
// views, each stage's backend and settings, identification, decomposition,
// export, memory limit) and the material table, as JSON data.
//
// `g2p run --options FILE` reads one; `g2p batch` writes one for each asset
// (the batch's options with the asset's own over them) and hashes it, so
// options cross from a batch to its workers, to a cluster and back as data,
// never as command-line text. docs/pipeline.md#options-files.
//
//   {"format": "g2p-options", "version": 1,
//    "import": {"unit_scale": 0.01, "height_m": 0, ..., "up": "auto"},
//    "views": {"count": 11, "width": 512, ...},
//    "segmenter": {"name": "hybrid", "settings": {"share": "0.5"}}, ...}
//
// A file may give any subset of the keys: the others keep the base's values
// (a batch's options under an asset's, PipelineOptions{} for g2p run), so
// {"views": {"count": 6}} is a whole options file. An unknown key, a value of
// the wrong type or a word that names nothing is an error naming its key
// path ("opts.json: views.count: expected an integer, got "six"").
#pragma once

#include <string>
#include <vector>

#include "g2p/io.h"
#include "g2p/materials.h"
#include "g2p/pipeline.h"
#include "g2p/render.h"
#include "g2p/status.h"
#include "g2p/visibility.h"

namespace g2p {

// The file format's version; a file of another is refused naming both.
constexpr int kOptionsFileVersion = 1;

// What an options file holds.
struct RunOptions {
  // Every field but `overrides` (a model's corrections: their own file),
  // `render`, `last_stage` and `measure_stage_memory`, which a file leaves at
  // the base's values.
  PipelineOptions pipeline;
  MaterialTable materials = MaterialTable::paper_default();  // written only when it is not the paper's
};

// The whole file: every key, so that it pins the run even where a later
// version changes a default. Secrets are never written: a URL setting's
// credentials and query values (`https://user:pw@host/?key=...`, the vlm
// backends' `url`) are written as *** (redact_url); a key belongs in the
// environment (the `api_key_env` setting).
G2P_API std::string options_file_json(const RunOptions& options);
// The key paths whose values options_file_json redacts ("refiner.settings.url").
G2P_API std::vector<std::string> options_file_redactions(const RunOptions& options);

// The keys `json` gives, over `base`. `where` names the text in errors (a path).
G2P_API Result<RunOptions> parse_options_file(const std::string& json, const std::string& where,
                                              const RunOptions& base = {});
G2P_API Result<RunOptions> read_options_file(const std::string& path, const RunOptions& base = {});
// Written whole (options_file_json), replacing `path` atomically.
G2P_API Status write_options_file(const std::string& path, const RunOptions& options);

// The words the file (and the command line) uses for these choices.
G2P_API const char* to_string(UpAxis up);                               // "auto", "x", "y", "z"
G2P_API Result<UpAxis> parse_up_axis(const std::string& text);          // case-insensitive
G2P_API const char* to_string(ViewLayout layout);                       // "sphere", "fibonacci", "turntable"
G2P_API Result<ViewLayout> parse_view_layout(const std::string& text);  // case-insensitive
G2P_API const char* to_string(VoteMode mode);                           // "hard", "soft"
G2P_API Result<VoteMode> parse_vote_mode(const std::string& text);

}  // namespace g2p
