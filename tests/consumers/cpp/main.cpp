// SPDX-License-Identifier: Apache-2.0
// A C++ program built against an installed vdbpack through find_package:
// packs a mesh file by random sequential addition, checks it with the
// library's checker, writes the .vdb and reads it back. Public API only.
#include <vdbpack/vdbpack.h>

#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>

namespace {
struct Context {
    vp_context *ctx = nullptr;
    Context() {
        if (vp_context_create(&ctx) != VP_OK) throw std::runtime_error("out of memory");
    }
    ~Context() { vp_context_destroy(ctx); }
    void check(vp_result r, const char *what) const {
        if (r != VP_OK)
            throw std::runtime_error(std::string(what) + ": " + vp_result_name(r) + ": " +
                                     vp_context_message(ctx));
    }
};
using Particles = std::unique_ptr<vp_particles, void (*)(vp_particles *)>;
using Container = std::unique_ptr<vp_container, void (*)(vp_container *)>;
} // namespace

int main(int argc, char **argv) try {
    if (argc != 3) {
        std::fprintf(stderr, "usage: consumer_cpp MESH OUT.vdb\n");
        return 2;
    }
    Context c;
    vp_rsa_pass pass;
    vp_rsa_pass_init(&pass);
    pass.count = 300;
    vp_size_dist_constant(&pass.radius, 0.05);
    vp_rsa_params rp;
    vp_rsa_params_init(&rp);
    rp.passes = &pass;
    rp.npasses = 1;
    rp.seed = 7;
    vp_container_params cp;
    vp_container_params_init(&cp);
    vp_container_params_for_rsa(&cp, &rp);
    vp_container *raw = nullptr;
    c.check(vp_container_load(c.ctx, argv[1], &cp, &raw), "load");
    Container box(raw, vp_container_destroy);
    vp_particles *praw = nullptr;
    vp_rsa_report rep;
    c.check(vp_pack_rsa(c.ctx, box.get(), &rp, &praw, &rep), "pack");
    Particles p(praw, vp_particles_destroy);
    vp_check_report chk;
    c.check(vp_check_particles(c.ctx, box.get(), p.get(), nullptr, &chk), "check");
    if (p->count != 300 || chk.overlapping_pairs || chk.outside)
        throw std::runtime_error("packed " + std::to_string(p->count) + ", " +
                                 std::to_string(chk.overlapping_pairs) + " overlaps, " +
                                 std::to_string(chk.outside) + " outside");
    c.check(vp_write_points(c.ctx, argv[2], p.get(), nullptr), "write");
    vp_particles *qraw = nullptr;
    c.check(vp_read_points(c.ctx, argv[2], &qraw), "read");
    Particles q(qraw, vp_particles_destroy);
    if (q->count != p->count) throw std::runtime_error("read back a different count");
    std::printf("consumer-cpp: vdbpack %s, %zu spheres in %s, fraction %.4f, read back\n",
                vp_version(), p->count, argv[1], chk.fraction);
    return 0;
} catch (const std::exception &e) {
    std::fprintf(stderr, "consumer-cpp: %s\n", e.what());
    return 1;
}
