// SPDX-License-Identifier: Apache-2.0
// Level sets: interior band check/rebuild and info (measure, leak test).
#include "vdb/vdb_internal.hpp"

#include <openvdb/tools/Count.h>
#include <openvdb/tools/FastSweeping.h>
#include <openvdb/tools/LevelSetMeasure.h>
#include <openvdb/tools/LevelSetRebuild.h>
#include <openvdb/tools/SignedFloodFill.h>
#include <openvdb/tools/ValueTransformer.h>
#include <openvdb/tree/LeafManager.h>

#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

using namespace vpv;

namespace {

// -(smallest value, active or not, tiles included); 0 for an empty grid.
// Inactive values count: in a narrow-band level set the inactive voxels
// inside hold -(interior band), which says "at least this deep", so the
// band is that width even where (a grid-aligned flat wall) no active
// voxel happens to lie deeper than a whole voxel less.
double interior_band(const openvdb::FloatGrid &g)
{
    const openvdb::FloatTree &t = g.tree();
    if (t.activeVoxelCount() == 0) return 0.0;
    const float active = openvdb::tools::minMax(t).min();
    float mn = active;
    auto tile = t.cbeginValueOff();
    tile.setMaxDepth(openvdb::FloatTree::ValueOffCIter::LEAF_DEPTH - 1); // tiles only
    for (; tile; ++tile) mn = std::min(mn, *tile);
    if (mn < active) return -double(mn); // tiles inside: they hold the band
    // no deeper tile (a thin container): the leaves' inactive voxels
    for (auto leaf = t.cbeginLeaf(); leaf; ++leaf) {
        const float *v = leaf->buffer().data();
        if (!v) continue;
        for (openvdb::Index i = 0; i < openvdb::FloatTree::LeafNodeType::SIZE; ++i)
            mn = std::min(mn, v[i]);
    }
    return std::max(0.0, -double(mn));
}

// The leak test: is any voxel on a face of bb (the active voxels' bounding
// box) inside (< 0)? It walks the tiles and leaves that touch a face, never
// a face voxel by voxel: a corrupt file's bounding box can span 2^32 voxels
// a side (a fuzzed file hung a loop over the face voxels).
// Voxels that no node holds read as the background, inside only if it is
// negative.
int leaks(const openvdb::FloatTree &t, const openvdb::CoordBBox &bb)
{
    if (t.background() < 0.0f) return 1;
    // the part of nb inside bb, when it reaches one of bb's faces
    auto on_face = [&bb](const openvdb::CoordBBox &nb, openvdb::CoordBBox &c) {
        c = nb;
        c.intersect(bb);
        if (c.empty()) return false;
        for (int a = 0; a < 3; ++a)
            if (c.min()[a] == bb.min()[a] || c.max()[a] == bb.max()[a]) return true;
        return false;
    };
    openvdb::CoordBBox c;
    auto tile = t.cbeginValueAll();
    tile.setMaxDepth(openvdb::FloatTree::ValueAllCIter::LEAF_DEPTH - 1); // tiles only
    for (; tile; ++tile) {
        if (*tile >= 0.0f) continue;
        openvdb::CoordBBox tb;
        tile.getBoundingBox(tb);
        if (on_face(tb, c)) return 1;
    }
    for (auto leaf = t.cbeginLeaf(); leaf; ++leaf) {
        if (!on_face(leaf->getNodeBoundingBox(), c)) continue;
        for (int i = c.min().x(); i <= c.max().x(); ++i)
            for (int j = c.min().y(); j <= c.max().y(); ++j)
                for (int k = c.min().z(); k <= c.max().z(); ++k) {
                    const openvdb::Coord ijk(i, j, k);
                    bool face = false;
                    for (int a = 0; a < 3; ++a)
                        face = face || ijk[a] == bb.min()[a] || ijk[a] == bb.max()[a];
                    if (face && leaf->getValue(ijk) < 0.0f) return 1;
                }
    }
    return 0;
}

// About how many voxels the zero crossing covers, for the cost of a
// rebuild: 64 a leaf (a leaf the surface crosses holds about one 8x8 sheet
// of it), plus each face of an inside tile (value < 0, active or not) whose
// neighbour just beyond the face's centre is outside (>= 0). The inside
// tiles of a narrow-band level set meet only its band or other inside
// tiles and add nothing; a hand-made or corrupt file's tile that meets the
// outside adds its faces (a 4096^3 one: 1e8 voxels).
double surface_voxels(const openvdb::FloatTree &t)
{
    double s = 64.0 * double(t.leafCount());
    openvdb::tree::ValueAccessor<const openvdb::FloatTree> acc(t);
    auto tile = t.cbeginValueAll();
    tile.setMaxDepth(openvdb::FloatTree::ValueAllCIter::LEAF_DEPTH - 1); // tiles only
    for (; tile; ++tile) {
        if (!(*tile < 0.0f)) continue;
        openvdb::CoordBBox b;
        tile.getBoundingBox(b);
        const openvdb::Coord d = b.dim();
        for (int a = 0; a < 3; ++a) {
            const int u = (a + 1) % 3, v = (a + 2) % 3;
            for (int side = 0; side < 2; ++side) {
                const int64_t at = side ? int64_t(b.max()[a]) + 1 : int64_t(b.min()[a]) - 1;
                if (at < INT32_MIN || at > INT32_MAX) continue; // nothing beyond the index space
                openvdb::Coord p;
                p[a] = int32_t(at);
                p[u] = int32_t((int64_t(b.min()[u]) + b.max()[u]) / 2);
                p[v] = int32_t((int64_t(b.min()[v]) + b.max()[v]) / 2);
                if (acc.getValue(p) >= 0.0f) s += double(d[u]) * double(d[v]);
            }
        }
    }
    return s;
}

// The inside's volume in voxels: every voxel of every leaf counts
// clamp(0.5 - value / voxel, 0, 1) (the smeared Heaviside of a distance),
// every tile below zero all its voxels. Each leaf's sum is taken in
// parallel and the sums are added in the leaves' order: the same volume,
// to the last bit, on every run (a parallel_reduce adds its pieces in the
// order the threads happen to finish them, and the jam packer's start
// scale, taken from this volume, then differed from run to run).
double heaviside_volume(const openvdb::FloatGrid &g)
{
    const openvdb::FloatTree &t = g.tree();
    const double h = g.transform().voxelSize()[0];
    openvdb::tree::LeafManager<const openvdb::FloatTree> lm(t);
    std::vector<double> sums(lm.leafCount(), 0.0);
    lm.foreach ([&](const openvdb::FloatTree::LeafNodeType &leaf, size_t n) {
        double s = 0.0;
        for (openvdb::Index i = 0; i < openvdb::FloatTree::LeafNodeType::SIZE; ++i)
            s += std::min(1.0, std::max(0.0, 0.5 - double(leaf.getValue(i)) / h));
        sums[n] = s;
    });
    double v = 0.0;
    for (double s : sums) v += s;
    auto tile = t.cbeginValueAll();
    tile.setMaxDepth(openvdb::FloatTree::ValueAllCIter::LEAF_DEPTH - 1);
    for (; tile; ++tile)
        if (*tile < 0.0f) v += double(tile.getVoxelCount());
    return v;
}

// The signs of orig on rebuilt, a rebuild of it on the same transform:
// levelSetRebuild meshes the zero crossing and voxelizes the mesh again,
// whose flood fill takes every region the outside cannot reach for
// inside, so a cavity holding positive values (a hollow ball) was filled.
// Every voxel of the rebuilt leaves takes the sign orig has there (its
// magnitude, the distance, is the rebuild's; where orig is 0 the rebuild's
// sign stays), then every tile the sign of orig at its centre.
void keep_signs(const openvdb::FloatGrid &orig, openvdb::FloatGrid &rebuilt)
{
    openvdb::FloatTree &t = rebuilt.tree();
    openvdb::tree::LeafManager<openvdb::FloatTree> leaves(t);
    leaves.foreach ([&](openvdb::FloatTree::LeafNodeType &leaf, size_t) {
        openvdb::tree::ValueAccessor<const openvdb::FloatTree> acc(orig.tree());
        for (openvdb::Index i = 0; i < openvdb::FloatTree::LeafNodeType::SIZE; ++i) {
            const float o = acc.getValue(leaf.offsetToGlobalCoord(i)), v = leaf.getValue(i);
            if (o != 0.0f && (o < 0.0f) != (v < 0.0f)) leaf.setValueOnly(i, -v);
        }
    });
    // the tiles between the leaves as the leaves say, then each as orig
    openvdb::tools::signedFloodFill(t, /*threaded=*/true, /*grainSize=*/1, /*minLevel=*/1);
    openvdb::tree::ValueAccessor<const openvdb::FloatTree> acc(orig.tree());
    auto tile = t.beginValueAll();
    tile.setMaxDepth(openvdb::FloatTree::ValueAllIter::LEAF_DEPTH - 1);
    for (; tile; ++tile) {
        openvdb::CoordBBox b;
        tile.getBoundingBox(b);
        // (the half extent added to min: min + max overflows an int for the
        // tiles of a hand-made file far from the origin)
        const openvdb::Coord c(b.min().x() + (b.max().x() - b.min().x()) / 2,
                               b.min().y() + (b.max().y() - b.min().y()) / 2,
                               b.min().z() + (b.max().z() - b.min().z()) / 2);
        const float o = acc.getValue(c), v = *tile;
        if (o != 0.0f && (o < 0.0f) != (v < 0.0f)) tile.setValue(-v);
    }
}

// After a band was widened: what lies inside past it (inactive voxels,
// tiles) holds minus the new band's depth, the deepest active value, as a
// narrow band's inside does ("at least this deep"); it held the old band's.
void deepen_inside(openvdb::FloatGrid &g)
{
    openvdb::FloatTree &t = g.tree();
    if (t.activeVoxelCount() == 0) return;
    const float deepest = openvdb::tools::minMax(t).min();
    if (!(deepest < 0.0f)) return;
    openvdb::tree::LeafManager<openvdb::FloatTree> leaves(t);
    leaves.foreach ([deepest](openvdb::FloatTree::LeafNodeType &leaf, size_t) {
        for (auto it = leaf.beginValueOff(); it; ++it)
            if (*it < 0.0f && *it > deepest) it.setValue(deepest);
    });
    auto tile = t.beginValueAll();
    tile.setMaxDepth(openvdb::FloatTree::ValueAllIter::LEAF_DEPTH - 1);
    for (; tile; ++tile)
        if (*tile < 0.0f && *tile > deepest) tile.setValue(deepest);
}

// interior_band of ls's grid, measured once per grid: the loader's
// get_info, its estimate of a rebuild's cost and ensure_interior all ask.
double band_of(const vpv_levelset &ls)
{
    if (ls.band < 0.0) ls.band = interior_band(*ls.grid) * ls.scale; // world units
    return ls.band;
}

// True when ensure_interior(ls, in_depth) has nothing to rebuild.
bool deep_enough(const vpv_levelset &ls, double in_depth)
{
    return in_depth <= 0.0 || in_depth <= ls.ensured_depth || band_of(ls) >= in_depth;
}

// The band widths, in voxels, of the rebuild that makes values distances
// to in_depth inside: interior (want) and exterior (ex). One definition for
// the rebuild and for the estimate of its cost.
void band_widths(const vpv_levelset &ls, double in_depth, double &want, double &ex)
{
    want = std::ceil(in_depth / ls.voxel) + 2.0;
    ex = std::max(3.0, double(ls.grid->background()) * ls.scale / ls.voxel);
}

// Every value of g (voxels and tiles, active or not) and its background times f.
void scale_values(openvdb::FloatGrid &g, float f)
{
    openvdb::tools::foreach (
        g.tree().beginValueAll(),
        [f](const openvdb::FloatTree::ValueAllIter &it) { it.setValue(*it * f); });
    g.tree().root().setBackground(g.tree().background() * f, /*updateChildNodes=*/false);
}

} // namespace

