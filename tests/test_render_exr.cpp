// SPDX-License-Identifier: Apache-2.0
// Preview renders checked against geometry, through an independent reader:
// vdbpack writes EXR with OpenEXR's C API (OpenEXRCore); this test reads it
// back with OpenEXR's C++ API (Imf::InputFile), a different code path.
// Scenes are built by hand with a known camera so that projected areas,
// depths and ids are known analytically.
#include "vdbpack/vdbpack.h"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "vp_test.h"

static std::string g_dir;

struct Exr {
    int w = 0, h = 0;
    std::vector<std::string> channels;
    std::vector<float> r, a, z;
    std::vector<unsigned> id;
    bool id_is_uint = false, z_is_float = false;
    float A(int x, int y) const { return a[(size_t)y * w + x]; }
    float Z(int x, int y) const { return z[(size_t)y * w + x]; }
    unsigned Id(int x, int y) const { return id[(size_t)y * w + x]; }
};

static Exr read_exr(const std::string &path) {
    Exr e;
    Imf::InputFile in(path.c_str());
    const Imath::Box2i dw = in.header().dataWindow();
    e.w = dw.max.x - dw.min.x + 1;
    e.h = dw.max.y - dw.min.y + 1;
    const Imf::ChannelList &cl = in.header().channels();
    for (Imf::ChannelList::ConstIterator it = cl.begin(); it != cl.end(); ++it) {
        e.channels.push_back(it.name());
        if (!strcmp(it.name(), "id")) e.id_is_uint = it.channel().type == Imf::UINT;
        if (!strcmp(it.name(), "Z")) e.z_is_float = it.channel().type == Imf::FLOAT;
    }
    size_t n = (size_t)e.w * e.h;
    e.r.resize(n);
    e.a.resize(n);
    e.z.resize(n);
    e.id.resize(n);
    Imf::FrameBuffer fb;
    char *base = nullptr;
    auto slice = [&](const char *name, Imf::PixelType t, void *data, size_t sz) {
        base = (char *)data - (dw.min.x + (size_t)dw.min.y * e.w) * sz;
        fb.insert(name, Imf::Slice(t, base, sz, sz * e.w));
    };
    slice("R", Imf::FLOAT, e.r.data(), 4);
    slice("A", Imf::FLOAT, e.a.data(), 4);
    slice("Z", Imf::FLOAT, e.z.data(), 4);
    slice("id", Imf::UINT, e.id.data(), 4);
    in.setFrameBuffer(fb);
    in.readPixels(dw.min.y, dw.max.y);
    return e;
}

static vp_particles *make_set(vp_context *ctx, size_t n) {
    vp_particles *p = nullptr;
    ASSERT_EQ_INT(vp_particles_create(ctx, n, &p), VP_OK);
    p->count = n;
    p->radii = (float *)malloc(n * sizeof(float));
    return p;
}

static void set_sphere(vp_particles *p, size_t i, double x, double y, double z, double r) {
    p->positions[3 * i] = x;
    p->positions[3 * i + 1] = y;
    p->positions[3 * i + 2] = z;
    p->radii[i] = (float)r;
}

// a camera on +Z looking at the origin
static void camera(vp_render_params *rp, int w, int h, double dist, double fov) {
    vp_render_params_init(rp);
    rp->width = w;
    rp->height = h;
    rp->view = VP_VIEW_CAMERA;
    rp->eye[2] = dist;
    rp->fov_degrees = fov;
}

static double focal(const vp_render_params &rp) {
    return 0.5 * rp.height / tan(rp.fov_degrees * M_PI / 360.0);
}

// Area in pixels of the perspective image of a sphere of radius r whose
// centre is at distance d from the eye and depth zc along the view axis:
// an ellipse with semi-axes f r / sqrt(zc^2 - r^2) and
// f r sqrt(d^2 - r^2) / (zc^2 - r^2).
static double sphere_area_px(double f, double r, double d, double zc) {
    double k = zc * zc - r * r;
    return M_PI * f * f * r * r * sqrt(d * d - r * r) / (k * sqrt(k));
}

