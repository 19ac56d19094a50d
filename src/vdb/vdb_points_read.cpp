// SPDX-License-Identifier: Apache-2.0
// OpenVDB PointDataGrid -> particles (P, pscale, orient, groups; in id order).
#include "vdb/vdb_internal.hpp"
#include "vdb/vdb_shape_names.hpp"

#include <openvdb/io/GridDescriptor.h>
#include <openvdb/points/AttributeArray.h>
#include <openvdb/points/PointCount.h>
#include <openvdb/points/PointDataGrid.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>

using namespace vpv;
namespace vp = openvdb::points;

namespace {

void free_particles(vp_particles *p)
{
    if (!p) return;
    free(p->positions);
    free(p->radii);
    free(p->orients);
    free(p->groups);
    free(p->shape_index);
    free(p);
}

struct Owner {
    vp_particles *p = nullptr;
    ~Owner() { free_particles(p); }
};

// "superball:P" sets param to P (the exponent; checked by the readers'
// users, as the library's shape functions refuse one out of range).
bool shape_text(const std::string &t, vp_shape &out, double &param)
{
    if (t == "mesh" || t.compare(0, 5, "mesh:") == 0) {
        out = VP_SHAPE_MESH;
        return true;
    }
    if (t.compare(0, 10, "superball:") == 0) {
        char *end = nullptr;
        const char *v = t.c_str() + 10;
        double p = std::strtod(v, &end);
        if (end == v || *end != '\0' || !std::isfinite(p)) return false;
        out = VP_SHAPE_SUPERBALL;
        param = p;
        return true;
    }
    for (int i = 0; i < VP_SHAPE_COUNT; ++i)
        if (t == kShapeNames[i]) {
            out = vp_shape(i);
            return true;
        }
    return false;
}

bool shape_from(const openvdb::MetaMap &m, vp_shape &out, double &param)
{
    openvdb::StringMetadata::ConstPtr s = m.getMetadata<openvdb::StringMetadata>("shape");
    if (!s) return false;
    if (s->value() == "mixed") {
        out = VP_SHAPE_MIXED;
        return true;
    }
    if (s->value().compare(0, 5, "mesh:") == 0) return false; // only "mesh" names the one shape
    return shape_text(s->value(), out, param);
}

// A mixed set's "shapes" ("sphere;cube;mesh:rock.obj") into P.shapes; false
// when absent, empty, too long or naming an unknown shape.
bool shapes_from(const openvdb::MetaMap &m, vp_particles &P)
{
    openvdb::StringMetadata::ConstPtr s = m.getMetadata<openvdb::StringMetadata>("shapes");
    if (!s) return false;
    const std::string &v = s->value();
    unsigned n = 0;
    for (size_t a = 0;;) {
        size_t b = v.find(';', a);
        const std::string t = v.substr(a, b == std::string::npos ? std::string::npos : b - a);
        if (n == VP_MAX_SHAPES) return false;
        vp_shape sh;
        double prm = 0.0;
        if (!shape_text(t, sh, prm)) return false;
        P.shapes[n].shape = sh;
        P.shapes[n].param = sh == VP_SHAPE_SUPERBALL ? prm : 0.0;
        P.shapes[n].mesh = nullptr;
        P.shape_names[n][0] = 0;
        if (sh == VP_SHAPE_MESH && t.size() > 5)
            snprintf(P.shape_names[n], VP_SHAPE_NAME_MAX, "%s", t.c_str() + 5);
        ++n;
        if (b == std::string::npos) break;
        a = b + 1;
    }
    P.shape_count = n;
    return n > 0;
}

} // namespace

