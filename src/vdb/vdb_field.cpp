// SPDX-License-Identifier: Apache-2.0
// Fields (src/vdb/vdb_field.h): a float grid read from a .vdb and sampled
// trilinearly with OpenVDB's BoxSampler, for radius, density and other
// per-point values; and the inside box of a level set, which a field must
// cover. Its own file: every file that includes OpenVDB takes about a
// minute and 1.5 GB to compile.
#include "vdb/vdb_field.h"
#include "vdb/vdb_internal.hpp"

#include <openvdb/tools/Interpolation.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

using namespace vpv;

struct vpv_field {
    openvdb::FloatGrid::Ptr grid;
    openvdb::Vec3d clo, chi; // index box of the active voxels' centres
    vpv_field_info info;
};

namespace {

// The world box of index box [lo, hi] (continuous index coordinates).
void world_box(const openvdb::math::Transform &xf, const openvdb::Vec3d &lo,
               const openvdb::Vec3d &hi, double scale, double wlo[3], double whi[3])
{
    for (int a = 0; a < 3; ++a) {
        wlo[a] = HUGE_VAL;
        whi[a] = -HUGE_VAL;
    }
    for (int c = 0; c < 8; ++c) {
        openvdb::Vec3d ip((c & 1) ? hi.x() : lo.x(), (c & 2) ? hi.y() : lo.y(),
                          (c & 4) ? hi.z() : lo.z());
        openvdb::Vec3d w = xf.indexToWorld(ip) * scale;
        for (int a = 0; a < 3; ++a) {
            wlo[a] = std::min(wlo[a], w[a]);
            whi[a] = std::max(whi[a], w[a]);
        }
    }
}

// The first value that is not finite (voxels and tiles, active or not, and
// the background), or none.
bool first_bad_value(const openvdb::FloatGrid &g, openvdb::Coord &at, float &v)
{
    if (!std::isfinite(g.background())) {
        at = openvdb::Coord::max();
        v = g.background();
        return true;
    }
    for (auto it = g.tree().cbeginValueAll(); it; ++it)
        if (!std::isfinite(*it)) {
            at = it.getCoord();
            v = *it;
            return true;
        }
    return false;
}

} // namespace

extern "C" int vpv_field_read(const char *path, const char *grid_name, vpv_field **out, char *err,
                              size_t errlen)
{
    clear(err, errlen);
    if (!out) return fail(err, errlen, VP_ERR_INVALID_ARGUMENT, "vpv_field_read: out is NULL");
    *out = nullptr;
    vpv_init();
    return guard(path, Op::Read, err, errlen, [&]() -> int {
        openvdb::io::File file(path ? path : "");
        openvdb::GridPtrVecPtr metas;
        int rc = read_grid_metadata(path, file, VP_ERR_INVALID_ARGUMENT, metas, err, errlen);
        if (rc != VP_OK) return rc;
        const openvdb::GridPtrVec &grids = *metas;
        size_t pick = grids.size();
        for (size_t i = 0; i < grids.size() && pick == grids.size(); ++i) {
            if (!grids[i]) continue;
            if (grid_name ? grids[i]->getName() == grid_name
                          : grids[i]->isType<openvdb::FloatGrid>())
                pick = i;
        }
        if (pick == grids.size())
            return fail(err, errlen, VP_ERR_INVALID_ARGUMENT,
                        grid_name ? "%s: no grid named '%s' (grids: %s)"
                                  : "%s: no float grid in the file%s (grids: %s)",
                        path, grid_name ? grid_name : "", list_grids(grids).c_str());
        if (!grids[pick]->isType<openvdb::FloatGrid>())
            return fail(err, errlen, VP_ERR_INVALID_ARGUMENT,
                        "%s: grid '%s' holds %s values, not float: a field is a float grid "
                        "(grids: %s)",
                        path, grids[pick]->getName().c_str(), value_type_name(*grids[pick]).c_str(),
                        list_grids(grids).c_str());
        openvdb::GridBase::Ptr base = file.readGrid(grids[pick]->getName());
        file.close();
        openvdb::FloatGrid::Ptr g = openvdb::gridPtrCast<openvdb::FloatGrid>(base);
        if (!g)
            return fail(err, errlen, VP_ERR_FORMAT, "%s: cannot read grid '%s'", path,
                        grids[pick]->getName().c_str());
        if (!g->transform().isLinear())
            return fail(err, errlen, VP_ERR_INVALID_ARGUMENT,
                        "%s: grid '%s' has a frustum (non-linear) transform; a field needs a "
                        "linear one",
                        path, g->getName().c_str());
        if (g->tree().activeVoxelCount() == 0)
            return fail(err, errlen, VP_ERR_INVALID_ARGUMENT,
                        "%s: grid '%s' has no active voxels: it defines no field", path,
                        g->getName().c_str());
        openvdb::Coord at;
        float bad;
        if (first_bad_value(*g, at, bad)) {
            if (at == openvdb::Coord::max())
                return fail(err, errlen, VP_ERR_INVALID_ARGUMENT,
                            "%s: grid '%s' has a %s background value: a field's values must "
                            "be finite",
                            path, g->getName().c_str(), std::isnan(bad) ? "NaN" : "infinite");
            const openvdb::Vec3d w = g->transform().indexToWorld(at);
            return fail(err, errlen, VP_ERR_INVALID_ARGUMENT,
                        "%s: grid '%s' has a %s value at voxel (%d, %d, %d), world (%g, %g, "
                        "%g): a field's values must be finite",
                        path, g->getName().c_str(), std::isnan(bad) ? "NaN" : "infinite", at.x(),
                        at.y(), at.z(), w.x(), w.y(), w.z());
        }
        auto *f = new (std::nothrow) vpv_field;
        if (!f) return fail(err, errlen, VP_ERR_OUT_OF_MEMORY, "%s: out of memory", path);
        f->grid = g;
        const openvdb::CoordBBox bb = g->evalActiveVoxelBoundingBox();
        f->clo = bb.min().asVec3d();
        f->chi = bb.max().asVec3d();
        std::memset(&f->info, 0, sizeof f->info);
        world_box(g->transform(), f->clo - openvdb::Vec3d(0.5), f->chi + openvdb::Vec3d(0.5), 1.0,
                  f->info.bmin, f->info.bmax);
        const openvdb::Vec3d vs = g->transform().voxelSize();
        f->info.voxel_size = std::min(vs[0], std::min(vs[1], vs[2]));
        float lo = g->background(), hi = g->background();
        for (auto it = g->tree().cbeginValueAll(); it; ++it) {
            lo = std::min(lo, *it);
            hi = std::max(hi, *it);
        }
        f->info.min = lo;
        f->info.max = hi;
        std::snprintf(f->info.name, sizeof f->info.name, "%s", g->getName().c_str());
        *out = f;
        return VP_OK;
    });
}

