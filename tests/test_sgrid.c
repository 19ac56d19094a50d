/* SPDX-License-Identifier: Apache-2.0 */
/* Unit tests of src/core/sgrid.c: vp_sgrid_query_near (own cell first)
 * visits exactly the particles that vp_sgrid_query visits, each once, on
 * grids of one and of several levels, for query points inside and
 * outside the grid (clamped to its border cells); every particle within
 * reach + r_j is among them. */
#include "core/sgrid.h"
#include "vp_test.h"

#include <stdint.h>
#include <string.h>

static uint64_t rng_state = 0x2545F4914F6CDD1Dull;
static double urand(void) {
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return (double)(rng_state >> 11) * (1.0 / 9007199254740992.0);
}

#define N 3000

typedef struct visits {
    unsigned char seen[N];
    int count, dup;
} visits;

static int mark(void *user, uint32_t j) {
    visits *v = user;
    if (v->seen[j]) v->dup++;
    v->seen[j] = 1;
    v->count++;
    return 0;
}

static double pos[N][3], rad[N];

static void run(double rmin, double rmax) {
    vp_sgrid g;
    double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
    ASSERT_EQ_INT(vp_sgrid_init(&g, lo, hi, rmin, rmax, 2 * N), 0);
    for (int i = 0; i < N; i++) {
        for (int k = 0; k < 3; k++) pos[i][k] = 1.1 * urand() - 0.05; /* some outside */
        rad[i] = rmin + (rmax - rmin) * urand();
        ASSERT_EQ_INT(vp_sgrid_insert(&g, (uint32_t)i, pos[i], rad[i]), 0);
    }
    static visits a, b;
    long total = 0;
    for (int it = 0; it < 400; it++) {
        double p[3], reach = rmin * (0.5 + 2.0 * urand());
        for (int k = 0; k < 3; k++) p[k] = 1.2 * urand() - 0.1;
        memset(&a, 0, sizeof a);
        memset(&b, 0, sizeof b);
        vp_sgrid_query(&g, p, reach, mark, &a);
        vp_sgrid_query_near(&g, p, reach, mark, &b);
        ASSERT_EQ_INT(b.dup, 0);
        ASSERT_EQ_INT(a.count, b.count);
        ASSERT_TRUE(memcmp(a.seen, b.seen, N) == 0);
        for (int j = 0; j < N; j++) { /* a superset of the particles within reach + r_j */
            double d2 = 0;
            for (int k = 0; k < 3; k++) d2 += (p[k] - pos[j][k]) * (p[k] - pos[j][k]);
            if (d2 < (reach + rad[j]) * (reach + rad[j])) ASSERT_TRUE(b.seen[j]);
        }
        total += b.count;
    }
    ASSERT_TRUE(total > 400); /* the queries did find particles */
    vp_sgrid_free(&g);
}

int main(void) {
    RUN_CASE(one_level, run(0.03, 0.03));
    RUN_CASE(several_levels, run(0.01, 0.09));
    fprintf(stderr, "all sgrid tests passed\n");
    return 0;
}