openvdb::FloatGrid::Ptr vpv::in_voxel_units(const openvdb::FloatGrid &g, bool distances)
{
    openvdb::FloatGrid::Ptr c = g.deepCopy();
    c->setTransform(openvdb::math::Transform::createLinearTransform(1.0));
    if (distances) scale_values(*c, float(1.0 / g.voxelSize()[0]));
    return c;
}

void vpv::to_world_units(openvdb::FloatGrid &g, double h, const openvdb::math::Transform &xf)
{
    scale_values(g, float(h));
    g.setTransform(xf.copy());
}

extern "C" int vpv_levelset_ensure_interior(vpv_levelset *ls, double in_depth, char *err,
                                            size_t errlen)
{
    clear(err, errlen);
    if (!ls || !ls->grid)
        return fail(err, errlen, VP_ERR_INVALID_ARGUMENT,
                    "vpv_levelset_ensure_interior: no level set");
    if (std::isnan(in_depth))
        return fail(err, errlen, VP_ERR_INVALID_ARGUMENT, "interior depth is not a number");
    vpv_init();
    const std::string name = ls->grid->getName();
    return guard(name.c_str(), Op::Compute, err, errlen, [&]() -> int {
        openvdb::FloatGrid &g = *ls->grid;
        if (deep_enough(*ls, in_depth)) {
            ls->ensured_depth = std::max(ls->ensured_depth, in_depth);
            return VP_OK;
        }
        if (!g.hasUniformVoxels())
            return fail(err, errlen, VP_ERR_NOT_LEVEL_SET,
                        "level set '%s': voxels are not cubes; cannot widen its interior band",
                        name.c_str());
        double want, ex;
        band_widths(*ls, in_depth, want, ex);
        // (the sweep cannot reach 1000 voxels: see in_voxel_units)
        if (!std::isfinite(want) || want > 990)
            return fail(err, errlen, VP_ERR_OUT_OF_MEMORY,
                        "level set '%s': an interior band %g deep is %.0f voxels, more than the "
                        "990 it can be widened to; use smaller particles or a coarser level set",
                        name.c_str(), in_depth, want);
        // widened inward by fast sweeping from the band it has (in voxel
        // units: see in_voxel_units), on a copy whose tiles are inactive
        // (the sweep makes every voxel of an active tile a voxel of its
        // own: a corrupt or hand-made file's tile of 4096^3 voxels took
        // all the memory there is). The signs stay as the file has them:
        // levelSetRebuild, which meshes the zero crossing and voxelizes
        // that again, lost a hollow ball's inner wall and filled its cavity.
        const int more = int(std::ceil((in_depth - band_of(*ls)) / ls->voxel)) + 2;
        openvdb::FloatGrid::Ptr work = in_voxel_units(g, /*distances=*/true);
        {
            auto tile = work->tree().beginValueOn();
            tile.setMaxDepth(openvdb::FloatTree::ValueOnIter::LEAF_DEPTH - 1);
            for (; tile; ++tile) tile.setActiveState(false);
        }
        openvdb::FloatGrid::Ptr ng =
            openvdb::tools::dilateSdf(*work, more, openvdb::tools::NN_FACE, 1,
                                      openvdb::tools::FastSweepingDomain::SWEEP_LESS_THAN_ISOVALUE);
        work.reset();
        if (!ng)
            return fail(err, errlen, VP_ERR_INTERNAL,
                        "level set '%s': the sweep that widens its band failed", name.c_str());
        to_world_units(*ng, g.voxelSize()[0], g.transform());
        keep_signs(g, *ng);
        deepen_inside(*ng);
        ng->setName(name);
        ng->setGridClass(openvdb::GRID_LEVEL_SET);
        ls->grid = ng;
        refresh_levelset(*ls);
        ls->ensured_depth = in_depth;
        return VP_OK;
    });
}

