// SPDX-License-Identifier: Apache-2.0
// Particles -> OpenVDB PointDataGrid "points" (P, pscale, id, orient, groups).
#include "vdb/vdb_internal.hpp"
#include "vdb/vdb_shape_names.hpp"

#include <openvdb/points/PointAttribute.h>
#include <openvdb/points/PointConversion.h>
#include <openvdb/points/PointDataGrid.h>
#include <openvdb/points/PointGroup.h>
#include <openvdb/tools/PointIndexGrid.h>

#include <algorithm>
#include <array>
#include <climits>
#include <vector>
#include <cmath>
#include <cstring>
#include <set>

using namespace vpv;
namespace vp = openvdb::points;

namespace {

// The caller's double positions, without a copy.
struct Positions {
    using PosType = openvdb::Vec3d;
    using value_type = openvdb::Vec3d;
    const double *p;
    size_t n;
    size_t size() const { return n; }
    void getPos(size_t i, openvdb::Vec3d &xyz) const
    {
        xyz = openvdb::Vec3d(p[3 * i], p[3 * i + 1], p[3 * i + 2]);
    }
};

struct Radii {
    using value_type = float;
    const float *r;
    void get(float &v, size_t n) const { v = r[n]; }
    void get(float &v, size_t n, openvdb::Index) const { v = r[n]; }
};

struct ShapeIndex {
    using value_type = int32_t;
    const uint8_t *k;
    void get(int32_t &v, size_t n) const { v = k[n]; }
    void get(int32_t &v, size_t n, openvdb::Index) const { v = k[n]; }
};

template <typename T> struct Ids {
    using value_type = T;
    void get(T &v, size_t n) const { v = T(n); }
    void get(T &v, size_t n, openvdb::Index) const { v = T(n); }
};

struct Orients {
    using value_type = openvdb::math::Quats;
    const float *q;
    void get(openvdb::math::Quats &v, size_t n) const
    {
        const float *x = q + 4 * n;
        v = openvdb::math::Quats(x[0], x[1], x[2], x[3]);
    }
    void get(openvdb::math::Quats &v, size_t n, openvdb::Index) const { get(v, n); }
};

// Memory of a points grid being built (and its point index grid): per
// leaf node, whatever the points in it (voxel offsets, attribute arrays and
// their headers, measured: docs/export.md), and per point.
constexpr double VPV_POINTS_LEAF_BYTES = 6000.0;
constexpr double VPV_POINTS_POINT_BYTES = 64.0;

void format_bytes(double b, char *out, size_t len)
{
    if (b >= 1e9) snprintf(out, len, "%.1f GB", b / 1e9);
    else snprintf(out, len, "%.1f MB", b / 1e6);
}

// The number of leaf nodes (8^3 voxels) the points occupy at this voxel
// size, counted only when the box they lie in could hold more than the
// memory limit's worth (the usual packing is far from it: at least one
// point per leaf by the count, a few per voxel). lo, hi: the points' box.
size_t leaf_count(const Positions &pos, const double lo[3], const double hi[3], double voxel,
                  double max_bytes)
{
    const double side = 8.0 * voxel;
    double box = 1.0;
    for (int k = 0; k < 3; ++k) box *= std::floor((hi[k] - lo[k]) / side) + 2.0;
    const double bound = std::min(double(pos.n), box);
    if (bound * VPV_POINTS_LEAF_BYTES <= max_bytes) return size_t(bound);
    std::vector<std::array<int64_t, 3>> keys(pos.n);
    for (size_t i = 0; i < pos.n; ++i)
        for (int k = 0; k < 3; ++k)
            keys[i][k] = int64_t(std::floor(std::floor(pos.p[3 * i + k] / voxel + 0.5) / 8.0));
    std::sort(keys.begin(), keys.end());
    return size_t(std::unique(keys.begin(), keys.end()) - keys.begin());
}

bool has_key(const vp_meta *meta, size_t n, const char *key)
{
    for (size_t i = 0; meta && i < n; ++i)
        if (meta[i].key && strcmp(meta[i].key, key) == 0) return true;
    return false;
}

} // namespace

