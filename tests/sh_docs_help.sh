#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# docs/cli.md and README.md against `--help`: every option that a command's
# --help lists is documented in docs/cli.md (in that command's section), and
# every option docs/cli.md names for a command is one its --help lists, so
# the two cannot drift. Also: each command's --help text appears verbatim in
# docs/cli.md.
set -euo pipefail
: "${VDBPACK:?}" "${VP_SRC:?}"
doc="$VP_SRC/docs/cli.md"
[ -f "$doc" ] || { echo "FAIL: $doc missing"; exit 1; }
fail=0
opts() { grep -oE -- '(^|[ ,\[(|])--[a-z][a-z-]*' | sed -E 's/^[ ,\[(|]//' | sort -u; }
for cmd in pack info check render convert; do
  help=$("$VDBPACK" "$cmd" --help)
  # the section of docs/cli.md for this command: from "## vdbpack CMD" to the next "## "
  section=$(awk -v h="## vdbpack $cmd" '$0 ~ "^## " {on = ($0 == h)} on' "$doc")
  [ -n "$section" ] || { echo "FAIL: docs/cli.md has no '## vdbpack $cmd' section"; fail=1; continue; }
  in_help=$(printf '%s\n' "$help" | opts)
  in_doc=$(printf '%s\n' "$section" | opts)
  missing=$(comm -23 <(echo "$in_help") <(echo "$in_doc") | tr '\n' ' ')
  extra=$(comm -13 <(echo "$in_help") <(echo "$in_doc") | tr '\n' ' ')
  [ -z "${missing// /}" ] || { echo "FAIL: $cmd: in --help but not in docs/cli.md: $missing"; fail=1; }
  [ -z "${extra// /}" ] || { echo "FAIL: $cmd: in docs/cli.md but not in --help: $extra"; fail=1; }
  # the help text itself is quoted in the section
  if ! printf '%s\n' "$section" | grep -qF -- "$(printf '%s\n' "$help" | head -n 1)"; then
    echo "FAIL: $cmd: docs/cli.md does not quote the first line of --help"; fail=1
  fi
  n_help=$(printf '%s\n' "$in_help" | grep -c . || true)
  echo "$cmd: $n_help options in --help, all documented"
done
# README's usage lines name commands that exist
# (lines inside ``` fences only: prose may start with "vdbpack fills ...")
for cmd in $(awk '/^```/ {f = !f; next} f' "$VP_SRC/README.md" | grep -oE '^vdbpack [a-z]+' |
             awk '{print $2}' | sort -u); do
  "$VDBPACK" "$cmd" --help >/dev/null 2>&1 || { echo "FAIL: README names 'vdbpack $cmd', which has no --help"; fail=1; }
done
[ $fail -eq 0 ] && echo "docs and --help agree"
exit $fail
