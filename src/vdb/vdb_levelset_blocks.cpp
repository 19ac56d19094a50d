// SPDX-License-Identifier: Apache-2.0
// Level sets: the coarse block map (which 8^3 blocks hold a leaf, and the
// tile value of those that do not), from which the core builds its depth
// map (src/core/depth_map.c).
#include "vdb/vdb_internal.hpp"

#include <openvdb/tree/ValueAccessor.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>

using namespace vpv;

extern "C" int vpv_levelset_blocks(const vpv_levelset *ls, size_t max_blocks, vpv_blocks *out,
                                   char *err, size_t errlen)
{
    clear(err, errlen);
    if (!out) return fail(err, errlen, VP_ERR_INVALID_ARGUMENT, "vpv_levelset_blocks: out is NULL");
    std::memset(out, 0, sizeof *out);
    if (!ls || !ls->grid)
        return fail(err, errlen, VP_ERR_INVALID_ARGUMENT, "vpv_levelset_blocks: no level set");
    return guard(ls->grid->getName().c_str(), Op::Compute, err, errlen, [&]() -> int {
        const openvdb::FloatGrid &g = *ls->grid;
        const openvdb::math::Transform &xf = g.transform();
        // Only an axis-aligned uniform scale (plus translation): then a
        // block is a world-space cube and a point's block is a division.
        // (in the grid's units; world = scale x grid, vpv_levelset::scale)
        const double s = ls->scale;
        const openvdb::Vec3d w0 = xf.indexToWorld(openvdb::Vec3d(0, 0, 0));
        const double v = ls->voxel / s;
        if (!xf.isLinear() || !(v > 0))
            return fail(err, errlen, VP_ERR_NOT_LEVEL_SET, "the transform is not linear");
        for (int a = 0; a < 3; ++a) {
            openvdb::Vec3d e(0, 0, 0);
            e[a] = 1.0;
            const openvdb::Vec3d d = xf.indexToWorld(e) - w0;
            for (int b = 0; b < 3; ++b) {
                const double want = a == b ? v : 0.0;
                if (std::fabs(d[b] - want) > 1e-9 * v)
                    return fail(err, errlen, VP_ERR_NOT_LEVEL_SET,
                                "the transform is not an axis-aligned uniform scale");
            }
        }
        const openvdb::FloatTree &t = g.tree();
        // every leaf's box: evalLeafBoundingBox counts only leaves with an
        // active voxel, and a leaf wholly past the band (the winding
        // route's, deep inside) has none, but must be marked too
        openvdb::CoordBBox bb;
        for (auto leaf = t.cbeginLeaf(); leaf; ++leaf) bb.expand(leaf->getNodeBoundingBox());
        if (bb.empty())
            return fail(err, errlen, VP_ERR_NOT_LEVEL_SET, "the level set has no leaf nodes");
        // one block of margin on each side: tiles beyond the last leaf
        const openvdb::Coord lo = (bb.min() >> 3) - openvdb::Coord(1, 1, 1);
        const openvdb::Coord hi = (bb.max() >> 3) + openvdb::Coord(1, 1, 1);
        int64_t dims[3];
        double n = 1.0;
        for (int a = 0; a < 3; ++a) {
            dims[a] = int64_t(hi[a]) - int64_t(lo[a]) + 1;
            n *= double(dims[a]);
        }
        if (n > double(max_blocks))
            return fail(err, errlen, VP_ERR_OUT_OF_MEMORY, "%.0f blocks, more than %zu", n,
                        max_blocks);
        float *val = static_cast<float *>(std::malloc(size_t(n) * sizeof(float)));
        if (!val)
            return fail(err, errlen, VP_ERR_OUT_OF_MEMORY, "out of memory for %.0f blocks", n);
        // Regions no node covers read the background (+, outside); then
        // every tile (inactive or not, at any level above the leaves)
        // paints the blocks it covers; then every leaf marks its block.
        const size_t nb = size_t(n);
        std::fill(val, val + nb, float(g.background()));
        auto at = [&](int64_t x, int64_t y, int64_t z) {
            return size_t((z * dims[1] + y) * dims[0] + x);
        };
        auto tile = t.cbeginValueAll();
        tile.setMaxDepth(openvdb::FloatTree::ValueAllCIter::LEAF_DEPTH - 1);
        for (; tile; ++tile) {
            openvdb::CoordBBox tb;
            tile.getBoundingBox(tb);
            int64_t b0[3], b1[3];
            bool empty = false;
            for (int a = 0; a < 3; ++a) {
                b0[a] = std::max<int64_t>(int64_t(tb.min()[a] >> 3) - lo[a], 0);
                b1[a] = std::min<int64_t>(int64_t(tb.max()[a] >> 3) - lo[a], dims[a] - 1);
                empty |= b0[a] > b1[a];
            }
            if (empty) continue;
            const float tv = *tile;
            for (int64_t z = b0[2]; z <= b1[2]; ++z)
                for (int64_t y = b0[1]; y <= b1[1]; ++y)
                    std::fill(val + at(b0[0], y, z), val + at(b1[0], y, z) + 1, tv);
        }
        const float nan = std::numeric_limits<float>::quiet_NaN();
        for (auto leaf = t.cbeginLeaf(); leaf; ++leaf) {
            const openvdb::Coord o = leaf->origin() >> 3;
            val[at(o[0] - lo[0], o[1] - lo[1], o[2] - lo[2])] = nan;
        }
        if (s != 1.0)
            for (size_t i = 0; i < nb; ++i) val[i] *= float(s);
        for (int a = 0; a < 3; ++a) {
            out->origin[a] = (w0[a] + double(lo[a]) * 8.0 * v) * s;
            out->dims[a] = dims[a];
        }
        out->block = 8.0 * v * s;
        out->voxel = v * s;
        out->background = std::fabs(double(g.background())) * s;
        out->value = val;
        return VP_OK;
    });
}
