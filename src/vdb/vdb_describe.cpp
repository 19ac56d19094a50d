// SPDX-License-Identifier: Apache-2.0
// Text / JSON description of a .vdb file: metadata, grids, points.
#include "vdb/vdb_internal.hpp"

#include <openvdb/points/PointCount.h>
#include <openvdb/points/PointDataGrid.h>
#include <openvdb/points/PointGroup.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>

using namespace vpv;
namespace vp = openvdb::points;

namespace {

std::string fmt(double v)
{
    if (!std::isfinite(v)) return "null";
    char b[64];
    snprintf(b, sizeof b, "%.10g", v);
    return b;
}

std::string jstr(const std::string &s)
{
    std::string o = "\"";
    for (unsigned char c : s) {
        switch (c) {
        case '"': o += "\\\""; break;
        case '\\': o += "\\\\"; break;
        case '\n': o += "\\n"; break;
        case '\r': o += "\\r"; break;
        case '\t': o += "\\t"; break;
        case '\b': o += "\\b"; break;
        case '\f': o += "\\f"; break;
        default:
            if (c < 0x20) {
                char b[8];
                snprintf(b, sizeof b, "\\u%04x", c);
                o += b;
            } else {
                o += char(c);
            }
        }
    }
    return o + "\"";
}

// A metadata value as JSON: numbers and number vectors as such, the rest
// as strings.
std::string jmeta(const openvdb::Metadata &m)
{
    const std::string t = m.typeName();
    if (t == "string") return jstr(m.str());
    if (t == "bool") return m.asBool() ? "true" : "false";
    // doubles in full: `check` reads the packing's voxel_size from here,
    // and str()'s six digits gave it another voxel size (a cube 1e-6
    // across then checked two particles 0.37 voxel outside)
    if (t == "double" || t == "float") {
        const double v = t == "double"
                             ? static_cast<const openvdb::DoubleMetadata &>(m).value()
                             : double(static_cast<const openvdb::FloatMetadata &>(m).value());
        if (!std::isfinite(v)) return "null";
        char buf[40];
        snprintf(buf, sizeof buf, t == "double" ? "%.17g" : "%.9g", v);
        return buf;
    }
    if (t == "int32" || t == "int64") {
        const std::string s = m.str();
        char *end = nullptr;
        const double v = strtod(s.c_str(), &end);
        if (end && *end == '\0' && std::isfinite(v)) return s;
        return "null";
    }
    const std::string s = m.str();
    if (t.compare(0, 3, "vec") == 0 && s.find_first_of("naif") == std::string::npos) return s;
    return jstr(s);
}

struct GridDesc {
    std::string name, type, cls;
    openvdb::Vec3d vs;
    uint64_t active = 0;
    bool has_bbox = false;
    openvdb::Vec3d bmin, bmax;
    bool points = false;
    uint64_t npoints = 0;
    struct Attr {
        std::string name, type, codec;
    };
    std::vector<Attr> attrs;
    std::vector<std::pair<std::string, uint64_t>> groups;
};

GridDesc describe(const openvdb::GridBase &g)
{
    GridDesc d;
    d.name = g.getName();
    d.type = g.isType<vp::PointDataGrid>() ? "points" : g.valueType();
    d.cls = g.isType<vp::PointDataGrid>() ? "points"
                                          : openvdb::GridBase::gridClassToString(g.getGridClass());
    d.vs = g.voxelSize();
    d.active = g.activeVoxelCount();
    const openvdb::CoordBBox bb = g.evalActiveVoxelBoundingBox();
    if (!bb.empty()) {
        d.has_bbox = true;
        d.bmin = openvdb::Vec3d(HUGE_VAL);
        d.bmax = openvdb::Vec3d(-HUGE_VAL);
        for (int c = 0; c < 8; ++c) {
            openvdb::Vec3d ip((c & 1) ? bb.max().x() : bb.min().x(),
                              (c & 2) ? bb.max().y() : bb.min().y(),
                              (c & 4) ? bb.max().z() : bb.min().z());
            const openvdb::Vec3d w = g.indexToWorld(ip);
            for (int a = 0; a < 3; ++a) {
                d.bmin[a] = std::min(d.bmin[a], w[a]);
                d.bmax[a] = std::max(d.bmax[a], w[a]);
            }
        }
    }
    if (const vp::PointDataGrid *pg = dynamic_cast<const vp::PointDataGrid *>(&g)) {
        d.points = true;
        const vp::PointDataTree &tree = pg->constTree();
        auto leaf = tree.cbeginLeaf();
        if (leaf) {
            d.npoints = vp::pointCount(tree);
            const vp::AttributeSet &set = leaf->attributeSet();
            const vp::AttributeSet::Descriptor &desc = set.descriptor();
            std::vector<std::pair<size_t, std::string>> byPos;
            for (const auto &kv : desc.map()) byPos.emplace_back(kv.second, kv.first);
            std::sort(byPos.begin(), byPos.end());
            for (const auto &a : byPos) {
                const openvdb::NamePair &t = desc.type(a.first);
                d.attrs.push_back({a.second, t.first, t.second});
            }
            std::vector<std::pair<size_t, std::string>> gs;
            for (const auto &kv : desc.groupMap()) gs.emplace_back(kv.second, kv.first);
            std::sort(gs.begin(), gs.end());
            for (const auto &gg : gs) {
                uint64_t n = 0;
                for (auto l = tree.cbeginLeaf(); l; ++l) n += l->groupPointCount(gg.second);
                d.groups.emplace_back(gg.second, n);
            }
        }
    }
    return d;
}

std::string vs_text(const openvdb::Vec3d &v)
{
    if (v[0] == v[1] && v[1] == v[2]) return fmt(v[0]);
    return fmt(v[0]) + " " + fmt(v[1]) + " " + fmt(v[2]);
}

} // namespace

