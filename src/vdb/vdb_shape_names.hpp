// SPDX-License-Identifier: Apache-2.0
// The shapes' names as the file's "shape" metadata holds them: those of
// vp_shape_name(), written out here because this layer links none of the
// core (tests/sh_layers.sh). The points reader and writer share them.
#ifndef VDBPACK_VDB_SHAPE_NAMES_HPP
#define VDBPACK_VDB_SHAPE_NAMES_HPP
#include "vdbpack/vdbpack.h"

namespace vpv {
inline constexpr const char *kShapeNames[] = {"sphere",
                                              "tetrahedron",
                                              "cube",
                                              "octahedron",
                                              "dodecahedron",
                                              "icosahedron",
                                              "truncated-tetrahedron",
                                              "cuboctahedron",
                                              "truncated-cube",
                                              "truncated-octahedron",
                                              "rhombicuboctahedron",
                                              "truncated-cuboctahedron",
                                              "snub-cube",
                                              "icosidodecahedron",
                                              "truncated-dodecahedron",
                                              "truncated-icosahedron",
                                              "rhombicosidodecahedron",
                                              "truncated-icosidodecahedron",
                                              "snub-dodecahedron"};
static_assert(sizeof kShapeNames / sizeof kShapeNames[0] == VP_SHAPE_COUNT, "one name per shape");
} // namespace vpv
#endif
