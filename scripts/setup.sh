#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Installs the Debian 12 packages vdbpack needs (only those missing) and
# builds it into ./build. Safe to run again: it only does what is missing.
set -euo pipefail
cd "$(dirname "$0")/.."

PKGS=(cmake g++ ninja-build pkg-config
      libopenvdb-dev libboost-iostreams-dev libopenexr-dev libassimp-dev liblog4cplus-dev libpng-dev
      libopenvdb-tools libopenvdb-ax-tools python3 python3-numpy python3-openvdb python3-pytest)
source scripts/apt_install.sh
apt_install setup "${PKGS[@]}"
# VP_BLENDER=1: also Debian's Blender 3.4.1 for the add-on's tests
# (tests/blender, docs/blender.md; about 1 minute, 190 MB installed). Mesa's
# EGL and DRI drivers are named because --no-install-recommends would leave
# them out, and Workbench renders need them even headless. xvfb (with xauth,
# which xvfb-run needs): a virtual X server for the test of the modal Fill
# under Blender's UI (blender_ui).
if [ "${VP_BLENDER:-0}" = 1 ]; then
  apt_install setup blender libegl-mesa0 libgl1-mesa-dri xvfb xauth
fi

BUILD_DIR=${BUILD_DIR:-build}
# Two compile jobs at most: one OpenVDB translation unit takes ~1.5 GB.
JOBS=${JOBS:-2}
if [ ! -f "$BUILD_DIR/build.ninja" ]; then
  cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=Release ${CMAKE_ARGS:-} >/dev/null
fi
cmake --build "$BUILD_DIR" -j "$JOBS"
