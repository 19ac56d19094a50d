// SPDX-License-Identifier: Apache-2.0
// Level sets: read, write, sample, gradient, destroy.
#include "vdb/vdb_internal.hpp"

#include <openvdb/io/GridDescriptor.h>
#include <openvdb/tools/FastSweeping.h>
#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/Morphology.h>
#include <openvdb/tools/SignedFloodFill.h>
#include <openvdb/tree/LeafManager.h>
#include <openvdb/tree/ValueAccessor.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <memory>

using namespace vpv;

namespace {

bool is_float_level_set(const openvdb::GridBase &g)
{
    return g.getGridClass() == openvdb::GRID_LEVEL_SET &&
           (g.isType<openvdb::FloatGrid>() || g.isType<openvdb::DoubleGrid>());
}

std::string unknown_class_note(const openvdb::GridPtrVec &grids)
{
    for (const auto &g : grids) {
        if (g && (g->isType<openvdb::FloatGrid>() || g->isType<openvdb::DoubleGrid>()) &&
            g->getGridClass() == openvdb::GRID_UNKNOWN) {
            return "; grid '" + g->getName() +
                   "' holds floats but its class is unknown, not level set (mark it as a level set "
                   "to use it)";
        }
    }
    return std::string();
}

// The grid read from the file, as an owned FloatGrid.
openvdb::FloatGrid::Ptr to_float_grid(const openvdb::GridBase::Ptr &g)
{
    if (auto f = openvdb::gridPtrCast<openvdb::FloatGrid>(g)) return f;
    auto d = openvdb::gridPtrCast<openvdb::DoubleGrid>(g);
    if (!d) return nullptr;
    openvdb::FloatTree::Ptr tree(new openvdb::FloatTree(d->tree())); // converts values
    openvdb::FloatGrid::Ptr f = openvdb::FloatGrid::create(tree);
    f->setTransform(d->transform().copy());
    for (auto it = d->beginMeta(); it != d->endMeta(); ++it)
        if (it->second) f->insertMeta(it->first, *it->second);
    f->setGridClass(openvdb::GRID_LEVEL_SET);
    f->setName(d->getName());
    return f;
}

using Acc = openvdb::tree::ValueAccessor<const openvdb::FloatTree, /*IsSafe=*/false>;

struct Slot {
    uint64_t gen = 0;
    std::unique_ptr<Acc> acc;
};

// Per-thread accessors, keyed by the level set's generation (unique for
// the process lifetime), so a freed grid whose address is reused is never
// looked up through a stale accessor. Unsafe (unregistered) accessors never
// touch their tree on destruction.
Acc &accessor(const vpv_levelset *ls)
{
    static thread_local Slot slots[4];
    static thread_local unsigned next = 0;
    if (slots[0].gen == ls->gen) return *slots[0].acc;
    for (int i = 1; i < 4; ++i) {
        if (slots[i].gen == ls->gen) {
            std::swap(slots[0], slots[i]); // most recent first
            return *slots[0].acc;
        }
    }
    Slot &s = slots[1 + (next++ % 3)];
    s.acc.reset(new Acc(ls->grid->constTree()));
    s.gen = ls->gen;
    std::swap(slots[0], s);
    return *slots[0].acc;
}

} // namespace

