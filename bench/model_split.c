/* SPDX-License-Identifier: Apache-2.0 */
// A model, not vdbpack's code: how much work (darts, cells split, children
// made, ball tests) random sequential addition in a periodic unit box
// needs to reach N spheres at a packing fraction F, with its active cells
// split (0) all at once, as src/random/rsa.c does (Ebeida et al.), but
// without its look-ahead, masks and top balls, or (1) one cell at a time,
// after K failed darts in it, the cells of every level sampled with weights
// by volume (the alternative docs/rsa.md weighs). Counts, not times.
//   build/bench/model_split N F MODE [K [SEED]]
//   build/bench/model_split 100000 0.333 0;  ... 100000 0.333 1 4
#include <stdio.h>
#include <stdlib.h>
#include <math.h>
#include <stdint.h>
#include <string.h>
#define PI_ 3.14159265358979323846
static uint64_t s = 88172645463325252ULL;
static inline uint64_t R() {
    s ^= s << 13;
    s ^= s >> 7;
    s ^= s << 17;
    return s;
}
static inline double U() { return (R() >> 11) * (1.0 / 9007199254740992.0); }
static double r, d2;
static int G;
static double gs;
static int *head, *nxt;
static double *P;
static int n = 0;
static long balltests = 0;
static inline double pd(double a) {
    a -= round(a);
    return a;
}
static int free_at(double x, double y, double z) {
    int cx = (int)(x / gs) % G, cy = (int)(y / gs) % G, cz = (int)(z / gs) % G;
    for (int dx = -1; dx <= 1; dx++)
        for (int dy = -1; dy <= 1; dy++)
            for (int dz = -1; dz <= 1; dz++) {
                int gx = (cx + dx + G) % G, gy = (cy + dy + G) % G, gz = (cz + dz + G) % G;
                for (int j = head[(gx * G + gy) * G + gz]; j >= 0; j = nxt[j]) {
                    balltests++;
                    double ex = pd(P[3 * j] - x), ey = pd(P[3 * j + 1] - y),
                           ez = pd(P[3 * j + 2] - z);
                    if (ex * ex + ey * ey + ez * ez < d2) return 0;
                }
            }
    return 1;
}
static void add(double x, double y, double z) {
    int cx = (int)(x / gs) % G, cy = (int)(y / gs) % G, cz = (int)(z / gs) % G;
    int c = (cx * G + cy) * G + cz;
    P[3 * n] = x;
    P[3 * n + 1] = y;
    P[3 * n + 2] = z;
    nxt[n] = head[c];
    head[c] = n;
    n++;
}
// cell covered by one ball: farthest corner within 2r
static int covered(double x0, double y0, double z0, double h) {
    double cx = x0 + h / 2, cy = y0 + h / 2, cz = z0 + h / 2;
    int gx0 = (int)floor(cx / gs), gy0 = (int)floor(cy / gs), gz0 = (int)floor(cz / gs);
    for (int dx = -1; dx <= 1; dx++)
        for (int dy = -1; dy <= 1; dy++)
            for (int dz = -1; dz <= 1; dz++) {
                int gx = ((gx0 + dx) % G + G) % G, gy = ((gy0 + dy) % G + G) % G,
                    gz = ((gz0 + dz) % G + G) % G;
                for (int j = head[(gx * G + gy) * G + gz]; j >= 0; j = nxt[j]) {
                    balltests++;
                    double ex = fabs(pd(P[3 * j] - cx)) + h / 2,
                           ey = fabs(pd(P[3 * j + 1] - cy)) + h / 2,
                           ez = fabs(pd(P[3 * j + 2] - cz)) + h / 2;
                    if (ex * ex + ey * ey + ez * ez <= d2) return 1;
                }
            }
    return 0;
}
typedef struct {
    float x, y, z;
    int fails;
} cell;
typedef struct {
    cell *c;
    long n, cap;
} clist;
static void push(clist *l, cell c) {
    if (l->n == l->cap) {
        l->cap = l->cap ? 2 * l->cap : 1024;
        l->c = realloc(l->c, l->cap * sizeof(cell));
    }
    l->c[l->n++] = c;
}
#define ML 30
int main(int argc, char **argv) {
    if (argc < 4) {
        fprintf(stderr, "usage: model_split N F MODE(0|1) [K [SEED]]\n");
        return 2;
    }
    int N = atoi(argv[1]);
    double target = atof(argv[2]);
    int mode = atoi(argv[3]);
    int K = argc > 4 ? atoi(argv[4]) : 4;
    if (argc > 5) s += strtoull(argv[5], 0, 10) * 0x9E3779B97F4A7C15ULL;
    if (N < 1000 || !(target > 0 && target < 0.38) || K < 1) {
        fprintf(stderr, "model_split: N >= 1000, 0 < F < 0.38, K >= 1\n");
        return 2;
    }
    r = cbrt(3 * target / N / (4 * PI_));
    d2 = 4 * r * r;
    G = (int)(1.0 / (2 * r));
    gs = 1.0 / G;
    head = malloc(sizeof(int) * G * G * G);
    for (long i = 0; i < (long)G * G * G; i++) head[i] = -1;
    nxt = malloc(sizeof(int) * 4 * N);
    P = malloc(sizeof(double) * 12 * N);
    // level 0 side: 2*(2r/sqrt3) rounded so it tiles the box
    int M = (int)ceil(1.0 / (2 * 2 * r / sqrt(3.0)));
    double h0 = 1.0 / M;
    clist L[ML];
    memset(L, 0, sizeof L);
    for (int i = 0; i < M; i++)
        for (int j = 0; j < M; j++)
            for (int k = 0; k < M; k++) {
                cell c = {i * h0, j * h0, k * h0, 0};
                push(&L[0], c);
            }
    long darts = 0, made = (long)M * M * M, splits = 0;
    int lev = 0;
    long target_n = N;
    if (mode == 0) { // uniform
        long thrown_level = 0;
        while (n < target_n) {
            clist *A = &L[lev];
            if (A->n == 0) break;
            double h = h0 / (1 << lev);
            long batch = A->n / 4;
            if (batch < 256) batch = 256;
            if (batch > 8192) batch = 8192;
            long succ = 0;
            for (long b = 0; b < batch && n < target_n && A->n > 0; b++) {
                long ci = R() % A->n;
                cell c = A->c[ci];
                double x = c.x + U() * h, y = c.y + U() * h, z = c.z + U() * h;
                darts++;
                thrown_level++;
                if (free_at(x, y, z)) {
                    add(x, y, z);
                    succ++;
                    if (h * sqrt(3.0) <= 2 * r + 1e-15) {
                        A->c[ci] = A->c[--A->n];
                    }
                }
            }
            if (A->n == 0) break;
            if (succ * 4 < batch && thrown_level >= 4 * A->n) {
                double hc = h / 2;
                clist *B = &L[lev + 1];
                for (long i = 0; i < A->n; i++) {
                    cell c = A->c[i];
                    splits++;
                    for (int o = 0; o < 8; o++) {
                        cell d = {c.x + (o & 1) * hc, c.y + ((o >> 1) & 1) * hc,
                                  c.z + ((o >> 2) & 1) * hc, 0};
                        made++;
                        if (!covered(d.x, d.y, d.z, hc)) push(B, d);
                    }
                }
                A->n = 0;
                lev++;
                thrown_level = 0;
            }
        }
    } else { // adaptive: choose level by volume, cell uniform; split a cell after K fails
        double vol[ML];
        while (n < target_n) {
            double tot = 0;
            for (int l = 0; l < ML; l++) {
                vol[l] = L[l].n * pow(h0 / (1 << l), 3);
                tot += vol[l];
            }
            if (tot <= 0) break;
            for (int b = 0; b < 4096 && n < target_n; b++) {
                double u = U() * tot;
                int l = 0;
                while (l < ML - 1 && (u >= vol[l] || L[l].n == 0)) {
                    u -= vol[l];
                    l++;
                }
                clist *A = &L[l];
                if (A->n == 0) break;
                double h = h0 / (1 << l);
                long ci = R() % A->n;
                cell *c = &A->c[ci];
                double x = c->x + U() * h, y = c->y + U() * h, z = c->z + U() * h;
                darts++;
                if (free_at(x, y, z)) {
                    add(x, y, z);
                    if (h * sqrt(3.0) <= 2 * r + 1e-15) {
                        A->c[ci] = A->c[--A->n];
                        vol[l] -= pow(h, 3);
                        tot -= pow(h, 3);
                    } else c->fails = 0;
                } else if (++c->fails >= K && l < ML - 1) {
                    cell cc = *c;
                    A->c[ci] = A->c[--A->n];
                    vol[l] -= pow(h, 3);
                    tot -= pow(h, 3);
                    splits++;
                    double hc = h / 2;
                    clist *B = &L[l + 1];
                    for (int o = 0; o < 8; o++) {
                        cell d = {cc.x + (o & 1) * hc, cc.y + ((o >> 1) & 1) * hc,
                                  cc.z + ((o >> 2) & 1) * hc, 0};
                        made++;
                        if (!covered(d.x, d.y, d.z, hc)) {
                            push(B, d);
                            vol[l + 1] += pow(hc, 3);
                            tot += pow(hc, 3);
                        }
                    }
                }
                if (tot <= 1e-300) break;
            }
        }
    }
    long live = 0;
    for (int l = 0; l < ML; l++) live += L[l].n;
    if (mode) printf("adaptive, K %d: ", K);
    else printf("uniform: ");
    printf("mode %d K %d: n %d frac %.4f darts %.2f/sph splits %.2f/sph made %.2f/sph balltests "
           "%.1f/sph live %ld\n",
           mode, mode ? K : 0, n, n * 4.0 / 3 * PI_ * r * r * r, (double)darts / n,
           (double)splits / n, (double)made / n, (double)balltests / n, live);
}