extern "C" int vpv_describe_file(const char *path, int json, char **out, char *err, size_t errlen)
{
    clear(err, errlen);
    if (!out) return fail(err, errlen, VP_ERR_INVALID_ARGUMENT, "vpv_describe_file: out is NULL");
    *out = nullptr;
    vpv_init();
    return guard(path, Op::Read, err, errlen, [&]() -> int {
        openvdb::io::File file(path ? path : "");
        int rc = open_file(path, file, err, errlen);
        if (rc != VP_OK) return rc;
        openvdb::MetaMap::Ptr fmeta = file.getMetadata();
        std::string version = file.version();
        openvdb::GridPtrVecPtr grids = file.getGrids();
        file.close();
        std::vector<GridDesc> ds;
        if (grids)
            for (const auto &g : *grids)
                if (g) ds.push_back(describe(*g));

        std::string s;
        if (json) {
            s = "{\"file\":" + jstr(path) + ",\"vdb_version\":" + jstr(version) + ",\"metadata\":{";
            bool first = true;
            if (fmeta)
                for (auto it = fmeta->beginMeta(); it != fmeta->endMeta(); ++it) {
                    if (!it->second) continue;
                    s += (first ? "" : ",") + jstr(it->first) + ":" + jmeta(*it->second);
                    first = false;
                }
            s += "},\"grids\":[";
            for (size_t i = 0; i < ds.size(); ++i) {
                const GridDesc &d = ds[i];
                s += i ? ",{" : "{";
                s += "\"name\":" + jstr(d.name) + ",\"type\":" + jstr(d.type) +
                     ",\"class\":" + jstr(d.cls);
                s += ",\"voxel_size\":" + fmt(std::min(d.vs[0], std::min(d.vs[1], d.vs[2])));
                s += ",\"voxel_size_xyz\":[" + fmt(d.vs[0]) + "," + fmt(d.vs[1]) + "," +
                     fmt(d.vs[2]) + "]";
                s += ",\"active_voxels\":" + std::to_string(d.active);
                if (d.has_bbox) {
                    s += ",\"bbox_min\":[" + fmt(d.bmin[0]) + "," + fmt(d.bmin[1]) + "," +
                         fmt(d.bmin[2]) + "]";
                    s += ",\"bbox_max\":[" + fmt(d.bmax[0]) + "," + fmt(d.bmax[1]) + "," +
                         fmt(d.bmax[2]) + "]";
                } else {
                    s += ",\"bbox_min\":null,\"bbox_max\":null";
                }
                if (d.points) {
                    s += ",\"points\":" + std::to_string(d.npoints) + ",\"attributes\":[";
                    for (size_t a = 0; a < d.attrs.size(); ++a)
                        s += (a ? ",{\"name\":" : "{\"name\":") + jstr(d.attrs[a].name) +
                             ",\"type\":" + jstr(d.attrs[a].type) +
                             ",\"codec\":" + jstr(d.attrs[a].codec) + "}";
                    s += "],\"groups\":[";
                    for (size_t a = 0; a < d.groups.size(); ++a)
                        s += (a ? ",{\"name\":" : "{\"name\":") + jstr(d.groups[a].first) +
                             ",\"count\":" + std::to_string(d.groups[a].second) + "}";
                    s += "]";
                }
                s += "}";
            }
            s += "]}\n";
        } else {
            s = "file: " + std::string(path) + " (OpenVDB file version " + version + ")\n";
            s += "metadata:";
            if (!fmeta || fmeta->metaCount() == 0) s += " (none)";
            s += "\n";
            if (fmeta)
                for (auto it = fmeta->beginMeta(); it != fmeta->endMeta(); ++it)
                    if (it->second) s += "  " + it->first + " = " + it->second->str() + "\n";
            s += "grids: " + std::to_string(ds.size()) + "\n";
            for (const GridDesc &d : ds) {
                s += "grid " + (d.name.empty() ? std::string("(unnamed)") : "'" + d.name + "'") +
                     "\n";
                s += "  type: " + d.type + "\n  class: " + d.cls + "\n";
                s += "  voxel size: " + vs_text(d.vs) + "\n";
                s += "  active voxels: " + std::to_string(d.active) + "\n";
                if (d.has_bbox)
                    s += "  bbox (world): [" + fmt(d.bmin[0]) + ", " + fmt(d.bmin[1]) + ", " +
                         fmt(d.bmin[2]) + "] -> [" + fmt(d.bmax[0]) + ", " + fmt(d.bmax[1]) + ", " +
                         fmt(d.bmax[2]) + "]\n";
                else s += "  bbox (world): empty\n";
                if (d.points) {
                    s += "  points: " + std::to_string(d.npoints) + "\n";
                    s += "  attributes:";
                    s += d.attrs.empty() ? " (none)\n" : "\n";
                    for (const auto &a : d.attrs)
                        s += "    " + a.name + ": " + a.type + " [" + a.codec + "]\n";
                    s += "  groups:";
                    s += d.groups.empty() ? " (none)\n" : "\n";
                    for (const auto &g : d.groups)
                        s += "    " + g.first + ": " + std::to_string(g.second) + "\n";
                }
            }
        }
        char *buf = static_cast<char *>(malloc(s.size() + 1));
        if (!buf) throw std::bad_alloc();
        memcpy(buf, s.c_str(), s.size() + 1);
        *out = buf;
        return VP_OK;
    });
}
