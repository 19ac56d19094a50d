#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Replaces the fenced help text under each "## vdbpack CMD" heading of
docs/cli.md with the current `vdbpack CMD --help` output.
Usage: python3 scripts/update_cli_doc.py [build/vdbpack]
tests/sh_docs_help.sh checks the result (options both ways)."""
import os
import re
import subprocess
import sys

root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
exe = sys.argv[1] if len(sys.argv) > 1 else os.path.join(root, "build", "vdbpack")
path = os.path.join(root, "docs", "cli.md")
text = open(path).read()


def repl(m):
    cmd = m.group(1)
    out = subprocess.run([exe, cmd, "--help"], capture_output=True, text=True, check=True).stdout
    return "## vdbpack %s\n\n```\n%s```\n" % (cmd, out)


new, n = re.subn(r"## vdbpack (\w+)\n\n```\n.*?```\n", repl, text, flags=re.S)
open(path, "w").write(new)
print("updated %d help blocks in %s" % (n, path))
