#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The Fill operator under Blender's real user interface
# (tests/blender/test_ui.py): Blender with its window on a virtual X server
# (xvfb-run; Mesa's llvmpipe gives it OpenGL), its modal run driven by
# Blender's own timers, Esc sent with --enable-event-simulate. Exit 77
# (CTest: skipped) when there is no blender or no xvfb-run; BLENDER names
# another Blender.
set -euo pipefail
: "${VP_SRC:?}" "${VP_BUILD:?}"
BLENDER=${BLENDER:-blender}
for tool in "$BLENDER" xvfb-run; do
  if ! command -v "$tool" >/dev/null 2>&1; then
    echo "SKIP: no $tool (Debian: apt-get install blender xvfb; scripts/setup.sh with VP_BLENDER=1)"
    exit 77
  fi
done
export PYTHONDONTWRITEBYTECODE=1
export VP_BLENDER_IMAGES=${VP_BLENDER_IMAGES:-$VP_BUILD/blender-images}
home=$(mktemp -d)
trap 'rm -rf "$home"' EXIT
export HOME="$home" BLENDER_USER_CONFIG="$home/config" BLENDER_USER_SCRIPTS="$home/scripts"
export PYTHONPATH="$VP_BUILD/python${PYTHONPATH:+:$PYTHONPATH}"
export VP_UI_RESULT="$home/result" VP_UI_TMP="$home"
# Blender quits from the test's timer with status 0 whatever happened: the
# outcome is in $VP_UI_RESULT. A Blender that never gets as far as the test
# (no display, no OpenGL 3.3) leaves none, which fails.
status=0
timeout 300 xvfb-run -a -s "-screen 0 800x600x24" "$BLENDER" --factory-startup \
  --enable-event-simulate --python-exit-code 1 --python "$VP_SRC/tests/blender/test_ui.py" \
  || status=$?
if [ ! -s "$VP_UI_RESULT" ]; then
  echo "FAIL: Blender's UI run ended (status $status) without a test result"
  exit 1
fi
cat "$VP_UI_RESULT"
[ "$status" = 0 ] && grep -q '^ok ' "$VP_UI_RESULT"