extern "C" double vpv_levelset_rebuild_voxels(const vpv_levelset *ls, double in_depth,
                                              double inside_voxels)
{
    if (!ls || !ls->grid || std::isnan(in_depth)) return 0.0;
    try {
        const openvdb::FloatGrid &g = *ls->grid;
        if (deep_enough(*ls, in_depth)) return 0.0;
        double want, ex;
        band_widths(*ls, in_depth, want, ex);
        const double surface = surface_voxels(g.tree());
        return std::min(surface * (want + ex), inside_voxels + surface * ex);
    } catch (...) {
        return 0.0; // (the rebuild itself then reports what is wrong)
    }
}

extern "C" void vpv_levelset_get_info(const vpv_levelset *ls, vpv_levelset_info *info)
{
    if (!info) return;
    memset(info, 0, sizeof *info);
    if (!ls || !ls->grid) return;
    try {
        const openvdb::FloatGrid &g = *ls->grid;
        const openvdb::FloatTree &t = g.tree();
        const openvdb::math::Transform &xf = g.transform();
        info->voxel_size = ls->voxel;
        snprintf(info->name, sizeof info->name, "%s", g.getName().c_str());
        info->background = std::fabs(double(g.background())) * ls->scale;
        info->active_voxels = size_t(t.activeVoxelCount());
        if (info->active_voxels == 0) return;
        info->interior_band = band_of(*ls);

        const openvdb::CoordBBox bb = g.evalActiveVoxelBoundingBox();
        for (int a = 0; a < 3; ++a) {
            info->bmin[a] = HUGE_VAL;
            info->bmax[a] = -HUGE_VAL;
        }
        for (int c = 0; c < 8; ++c) {
            openvdb::Vec3d ip((c & 1) ? bb.max().x() : bb.min().x(),
                              (c & 2) ? bb.max().y() : bb.min().y(),
                              (c & 4) ? bb.max().z() : bb.min().z());
            openvdb::Vec3d w = xf.indexToWorld(ip) * ls->scale;
            for (int a = 0; a < 3; ++a) {
                info->bmin[a] = std::min(info->bmin[a], w[a]);
                info->bmax[a] = std::max(info->bmax[a], w[a]);
            }
        }

        // active voxels below zero: the leaves in parallel, then the tiles
        openvdb::tree::LeafManager<const openvdb::FloatTree> lm(t);
        size_t inside = tbb::parallel_reduce(
            lm.leafRange(), size_t(0),
            [](const openvdb::tree::LeafManager<const openvdb::FloatTree>::LeafRange &r, size_t n) {
                for (auto leaf = r.begin(); leaf; ++leaf)
                    for (auto it = leaf->cbeginValueOn(); it; ++it) n += *it < 0.0f;
                return n;
            },
            [](size_t a, size_t b) { return a + b; });
        auto tile = t.cbeginValueOn();
        tile.setMaxDepth(openvdb::FloatTree::ValueOnCIter::LEAF_DEPTH - 1); // tiles only
        for (; tile; ++tile)
            if (*tile < 0.0f) inside += size_t(tile.getVoxelCount());
        info->inside_voxels = inside;

        // levelSetVolume measures the surface in the leaves: an inside tile
        // that meets the outside (surface_voxels) is not in it, so the
        // inside voxels, a lower bound, count too
        const openvdb::Vec3d vs = xf.voxelSize();
        const double s3 = ls->scale * ls->scale * ls->scale;
        info->volume = double(inside) * vs[0] * vs[1] * vs[2] * s3;
        if (ls->heaviside_volume) {
            info->volume = heaviside_volume(g) * vs[0] * vs[1] * vs[2] * s3;
        } else {
            try {
                info->volume = std::max(
                    info->volume,
                    double(openvdb::tools::levelSetVolume(g, /*useWorldSpace=*/true)) * s3);
            } catch (...) {
                // (non-cubic voxels and the like: the inside voxels' volume stands)
            }
        }

        info->leaked = leaks(t, bb);
    } catch (...) {
        // get_info cannot report errors; leave what was filled.
    }
}