static std::string render_to(vp_context *ctx, const vp_particles *p, const vp_render_params *rp,
                             const char *name) {
    vp_image *img = nullptr;
    vp_result r = vp_render(ctx, p, rp, &img);
    if (r != VP_OK) fprintf(stderr, "render: %s\n", vp_context_message(ctx));
    ASSERT_EQ_INT(r, VP_OK);
    std::string path = g_dir + "/" + name;
    r = vp_image_write(ctx, img, path.c_str());
    if (r != VP_OK) fprintf(stderr, "write: %s\n", vp_context_message(ctx));
    ASSERT_EQ_INT(r, VP_OK);
    vp_image_destroy(img);
    return path;
}

static void test_spheres_channels_coverage_depth_id() {
    vp_context *ctx = nullptr;
    vp_context_create(&ctx);
    vp_particles *p = make_set(ctx, 3);
    set_sphere(p, 0, 0, 0, 0, 1.0);
    set_sphere(p, 1, 2.5, 0, 0, 0.5);
    set_sphere(p, 2, -2.0, 1.2, -1.0, 0.7);
    vp_render_params rp;
    camera(&rp, 401, 301, 10, 40);
    Exr e = read_exr(render_to(ctx, p, &rp, "spheres.exr"));
    // channel list and types
    ASSERT_EQ_INT(e.channels.size(), 6);
    const char *want[6] = {"A", "B", "G", "R", "Z", "id"}; // the file's sorted order
    for (int k = 0; k < 6; k++) ASSERT_TRUE(e.channels[k] == want[k]);
    ASSERT_TRUE(e.id_is_uint);
    ASSERT_TRUE(e.z_is_float);
    ASSERT_EQ_INT(e.w, 401);
    ASSERT_EQ_INT(e.h, 301);
    // background in the corners
    int corners[4][2] = {{0, 0}, {400, 0}, {0, 300}, {400, 300}};
    for (auto &c : corners) {
        ASSERT_EQ_INT(e.A(c[0], c[1]), 0);
        ASSERT_TRUE(std::isinf(e.Z(c[0], c[1])) && e.Z(c[0], c[1]) > 0);
        ASSERT_EQ_INT(e.Id(c[0], c[1]), VP_RENDER_BACKGROUND_ID);
    }
    // ids and depths at the projected centres
    double f = focal(rp);
    for (int i = 0; i < 3; i++) {
        const double *c = p->positions + 3 * i;
        double zc = 10 - c[2];
        int px = (int)floor(200.5 + f * c[0] / zc), py = (int)floor(150.5 - f * c[1] / zc);
        ASSERT_EQ_INT(e.Id(px, py), i);
        ASSERT_EQ_INT(e.A(px, py), 1);
        double d = sqrt(c[0] * c[0] + c[1] * c[1] + zc * zc);
        ASSERT_NEAR(e.Z(px, py), d - p->radii[i], 2e-3 * d);
    }
    // the centre pixel's ray passes through sphere 0's centre exactly
    ASSERT_NEAR(e.Z(200, 150), 9.0, 1e-5);
    // coverage per sphere against the analytic projected area
    for (int i = 0; i < 3; i++) {
        const double *c = p->positions + 3 * i;
        double zc = 10 - c[2], d = sqrt(c[0] * c[0] + c[1] * c[1] + zc * zc);
        double want_px = sphere_area_px(f, p->radii[i], d, zc);
        size_t got = 0;
        for (size_t q = 0; q < e.id.size(); q++) got += e.id[q] == (unsigned)i && e.a[q] > 0;
        fprintf(stderr, "   sphere %d: %zu pixels, analytic %.1f\n", i, got, want_px);
        ASSERT_NEAR(got / want_px, 1.0, 0.02);
    }
    size_t covered = 0, ided = 0;
    for (size_t q = 0; q < e.a.size(); q++)
        covered += e.a[q] > 0, ided += e.id[q] != VP_RENDER_BACKGROUND_ID;
    ASSERT_EQ_INT(covered, ided);
    vp_particles_destroy(p);
    vp_context_destroy(ctx);
}

