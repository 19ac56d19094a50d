#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# One section of the Blender add-on's tests (tests/blender/test_addon.py) in
# a headless Blender: `run.sh SECTION`. Exit 77 (CTest: skipped) when there
# is no blender; BLENDER names another one.
set -euo pipefail
: "${VP_SRC:?}" "${VP_BUILD:?}"
BLENDER=${BLENDER:-blender}
if ! command -v "$BLENDER" >/dev/null 2>&1; then
  echo "SKIP: no blender (Debian: apt-get install blender; scripts/setup.sh with VP_BLENDER=1)"
  exit 77
fi
export PYTHONDONTWRITEBYTECODE=1
export VP_BLENDER_IMAGES=${VP_BLENDER_IMAGES:-$VP_BUILD/blender-images}
# the user's Blender settings and add-ons stay out of the test
home=$(mktemp -d)
trap 'rm -rf "$home"' EXIT
[ "${1:-}" != install ] || python3 "$VP_SRC/blender/make_zip.py" "$home/vdbpack_blender.zip" >/dev/null
export HOME="$home" BLENDER_USER_CONFIG="$home/config" BLENDER_USER_SCRIPTS="$home/scripts"
if [ "${1:-}" = install ]; then
  # the zip as a user installs it, in a Blender that has no PYTHONPATH
  env -u PYTHONPATH "$BLENDER" -b --factory-startup --python-exit-code 1 \
    --python "$VP_SRC/tests/blender/test_install.py" -- "$home/vdbpack_blender.zip" "$VP_BUILD/python"
  exit
fi
export PYTHONPATH="$VP_BUILD/python${PYTHONPATH:+:$PYTHONPATH}"
"$BLENDER" -b --factory-startup --python-exit-code 1 \
  --python "$VP_SRC/tests/blender/test_addon.py" -- "$@"
