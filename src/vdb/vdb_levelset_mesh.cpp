// SPDX-License-Identifier: Apache-2.0
// Level sets from triangle meshes (openvdb::tools::meshToVolume): closed
// meshes with OpenVDB's own sign, any mesh with the sign of a callback
// (the winding number, src/mesh/mesh_inside.c and src/core/winding.c).
#include "vdb/vdb_internal.hpp"

#include <atomic>
#include <utility>
#include <mutex>
#include <openvdb/util/NullInterrupter.h>

#include <openvdb/tools/MeshToVolume.h>
#include <openvdb/tools/FastSweeping.h>
#include <openvdb/tools/SignedFloodFill.h>
#include <openvdb/tree/LeafManager.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <vector>

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

namespace {

// The checks and the transform both voxelizations share: VP_OK and the
// mesh's bounds, or a failure. The transform is centred on the mesh.
int check_mesh(const double *verts, size_t nverts, const uint32_t *tris, size_t ntris, double voxel,
               double ex_band, double in_band, double lo[3], double hi[3], char *err, size_t errlen)
{
    if (!(voxel > 0.0) || !std::isfinite(voxel))
        return fail(err, errlen, VP_ERR_INVALID_ARGUMENT, "voxel size %g is not a positive number",
                    voxel);
    if (!(ex_band >= 1.0) || !(in_band >= 1.0) || std::isnan(ex_band) || std::isnan(in_band))
        return fail(err, errlen, VP_ERR_INVALID_ARGUMENT,
                    "band widths must be at least 1 voxel (exterior %g, interior %g)", ex_band,
                    in_band);
    if (!verts || !tris || nverts == 0 || ntris == 0)
        return fail(err, errlen, VP_ERR_INVALID_ARGUMENT,
                    "the mesh is empty (%zu vertices, %zu triangles)", nverts, ntris);
    for (int a = 0; a < 3; ++a) {
        lo[a] = HUGE_VAL;
        hi[a] = -HUGE_VAL;
    }
    for (size_t i = 0; i < nverts; ++i) {
        for (int a = 0; a < 3; ++a) {
            const double x = verts[3 * i + a];
            if (!std::isfinite(x))
                return fail(err, errlen, VP_ERR_INVALID_ARGUMENT,
                            "vertex %zu has a non-finite coordinate", i);
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
                        "the mesh is %.0f voxels along %c at voxel size %g (limit 100000): use a "
                        "larger voxel",
                        dim, axes[a], voxel);
    }
    return VP_OK;
}

// Built directly (not createLinearTransform + postTranslate) so the scale
// stays exactly `voxel` with a large translation.
openvdb::math::Transform::Ptr centred_transform(double voxel, const double c[3])
{
    return openvdb::math::Transform::Ptr(new openvdb::math::Transform(openvdb::math::MapBase::Ptr(
        new openvdb::math::UniformScaleTranslateMap(voxel, openvdb::Vec3d(c[0], c[1], c[2])))));
}

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

// The winding callback seen from a grid in scaled units: its points are
// multiplied back to world units first.
struct ScaledWinding {
    const vpv_winding_ops *ops;
    double s;
    static void points(void *self, const double *pts, size_t n, double *w)
    {
        const ScaledWinding &a = *static_cast<const ScaledWinding *>(self);
        thread_local std::vector<double> world;
        world.assign(pts, pts + 3 * n);
        for (double &x : world) x *= a.s;
        a.ops->points(a.ops->user, world.data(), n, w);
    }
    static void block(void *self, const double lo[3], double h, double *w)
    {
        const ScaledWinding &a = *static_cast<const ScaledWinding *>(self);
        const double wlo[3] = {lo[0] * a.s, lo[1] * a.s, lo[2] * a.s};
        a.ops->block(a.ops->user, wlo, h * a.s, w);
    }
};

float band_float(double band)
{
    return band >= double(std::numeric_limits<float>::max()) ? std::numeric_limits<float>::max()
                                                             : float(band);
}

std::unique_ptr<vpv_levelset> wrap(openvdb::FloatGrid::Ptr g, double scale)
{
    g->setGridClass(openvdb::GRID_LEVEL_SET);
    g->setName("container");
    std::unique_ptr<vpv_levelset> ls(new vpv_levelset);
    ls->grid = g;
    ls->scale = scale;
    refresh_levelset(*ls);
    return ls;
}

} // namespace