extern "C" int vpv_points_read(const char *path, vp_particles **out, char *err, size_t errlen)
{
    clear(err, errlen);
    if (!out) return fail(err, errlen, VP_ERR_INVALID_ARGUMENT, "vpv_points_read: out is NULL");
    *out = nullptr;
    vpv_init();
    return guard(path, Op::Read, err, errlen, [&]() -> int {
        openvdb::io::File file(path ? path : "");
        openvdb::GridPtrVecPtr metas;
        int rc = read_grid_metadata(path, file, VP_ERR_FORMAT, metas, err, errlen);
        if (rc != VP_OK) return rc;
        const openvdb::GridPtrVec &grids = *metas;
        size_t pick = grids.size();
        for (size_t i = 0; i < grids.size(); ++i)
            if (grids[i] && grids[i]->isType<vp::PointDataGrid>() &&
                grids[i]->getName() == "points") {
                pick = i;
                break;
            }
        if (pick == grids.size())
            for (size_t i = 0; i < grids.size(); ++i)
                if (grids[i] && grids[i]->isType<vp::PointDataGrid>()) {
                    pick = i;
                    break;
                }
        if (pick == grids.size())
            return fail(err, errlen, VP_ERR_FORMAT,
                        "%s: no point data grid in the file (grids: %s)", path,
                        list_grids(grids).c_str());
        const std::string name = grids[pick]->getName();
        int dup = 0;
        for (size_t i = 0; i < pick; ++i)
            if (grids[i] && grids[i]->getName() == name) ++dup;
        openvdb::GridBase::Ptr base =
            file.readGrid(dup ? openvdb::io::GridDescriptor::addSuffix(name, dup) : name);
        openvdb::MetaMap::Ptr fmeta = file.getMetadata();
        file.close();
        vp::PointDataGrid::Ptr grid = openvdb::gridPtrCast<vp::PointDataGrid>(base);
        if (!grid)
            return fail(err, errlen, VP_ERR_FORMAT, "%s: grid '%s' is not a point data grid", path,
                        name.c_str());
        const vp::PointDataTree &tree = grid->constTree();
        const openvdb::math::Transform &xf = grid->transform();

        Owner own;
        own.p = static_cast<vp_particles *>(calloc(1, sizeof(vp_particles)));
        if (!own.p) throw std::bad_alloc();
        vp_particles &P = *own.p;
        P.shape = VP_SHAPE_SPHERE;
        P.uniform_orient[3] = 1.0f;
        P.group_count = 1;
        snprintf(P.group_names[0], VP_GROUP_NAME_MAX, "%s", "all");
        vp_shape sh;
        double shp = 0.0;
        if (shape_from(*grid, sh, shp) || (fmeta && shape_from(*fmeta, sh, shp))) {
            P.shape = sh;
            P.shape_param = sh == VP_SHAPE_SUPERBALL ? shp : 0.0;
        }
        if (P.shape == VP_SHAPE_MIXED && !shapes_from(*grid, P) &&
            !(fmeta && shapes_from(*fmeta, P)))
            return fail(err, errlen, VP_ERR_FORMAT,
                        "%s: grid '%s' says shape \"mixed\" but its \"shapes\" metadata is missing "
                        "or names an unknown shape",
                        path, name.c_str());

        auto leaf0 = tree.cbeginLeaf();
        const size_t count = leaf0 ? size_t(vp::pointCount(tree)) : 0;
        if (count == 0) {
            *out = own.p;
            own.p = nullptr;
            return VP_OK;
        }
        const vp::AttributeSet::Descriptor &desc = leaf0->attributeSet().descriptor();
        const size_t NONE = vp::AttributeSet::INVALID_POS;
        const size_t iP = desc.find("P");
        if (iP == NONE || desc.valueType(iP) != openvdb::typeNameAsString<openvdb::Vec3f>())
            return fail(err, errlen, VP_ERR_FORMAT, "%s: grid '%s' has no vec3s P attribute", path,
                        name.c_str());
        size_t iR = desc.find("pscale");
        if (iR != NONE && desc.valueType(iR) != openvdb::typeNameAsString<float>()) iR = NONE;
        size_t iO = desc.find("orient");
        if (iO != NONE && desc.valueType(iO) != openvdb::typeNameAsString<openvdb::math::Quats>())
            iO = NONE;
        size_t iI = desc.find("id");
        const bool id32 = iI != NONE && desc.valueType(iI) == openvdb::typeNameAsString<int32_t>();
        const bool id64 = iI != NONE && desc.valueType(iI) == openvdb::typeNameAsString<int64_t>();
        if (!id32 && !id64) iI = NONE;
        size_t iS = desc.find("shape");
        if (P.shape == VP_SHAPE_MIXED) {
            if (iS == NONE || desc.valueType(iS) != openvdb::typeNameAsString<int32_t>())
                return fail(
                    err, errlen, VP_ERR_FORMAT,
                    "%s: grid '%s' is a packing of several shapes without an int32 \"shape\" "
                    "attribute",
                    path, name.c_str());
            P.shape_index = static_cast<uint8_t *>(malloc(count));
            if (!P.shape_index) throw std::bad_alloc();
        }

        // Output order: by id when the ids are a permutation of 0..count-1.
        std::vector<size_t> dest;
        if (iI != NONE) {
            dest.resize(count);
            std::vector<bool> seen(count, false);
            size_t k = 0;
            bool ok = true;
            for (auto leaf = tree.cbeginLeaf(); leaf && ok; ++leaf) {
                std::unique_ptr<vp::AttributeHandle<int32_t>> h32;
                std::unique_ptr<vp::AttributeHandle<int64_t>> h64;
                if (id32)
                    h32.reset(new vp::AttributeHandle<int32_t>(leaf->constAttributeArray(iI)));
                else h64.reset(new vp::AttributeHandle<int64_t>(leaf->constAttributeArray(iI)));
                for (auto idx = leaf->beginIndexAll(); idx; ++idx, ++k) {
                    const int64_t id = h32 ? int64_t(h32->get(*idx)) : h64->get(*idx);
                    if (k >= count || id < 0 || uint64_t(id) >= count || seen[size_t(id)]) {
                        ok = false;
                        break;
                    }
                    seen[size_t(id)] = true;
                    dest[k] = size_t(id);
                }
            }
            if (!ok || k != count) {
                dest.clear();
                dest.shrink_to_fit();
            }
        }

        // Groups in descriptor (offset) order, at most VP_MAX_GROUPS.
        std::vector<std::pair<size_t, std::string>> gs;
        for (const auto &kv : desc.groupMap()) gs.emplace_back(kv.second, kv.first);
        std::sort(gs.begin(), gs.end());
        if (gs.size() > VP_MAX_GROUPS) gs.resize(VP_MAX_GROUPS);

        P.positions = static_cast<double *>(malloc(sizeof(double) * 3 * count));
        if (!P.positions) throw std::bad_alloc();
        if (iR != NONE) {
            P.radii = static_cast<float *>(malloc(sizeof(float) * count));
            if (!P.radii) throw std::bad_alloc();
        }
        if (iO != NONE) {
            P.orients = static_cast<float *>(malloc(sizeof(float) * 4 * count));
            if (!P.orients) throw std::bad_alloc();
            P.has_orient = 1;
        }
        if (!gs.empty()) {
            P.group_count = unsigned(gs.size());
            for (size_t g = 0; g < gs.size(); ++g)
                snprintf(P.group_names[g], VP_GROUP_NAME_MAX, "%s", gs[g].second.c_str());
            P.groups = static_cast<uint16_t *>(calloc(count, sizeof(uint16_t)));
            if (!P.groups) throw std::bad_alloc();
        }

        size_t k = 0;
        for (auto leaf = tree.cbeginLeaf(); leaf; ++leaf) {
            vp::AttributeHandle<openvdb::Vec3f> hp(leaf->constAttributeArray(iP));
            std::unique_ptr<vp::AttributeHandle<float>> hr;
            std::unique_ptr<vp::AttributeHandle<openvdb::math::Quats>> ho;
            if (iR != NONE) hr.reset(new vp::AttributeHandle<float>(leaf->constAttributeArray(iR)));
            if (iO != NONE)
                ho.reset(
                    new vp::AttributeHandle<openvdb::math::Quats>(leaf->constAttributeArray(iO)));
            std::unique_ptr<vp::AttributeHandle<int32_t>> hs;
            if (P.shape_index)
                hs.reset(new vp::AttributeHandle<int32_t>(leaf->constAttributeArray(iS)));
            std::vector<vp::GroupHandle> gh;
            for (const auto &g : gs) gh.push_back(leaf->groupHandle(g.second));
            for (auto idx = leaf->beginIndexAll(); idx; ++idx, ++k) {
                if (k >= count) break;
                const size_t d = dest.empty() ? k : dest[k];
                const openvdb::Vec3d ip = idx.getCoord().asVec3d() + openvdb::Vec3d(hp.get(*idx));
                const openvdb::Vec3d w = xf.indexToWorld(ip);
                P.positions[3 * d] = w[0];
                P.positions[3 * d + 1] = w[1];
                P.positions[3 * d + 2] = w[2];
                if (hr) P.radii[d] = hr->get(*idx);
                if (hs) {
                    const int32_t v = hs->get(*idx);
                    if (v < 0 || unsigned(v) >= P.shape_count)
                        return fail(err, errlen, VP_ERR_FORMAT,
                                    "%s: point %zu has shape %d, but the file names %u shapes",
                                    path, d, int(v), P.shape_count);
                    P.shape_index[d] = uint8_t(v);
                }
                if (ho) {
                    const openvdb::math::Quats q = ho->get(*idx);
                    for (int c = 0; c < 4; ++c) P.orients[4 * d + c] = q[c];
                }
                for (size_t g = 0; g < gh.size(); ++g)
                    if (gh[g].get(*idx)) {
                        P.groups[d] = uint16_t(g);
                        break;
                    }
            }
        }
        P.count = P.capacity = std::min(k, count);

        // How exactly P was stored: each component of the voxel-local
        // offset in [-0.5, 0.5] is rounded to the codec's step.
        {
            const std::string codec = leaf0->constAttributeArray(iP).codecType();
            double step = 0.0; // in voxels
            if (codec.find("fxpt16") != std::string::npos) step = 1.0 / 65535.0;
            else if (codec.find("fxpt8") != std::string::npos) step = 1.0 / 255.0;
            else if (codec == "trnc") step = std::ldexp(1.0, -11); // half floats
            else step = std::ldexp(1.0, -24);                      // float
            const openvdb::Vec3d vs = xf.voxelSize();
            const double voxel = std::max(vs[0], std::max(vs[1], vs[2]));
            // up to one whole step per component: the codec truncates, and
            // the offset is rounded to float before it is encoded
            P.position_error = std::sqrt(3.0) * step * voxel;
        }

        // Collapse uniform per-point data to the uniform fields.
        if (P.radii) {
            bool uni = true;
            for (size_t i = 1; i < P.count && uni; ++i) uni = P.radii[i] == P.radii[0];
            if (uni) {
                P.uniform_radius = P.radii[0];
                free(P.radii);
                P.radii = nullptr;
            }
        }
        if (P.orients) {
            bool uni = true;
            for (size_t i = 1; i < P.count && uni; ++i)
                uni = memcmp(P.orients + 4 * i, P.orients, 4 * sizeof(float)) == 0;
            if (uni) {
                memcpy(P.uniform_orient, P.orients, 4 * sizeof(float));
                free(P.orients);
                P.orients = nullptr;
            }
        }
        if (P.groups) {
            bool zero = true;
            for (size_t i = 0; i < P.count && zero; ++i) zero = P.groups[i] == 0;
            if (zero) {
                free(P.groups);
                P.groups = nullptr;
            }
        }
        *out = own.p;
        own.p = nullptr;
        return VP_OK;
    });
}