static void test_cube_face_on_and_orientation() {
    vp_context *ctx = nullptr;
    vp_context_create(&ctx);
    vp_particles *p = make_set(ctx, 1);
    set_sphere(p, 0, 0, 0, 0, 1.0); // circumradius 1: half-edge 1/sqrt(3)
    p->shape = VP_SHAPE_CUBE;
    p->has_orient = 1;
    p->orients = (float *)malloc(4 * sizeof(float));
    float ident[4] = {0, 0, 0, 1};
    memcpy(p->orients, ident, sizeof ident);
    vp_render_params rp;
    camera(&rp, 301, 301, 6, 30);
    double f = focal(rp), a = 1 / sqrt(3.0);
    double half_px = f * a / (6 - a); // the front face's half-size in pixels
    Exr e = read_exr(render_to(ctx, p, &rp, "cube.exr"));
    size_t got = 0;
    for (float v : e.a) got += v > 0;
    double want = 4 * half_px * half_px;
    fprintf(stderr, "   cube face-on: %zu pixels, analytic %.1f\n", got, want);
    ASSERT_NEAR(got / want, 1.0, 0.02);
    ASSERT_NEAR(e.Z(150, 150), 6 - a, 1e-5);
    int off = (int)ceil(1.2 * half_px);
    ASSERT_EQ_INT(e.A(150 + off, 150), 0); // beyond the unrotated square
    // turned by 45 degrees about the view axis: a diamond of the same area
    // reaching sqrt(2) times as far along x
    float q45[4] = {0, 0, (float)sin(M_PI / 8), (float)cos(M_PI / 8)};
    memcpy(p->orients, q45, sizeof q45);
    e = read_exr(render_to(ctx, p, &rp, "cube45.exr"));
    got = 0;
    for (float v : e.a) got += v > 0;
    fprintf(stderr, "   cube turned 45 deg: %zu pixels\n", got);
    ASSERT_NEAR(got / want, 1.0, 0.02);
    ASSERT_EQ_INT(e.A(150 + off, 150), 1);
    ASSERT_EQ_INT(e.A(150 + off, 150 + off), 0);
    vp_particles_destroy(p);
    vp_context_destroy(ctx);
}

static void test_cut_plane_removes_the_plus_side() {
    vp_context *ctx = nullptr;
    vp_context_create(&ctx);
    vp_particles *p = make_set(ctx, 3);
    set_sphere(p, 0, -2.5, 0, 0, 1.0); // wholly on the - side
    set_sphere(p, 1, 2.5, 0, 0, 1.0);  // wholly on the + side
    set_sphere(p, 2, 0, 0, 0, 1.0);    // crosses x = 0
    vp_render_params rp;
    camera(&rp, 401, 301, 12, 40);
    rp.cut_axis = 0;
    rp.cut_value = 0.0;
    Exr e = read_exr(render_to(ctx, p, &rp, "cut.exr"));
    size_t n[3] = {0, 0, 0};
    for (size_t q = 0; q < e.id.size(); q++)
        if (e.id[q] < 3) n[e.id[q]]++;
    double f = focal(rp), disk = sphere_area_px(f, 1.0, 12, 12);
    fprintf(stderr, "   cut: %zu %zu %zu pixels (full disk %.1f)\n", n[0], n[1], n[2], disk);
    ASSERT_EQ_INT(n[1], 0);
    ASSERT_TRUE(n[0] > 0.9 * sphere_area_px(f, 1.0, sqrt(12 * 12 + 2.5 * 2.5), 12));
    ASSERT_NEAR(n[2] / (0.5 * disk), 1.0, 0.03); // the half on the - side
    // without the cut, all three show
    rp.cut_axis = -1;
    e = read_exr(render_to(ctx, p, &rp, "nocut.exr"));
    size_t m1 = 0;
    for (unsigned v : e.id) m1 += v == 1;
    ASSERT_TRUE(m1 > 0);
    vp_particles_destroy(p);
    vp_context_destroy(ctx);
}

