// SPDX-License-Identifier: Apache-2.0
// An independent reader of OpenVDB points for the export tests: OpenVDB's
// own API only (no vdbpack code). Prints one line per point of the first
// PointDataGrid (preferring "points"):
//   id x y z pscale [qx qy qz qw] groups [shape]
// (shape: the int32 "shape" attribute of a set of several shapes)
// world position = indexToWorld(voxel coordinate + P), printed with %.17g;
// pscale and orient as stored (%.9g); groups = comma list of group names.
#include <openvdb/openvdb.h>
#include <openvdb/points/PointDataGrid.h>

#include <cstdio>
#include <string>
#include <vector>

int main(int argc, char **argv) {
    if (argc != 2) {
        std::fprintf(stderr, "usage: dump_points FILE.vdb\n");
        return 2;
    }
    openvdb::initialize();
    namespace vp = openvdb::points;
    try {
        openvdb::io::File file(argv[1]);
        file.open(false);
        openvdb::GridPtrVecPtr grids = file.getGrids();
        file.close();
        vp::PointDataGrid::Ptr grid;
        for (auto &g : *grids)
            if (auto p = openvdb::gridPtrCast<vp::PointDataGrid>(g))
                if (!grid || p->getName() == "points") grid = p;
        if (!grid) {
            std::fprintf(stderr, "no points grid\n");
            return 1;
        }
        const auto &xf = grid->transform();
        for (auto leaf = grid->tree().cbeginLeaf(); leaf; ++leaf) {
            const auto &desc = leaf->attributeSet().descriptor();
            vp::AttributeHandle<openvdb::Vec3f> hp(leaf->constAttributeArray("P"));
            vp::AttributeHandle<float> hr(leaf->constAttributeArray("pscale"));
            vp::AttributeHandle<int32_t> hi(leaf->constAttributeArray("id"));
            std::unique_ptr<vp::AttributeHandle<openvdb::math::Quats>> ho;
            if (desc.find("orient") != vp::AttributeSet::INVALID_POS)
                ho.reset(new vp::AttributeHandle<openvdb::math::Quats>(
                    leaf->constAttributeArray("orient")));
            std::unique_ptr<vp::AttributeHandle<int32_t>> hs;
            if (desc.find("shape") != vp::AttributeSet::INVALID_POS)
                hs.reset(new vp::AttributeHandle<int32_t>(leaf->constAttributeArray("shape")));
            std::vector<std::pair<std::string, vp::GroupHandle>> gh;
            for (const auto &kv : desc.groupMap())
                gh.emplace_back(kv.first, leaf->groupHandle(kv.first));
            for (auto idx = leaf->beginIndexOn(); idx; ++idx) {
                const openvdb::Vec3d w =
                    xf.indexToWorld(idx.getCoord().asVec3d() + openvdb::Vec3d(hp.get(*idx)));
                std::printf("%d %.17g %.17g %.17g %.9g", hi.get(*idx), w[0], w[1], w[2],
                            double(hr.get(*idx)));
                if (ho) {
                    const openvdb::math::Quats q = ho->get(*idx);
                    std::printf(" %.9g %.9g %.9g %.9g", double(q[0]), double(q[1]), double(q[2]),
                                double(q[3]));
                }
                std::string gs;
                for (auto &g : gh)
                    if (g.second.get(*idx)) gs += (gs.empty() ? "" : ",") + g.first;
                std::printf(" %s", gs.empty() ? "-" : gs.c_str());
                if (hs) std::printf(" %d", hs->get(*idx));
                std::printf("\n");
            }
        }
    } catch (const std::exception &e) {
        std::fprintf(stderr, "dump_points: %s\n", e.what());
        return 1;
    }
    return 0;
}
