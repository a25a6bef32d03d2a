#!/usr/bin/env bash
# A sharded run on this machine: N shard processes, P at a time (xargs -P), then the merge.
#   scripts/cluster/local.sh COMMAND [N] [P]        e.g. scripts/cluster/local.sh ablations 3 3
# COMMAND as for shard.sh; N defaults to 3, P to N. The shards go to
# results/.scratch/shards/COMMAND (emptied first: it is the tool's git-ignored scratch), the merged
# files where the Makefile's target writes them. Each process uses every core (rayon), so on one
# machine P > 1 mainly shows the mechanism; the gain is on more machines. See docs/cluster.md.
set -euo pipefail
cd "$(dirname "$0")/../.."
command=${1:?usage: scripts/cluster/local.sh reproduce|ablations|seed-spread [N] [P]}
n=${2:-3}
p=${3:-$n}
shards=results/.scratch/shards/$command
rm -rf "$shards"
seq 0 $((n - 1)) | xargs -P "$p" -I{} scripts/cluster/shard.sh "$command" {} "$n" "$shards"
scripts/cluster/merge.sh "$command" "$shards"
