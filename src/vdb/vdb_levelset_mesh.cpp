// SPDX-License-Identifier: Apache-2.0
// Level sets from closed triangle meshes (openvdb::tools::meshToVolume).
#include "vdb/vdb_internal.hpp"

#include <atomic>
#include <mutex>
#include <openvdb/util/NullInterrupter.h>

#include <openvdb/tools/MeshToVolume.h>

#include <cmath>
#include <limits>
#include <memory>

using namespace vpv;

namespace {

// Mesh adapter handing meshToVolume index-space points computed in double
// precision relative to the mesh centre (no copy of the mesh).
struct CentredMesh {
    const double *v;
    size_t nv;
    const uint32_t *t;
    size_t nt;
    double c[3];
    double inv_voxel;

    size_t polygonCount() const { return nt; }
    size_t pointCount() const { return nv; }
    size_t vertexCount(size_t) const { return 3; }
    void getIndexSpacePoint(size_t n, size_t k, openvdb::Vec3d &pos) const
    {
        const double *p = v + 3 * size_t(t[3 * n + k]);
        pos = openvdb::Vec3d((p[0] - c[0]) * inv_voxel, (p[1] - c[1]) * inv_voxel,
                             (p[2] - c[2]) * inv_voxel);
    }
};

// The scale a mesh is voxelized at (vpv_levelset::scale): 1 for voxels in
// [2^-10, 2^10], else the power of two that brings the voxel into [1, 2),
// so that OpenVDB's transform accepts it (a cube 1e-4 across has voxels of
// 4e-7: "Non-zero scale values required"). Index-space points, and so the
// voxels' values in voxel units, do not change.
double grid_scale(double voxel)
{
    if (voxel >= 0x1p-10 && voxel <= 0x1p10) return 1.0;
    return std::ldexp(1.0, std::ilogb(voxel));
}

} // namespace

namespace {
// OpenVDB interrupter around the library's progress callback: polled from
// TBB worker threads, so calls are serialized and a refusal is latched.
struct CallbackInterrupter : openvdb::util::NullInterrupter {
    int (*keep_going)(void *) = nullptr;
    void *user = nullptr;
    std::atomic<bool> stop{false};
    std::mutex mutex;
    bool wasInterrupted(int = -1) override
    {
        if (stop.load(std::memory_order_relaxed)) return true;
        if (!keep_going) return false;
        std::lock_guard<std::mutex> lock(mutex);
        if (!stop.load() && !keep_going(user)) stop.store(true);
        return stop.load();
    }
};
} // namespace

extern "C" int vpv_levelset_from_mesh(const double *verts, size_t nverts, const uint32_t *tris,
                                      size_t ntris, double voxel, double ex_band, double in_band,
                                      int renormalize, int (*keep_going)(void *user), void *user,
                                      vpv_levelset **out, char *err, size_t errlen)
{
    clear(err, errlen);
    if (!out) return fail(err, errlen, VP_ERR_INVALID_ARGUMENT, "vpv_levelset_from_mesh: out is NULL");
    *out = nullptr;
    if (!(voxel > 0.0) || !std::isfinite(voxel))
        return fail(err, errlen, VP_ERR_INVALID_ARGUMENT, "voxel size %g is not a positive number", voxel);
    if (!(ex_band >= 1.0) || !(in_band >= 1.0) || std::isnan(ex_band) || std::isnan(in_band))
        return fail(err, errlen, VP_ERR_INVALID_ARGUMENT,
                    "band widths must be at least 1 voxel (exterior %g, interior %g)", ex_band, in_band);
    if (!verts || !tris || nverts == 0 || ntris == 0)
        return fail(err, errlen, VP_ERR_INVALID_ARGUMENT, "the mesh is empty (%zu vertices, %zu triangles)",
                    nverts, ntris);
    double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
    for (size_t i = 0; i < nverts; ++i) {
        for (int a = 0; a < 3; ++a) {
            const double x = verts[3 * i + a];
            if (!std::isfinite(x))
                return fail(err, errlen, VP_ERR_INVALID_ARGUMENT, "vertex %zu has a non-finite coordinate", i);
            if (x < lo[a]) lo[a] = x;
            if (x > hi[a]) hi[a] = x;
        }
    }
    for (size_t i = 0; i < 3 * ntris; ++i)
        if (tris[i] >= nverts)
            return fail(err, errlen, VP_ERR_INVALID_ARGUMENT,
                        "triangle %zu refers to vertex %u but the mesh has %zu vertices", i / 3,
                        (unsigned)tris[i], nverts);
    static const char axes[] = "xyz";
    for (int a = 0; a < 3; ++a) {
        const double dim = (hi[a] - lo[a]) / voxel;
        if (dim > 100000.0)
            return fail(err, errlen, VP_ERR_OUT_OF_MEMORY,
                        "the mesh is %.0f voxels along %c at voxel size %g (limit 100000): use a larger voxel",
                        dim, axes[a], voxel);
    }
    const float exf = float(std::min(ex_band, 1e6));
    const float inf = in_band >= double(std::numeric_limits<float>::max())
                          ? std::numeric_limits<float>::max()
                          : float(in_band);
    vpv_init();
    return guard(nullptr, Op::Compute, err, errlen, [&]() -> int {
        CentredMesh mesh{verts, nverts, tris, ntris,
                         {0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), 0.5 * (lo[2] + hi[2])},
                         1.0 / voxel};
        // Built directly (not createLinearTransform + postTranslate) so the
        // scale stays exactly `voxel` with a large translation; in the
        // grid's units (grid_scale)
        const double s = grid_scale(voxel);
        openvdb::math::Transform::Ptr xf(new openvdb::math::Transform(
            openvdb::math::MapBase::Ptr(new openvdb::math::UniformScaleTranslateMap(
                voxel / s, openvdb::Vec3d(mesh.c[0] / s, mesh.c[1] / s, mesh.c[2] / s)))));
        CallbackInterrupter interrupter;
        interrupter.keep_going = keep_going;
        interrupter.user = user;
        openvdb::FloatGrid::Ptr g = openvdb::tools::meshToVolume<openvdb::FloatGrid>(
            interrupter, mesh, *xf, exf, inf,
            renormalize ? 0 : openvdb::tools::DISABLE_RENORMALIZATION);
        if (interrupter.stop.load()) return fail(err, errlen, VP_ERR_CANCELLED, "cancelled");
        if (!g) return fail(err, errlen, VP_ERR_INTERNAL, "meshToVolume returned no grid");
        g->setGridClass(openvdb::GRID_LEVEL_SET);
        g->setName("container");
        std::unique_ptr<vpv_levelset> ls(new vpv_levelset);
        ls->grid = g;
        ls->scale = s;
        refresh_levelset(*ls);
        *out = ls.release();
        return VP_OK;
    });
}
