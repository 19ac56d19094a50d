#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Set up, build, and run the whole test suite: the CTest suite on the normal
# build, then the hardening stages (scripts/ci_hardening.sh: valgrind,
# fuzzing, the CTest suite again under ASan + UBSan). VP_SKIP_HARDENING=1
# runs only the first part (about 7 minutes instead of about 30 on 2 cores).
set -euo pipefail
cd "$(dirname "$0")/.."
# Blender for the add-on's tests (blender_*: about 1 minute to install, 1 to
# run; VP_BLENDER=0 leaves it out and they are skipped)
VP_BLENDER=${VP_BLENDER:-1} bash scripts/setup.sh
(cd build && ctest --output-on-failure -j "${CTEST_JOBS:-2}" "$@")
if [ "${VP_SKIP_HARDENING:-0}" != 1 ]; then
  bash scripts/ci_hardening.sh
fi
