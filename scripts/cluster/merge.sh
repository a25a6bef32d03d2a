#!/usr/bin/env bash
# Merges every shard of a sharded run into the files the Makefile's unsharded target writes:
#   scripts/cluster/merge.sh COMMAND [SHARDS]
#     reproduce    results/, paper/tables/ and the README's tables block (as `make reproduce`)
#     ablations    results/ablations/ (as `make ablations`)
#     seed-spread  experiments/learn-seed-spread.json (as `learn meta-train --seed-spread`)
#   SHARDS: the folder of the shards' folders (default results/.scratch/shards/COMMAND).
# `learn merge` refuses shards of another configuration, data, split or commit, and names missing
# or duplicated items (and the shards to run again). See docs/cluster.md.
set -euo pipefail
cd "$(dirname "$0")/../.."
usage="usage: scripts/cluster/merge.sh reproduce|ablations|seed-spread [SHARDS]"
command=${1:?$usage}
shards=${2:-results/.scratch/shards/$command}
learn=${LEARN:-target/debug/learn}
dirs=("$shards"/*/)
case "$command" in
  reproduce)
    exec "$learn" merge --out results --latex-dir paper/tables --readme README.md --force "${dirs[@]}" ;;
  ablations)
    exec "$learn" merge --out results/ablations --force "${dirs[@]}" ;;
  seed-spread)
    exec "$learn" merge --out experiments/learn-seed-spread.json --force "${dirs[@]}" ;;
  *)
    echo "merge.sh: unknown command '$command'; $usage" >&2
    exit 2 ;;
esac