extern "C" int vpv_levelset_from_mesh(const double *verts, size_t nverts, const uint32_t *tris,
                                      size_t ntris, double voxel, double ex_band, double in_band,
                                      int renormalize, int (*keep_going)(void *user), void *user,
                                      vpv_levelset **out, char *err, size_t errlen)
{
    clear(err, errlen);
    if (!out)
        return fail(err, errlen, VP_ERR_INVALID_ARGUMENT, "vpv_levelset_from_mesh: out is NULL");
    *out = nullptr;
    double lo[3], hi[3];
    int rc = check_mesh(verts, nverts, tris, ntris, voxel, ex_band, in_band, lo, hi, err, errlen);
    if (rc != VP_OK) return rc;
    vpv_init();
    return guard(nullptr, Op::Compute, err, errlen, [&]() -> int {
        CentredMesh mesh{verts,
                         nverts,
                         tris,
                         ntris,
                         {0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), 0.5 * (lo[2] + hi[2])},
                         1.0 / voxel};
        const double s = grid_scale(voxel), cs[3] = {mesh.c[0] / s, mesh.c[1] / s, mesh.c[2] / s};
        openvdb::math::Transform::Ptr xf = centred_transform(voxel / s, cs);
        CallbackInterrupter interrupter;
        interrupter.keep_going = keep_going;
        interrupter.user = user;
        openvdb::FloatGrid::Ptr g = openvdb::tools::meshToVolume<openvdb::FloatGrid>(
            interrupter, mesh, *xf, float(std::min(ex_band, 1e6)), band_float(in_band),
            renormalize ? 0 : openvdb::tools::DISABLE_RENORMALIZATION);
        if (interrupter.stop.load()) return fail(err, errlen, VP_ERR_CANCELLED, "cancelled");
        if (!g) return fail(err, errlen, VP_ERR_INTERNAL, "meshToVolume returned no grid");
        *out = wrap(g, s).release();
        return VP_OK;
    });
}