static std::string slurp(const std::string &path) {
    std::ifstream f(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
}

static void test_one_thread_equals_two() {
    vp_context *ctx = nullptr;
    vp_context_create(&ctx);
    // a small random cloud of octahedra with random orientations
    const size_t n = 2000;
    vp_particles *p = make_set(ctx, n);
    p->shape = VP_SHAPE_OCTAHEDRON;
    p->has_orient = 1;
    p->orients = (float *)malloc(4 * n * sizeof(float));
    uint64_t s = 12345;
    auto rnd = [&s]() {
        s = s * 6364136223846793005ull + 1442695040888963407ull;
        return (double)(s >> 11) / 9007199254740992.0;
    };
    for (size_t i = 0; i < n; i++) {
        set_sphere(p, i, rnd(), rnd(), rnd(), 0.02 + 0.03 * rnd());
        double q[4] = {rnd() - 0.5, rnd() - 0.5, rnd() - 0.5, rnd() - 0.5};
        for (int k = 0; k < 4; k++) p->orients[4 * i + k] = (float)q[k];
    }
    vp_render_params rp;
    vp_render_params_init(&rp);
    rp.width = 320;
    rp.height = 200;
    vp_context_set_threads(ctx, 1);
    std::string a = slurp(render_to(ctx, p, &rp, "t1.exr"));
    vp_context_set_threads(ctx, 2);
    std::string b = slurp(render_to(ctx, p, &rp, "t2.exr"));
    vp_context_set_threads(ctx, 7);
    std::string c = slurp(render_to(ctx, p, &rp, "t7.exr"));
    ASSERT_TRUE(a.size() > 1000);
    ASSERT_TRUE(a == b);
    ASSERT_TRUE(a == c);
    vp_particles_destroy(p);
    vp_context_destroy(ctx);
}

static void test_bad_parameters() {
    vp_context *ctx = nullptr;
    vp_context_create(&ctx);
    vp_particles *p = make_set(ctx, 1);
    set_sphere(p, 0, 0, 0, 0, 1.0);
    vp_image *img = nullptr;
    vp_render_params rp;
    vp_render_params_init(&rp);
    rp.width = 0;
    ASSERT_EQ_INT(vp_render(ctx, p, &rp, &img), VP_ERR_INVALID_ARGUMENT);
    ASSERT_TRUE(img == nullptr);
    vp_render_params_init(&rp);
    rp.width = 16384, rp.height = 16384;
    ASSERT_EQ_INT(vp_render(ctx, p, &rp, &img), VP_ERR_INVALID_ARGUMENT);
    vp_render_params_init(&rp);
    rp.cut_axis = 2, rp.cut_value = -5; // removes everything
    ASSERT_EQ_INT(vp_render(ctx, p, &rp, &img), VP_ERR_INVALID_ARGUMENT);
    ASSERT_TRUE(strstr(vp_context_message(ctx), "cut") != nullptr);
    vp_render_params_init(&rp);
    rp.view = VP_VIEW_CAMERA; // eye == target
    ASSERT_EQ_INT(vp_render(ctx, p, &rp, &img), VP_ERR_INVALID_ARGUMENT);
    p->count = 0;
    ASSERT_EQ_INT(vp_render(ctx, p, nullptr, &img), VP_ERR_INVALID_ARGUMENT);
    p->count = 1;
    ASSERT_EQ_INT(vp_render(ctx, p, nullptr, &img), VP_OK);
    ASSERT_EQ_INT(vp_image_write(ctx, img, (g_dir + "/x.jpg").c_str()), VP_ERR_INVALID_ARGUMENT);
    ASSERT_EQ_INT(vp_image_write(ctx, img, (g_dir + "/nodir/x.exr").c_str()), VP_ERR_IO);
    vp_image_destroy(img);
    vp_image_destroy(nullptr);
    vp_particles_destroy(p);
    vp_context_destroy(ctx);
}

int main() {
    char tmpl[] = "/tmp/vp_render_test.XXXXXX";
    if (!mkdtemp(tmpl)) return 1;
    g_dir = tmpl;
    RUN_TEST(test_spheres_channels_coverage_depth_id);
    RUN_TEST(test_cube_face_on_and_orientation);
    RUN_TEST(test_cut_plane_removes_the_plus_side);
    RUN_TEST(test_one_thread_equals_two);
    RUN_TEST(test_bad_parameters);
    std::string cmd = "rm -rf '" + g_dir + "'";
    if (system(cmd.c_str()) != 0) return 1;
    fprintf(stderr, "all render tests passed\n");
    return 0;
}
