#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Packs the add-on for Blender's Preferences > Add-ons > Install:
`python3 blender/make_zip.py [OUT.zip]` (default ./vdbpack_blender.zip)."""
import os
import sys
import zipfile

here = os.path.join(os.path.dirname(os.path.abspath(__file__)), "vdbpack_blender")
out = sys.argv[1] if len(sys.argv) > 1 else "vdbpack_blender.zip"
with zipfile.ZipFile(out, "w", zipfile.ZIP_DEFLATED) as z:
    for name in sorted(os.listdir(here)):
        if name.endswith(".py"):
            z.write(os.path.join(here, name), "vdbpack_blender/" + name)
print(out)