namespace {

using Leaf = openvdb::FloatTree::LeafNodeType;
constexpr int LEAF_DIM = int(Leaf::DIM); // 8

bool coord_less(const openvdb::Coord &a, const openvdb::Coord &b)
{
    return a.x() != b.x() ? a.x() < b.x() : a.y() != b.y() ? a.y() < b.y() : a.z() < b.z();
}

// The winding numbers of a leaf's voxels into w (Leaf::SIZE, in the
// leaf's order).
void leaf_winding(const Leaf &leaf, const openvdb::math::Transform &xf,
                  const vpv_winding_ops &winding, double *w)
{
    const openvdb::Vec3d lo = xf.indexToWorld(leaf.origin());
    const double p[3] = {lo[0], lo[1], lo[2]};
    winding.block(winding.user, p, xf.voxelSize()[0], w);
}

// Step 2: every voxel of every leaf of the unsigned distance (tree) takes
// the sign of its winding number (negative where w >= 0.5); the winding
// numbers go to wtree, a copy of tree's topology.
void sign_leaves(openvdb::FloatTree &tree, openvdb::FloatTree &wtree,
                 const openvdb::math::Transform &xf, const vpv_winding_ops &winding,
                 CallbackInterrupter &interrupter)
{
    openvdb::tree::LeafManager<openvdb::FloatTree> leaves(tree);
    tbb::parallel_for(leaves.leafRange(),
                      [&](openvdb::tree::LeafManager<openvdb::FloatTree>::LeafRange &r) {
                          std::vector<double> w(Leaf::SIZE);
                          for (auto leaf = r.begin(); leaf; ++leaf) {
                              if (interrupter.wasInterrupted()) return;
                              leaf_winding(*leaf, xf, winding, w.data());
                              Leaf *wl = wtree.probeLeaf(leaf->origin());
                              for (openvdb::Index i = 0; i < Leaf::SIZE; ++i) {
                                  const float v = std::fabs(leaf->getValue(i));
                                  leaf->setValueOnly(i, w[i] >= 0.5 ? -v : v);
                                  if (wl) wl->setValueOnly(i, float(w[i]));
                              }
                          }
                      });
}

// Step 3: the film across the holes, the surface where the winding number
// crosses 0.5 away from the triangles, which no leaf of the unsigned
// distance holds. In each hole's box (6 doubles: min, max, world) the
// winding number is evaluated at the corners of 8-voxel blocks; a block
// whose corners disagree, and the blocks within the band's width (band
// voxels) of it, become active leaves (as a narrow band's leaves reach
// its width: beyond them, tiles claim the whole band's depth), signed by
// their winding numbers, at the band's depth until the next step. Returns
// the origins of the leaves added.
std::vector<openvdb::Coord> add_film(openvdb::FloatTree &tree, openvdb::FloatTree &wtree,
                                     const openvdb::math::Transform &xf, double band,
                                     const double *boxes, size_t nboxes,
                                     const vpv_winding_ops &winding,
                                     CallbackInterrupter &interrupter)
{
    using openvdb::Coord;
    const int B = LEAF_DIM, reach = int(std::ceil(band / B)) + 1;
    std::vector<Coord> marked;
    for (size_t h = 0; h < nboxes; ++h) {
        if (interrupter.wasInterrupted()) return {};
        const double *b = boxes + 6 * h;
        const Coord lo = xf.worldToIndexCellCentered(openvdb::Vec3d(b[0], b[1], b[2]));
        const Coord hi = xf.worldToIndexCellCentered(openvdb::Vec3d(b[3], b[4], b[5]));
        Coord c0, c1; // block-aligned corners covering the box
        for (int a = 0; a < 3; ++a) {
            c0[a] = (lo[a] >= 0 ? lo[a] / B : -((-lo[a] + B - 1) / B)) * B;
            c1[a] = (hi[a] >= 0 ? (hi[a] + B - 1) / B : -((-hi[a]) / B)) * B;
        }
        const int nx = (c1.x() - c0.x()) / B + 1, ny = (c1.y() - c0.y()) / B + 1,
                  nz = (c1.z() - c0.z()) / B + 1;
        if (nx < 2 || ny < 2 || nz < 2 || double(nx) * ny * nz > 64e6) continue;
        const size_t n = size_t(nx) * size_t(ny) * size_t(nz);
        std::vector<double> w(n);
        // the corners lie far apart: one at a time (a batch would find
        // nothing far from all of them)
        tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 256),
                          [&](const tbb::blocked_range<size_t> &r) {
                              for (size_t i = r.begin(); i < r.end(); ++i) {
                                  const Coord ijk(c0.x() + B * int(i % size_t(nx)),
                                                  c0.y() + B * int((i / size_t(nx)) % size_t(ny)),
                                                  c0.z() + B * int(i / (size_t(nx) * size_t(ny))));
                                  const openvdb::Vec3d p = xf.indexToWorld(ijk);
                                  const double q[3] = {p[0], p[1], p[2]};
                                  winding.points(winding.user, q, 1, &w[i]);
                              }
                          });
        auto in = [&](int x, int y, int z) {
            return w[size_t(x) + size_t(nx) * (size_t(y) + size_t(ny) * size_t(z))] >= 0.5;
        };
        for (int z = 0; z + 1 < nz; ++z)
            for (int y = 0; y + 1 < ny; ++y)
                for (int x = 0; x + 1 < nx; ++x) {
                    const bool in0 = in(x, y, z);
                    bool differ = false;
                    for (int k = 1; k < 8 && !differ; ++k)
                        differ = in(x + (k & 1), y + ((k >> 1) & 1), z + ((k >> 2) & 1)) != in0;
                    if (!differ) continue;
                    for (int dz = -reach; dz <= reach; ++dz)
                        for (int dy = -reach; dy <= reach; ++dy)
                            for (int dx = -reach; dx <= reach; ++dx)
                                marked.push_back(Coord(c0.x() + B * (x + dx), c0.y() + B * (y + dy),
                                                       c0.z() + B * (z + dz)));
                }
    }
    std::sort(marked.begin(), marked.end(), coord_less);
    marked.erase(std::unique(marked.begin(), marked.end()), marked.end());
    std::vector<std::pair<Leaf *, Leaf *>> fresh;
    std::vector<Coord> origins;
    for (const Coord &c : marked) {
        if (tree.probeConstLeaf(c)) continue; // the band's: signed already
        fresh.emplace_back(tree.touchLeaf(c), wtree.touchLeaf(c));
        origins.push_back(fresh.back().first->origin());
    }
    const float bg = std::fabs(tree.background());
    tbb::parallel_for(tbb::blocked_range<size_t>(0, fresh.size(), 1),
                      [&](const tbb::blocked_range<size_t> &r) {
                          std::vector<double> w(Leaf::SIZE);
                          for (size_t k = r.begin(); k < r.end(); ++k) {
                              Leaf &leaf = *fresh[k].first, &wl = *fresh[k].second;
                              leaf_winding(leaf, xf, winding, w.data());
                              for (openvdb::Index i = 0; i < Leaf::SIZE; ++i) {
                                  leaf.setValueOn(i, w[i] >= 0.5 ? -bg : bg);
                                  wl.setValueOn(i, float(w[i]));
                              }
                          }
                      });
    return origins;
}