extern "C" void vpv_field_get_info(const vpv_field *f, vpv_field_info *info)
{
    if (!info) return;
    if (!f) {
        std::memset(info, 0, sizeof *info);
        return;
    }
    *info = f->info;
}

extern "C" double vpv_field_sample(const vpv_field *f, const double p[3])
{
    try {
        openvdb::Vec3d i = f->grid->transform().worldToIndex(openvdb::Vec3d(p[0], p[1], p[2]));
        // (a NaN index would reach Coord::floor's conversion to int)
        if (!std::isfinite(i[0]) || !std::isfinite(i[1]) || !std::isfinite(i[2]))
            return std::nan("");
        for (int a = 0; a < 3; ++a) i[a] = std::min(std::max(i[a], f->clo[a]), f->chi[a]);
        return double(openvdb::tools::BoxSampler::sample(f->grid->tree(), i));
    } catch (...) {
        return std::nan("");
    }
}

extern "C" int vpv_field_range(const vpv_field *f, const double lo[3], const double hi[3],
                               double *vmin, double *vmax, char *err, size_t errlen)
{
    clear(err, errlen);
    return guard(nullptr, Op::Compute, err, errlen, [&]() -> int {
        const openvdb::math::Transform &xf = f->grid->transform();
        openvdb::Vec3d ilo(HUGE_VAL), ihi(-HUGE_VAL);
        for (int c = 0; c < 8; ++c) {
            openvdb::Vec3d w((c & 1) ? hi[0] : lo[0], (c & 2) ? hi[1] : lo[1],
                             (c & 4) ? hi[2] : lo[2]);
            openvdb::Vec3d i = xf.worldToIndex(w);
            for (int a = 0; a < 3; ++a) {
                // samples are clamped to the centres' box
                double v = std::min(std::max(i[a], f->clo[a]), f->chi[a]);
                ilo[a] = std::min(ilo[a], v);
                ihi[a] = std::max(ihi[a], v);
            }
        }
        // the voxels a trilinear sample in [ilo, ihi] reads
        const openvdb::CoordBBox box(openvdb::Coord::floor(ilo),
                                     openvdb::Coord::floor(ihi).offsetBy(1));
        double mn = HUGE_VAL, mx = -HUGE_VAL, covered = 0.0;
        for (auto it = f->grid->tree().cbeginValueAll(); it; ++it) {
            openvdb::CoordBBox b;
            it.getBoundingBox(b);
            if (!b.hasOverlap(box)) continue;
            b.intersect(box);
            covered += double(b.volume());
            mn = std::min(mn, double(*it));
            mx = std::max(mx, double(*it));
        }
        if (covered < double(box.volume())) { // parts with no node: the background
            mn = std::min(mn, double(f->grid->background()));
            mx = std::max(mx, double(f->grid->background()));
        }
        *vmin = mn;
        *vmax = mx;
        return VP_OK;
    });
}

extern "C" void vpv_field_destroy(vpv_field *f) { delete f; }

extern "C" int vpv_levelset_inside_box(const vpv_levelset *ls, double lo[3], double hi[3])
{
    try {
        if (!ls || !ls->grid) return -1;
        const openvdb::FloatGrid &g = *ls->grid;
        openvdb::CoordBBox in; // empty
        for (auto it = g.tree().cbeginValueAll(); it; ++it) {
            if (!(*it < 0.0f)) continue;
            openvdb::CoordBBox b;
            it.getBoundingBox(b);
            in.expand(b);
        }
        if (in.empty()) return -1;
        world_box(g.transform(), in.min().asVec3d() - openvdb::Vec3d(1.0),
                  in.max().asVec3d() + openvdb::Vec3d(1.0), ls->scale, lo, hi);
        return 0;
    } catch (...) {
        return -1;
    }
}
