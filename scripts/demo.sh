#!/usr/bin/env bash
# The main job: set up, build, and pack the default sample container.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
./build/vdbpack pack vdb_samples/bean.obj --count 20000 -o bean_packed.vdb \
  --save-container bean_container.vdb "$@"
./build/vdbpack info bean_packed.vdb | head -n 20
