#!/bin/bash
# Rebuilds libg2p's region classifier (libg2p/data/models/g2p-regions.json and g2p-regions.yml.gz; docs/regions.md and
# docs/training.md, "The region classifier") from the training libraries, in one command:
#
#   tools/training/train_regions.sh SH3D LABELS OUT [--jobs J] [--with-pbr]
#
#   SH3D    the unpacked sweethome3d-furniture libraries (docs/training.md, "Data")
#   LABELS  data/dataset/labels_val.json: labels.json with the validation models marked (val_labels.py)
#   OUT     a folder for the region rows and the classifier
#
#   1. writes the regions of every training model (split "train") with their features and true class, as the
#      network's votes give them with names removed and base colour only, what an image-to-3D mesh shows
#      (g2p eval seg --segmenter learned --anonymize-names --base-color-only --region-features), in J shards;
#      with --with-pbr, also as they come with the importer's PBR kept (names still removed), which doubles the rows;
#   2. the same for the validation models (split "val", base colour only), to check the classifier;
#   3. trains the random trees with class-balanced weights (g2p_train_regions --balance), writes the card with their
#      region accuracy on validation.
#
# About 10 minutes on 2 cores for step 1 (20 with --with-pbr). G2P_BIN (default build/bin) is where g2p and g2p_train_regions are.
set -euo pipefail
{
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
bin=${G2P_BIN:-$root/build/bin}
[ $# -ge 3 ] || { sed -n '5p' "$0" | sed 's/^# *//' >&2; exit 2; }
sh3d=$1 labels=$2 out=$3; shift 3
jobs=2
with_pbr=0
while [ $# -gt 0 ]; do
  case $1 in
    --jobs) [ $# -ge 2 ] || { echo "train_regions.sh: --jobs needs a number" >&2; exit 2; }; jobs=$2; shift 2 ;;
    --with-pbr) with_pbr=1; shift ;;
    *) echo "train_regions.sh: unknown option $1" >&2; exit 2 ;;
  esac
done
[[ $jobs =~ ^[1-9][0-9]*$ ]] || { echo "train_regions.sh: --jobs must be a positive whole number, got '$jobs'" >&2; exit 2; }
mkdir -p "$out"
condition=(--segmenter learned --anonymize-names --base-color-only --assets "$sh3d" --truth "$labels")
# --with-pbr: the same models as they come with the importer's PBR (names still removed).
with_pbr_condition=(--segmenter learned --anonymize-names --assets "$sh3d" --truth "$labels")

# The training models, in J shards of every J-th key (sorted), each its own process.
keys_text=$(/usr/bin/python3 -c "
import json, sys
d = json.load(open(sys.argv[1]))
print('\n'.join(sorted(k for k, v in d['models'].items() if v.get('split') == 'train')))" "$labels")
mapfile -t keys <<< "$keys_text"
[ -n "$keys_text" ] || { echo "train_regions.sh: $labels has no model of split \"train\"" >&2; exit 1; }
[ "$jobs" -le "${#keys[@]}" ] || jobs=${#keys[@]}
echo "train_regions.sh: ${#keys[@]} training models in $jobs shards" >&2
shards() {  # PREFIX CONDITION...: the training rows in J shards, PREFIX0.csv ...
  local prefix=$1 s i list pids=() failed=0
  shift
  for ((s = 0; s < jobs; s++)); do
    local shard=()
    for ((i = s; i < ${#keys[@]}; i += jobs)); do shard+=("${keys[i]}"); done
    list=$(IFS=,; echo "${shard[*]}")
    "$bin/g2p" eval seg "$@" --models "$list" --region-features "$out/$prefix$s.csv" \
      --json "$out/$prefix$s.json" > "$out/$prefix$s.log" 2>&1 &
    pids+=($!)
  done
  for ((s = 0; s < jobs; s++)); do
    wait "${pids[s]}" || { echo "train_regions.sh: shard $s failed: $out/$prefix$s.log" >&2; failed=1; }
  done
  [ "$failed" = 0 ] || exit 1
}
shards train "${condition[@]}"
[ "$with_pbr" = 0 ] || shards train_pbr "${with_pbr_condition[@]}"
"$bin/g2p" eval seg "${condition[@]}" --split val --region-features "$out/val.csv" --json "$out/val.json" \
  > "$out/val.log" 2>&1

train=()
for ((s = 0; s < jobs; s++)); do
  train+=("$out/train$s.csv")
  [ "$with_pbr" = 0 ] || train+=("$out/train_pbr$s.csv")
done
# Class-balanced weights: the choice made on validation (docs/accuracy.md).
"$bin/g2p_train_regions" "${train[@]}" -o "$out" --balance --check "$out/val.csv"
}