// Step 5: the voxels beside the film. Two neighbours of opposite sign with
// no triangle between them (their distances to the triangles add up to
// more than a voxel: a triangle crossing the segment between them would be
// nearer) lie across the film; each takes its distance to where the
// winding number, linear along the segment, crosses 0.5, if that is
// nearer than what it holds. Returns the origins of the leaves that changed.
std::vector<openvdb::Coord> film_crossings(openvdb::FloatTree &tree,
                                           const openvdb::FloatTree &wtree, double voxel)
{
    using openvdb::Coord;
    openvdb::tree::LeafManager<openvdb::FloatTree> leaves(tree, /*auxBuffersPerLeaf=*/1);
    leaves.syncAllBuffers(); // buffer 1: the values before this step
    std::vector<char> changed(leaves.leafCount(), 0);
    const float h = float(voxel);
    leaves.foreach ([&](Leaf &leaf, size_t idx) {
        openvdb::tree::ValueAccessor<const openvdb::FloatTree> acc(tree), wacc(wtree);
        const auto &before = leaves.getBuffer(idx, 1);
        size_t n = 0;
        for (openvdb::Index i = 0; i < Leaf::SIZE; ++i) {
            const Coord c = leaf.offsetToGlobalCoord(i);
            const float d = before.getValue(i), w = wacc.getValue(c);
            float best = std::fabs(d);
            for (int a = 0; a < 3; ++a)
                for (int s = -1; s <= 1; s += 2) {
                    Coord u = c;
                    u[a] += s;
                    if (!acc.isVoxel(u)) continue; /* a tile: a band's depth away */
                    const float du = acc.getValue(u);
                    if ((du < 0) == (d < 0) || std::fabs(du) + std::fabs(d) <= h) continue;
                    const float wu = wacc.getValue(u);
                    if (!(std::fabs(w - wu) > 0)) continue;
                    const float t = std::min(1.0f, std::max(0.0f, (w - 0.5f) / (w - wu)));
                    best = std::min(best, t * h);
                }
            if (best < std::fabs(d)) {
                leaf.setValueOnly(i, d < 0 ? -best : best);
                ++n;
            }
        }
        changed[idx] = n > 0;
    });
    std::vector<openvdb::Coord> origins;
    for (size_t i = 0; i < changed.size(); ++i)
        if (changed[i]) origins.push_back(leaves.leaf(i).origin());
    return origins;
}

