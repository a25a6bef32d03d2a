#!/usr/bin/env bash
# Fills data/neural-fly: a link to ../shared/data/neural-fly when it exists, otherwise a shallow
# clone of the upstream public repository (its data/ folder has the same layout). Links
# data/ulog and data/crazyflie to ../shared/data (the public PX4 logs and the Crazyflie flight the
# tests of other layouts read) when they exist.
# Never copies flight logs into the project: data/ is git-ignored.
set -euo pipefail
cd "$(dirname "$0")/.."
mkdir -p data
for folder in ulog crazyflie; do
  if [ ! -e "data/$folder" ] && [ -d "../shared/data/$folder" ]; then
    ln -s "$(cd "../shared/data/$folder" && pwd)" "data/$folder"
    echo "data: linked data/$folder -> ../shared/data/$folder"
  fi
done
target=data/neural-fly
if [ -e "$target" ]; then
  echo "data: $target already present"
  exit 0
fi
shared=../shared/data/neural-fly
if [ -d "$shared" ]; then
  ln -s "$(cd "$shared" && pwd)" "$target"
  echo "data: linked $target -> $shared"
  exit 0
fi
echo "data: $shared not found; cloning the upstream Neural-Fly repository"
tmp=$(mktemp -d)
git clone --depth 1 https://github.com/aerorobotics/neural-fly "$tmp/neural-fly"
mv "$tmp/neural-fly/data" "$target"
rm -rf "$tmp"
echo "data: downloaded into $target"