namespace {

bool is_float_grid(const openvdb::GridBase &g)
{
    return g.isType<openvdb::FloatGrid>() || g.isType<openvdb::DoubleGrid>();
}

// "; a fog or density grid ('density') is a container with --iso V ..."
// when the file has a float grid that is not a level set.
std::string fog_note(const openvdb::GridPtrVec &grids)
{
    for (const auto &g : grids)
        if (g && is_float_grid(*g) && !is_float_level_set(*g))
            return "; a fog or density grid such as '" + g->getName() +
                   "' is a container with --iso V (inside where its value is at least V)";
    return std::string();
}

// The fog or density grid f as a level set: inside where f >= iso, at f's
// voxel size, by OpenVDB's fast sweeping (fogToSdf) over f's active voxels;
// outside values past 3 voxels are clamped to that (the background) and
// made inactive, as a narrow band's are.
int fog_to_levelset(const char *path, openvdb::FloatGrid::Ptr &f, double iso, char *err,
                    size_t errlen)
{
    const openvdb::FloatTree &t = f->tree();
    if (t.activeVoxelCount() == 0)
        return fail(err, errlen, VP_ERR_BAD_CONTAINER, "%s: grid '%s' has no active voxels", path,
                    f->getName().c_str());
    const auto mm = openvdb::tools::minMax(t);
    const double lo = std::min(double(mm.min()), double(t.background()));
    const double hi = std::max(double(mm.max()), double(t.background()));
    if (!(iso > lo && iso < hi))
        return fail(err, errlen, VP_ERR_INVALID_ARGUMENT,
                    "%s: --iso %g is not inside the values of grid '%s' (%g to %g): no surface "
                    "is there",
                    path, iso, f->getName().c_str(), lo, hi);
    // the sweep sees active voxels only, and a fog's outside is often
    // inactive (sdfToFogVolume, Houdini's VDB from Polygons): a copy whose
    // active region reaches two voxels past the fog's gives the surface an
    // outside to be found in
    // (in voxel units: see in_voxel_units)
    openvdb::FloatGrid::Ptr work = in_voxel_units(*f, /*distances=*/false);
    openvdb::tools::dilateActiveValues(work->tree(), 2, openvdb::tools::NN_FACE_EDGE_VERTEX,
                                       openvdb::tools::PRESERVE_TILES);
    openvdb::FloatGrid::Ptr sdf = openvdb::tools::fogToSdf(*work, float(iso), 1);
    work.reset();
    if (!sdf) return fail(err, errlen, VP_ERR_INTERNAL, "%s: fogToSdf failed", path);
    to_world_units(*sdf, f->voxelSize()[0], f->transform());
    const float bgw = float(3.0 * f->voxelSize()[0]);
    openvdb::tree::LeafManager<openvdb::FloatTree> leaves(sdf->tree());
    leaves.foreach ([bgw](openvdb::FloatTree::LeafNodeType &leaf, size_t) {
        for (openvdb::Index i = 0; i < openvdb::FloatTree::LeafNodeType::SIZE; ++i) {
            const float v = leaf.getValue(i);
            if (!(v < bgw)) { // past the band outside, or never reached (+inf)
                leaf.setValueOnly(i, bgw);
                leaf.setValueOff(i);
            } else if (!std::isfinite(v) || v < -1e30f) { // never reached, inside
                leaf.setValueOnly(i, -bgw);
            }
        }
    });
    sdf->tree().root().setBackground(bgw, /*updateChildNodes=*/true);
    openvdb::tools::signedFloodFill(sdf->tree(), true, 1, /*minLevel=*/1);
    sdf->setGridClass(openvdb::GRID_LEVEL_SET);
    sdf->setName(f->getName());
    f = sdf;
    return VP_OK;
}

// Reads a level set, or with iso a fog grid converted (see bridge.h).
int read_levelset(const char *path, const char *grid_name, const double *iso, vpv_levelset **out,
                  char *err, size_t errlen);

} // namespace

extern "C" int vpv_levelset_read(const char *path, const char *grid_name, vpv_levelset **out,
                                 char *err, size_t errlen)
{
    return read_levelset(path, grid_name, nullptr, out, err, errlen);
}

extern "C" int vpv_levelset_read_fog(const char *path, const char *grid_name, double iso,
                                     vpv_levelset **out, char *err, size_t errlen)
{
    if (!std::isfinite(iso)) {
        clear(err, errlen);
        if (out) *out = nullptr;
        return fail(err, errlen, VP_ERR_INVALID_ARGUMENT, "--iso must be a finite number");
    }
    return read_levelset(path, grid_name, &iso, out, err, errlen);
}

