#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The main job: set up, build, and pack the default sample container.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
./build/vdbpack pack vdb_samples/peanut.obj --count 20000 -o peanut_packed.vdb \
  --save-container peanut_container.vdb "$@"
./build/vdbpack info peanut_packed.vdb | sed -n 1,20p