extern "C" int vpv_points_write(const char *path, const vp_particles *p,
                                const vp_write_params *params, char *err, size_t errlen)
{
    clear(err, errlen);
    if (!p) return fail(err, errlen, VP_ERR_INVALID_ARGUMENT, "vpv_points_write: no particles");
    const size_t count = p->count;
    if (count > 0 && !p->positions)
        return fail(err, errlen, VP_ERR_INVALID_ARGUMENT, "vpv_points_write: positions are NULL");
    const int full = params ? params->full_precision : 0;
    const int ppv_in = params ? params->points_per_voxel : 0;
    if (ppv_in < 0)
        return fail(err, errlen, VP_ERR_INVALID_ARGUMENT, "points per voxel %d is negative",
                    ppv_in);
    const uint32_t ppv = ppv_in > 0 ? uint32_t(ppv_in) : 8u;
    const vp_meta *meta = params ? params->meta : nullptr;
    const size_t meta_count = params ? params->meta_count : 0;

    // Validate everything before touching OpenVDB.
    const unsigned ngroups = p->group_count;
    if (ngroups > VP_MAX_GROUPS)
        return fail(err, errlen, VP_ERR_INVALID_ARGUMENT, "%u groups (at most %d)", ngroups,
                    VP_MAX_GROUPS);
    std::vector<std::string> gnames;
    {
        std::set<std::string> seen;
        for (unsigned g = 0; g < ngroups; ++g) {
            std::string s(p->group_names[g], strnlen(p->group_names[g], VP_GROUP_NAME_MAX));
            if (s.empty() || !vp::AttributeSet::Descriptor::validName(s))
                return fail(err, errlen, VP_ERR_INVALID_ARGUMENT,
                            "group %u: name '%s' is not valid (letters, digits, _ | : only)", g,
                            s.c_str());
            if (!seen.insert(s).second)
                return fail(err, errlen, VP_ERR_INVALID_ARGUMENT, "group name '%s' is used twice",
                            s.c_str());
            gnames.push_back(s);
        }
    }
    double maxabs = 0.0, rmax = p->radii ? 0.0 : std::fabs(double(p->uniform_radius));
    double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
    for (size_t i = 0; i < 3 * count; ++i) {
        const double x = p->positions[i];
        if (!std::isfinite(x))
            return fail(err, errlen, VP_ERR_INVALID_ARGUMENT,
                        "particle %zu has a non-finite position", i / 3);
        maxabs = std::max(maxabs, std::fabs(x));
        lo[i % 3] = std::min(lo[i % 3], x);
        hi[i % 3] = std::max(hi[i % 3], x);
    }
    if (p->radii)
        for (size_t i = 0; i < count; ++i) rmax = std::max(rmax, std::fabs(double(p->radii[i])));
    // The smallest positive radius bounds the position error allowed
    // (VP_POSITION_ERROR_LIMIT); particles without a radius set none.
    double rmin = HUGE_VAL;
    if (count > 0) {
        if (p->radii) {
            for (size_t i = 0; i < count; ++i)
                if (double(p->radii[i]) > 0.0) rmin = std::min(rmin, double(p->radii[i]));
        } else if (double(p->uniform_radius) > 0.0) {
            rmin = double(p->uniform_radius);
        }
    }
    if (p->groups && ngroups > 0)
        for (size_t i = 0; i < count; ++i)
            if (p->groups[i] >= ngroups)
                return fail(err, errlen, VP_ERR_INVALID_ARGUMENT,
                            "particle %zu is in group %u of %u", i, (unsigned)p->groups[i],
                            ngroups);

    if (p->shape == VP_SHAPE_MIXED) {
        if (!p->shape_index || p->shape_count < 1 || p->shape_count > VP_MAX_SHAPES)
            return fail(err, errlen, VP_ERR_INVALID_ARGUMENT,
                        "a mixed set needs its shape indices and 1..%d shapes", VP_MAX_SHAPES);
        for (size_t i = 0; i < count; ++i)
            if (p->shape_index[i] >= p->shape_count)
                return fail(err, errlen, VP_ERR_INVALID_ARGUMENT, "particle %zu has shape %u of %u",
                            i, unsigned(p->shape_index[i]), p->shape_count);
    }

    vpv_init();
    return guard(path, Op::Write, err, errlen, [&]() -> int {
        const Positions pos{p->positions, count};
        double voxel;
        if (count == 0) {
            voxel = 1.0;
        } else if (count == 1) {
            voxel = rmax > 0.0 && std::isfinite(rmax) ? 2.0 * rmax : 0.1;
        } else {
            voxel = double(vp::computeVoxelSize(pos, ppv));
            if (!(voxel > 0.0) || !std::isfinite(voxel)) voxel = rmax > 0.0 ? 2.0 * rmax : 0.1;
        }
        // Not below the smallest scale OpenVDB's transforms accept (they
        // throw "Non-zero scale values required"; computeVoxelSize can
        // return less once it truncates to decimal places), and index
        // coordinates well inside int32.
        const double vmin = vpv_points_min_voxel(maxabs);
        if (!(voxel >= vmin)) voxel = vmin;

        // Precision: never an error above VP_POSITION_ERROR_LIMIT of the
        // smallest radius. 16-bit fixed point that would exceed it becomes
        // float; float that would, a finer voxel, down to vmin.
        bool use_full = full != 0, promoted = false;
        const double fixed_err = vpv_points_error(voxel, 0);
        if (std::isfinite(rmin)) {
            const double allowed = VP_POSITION_ERROR_LIMIT * rmin;
            if (!use_full && fixed_err > allowed) use_full = promoted = true;
            if (use_full && vpv_points_error(voxel, 1) > allowed)
                voxel = std::max(vmin, allowed / vpv_points_error(1.0, 1) * (1.0 - 1e-9));
            if (use_full && vpv_points_error(voxel, 1) > allowed * (1.0 + 1e-9)) {
                const double least = vpv_points_error(vmin, 1) / VP_POSITION_ERROR_LIMIT;
                if (vmin > VP_POINTS_MIN_VOXEL)
                    return fail(err, errlen, VP_ERR_INVALID_ARGUMENT,
                                "radius %g is too small for a .vdb with coordinates up to %g: it "
                                "stores them only to within %.3g, more than %g of the radius "
                                "(radii from %.3g fit); move the scene near the origin, or write "
                                ".csv",
                                rmin, maxabs, vpv_points_error(vmin, 1), VP_POSITION_ERROR_LIMIT,
                                least);
                return fail(err, errlen, VP_ERR_INVALID_ARGUMENT,
                            "radius %g is too small for a .vdb: OpenVDB's smallest voxel (%.4g) "
                            "stores positions only to within %.3g, more than %g of the radius "
                            "(radii from %.3g fit); write .csv or .ply, or scale the scene up",
                            rmin, VP_POINTS_MIN_VOXEL, vpv_points_error(vmin, 1),
                            VP_POSITION_ERROR_LIMIT, least);
            }
        }
        const double pos_err = vpv_points_error(voxel, use_full);
        const uint64_t max_bytes = params ? params->max_memory : 0;
        if (max_bytes > 0) {
            const double leaves = double(leaf_count(pos, lo, hi, voxel, double(max_bytes)));
            const double bytes =
                leaves * VPV_POINTS_LEAF_BYTES + double(count) * VPV_POINTS_POINT_BYTES;
            if (bytes > double(max_bytes)) {
                char need[32], lim[32];
                format_bytes(bytes, need, sizeof need);
                format_bytes(double(max_bytes), lim, sizeof lim);
                return fail(err, errlen, VP_ERR_OUT_OF_MEMORY,
                            "a .vdb of these %zu particles needs an estimated %s of memory "
                            "(%.0f leaf nodes: positions to within %g of the smallest radius need "
                            "voxels of %.3g, and the particles lie far apart at that scale), "
                            "more than the limit of %s; write .csv or .ply, or raise --max-memory",
                            count, need, leaves, VP_POSITION_ERROR_LIMIT, voxel, lim);
            }
        }

        int rc = check_writable(path, err, errlen);
        if (rc != VP_OK) return rc;

        openvdb::math::Transform::Ptr xf = openvdb::math::Transform::createLinearTransform(voxel);
        vp::PointDataGrid::Ptr grid;
        openvdb::tools::PointIndexGrid::Ptr index;
        if (count == 0) {
            grid = vp::PointDataGrid::create();
            grid->setTransform(xf);
        } else {
            index = openvdb::tools::createPointIndexGrid<openvdb::tools::PointIndexGrid>(pos, *xf);
            if (use_full)
                grid = vp::createPointDataGrid<vp::NullCodec, vp::PointDataGrid>(*index, pos, *xf);
            else
                grid = vp::createPointDataGrid<vp::FixedPointCodec<false, vp::PositionRange>,
                                               vp::PointDataGrid>(*index, pos, *xf);
        }
        grid->setName("points");
        vp::PointDataTree &tree = grid->tree();

        if (count > 0) {
            const openvdb::tools::PointIndexTree &itree = index->tree();
            // pscale
            if (p->radii) {
                vp::appendAttribute<float>(tree, "pscale");
                vp::populateAttribute(tree, itree, "pscale", Radii{p->radii});
            } else {
                vp::appendAttribute<float>(tree, "pscale", p->uniform_radius);
            }
            // id = index in the caller's order
            if (count > size_t(INT32_MAX)) {
                vp::appendAttribute<int64_t>(tree, "id");
                vp::populateAttribute(tree, itree, "id", Ids<int64_t>{});
            } else {
                vp::appendAttribute<int32_t>(tree, "id");
                vp::populateAttribute(tree, itree, "id", Ids<int32_t>{});
            }
            // orient (quaternions, x y z w)
            if (p->has_orient) {
                if (p->orients) {
                    vp::appendAttribute<openvdb::math::Quats>(tree, "orient");
                    vp::populateAttribute(tree, itree, "orient", Orients{p->orients});
                } else {
                    const float *u = p->uniform_orient;
                    vp::appendAttribute<openvdb::math::Quats>(
                        tree, "orient", openvdb::math::Quats(u[0], u[1], u[2], u[3]));
                }
            }
            // shape: a mixed set's index into its "shapes" metadata
            if (p->shape == VP_SHAPE_MIXED && p->shape_index) {
                vp::appendAttribute<int32_t>(tree, "shape");
                vp::populateAttribute(tree, itree, "shape", ShapeIndex{p->shape_index});
            }
            // groups
            for (const std::string &g : gnames) vp::appendGroup(tree, g);
            if (!gnames.empty()) {
                if (!p->groups) {
                    vp::setGroup(tree, gnames[0], true);
                } else {
                    std::vector<short> member(count);
                    for (unsigned g = 0; g < ngroups; ++g) {
                        size_t n = 0;
                        for (size_t i = 0; i < count; ++i) n += (member[i] = (p->groups[i] == g));
                        if (n) vp::setGroup(tree, itree, member, gnames[g]);
                    }
                }
            }
            index.reset();
        } else {
            // An empty grid still carries the attribute layout in its
            // descriptor only when it has leaves; nothing more to do.
        }

        openvdb::MetaMap fm;
        fill_meta(fm, meta, meta_count, false);
        fill_meta(*grid, meta, meta_count, true);
        if (!has_key(meta, meta_count, "shape") && p->shape >= 0 && p->shape < VP_SHAPE_COUNT) {
            fm.insertMeta("shape", openvdb::StringMetadata(kShapeNames[p->shape]));
            grid->insertMeta("shape", openvdb::StringMetadata(kShapeNames[p->shape]));
        }
        if (!has_key(meta, meta_count, "shape") && p->shape == VP_SHAPE_SUPERBALL) {
            char sb[64];
            for (int prec = 15; prec <= 17; prec++) { // the fewest digits that read back
                snprintf(sb, sizeof sb, "superball:%.*g", prec, p->shape_param);
                if (std::strtod(sb + 10, nullptr) == p->shape_param) break;
            }
            fm.insertMeta("shape", openvdb::StringMetadata(sb));
            grid->insertMeta("shape", openvdb::StringMetadata(sb));
        }

        // How P is stored (the codec alone does not say that 16-bit fixed
        // point was asked for and refused)
        if (count > 0 && !has_key(meta, meta_count, "position_precision")) {
            const char *prec = use_full ? "full" : "fixed16";
            fm.insertMeta("position_precision", openvdb::StringMetadata(prec));
            grid->insertMeta("position_precision", openvdb::StringMetadata(prec));
            fm.insertMeta("position_error", openvdb::DoubleMetadata(pos_err));
            grid->insertMeta("position_error", openvdb::DoubleMetadata(pos_err));
            if (promoted) {
                fm.insertMeta("position_precision_requested", openvdb::StringMetadata("fixed16"));
                grid->insertMeta("position_precision_requested",
                                 openvdb::StringMetadata("fixed16"));
            }
        }

        openvdb::GridCPtrVec grids;
        grids.push_back(grid);
        rc = write_vdb_checked(path, grids, fm, err, errlen);
        if (rc == VP_OK && params && params->report) {
            vp_write_report *r = params->report;
            r->full_precision = use_full ? 1 : 0;
            r->promoted = promoted ? 1 : 0;
            r->voxel_size = voxel;
            r->position_error = pos_err;
            r->fixed16_error = vpv_points_error(voxel, 0);
            r->min_radius = std::isfinite(rmin) ? rmin : 0.0;
        }
        return rc;
    });
}