namespace {
int read_levelset(const char *path, const char *grid_name, const double *iso, vpv_levelset **out,
                  char *err, size_t errlen)
{
    clear(err, errlen);
    if (!out) return fail(err, errlen, VP_ERR_INVALID_ARGUMENT, "vpv_levelset_read: out is NULL");
    *out = nullptr;
    vpv_init();
    return guard(path, Op::Read, err, errlen, [&]() -> int {
        openvdb::io::File file(path ? path : "");
        openvdb::GridPtrVecPtr metas;
        int rc = read_grid_metadata(path, file, VP_ERR_NOT_LEVEL_SET, metas, err, errlen);
        if (rc != VP_OK) return rc;
        const openvdb::GridPtrVec &grids = *metas;
        size_t pick = grids.size();
        if (!grid_name) {
            for (size_t i = 0; i < grids.size(); ++i)
                if (grids[i] && (iso ? is_float_grid(*grids[i]) && !is_float_level_set(*grids[i])
                                     : is_float_level_set(*grids[i]))) {
                    pick = i;
                    break;
                }
            if (pick == grids.size() && iso)
                return fail(err, errlen, VP_ERR_NOT_LEVEL_SET,
                            "%s: --iso takes a fog or density grid (float, not a level set), and "
                            "the file has none (grids: %s)",
                            path, list_grids(grids).c_str());
            if (pick == grids.size())
                return fail(err, errlen, VP_ERR_NOT_LEVEL_SET,
                            "%s: no float level set in the file (grids: %s)%s%s", path,
                            list_grids(grids).c_str(), unknown_class_note(grids).c_str(),
                            fog_note(grids).c_str());
        } else {
            // "name" must be unique; "name[k]" picks the k-th of several
            // grids sharing a name (io::File's own convention)
            std::string want = grid_name;
            long want_k = -1;
            size_t nsame = 0;
            for (size_t i = 0; i < grids.size(); ++i)
                if (grids[i] && grids[i]->getName() == want && nsame++ == 0) pick = i;
            if (nsame == 0 && want.size() > 3 && want.back() == ']') {
                size_t lb = want.rfind('[');
                char *end = nullptr;
                if (lb != std::string::npos && lb + 1 < want.size() - 1) {
                    want_k = std::strtol(want.c_str() + lb + 1, &end, 10);
                    if (end != want.c_str() + want.size() - 1 || want_k < 0) want_k = -1;
                }
                if (want_k >= 0) {
                    want.resize(lb);
                    long k = 0;
                    for (size_t i = 0; i < grids.size(); ++i)
                        if (grids[i] && grids[i]->getName() == want && k++ == want_k) pick = i;
                }
            }
            if (nsame > 1)
                return fail(err, errlen, VP_ERR_NOT_LEVEL_SET,
                            "%s: %zu grids are named '%s'; pick one with --grid '%s[0]' .. "
                            "'%s[%zu]' (grids: %s)",
                            path, nsame, grid_name, grid_name, grid_name, nsame - 1,
                            list_grids(grids).c_str());
            if (pick == grids.size())
                return fail(err, errlen, VP_ERR_NOT_LEVEL_SET, "%s: no grid named '%s' (grids: %s)",
                            path, grid_name, list_grids(grids).c_str());
            const openvdb::GridBase &g = *grids[pick];
            if (iso && is_float_level_set(g))
                return fail(err, errlen, VP_ERR_INVALID_ARGUMENT,
                            "%s: grid '%s' is a level set; --iso is for fog or density grids "
                            "(leave it out)",
                            path, grid_name);
            if (iso && !is_float_grid(g))
                return fail(err, errlen, VP_ERR_NOT_LEVEL_SET,
                            "%s: grid '%s' is not a float grid (it is [%s, %s]); --iso takes a "
                            "fog or density grid",
                            path, grid_name, class_name(g).c_str(), value_type_name(g).c_str());
            if (!iso && !is_float_level_set(g))
                return fail(err, errlen, VP_ERR_NOT_LEVEL_SET,
                            "%s: grid '%s' is not a float level set (it is [%s, %s])%s", path,
                            grid_name, class_name(g).c_str(), value_type_name(g).c_str(),
                            (g.getGridClass() == openvdb::GRID_UNKNOWN &&
                             (g.isType<openvdb::FloatGrid>() || g.isType<openvdb::DoubleGrid>()))
                                ? "; its class is unknown: mark it as a level set to use it, or "
                                  "give --iso V to take it as a fog or density grid"
                            : is_float_grid(g) ? "; a fog or density grid is a container with "
                                                 "--iso V (inside where its value is at least V)"
                                               : "");
        }
        // Grids sharing a name are addressed as "name[k]" by io::File.
        const std::string name = grids[pick]->getName();
        int dup = 0;
        for (size_t i = 0; i < pick; ++i)
            if (grids[i] && grids[i]->getName() == name) ++dup;
        const std::string key = dup ? openvdb::io::GridDescriptor::addSuffix(name, dup) : name;
        openvdb::GridBase::Ptr g = file.readGrid(key);
        file.close();
        openvdb::FloatGrid::Ptr fg = to_float_grid(g);
        if (!fg)
            return fail(err, errlen, VP_ERR_FORMAT,
                        "%s: grid '%s' could not be read as a float grid", path, name.c_str());
        if (iso) {
            int frc = fog_to_levelset(path, fg, *iso, err, errlen);
            if (frc != VP_OK) return frc;
        }
        fg->setGridClass(openvdb::GRID_LEVEL_SET);
        std::unique_ptr<vpv_levelset> ls(new vpv_levelset);
        ls->grid = fg;
        refresh_levelset(*ls);
        *out = ls.release();
        return VP_OK;
    });
}
} // namespace