// Step 6: the distances about the film, once every voxel and tile has its
// sign: OpenVDB's fast sweeping solves the distance to every zero crossing
// (the film's, from the voxels beside it, and the triangles') over the
// leaves within the band's reach of the film (seeds: the film's leaves and
// those beside it); each voxel more than a voxel from a crossing keeps the nearer of
// that and its own value (the exact distance to the triangles), the others
// their own (exact, or the film's from step 4), and no value goes past
// the band.
void sweep_film(openvdb::FloatGrid &g, double voxel, std::vector<openvdb::Coord> seeds, int reach)
{
    using openvdb::Coord;
    const float h = float(voxel);
    openvdb::FloatTree &tree = g.tree();
    const float bg = std::fabs(tree.background());
    // the leaves within reach (in leaves) of the film's take part, every
    // voxel of them (the sweep updates active voxels only, and the band's
    // leaves leave those past the band from the triangles inactive,
    // however near the film); the others are kept out, inactive: their
    // values, exact distances to the triangles, bound the sweep's region
    std::vector<Coord> near;
    for (const Coord &o : seeds)
        for (int dz = -reach; dz <= reach; ++dz)
            for (int dy = -reach; dy <= reach; ++dy)
                for (int dx = -reach; dx <= reach; ++dx)
                    near.push_back(o.offsetBy(LEAF_DIM * dx, LEAF_DIM * dy, LEAF_DIM * dz));
    std::sort(near.begin(), near.end(), coord_less);
    near.erase(std::unique(near.begin(), near.end()), near.end());
    openvdb::tree::LeafManager<openvdb::FloatTree> all(tree);
    all.foreach ([&](Leaf &leaf, size_t) {
        if (std::binary_search(near.begin(), near.end(), leaf.origin(), coord_less))
            leaf.setValuesOn();
        else leaf.setValuesOff();
    });
    // (in voxel units: see in_voxel_units)
    openvdb::FloatGrid::Ptr swept = openvdb::tools::sdfToSdf(*in_voxel_units(g, true), 0.0f, 1);
    if (!swept) return;
    to_world_units(*swept, g.voxelSize()[0], g.transform());
    const openvdb::FloatTree &st = swept->tree();
    openvdb::tree::LeafManager<openvdb::FloatTree> leaves(tree);
    leaves.foreach ([&](Leaf &dst, size_t) {
        const Leaf *src = st.probeConstLeaf(dst.origin());
        if (!src) return;
        for (openvdb::Index i = 0; i < Leaf::SIZE; ++i) {
            const float o = dst.getValue(i), n = src->getValue(i);
            float m = std::min(std::fabs(o), bg);
            // within a voxel of a crossing the value is exact already (the
            // sweep's own start there would move the surface)
            if (std::isfinite(n) && m > h) m = std::min(m, std::max(std::fabs(n), h));
            dst.setValueOnly(i, o < 0 ? -m : m);
        }
    });
    // active again as a narrow band's voxels are: within the band
    all.foreach ([bg](Leaf &leaf, size_t) {
        for (openvdb::Index i = 0; i < Leaf::SIZE; ++i)
            leaf.setActiveState(i, std::fabs(leaf.getValue(i)) < bg);
    });
}

// Step 4: the tiles beyond the leaves: first as the leaves around them say
// (signedFloodFill, which also fills the root's gaps between nodes), then
// each as the winding number at its centre says.
void sign_tiles(openvdb::FloatTree &tree, const openvdb::math::Transform &xf,
                const vpv_winding_ops &winding)
{
    // (from the internal nodes up: the leaves' inactive voxels hold their
    // winding sign and, beside the film, its distance already)
    openvdb::tools::signedFloodFill(tree, /*threaded=*/true, /*grainSize=*/1, /*minLevel=*/1);
    std::vector<openvdb::Vec3d> centres;
    {
        auto tile = tree.cbeginValueAll();
        tile.setMaxDepth(openvdb::FloatTree::ValueAllCIter::LEAF_DEPTH - 1);
        for (; tile; ++tile) {
            openvdb::CoordBBox b;
            tile.getBoundingBox(b);
            centres.push_back(xf.indexToWorld((b.min().asVec3d() + b.max().asVec3d()) * 0.5));
        }
    }
    std::vector<double> w(centres.size());
    tbb::parallel_for(tbb::blocked_range<size_t>(0, centres.size(), 64),
                      [&](const tbb::blocked_range<size_t> &r) {
                          for (size_t i = r.begin(); i < r.end(); ++i) {
                              const double p[3] = {centres[i][0], centres[i][1], centres[i][2]};
                              winding.points(winding.user, p, 1, &w[i]);
                          }
                      });
    const float bg = std::fabs(tree.background());
    size_t i = 0;
    auto tile = tree.beginValueAll();
    tile.setMaxDepth(openvdb::FloatTree::ValueAllIter::LEAF_DEPTH - 1);
    for (; tile; ++tile, ++i) tile.setValue(w[i] >= 0.5 ? -bg : bg);
}

} // namespace

