#!/usr/bin/env bash
# One shard of a sharded run, with the configurations the Makefile uses:
#   scripts/cluster/shard.sh COMMAND K N [SHARDS]
#     COMMAND  reproduce | ablations | seed-spread
#     K N      this shard, K counted from 0, of N
#     SHARDS   where every shard of the run goes (default results/.scratch/shards/COMMAND);
#              this one writes SHARDS/K/shard.json and nothing else
# Environment: LEARN (default target/debug/learn, built by `make build`); the flights as for any
# command (NEURAL_FLY_DIR, or data/neural-fly from `make data`). A shard run again replaces its
# own earlier shard.json (--force), never a file learn did not write. See docs/cluster.md.
set -euo pipefail
cd "$(dirname "$0")/../.."
usage="usage: scripts/cluster/shard.sh reproduce|ablations|seed-spread K N [SHARDS]"
command=${1:?$usage}
k=${2:?$usage}
n=${3:?$usage}
shards=${4:-results/.scratch/shards/$command}
learn=${LEARN:-target/debug/learn}
out="$shards/$k"
case "$command" in
  reproduce)
    exec "$learn" --quiet reproduce --config experiments/reproduce.json --shard "$k/$n" --out "$out" --force ;;
  ablations)
    exec "$learn" --quiet ablations --config experiments/variants.json --shard "$k/$n" --out "$out" --force ;;
  seed-spread)
    exec "$learn" --quiet meta-train --seed-spread --config experiments/learn.json --shard "$k/$n" --out "$out" --force ;;
  *)
    echo "shard.sh: unknown command '$command'; $usage" >&2
    exit 2 ;;
esac