namespace {

// The grid's value at world point p, in the grid's units (see
// vpv_levelset::scale).
double sample_grid(const vpv_levelset *ls, const double p[3])
{
    openvdb::Vec3d w(p[0], p[1], p[2]);
    openvdb::Vec3d idx =
        ls->affine ? ls->w2i.transform(w) : ls->grid->transform().worldToIndex(w / ls->scale);
    Acc &acc = accessor(ls);
    // Fast path: when the 8 corners lie in one 8^3 leaf (about 2/3 of
    // lookups), read them from its buffer instead of 8 accessor calls; the
    // sampling packers spend most of their time here. Same trilinear weights
    // as tools::BoxSampler, evaluated in double.
    const double fx = std::floor(idx[0]), fy = std::floor(idx[1]), fz = std::floor(idx[2]);
    if (std::abs(fx) < 1e9 && std::abs(fy) < 1e9 && std::abs(fz) < 1e9) {
        const openvdb::Coord ijk{static_cast<int>(fx), static_cast<int>(fy), static_cast<int>(fz)};
        if ((ijk[0] & 7) != 7 && (ijk[1] & 7) != 7 && (ijk[2] & 7) != 7) {
            const auto *leaf = acc.probeConstLeaf(ijk);
            // No leaf: the 8 corners lie in one tile (deep inside or far
            // outside), all of one value, which is then the trilinear value.
            if (!leaf) return double(acc.getValue(ijk));
            {
                const float *v = leaf->buffer().data();
                if (v) {
                    const openvdb::Index o = leaf->coordToOffset(ijk);
                    // LeafNode<float,3> offsets: x * 64 + y * 8 + z
                    const double tx = idx[0] - fx, ty = idx[1] - fy, tz = idx[2] - fz;
                    const double c000 = v[o], c001 = v[o + 1], c010 = v[o + 8], c011 = v[o + 9];
                    const double c100 = v[o + 64], c101 = v[o + 65], c110 = v[o + 72],
                                 c111 = v[o + 73];
                    const double c00 = c000 + (c001 - c000) * tz, c01 = c010 + (c011 - c010) * tz;
                    const double c10 = c100 + (c101 - c100) * tz, c11 = c110 + (c111 - c110) * tz;
                    const double c0 = c00 + (c01 - c00) * ty, c1 = c10 + (c11 - c10) * ty;
                    return c0 + (c1 - c0) * tx;
                }
            }
        }
    }
    return double(openvdb::tools::BoxSampler::sample(acc, idx));
}

} // namespace