extern "C" int vpv_levelset_from_mesh_winding(const double *verts, size_t nverts,
                                              const uint32_t *tris, size_t ntris, double voxel,
                                              double ex_band, double in_band,
                                              const vpv_winding_ops *winding, const double *holes,
                                              size_t nholes, int (*keep_going)(void *user),
                                              void *user, vpv_levelset **out, char *err,
                                              size_t errlen)
{
    clear(err, errlen);
    if (!out || !winding || !winding->points || !winding->block)
        return fail(err, errlen, VP_ERR_INVALID_ARGUMENT,
                    "vpv_levelset_from_mesh_winding: NULL argument");
    *out = nullptr;
    double lo[3], hi[3];
    int rc = check_mesh(verts, nverts, tris, ntris, voxel, ex_band, in_band, lo, hi, err, errlen);
    if (rc != VP_OK) return rc;
    vpv_init();
    return guard(nullptr, Op::Compute, err, errlen, [&]() -> int {
        CentredMesh mesh{verts,
                         nverts,
                         tris,
                         ntris,
                         {0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), 0.5 * (lo[2] + hi[2])},
                         1.0 / voxel};
        // in the grid's units (grid_scale): the transform, the voxel, the
        // holes' boxes; the winding number is asked in world units
        const double s = grid_scale(voxel), cs[3] = {mesh.c[0] / s, mesh.c[1] / s, mesh.c[2] / s};
        openvdb::math::Transform::Ptr xf = centred_transform(voxel / s, cs);
        ScaledWinding scaled{winding, s};
        const vpv_winding_ops scaled_ops{&scaled, ScaledWinding::points, ScaledWinding::block};
        std::vector<double> sholes;
        if (s != 1.0) {
            winding = &scaled_ops;
            sholes.assign(holes, holes + 6 * nholes);
            for (double &x : sholes) x /= s;
            holes = sholes.data();
            voxel /= s;
        }
        CallbackInterrupter interrupter;
        interrupter.keep_going = keep_going;
        interrupter.user = user;
        auto cancelled = [&]() { return fail(err, errlen, VP_ERR_CANCELLED, "cancelled"); };
        // 1. the distance to the triangles, the same band on both sides
        const float band = band_float(std::max(std::min(ex_band, 1e6), in_band));
        openvdb::FloatGrid::Ptr g = openvdb::tools::meshToVolume<openvdb::FloatGrid>(
            interrupter, mesh, *xf, band, band, openvdb::tools::UNSIGNED_DISTANCE_FIELD);
        if (interrupter.stop.load()) return cancelled();
        if (!g) return fail(err, errlen, VP_ERR_INTERNAL, "meshToVolume returned no grid");
        const openvdb::math::Transform &gx = g->transform();
        openvdb::FloatTree &tree = g->tree();
        openvdb::FloatTree wtree(tree, 0.0f, openvdb::TopologyCopy());
        // 2. its sign from the winding number, voxel by voxel
        sign_leaves(tree, wtree, gx, *winding, interrupter);
        if (interrupter.stop.load()) return cancelled();
        // 3. the film across the holes
        const std::vector<openvdb::Coord> film =
            add_film(tree, wtree, gx, double(band), holes, nholes, *winding, interrupter);
        if (interrupter.stop.load()) return cancelled();
        // 4. the tiles, 5. the voxels beside the film, 6. the distances to it
        sign_tiles(tree, gx, *winding);
        if (interrupter.stop.load()) return cancelled();
        std::vector<openvdb::Coord> seeds = film_crossings(tree, wtree, voxel);
        seeds.insert(seeds.end(), film.begin(), film.end());
        if (!seeds.empty())
            sweep_film(*g, voxel, std::move(seeds), int(std::ceil(double(band) / LEAF_DIM)) + 1);
        if (interrupter.stop.load()) return cancelled();
        std::unique_ptr<vpv_levelset> ls = wrap(g, s);
        ls->heaviside_volume = true;
        *out = ls.release();
        return VP_OK;
    });
}
