#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Every tracked source, script and CMake file starts (within its first five
# lines) with "SPDX-License-Identifier: Apache-2.0", and LICENSE holds the
# Apache License 2.0. Files counted: *.c *.h *.cpp *.hpp *.py *.sh *.cmake
# *.in *.map, CMakeLists.txt and .ci/run, as `git ls-files` lists them (all
# such files under the tree when it is not a git checkout).
set -euo pipefail
: "${VP_SRC:?}"
cd "$VP_SRC"
grep -q 'Apache License' LICENSE && grep -q 'Version 2.0, January 2004' LICENSE ||
  { echo "FAIL: LICENSE is not the Apache License 2.0"; exit 1; }
if git rev-parse --is-inside-work-tree >/dev/null 2>&1; then
  list() { git ls-files --cached --others --exclude-standard; }
else
  list() { find . -type f -not -path './build*' -not -path './.git/*' | sed 's#^\./##'; }
fi
n=0; bad=0
while IFS= read -r f; do
  case "$f" in
    *.c|*.h|*.cpp|*.hpp|*.py|*.sh|*.cmake|*.in|*.map|CMakeLists.txt|*/CMakeLists.txt|.ci/run) ;;
    *) continue ;;
  esac
  [ -f "$f" ] || continue
  n=$((n + 1))
  if ! head -n 5 "$f" | grep -q 'SPDX-License-Identifier: Apache-2.0'; then
    echo "FAIL: $f has no SPDX-License-Identifier: Apache-2.0 line at its top"
    bad=$((bad + 1))
  fi
done < <(list)
[ "$n" -gt 100 ] || { echo "FAIL: only $n source files found (expected over 100)"; exit 1; }
[ "$bad" -eq 0 ] || { echo "FAIL: $bad of $n files lack the SPDX line"; exit 1; }
echo "ok: $n source files, each with an SPDX-License-Identifier: Apache-2.0 line"