extern "C" double vpv_levelset_sample(const vpv_levelset *ls, const double p[3])
{
    if (!ls || !ls->grid) return HUGE_VAL;
    return ls->scale * sample_grid(ls, p);
}

extern "C" void vpv_levelset_gradient(const vpv_levelset *ls, const double p[3], double g[3])
{
    g[0] = g[1] = g[2] = 0.0;
    if (!ls || !ls->grid) return;
    const double h = 0.5 * ls->voxel;
    double d[3];
    for (int a = 0; a < 3; ++a) {
        double q[3] = {p[0], p[1], p[2]};
        q[a] = p[a] + h;
        double fp = vpv_levelset_sample(ls, q);
        q[a] = p[a] - h;
        double fm = vpv_levelset_sample(ls, q);
        d[a] = (fp - fm) / (2.0 * h);
    }
    double n = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    if (!(n > 1e-300) || !std::isfinite(n)) return;
    for (int a = 0; a < 3; ++a) g[a] = d[a] / n;
}

extern "C" int vpv_levelset_write(const vpv_levelset *ls, const char *path, const vp_meta *meta,
                                  size_t meta_count, char *err, size_t errlen)
{
    clear(err, errlen);
    if (!ls || !ls->grid)
        return fail(err, errlen, VP_ERR_INVALID_ARGUMENT, "vpv_levelset_write: no level set");
    vpv_init();
    return guard(path, Op::Write, err, errlen, [&]() -> int {
        int rc = check_writable(path, err, errlen);
        if (rc != VP_OK) return rc;
        openvdb::FloatGrid::ConstPtr grid = ls->grid;
        if (ls->scale != 1.0) {
            // a scaled grid (vpv_levelset::scale) goes out in world units,
            // where OpenVDB's transforms allow it
            if (!(ls->voxel >= VP_POINTS_MIN_VOXEL))
                return fail(err, errlen, VP_ERR_INVALID_ARGUMENT,
                            "the level set's voxel size %g is below the smallest OpenVDB's "
                            "transforms accept (%g): a .vdb cannot hold it; scale the "
                            "container up",
                            ls->voxel, VP_POINTS_MIN_VOXEL);
            openvdb::FloatGrid::Ptr w = ls->grid->deepCopy();
            const float s = float(ls->scale); // a power of two: exact
            for (auto it = w->tree().beginValueAll(); it; ++it) it.setValue(*it * s);
            w->tree().root().setBackground(ls->grid->background() * s, false);
            const openvdb::Vec3d t =
                ls->grid->transform().baseMap()->getAffineMap()->getMat4().getTranslation() *
                ls->scale;
            w->setTransform(openvdb::math::Transform::Ptr(
                new openvdb::math::Transform(openvdb::math::MapBase::Ptr(
                    new openvdb::math::UniformScaleTranslateMap(ls->voxel, t)))));
            grid = w;
        }
        openvdb::MetaMap fm;
        fill_meta(fm, meta, meta_count, false);
        openvdb::GridCPtrVec grids;
        grids.push_back(grid);
        return write_vdb_checked(path, grids, fm, err, errlen);
    });
}

extern "C" void vpv_levelset_destroy(vpv_levelset *ls)
{
    try {
        delete ls;
    } catch (...) {
    }
}
