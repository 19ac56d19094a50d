/* SPDX-License-Identifier: Apache-2.0 */
/* lattice_enum: the densest lattice packing of a convex polytope K by
 * enumerating Minkowski's configurations, after Betke & Henk (2000,
 * "Densest lattice packings of 3-polytopes", Comput. Geom. 16, 157-186).
 *
 * A lattice L packs K iff no non-zero vector of L lies in the interior of
 * the difference body D = K - K. A densest packing lattice is a critical
 * lattice of D, and (Minkowski) a critical lattice of a 3-dimensional
 * o-symmetric convex body has a basis b1, b2, b3 with six points on the
 * boundary of D in one of two patterns:
 *   chain: b1, b2, b1+b2, b3, b2+b3, b1+b2+b3   (the FCC pattern up to a
 *          change of basis: b1, b2, b3, b1-b2, b2-b3, b3-b1);
 *   sums:  b1, b2, b1+b2, b3, b1+b3, b2+b3      (a seventh point,
 *          b1+b2+b3, makes the chain pattern too).
 * For a polytope each point lies in a facet of D, where its constraint is
 * linear in B. The program assigns a facet to each point in turn (b1's up
 * to D's symmetry), prunes an assignment as soon as a linear program finds
 * no basis that keeps the points so far in their facets and inside D, and
 * at each complete assignment (a three-dimensional polytope of bases)
 * minimises |det B| by an active-set Newton method from many starts,
 * keeping minima whose lattice is admissible (least gauge over |n_i| <= 3
 * of the reduced basis at least 1; a minimum that lets another lattice
 * vector in gets a linear cut holding it out, and is minimised again).
 * The fraction is V(K) / min |det B|.
 *
 * This is a numerical search: the leaves' minimisations are local (from
 * 40 starts each) and the linear programs use tolerances of 1e-10; it is
 * exhaustive over the configurations. docs/lattices.md has its results.
 *
 * Input: the file `scripts/archimedean_lattices.py --diff-body NAME`
 * writes: "M V" then M rows g with gauge_D(x) = max |g . x|.
 * Usage: lattice_enum FILE [--pattern chain|sums|both] [--starts N]
 *                          [--part I/N]
 * Prints the best fraction, its basis and counts; --part runs every N-th
 * branch (for parallel runs by hand; the best of the parts is the result).
 * LATTICE_ENUM_TABLEAU=1 solves every LP by the tableau (a cross-check).
 * Exit 0 with a result, 1 on bad input or when nothing is admissible. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define MAXG 128        /* facet pairs of D */
#define MAXF (2 * MAXG) /* signed facets */
#define MAXR (6 * MAXF) /* inequality rows of a leaf */
#define MAXV 10         /* LP variables: the null space and the slack */

/* ---------------- D, the patterns ---------------- */
static int ng, nf;
static double G[MAXG][3], A[MAXF][3], volume_k;
static const int PATTERN[2][6][3] = {
    {{1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {0, 0, 1}, {0, 1, 1}, {1, 1, 1}},
    {{1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {0, 0, 1}, {1, 0, 1}, {0, 1, 1}},
};
static const char *PATTERN_NAME[2] = {"chain", "sums"};

static double dot3(const double *a, const double *b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
static double det_rows(const double *a, const double *b, const double *c) {
    return a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
           a[2] * (b[0] * c[1] - b[1] * c[0]);
}

static uint64_t rng_state = 0x9e3779b97f4a7c15ull;
static double urand(void) {
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return (double)(rng_state >> 11) / 9007199254740992.0;
}

/* Gaussian elimination with partial pivoting; M (n*n) is overwritten,
 * b becomes the solution. 0 when singular. */
static int solve(int n, double *M, double *b) {
    for (int c = 0; c < n; c++) {
        int p = c;
        for (int r = c + 1; r < n; r++)
            if (fabs(M[r * n + c]) > fabs(M[p * n + c])) p = r;
        if (fabs(M[p * n + c]) < 1e-14) return 0;
        if (p != c) {
            for (int k = 0; k < n; k++) {
                double t = M[c * n + k];
                M[c * n + k] = M[p * n + k];
                M[p * n + k] = t;
            }
            double t = b[c];
            b[c] = b[p];
            b[p] = t;
        }
        for (int r = c + 1; r < n; r++) {
            double f = M[r * n + c] / M[c * n + c];
            for (int k = c; k < n; k++) M[r * n + k] -= f * M[c * n + k];
            b[r] -= f * b[c];
        }
    }
    for (int c = n - 1; c >= 0; c--) {
        double s = b[c];
        for (int k = c + 1; k < n; k++) s -= M[c * n + k] * b[k];
        b[c] = s / M[c * n + c];
    }
    return 1;
}

/* Orthonormalises v against the first `count` rows of Q (twice, for
 * accuracy); returns its remaining length, v normalised when not tiny. */
static double orthonormalise(double *v, int dim, double Q[][9], int count) {
    for (int pass = 0; pass < 2; pass++)
        for (int i = 0; i < count; i++) {
            double s = 0;
            for (int q = 0; q < dim; q++) s += v[q] * Q[i][q];
            for (int q = 0; q < dim; q++) v[q] -= s * Q[i][q];
        }
    double l = 0;
    for (int q = 0; q < dim; q++) l += v[q] * v[q];
    l = sqrt(l);
    if (l > 1e-300)
        for (int q = 0; q < dim; q++) v[q] /= l;
    return l;
}

/* ---------------- linear programs ----------------
 * min c.z subject to R z <= d, from a feasible z: an active-set method
 * (the projected gradient walks along faces; Bland's smallest index on
 * ties). Returns 0 at an optimum, < 0 on failure (singular working set,
 * no progress in 2000 iterations); callers retry with perturbed d. */
static double R[MAXR + 1][MAXV], rhs[MAXR + 1];
static long lp_failures, lp_unresolved, tableau_solves;

static int lp_min(int m, int n, const double *c, double *z) {
    int W[MAXV], nw = 0;
    static char in_w[MAXR + 1];
    memset(in_w, 0, (size_t)m);
    for (int it = 0; it < 2000; it++) {
        double p[MAXV], mu[MAXV];
        if (nw) {
            double Gm[MAXV * MAXV];
            for (int i = 0; i < nw; i++) {
                for (int j = 0; j < nw; j++) {
                    double s = 0;
                    for (int k = 0; k < n; k++) s += R[W[i]][k] * R[W[j]][k];
                    Gm[i * nw + j] = s;
                }
                double s = 0;
                for (int k = 0; k < n; k++) s += R[W[i]][k] * c[k];
                mu[i] = s;
            }
            if (!solve(nw, Gm, mu)) return -2;
        }
        double pn = 0;
        for (int k = 0; k < n; k++) {
            double s = -c[k];
            for (int i = 0; i < nw; i++) s += R[W[i]][k] * mu[i];
            p[k] = s;
            pn += s * s;
        }
        pn = nw == n ? 0 : sqrt(pn);
        if (pn < 1e-11) { /* a KKT point unless a multiplier is negative */
            int drop = -1;
            for (int i = 0; i < nw; i++)
                if (mu[i] > 1e-12 && (drop < 0 || W[i] < W[drop])) drop = i;
            if (drop < 0) return 0;
            in_w[W[drop]] = 0;
            W[drop] = W[--nw];
            continue;
        }
        double step = HUGE_VAL;
        int block = -1;
        for (int i = 0; i < m; i++) {
            if (in_w[i]) continue;
            double rp = 0, rz = 0, rn = 0;
            for (int k = 0; k < n; k++) {
                rp += R[i][k] * p[k];
                rz += R[i][k] * z[k];
                rn += R[i][k] * R[i][k];
            }
            if (rp <= 1e-9 * sqrt(rn) * pn) continue; /* parallel to the face: not blocking */
            double a = (rhs[i] - rz) / rp;
            if (a < 0) a = 0;
            if (a < step - 1e-15) {
                step = a;
                block = i;
            }
        }
        if (block < 0) return -1;
        for (int k = 0; k < n; k++) z[k] += step * p[k];
        if (nw >= n) return -3;
        W[nw++] = block;
        in_w[block] = 1;
    }
    return -4;
}

/* ---------------- an assignment: points in facets ----------------
 * x = vec(B) (rows b1, b2, b3) = x0 + N y; rows Cy y <= dy keep every
 * assigned point inside D. */
static int pattern, npoints, facet_of[6];
static double x0[9], N[9][9], Cy[MAXR][9], dy[MAXR];
static int kdim, nrows;

static void point_row(int k, const double *a, double *row) {
    for (int j = 0; j < 3; j++)
        for (int q = 0; q < 3; q++) row[3 * j + q] = PATTERN[pattern][k][j] * a[q];
}

/* Sets x0, N and the rows from facet_of[0..npoints); 0 when the
 * equalities are inconsistent. */
static int build(void) {
    double E[6][9], Q[9][9];
    int rank = 0, ind[6];
    for (int k = 0; k < npoints; k++) {
        point_row(k, A[facet_of[k]], E[k]);
        double v[9];
        memcpy(v, E[k], sizeof v);
        if (orthonormalise(v, 9, Q, rank) < 1e-9) continue;
        memcpy(Q[rank], v, sizeof v);
        ind[rank++] = k;
    }
    double Gm[36], w[6];
    for (int i = 0; i < rank; i++) {
        for (int j = 0; j < rank; j++) {
            double s = 0;
            for (int q = 0; q < 9; q++) s += E[ind[i]][q] * E[ind[j]][q];
            Gm[i * rank + j] = s;
        }
        w[i] = 1;
    }
    if (rank && !solve(rank, Gm, w)) return 0;
    for (int q = 0; q < 9; q++) {
        double s = 0;
        for (int i = 0; i < rank; i++) s += E[ind[i]][q] * w[i];
        x0[q] = s;
    }
    for (int k = 0; k < npoints; k++) {
        double s = 0;
        for (int q = 0; q < 9; q++) s += E[k][q] * x0[q];
        if (fabs(s - 1) > 1e-9) return 0;
    }
    kdim = 0;
    for (int u = 0; u < 9 && rank + kdim < 9; u++) {
        double v[9] = {0};
        v[u] = 1;
        if (orthonormalise(v, 9, Q, rank + kdim) < 1e-6) continue;
        memcpy(Q[rank + kdim], v, sizeof v);
        for (int q = 0; q < 9; q++) N[q][kdim] = v[q];
        kdim++;
    }
    nrows = 0;
    for (int k = 0; k < npoints; k++)
        for (int f = 0; f < nf; f++) {
            if (f == facet_of[k] || f == (facet_of[k] ^ 1)) continue;
            double row[9], s = 0;
            point_row(k, A[f], row);
            for (int q = 0; q < 9; q++) s += row[q] * x0[q];
            for (int c = 0; c < kdim; c++) {
                double t = 0;
                for (int q = 0; q < 9; q++) t += row[q] * N[q][c];
                Cy[nrows][c] = t;
            }
            dy[nrows++] = 1 - s;
        }
    return 1;
}

/* The same LP by a dense tableau simplex with Bland's rule, which cannot
 * cycle (slower: the fallback when the active-set method fails). With
 * s = s0 - u (s0 feasible at y = 0) and y = y+ - y-, it is max u subject
 * to [Cy, -Cy, 1] (y+, y-, u) <= dy + s0 (all >= 0), u <= s0 + 1, whose
 * origin is a feasible vertex. Returns the least s, y in yout; HUGE_VAL on
 * failure. */
static double phase1_tableau(double *yout) {
    const int k = kdim, nv = 2 * k + 1, m = nrows + 1, cols = nv + m + 1; /* + rhs */
    double *T = calloc((size_t)(m + 1) * (size_t)cols, sizeof *T);
    int *basis = malloc((size_t)m * sizeof *basis);
    if (!T || !basis) {
        free(T);
        free(basis);
        return HUGE_VAL;
    }
    double s0 = -1;
    for (int i = 0; i < nrows; i++)
        if (-dy[i] > s0) s0 = -dy[i];
    for (int i = 0; i < m; i++) {
        double *row = T + (size_t)i * cols;
        if (i < nrows) {
            for (int c = 0; c < k; c++) {
                row[c] = Cy[i][c];
                row[k + c] = -Cy[i][c];
            }
            row[2 * k] = 1;
            row[cols - 1] = dy[i] + s0;
        } else {
            row[2 * k] = 1;
            row[cols - 1] = s0 + 1;
        }
        row[nv + i] = 1;
        basis[i] = nv + i;
    }
    double *obj = T + (size_t)m * cols; /* reduced profits of max u, as -1 */
    obj[2 * k] = -1;
    int ok = 0;
    for (int it = 0; it < 50000; it++) {
        int enter = -1;
        for (int j = 0; j < nv + m; j++)
            if (obj[j] < -1e-12) {
                enter = j;
                break;
            }
        if (enter < 0) {
            ok = 1;
            break;
        }
        int leave = -1;
        double best = HUGE_VAL;
        for (int i = 0; i < m; i++) {
            double a = T[(size_t)i * cols + enter];
            if (a <= 1e-12) continue;
            double r = T[(size_t)i * cols + cols - 1] / a;
            if (r < best - 1e-15 || (r < best + 1e-15 && leave >= 0 && basis[i] < basis[leave])) {
                best = r;
                leave = i;
            }
        }
        if (leave < 0) break; /* unbounded: cannot happen with u bounded */
        double *pr = T + (size_t)leave * cols, piv = pr[enter];
        for (int j = 0; j < cols; j++) pr[j] /= piv;
        for (int i = 0; i <= m; i++) {
            if (i == leave) continue;
            double *row = T + (size_t)i * cols, f = row[enter];
            if (f == 0) continue;
            for (int j = 0; j < cols; j++) row[j] -= f * pr[j];
        }
        basis[leave] = enter;
    }
    double val[2 * 9 + 1] = {0};
    for (int i = 0; i < m; i++)
        if (basis[i] < nv) val[basis[i]] = T[(size_t)i * cols + cols - 1];
    free(T);
    free(basis);
    if (!ok) return HUGE_VAL;
    if (yout)
        for (int c = 0; c < k; c++) yout[c] = val[c] - val[k + c];
    return s0 - val[2 * k];
}

/* The least s with Cy y - s <= dy (s >= -1), y in yout: <= 0 when the
 * assignment is feasible. When the active-set LP fails, the tableau
 * simplex solves it; when that fails too, the right-hand sides are
 * perturbed (1e-10 .. 1e-8, relaxing them) for the active-set LP again;
 * -HUGE_VAL when nothing solves it (callers then keep the branch). */
static int force_tableau; /* LATTICE_ENUM_TABLEAU=1: every LP by the tableau (a cross-check) */

static double phase1(double *yout) {
    const int n = kdim + 1;
    if (force_tableau) {
        double s = phase1_tableau(yout);
        if (s < HUGE_VAL) {
            tableau_solves++;
            return s;
        }
    }
    for (int attempt = 0; attempt < 4; attempt++) {
        if (attempt == 1) {
            double s = phase1_tableau(yout);
            if (s < HUGE_VAL) {
                tableau_solves++;
                return s;
            }
        }
        double scale = attempt ? 1e-11 * pow(10.0, attempt) : 0;
        double z[MAXV] = {0}, c[MAXV] = {0}, s0 = -1;
        for (int i = 0; i < nrows; i++) {
            for (int k = 0; k < kdim; k++) R[i][k] = Cy[i][k];
            R[i][kdim] = -1;
            rhs[i] = dy[i] + scale * urand();
            if (-rhs[i] > s0) s0 = -rhs[i];
        }
        for (int k = 0; k < kdim; k++) R[nrows][k] = 0;
        R[nrows][kdim] = -1;
        rhs[nrows] = 1;
        z[kdim] = s0 + 1e-12;
        c[kdim] = 1;
        if (lp_min(nrows + 1, n, c, z) == 0) {
            /* a perturbed (relaxed) LP can only say "feasible" more often:
             * a branch is never dropped for it */
            if (yout) memcpy(yout, z, sizeof(double) * (size_t)kdim);
            return z[kdim];
        }
        lp_failures++;
    }
    lp_unresolved++;
    return -HUGE_VAL;
}

/* ---------------- lattices ---------------- */
static int Z3[342][3], nz3;

/* The least gauge over the lattice vectors z B, |z_i| <= 3; *zmin (may be
 * NULL) gets its z. */
static double least_gauge(double B[3][3], int *zmin) {
    double best = HUGE_VAL;
    for (int z = 0; z < nz3; z++) {
        double x[3], g = 0;
        for (int k = 0; k < 3; k++)
            x[k] = Z3[z][0] * B[0][k] + Z3[z][1] * B[1][k] + Z3[z][2] * B[2][k];
        for (int a = 0; a < ng && g < best; a++) {
            double p = fabs(dot3(G[a], x));
            if (p > g) g = p;
        }
        if (g < best) {
            best = g;
            if (zmin) memcpy(zmin, Z3[z], sizeof Z3[z]);
        }
    }
    return best;
}

/* Pairwise (Lagrange) reduction; U (may be NULL) becomes the unimodular
 * matrix with B_reduced = U B. */
static void reduce(double B[3][3], double U[3][3]) {
    double Ul[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    for (int it = 0; it < 100; it++) {
        int changed = 0;
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++) {
                if (i == j) continue;
                double bb = dot3(B[j], B[j]);
                if (bb < 1e-300) goto out;
                double m = round(dot3(B[i], B[j]) / bb);
                if (m != 0) {
                    for (int k = 0; k < 3; k++) {
                        B[i][k] -= m * B[j][k];
                        Ul[i][k] -= m * Ul[j][k];
                    }
                    changed = 1;
                }
            }
        if (!changed) break;
    }
out:
    if (U) memcpy(U, Ul, sizeof Ul);
}

static void basis_of(const double *y, double B[3][3]) {
    for (int q = 0; q < 9; q++) {
        double s = x0[q];
        for (int c = 0; c < kdim; c++) s += N[q][c] * y[c];
        (&B[0][0])[q] = s;
    }
}
static double det_of(const double *y) {
    double B[3][3];
    basis_of(y, B);
    return det_rows(B[0], B[1], B[2]);
}
static double violation(const double *y) {
    double v = -HUGE_VAL;
    for (int i = 0; i < nrows; i++) {
        double s = -dy[i];
        for (int c = 0; c < kdim; c++) s += Cy[i][c] * y[c];
        if (s > v) v = s;
    }
    return v;
}

/* Gradient and Hessian of det B(y): det is linear in each row, so a
 * derivative replaces rows of B by rows of the direction N_c. */
static void det_derivatives(const double *y, double *g, double H[9][9]) {
    double B[3][3], Nc[9][3][3];
    basis_of(y, B);
    for (int c = 0; c < kdim; c++)
        for (int q = 0; q < 9; q++) (&Nc[c][0][0])[q] = N[q][c];
    for (int c = 0; c < kdim; c++)
        g[c] = det_rows(Nc[c][0], B[1], B[2]) + det_rows(B[0], Nc[c][1], B[2]) +
               det_rows(B[0], B[1], Nc[c][2]);
    for (int c = 0; c < kdim; c++)
        for (int e = 0; e < kdim; e++)
            H[c][e] = det_rows(Nc[c][0], Nc[e][1], B[2]) + det_rows(Nc[c][0], B[1], Nc[e][2]) +
                      det_rows(Nc[e][0], Nc[c][1], B[2]) + det_rows(B[0], Nc[c][1], Nc[e][2]) +
                      det_rows(Nc[e][0], B[1], Nc[c][2]) + det_rows(B[0], Nc[e][1], Nc[c][2]);
}

/* A local minimum of sign * det B(y) subject to Cy y <= dy, from a
 * feasible y (updated in place): active set, Newton steps in the null
 * space of the active rows when the reduced Hessian is positive definite
 * (steepest descent otherwise), Armijo backtracking, and the most negative
 * multiplier dropped at a stationary point. */
static long newton_stalls;

static void newton(double *y, double sign) {
    const int n = kdim;
    int W[9], nw = 0;
    for (int it = 0; it < 300; it++) {
        double g[9], H[9][9], Q[9][9], Z[9][9];
        det_derivatives(y, g, H);
        for (int c = 0; c < n; c++) {
            g[c] *= sign;
            for (int e = 0; e < n; e++) H[c][e] *= sign;
        }
        int r = 0, nz = 0;
        for (int i = 0; i < nw; i++) {
            double v[9];
            memcpy(v, Cy[W[i]], sizeof(double) * (size_t)n);
            if (orthonormalise(v, n, Q, r) >= 1e-10) memcpy(Q[r++], v, sizeof v);
        }
        for (int u = 0; u < n && r + nz < n; u++) {
            double v[9] = {0};
            v[u] = 1;
            if (orthonormalise(v, n, Q, r) < 1e-6) continue;
            if (orthonormalise(v, n, Z, nz) < 1e-6) continue;
            memcpy(Z[nz++], v, sizeof v);
        }
        double zg[9], gn = 0;
        for (int a = 0; a < nz; a++) {
            zg[a] = 0;
            for (int c = 0; c < n; c++) zg[a] += Z[a][c] * g[c];
            gn += zg[a] * zg[a];
        }
        if (sqrt(gn) < 1e-13) {
            if (!nw) return;
            double Gm[81], lam[9];
            for (int i = 0; i < nw; i++) {
                lam[i] = 0;
                for (int j = 0; j < nw; j++) {
                    double s = 0;
                    for (int c = 0; c < n; c++) s += Cy[W[i]][c] * Cy[W[j]][c];
                    Gm[i * nw + j] = s;
                }
                for (int c = 0; c < n; c++) lam[i] -= Cy[W[i]][c] * g[c];
            }
            if (!solve(nw, Gm, lam)) {
                newton_stalls++;
                return;
            }
            int drop = -1;
            for (int i = 0; i < nw; i++)
                if (lam[i] < -1e-12 && (drop < 0 || lam[i] < lam[drop])) drop = i;
            if (drop < 0) return;
            W[drop] = W[--nw];
            continue;
        }
        double zh[81], L[81], dz[9], p[9];
        for (int a = 0; a < nz; a++)
            for (int b = 0; b < nz; b++) {
                double s = 0;
                for (int c = 0; c < n; c++)
                    for (int e = 0; e < n; e++) s += Z[a][c] * H[c][e] * Z[b][e];
                zh[a * nz + b] = s;
            }
        int definite = 1; /* Cholesky as the test */
        memcpy(L, zh, sizeof(double) * (size_t)(nz * nz));
        for (int j = 0; j < nz && definite; j++) {
            double s = L[j * nz + j];
            for (int k = 0; k < j; k++) s -= L[j * nz + k] * L[j * nz + k];
            if (s <= 1e-14) {
                definite = 0;
                break;
            }
            L[j * nz + j] = sqrt(s);
            for (int i = j + 1; i < nz; i++) {
                double t = L[i * nz + j];
                for (int k = 0; k < j; k++) t -= L[i * nz + k] * L[j * nz + k];
                L[i * nz + j] = t / L[j * nz + j];
            }
        }
        memcpy(dz, zg, sizeof(double) * (size_t)nz);
        if (definite) solve(nz, zh, dz);
        for (int c = 0; c < n; c++) {
            p[c] = 0;
            for (int a = 0; a < nz; a++) p[c] -= Z[a][c] * dz[a];
        }
        double amax = definite ? 1.0 : HUGE_VAL;
        int block = -1;
        for (int i = 0; i < nrows; i++) {
            int active = 0;
            for (int j = 0; j < nw; j++) active |= W[j] == i;
            if (active) continue;
            double rp = 0, rz = -dy[i];
            for (int c = 0; c < n; c++) {
                rp += Cy[i][c] * p[c];
                rz += Cy[i][c] * y[c];
            }
            if (rp <= 1e-15) continue;
            double a = rz < 0 ? -rz / rp : 0;
            if (a < amax) {
                amax = a;
                block = i;
            }
        }
        if (!(amax < HUGE_VAL)) {
            newton_stalls++;
            return;
        }
        double f0 = sign * det_of(y), slope = 0, a = amax, yn[9];
        for (int c = 0; c < n; c++) slope += g[c] * p[c];
        int accepted = 0;
        for (int bt = 0; bt < 60; bt++) {
            for (int c = 0; c < n; c++) yn[c] = y[c] + a * p[c];
            if (sign * det_of(yn) <= f0 + 1e-4 * a * slope) {
                accepted = 1;
                break;
            }
            a *= 0.5;
            block = -1;
        }
        if (!accepted || (a == 0 && block < 0)) {
            newton_stalls++;
            return;
        }
        memcpy(y, yn, sizeof(double) * (size_t)n);
        if (block >= 0 && nw < n) W[nw++] = block;
    }
    newton_stalls++;
}

/* The least admissible |det B| found on the current leaf: Newton from
 * the phase-1 point, from vertices (LPs of random objectives) and from
 * random convex combinations of them; HUGE_VAL when none is admissible. */
static int nstarts = 40;
static long inadmissible, cuts;
static double best_det = HUGE_VAL, best_B[3][3];

static double leaf_minimum(const double *yfeas) {
    const int n = kdim;
    double vert[24][9], best = HUGE_VAL;
    int nv = 0;
    for (int t = 0; t < 24 && n > 0; t++) {
        double c[9], z[9];
        for (int i = 0; i < nrows; i++) {
            memcpy(R[i], Cy[i], sizeof(double) * (size_t)n);
            rhs[i] = dy[i];
        }
        for (int k = 0; k < n; k++) c[k] = 2 * urand() - 1;
        memcpy(z, yfeas, sizeof(double) * (size_t)n);
        if (lp_min(nrows, n, c, z) == 0 && violation(z) < 1e-11) memcpy(vert[nv++], z, sizeof z);
    }
    const int ns = n && nv ? nstarts : 1;
    for (int s = 0; s < ns; s++) {
        double y[9] = {0};
        if (s == 0) memcpy(y, yfeas, sizeof(double) * (size_t)n);
        else if (s <= nv) memcpy(y, vert[s - 1], sizeof y);
        else {
            double wsum = 0;
            for (int v = 0; v < nv; v++) {
                double w = -log(urand() + 1e-300);
                wsum += w;
                for (int k = 0; k < n; k++) y[k] += w * vert[v][k];
            }
            for (int k = 0; k < n; k++) y[k] /= wsum;
        }
        const int base_rows = nrows;
        double d = HUGE_VAL;
        /* Newton ignores the other lattice vectors; when its minimum lets
         * one into the interior of D, that vector is held on the facet of
         * D it is nearest to leaving by (a linear cut), and again, up to
         * eight times */
        for (int round = 0; round <= 8; round++) {
            double d0 = det_of(y);
            if (d0 == 0) break;
            if (n) newton(y, d0 > 0 ? 1 : -1);
            if (violation(y) > 1e-9) break;
            double B[3][3], U[3][3];
            basis_of(y, B);
            d = fabs(det_rows(B[0], B[1], B[2]));
            if (d < 1e-9) {
                d = HUGE_VAL;
                break;
            }
            reduce(B, U);
            int zr[3] = {0, 0, 0};
            if (least_gauge(B, zr) >= 1 - 1e-9) break; /* admissible */
            d = HUGE_VAL;
            if (round == 8 || nrows >= MAXR || n == 0) {
                inadmissible++;
                break;
            }
            double z[3], x[3], row[9], s0 = 0;
            for (int j = 0; j < 3; j++) z[j] = zr[0] * U[0][j] + zr[1] * U[1][j] + zr[2] * U[2][j];
            basis_of(y, B);
            for (int q = 0; q < 3; q++) x[q] = z[0] * B[0][q] + z[1] * B[1][q] + z[2] * B[2][q];
            int fbest = 0;
            for (int f = 1; f < nf; f++)
                if (dot3(A[f], x) > dot3(A[fbest], x)) fbest = f;
            for (int j = 0; j < 3; j++)
                for (int q = 0; q < 3; q++) row[3 * j + q] = -z[j] * A[fbest][q];
            for (int q = 0; q < 9; q++) s0 += row[q] * x0[q];
            for (int c = 0; c < n; c++) {
                double t = 0;
                for (int q = 0; q < 9; q++) t += row[q] * N[q][c];
                Cy[nrows][c] = t;
            }
            dy[nrows++] = -1 - s0;
            cuts++;
            if (phase1(y) > 1e-10) break; /* no basis of the leaf keeps it out */
        }
        nrows = base_rows;
        if (d == HUGE_VAL) continue;
        if (d < best) best = d;
        if (d < best_det) {
            best_det = d;
            basis_of(y, best_B);
        }
    }
    return best;
}

/* ---------------- the enumeration ---------------- */
static long leaves, feasible_leaves, admissible_leaves, lps;
static int part, parts, branch;
#define TOP 8
static double top[TOP];
static int ntop;

static void note_top(double frac) {
    for (int i = 0; i < ntop; i++)
        if (fabs(top[i] - frac) < 1e-9) return;
    if (ntop < TOP) top[ntop++] = frac;
    else if (frac > top[TOP - 1]) top[TOP - 1] = frac;
    else return;
    for (int i = ntop - 1; i > 0 && top[i] > top[i - 1]; i--) {
        double t = top[i];
        top[i] = top[i - 1];
        top[i - 1] = t;
    }
}

static int prefix_feasible(void) {
    lps++;
    return build() && phase1(NULL) <= 1e-10;
}

static void assign(int k) {
    if (k == 6) {
        double y[9];
        leaves++;
        lps++;
        if (!build()) return;
        double s = phase1(y);
        if (s > 1e-10) return;
        feasible_leaves++;
        if (s == -HUGE_VAL) { /* no LP point: named, and Newton tried from y = 0 */
            fprintf(stderr, "lattice_enum: unresolved assignment %s %d %d %d %d %d %d\n",
                    PATTERN_NAME[pattern], facet_of[0], facet_of[1], facet_of[2], facet_of[3],
                    facet_of[4], facet_of[5]);
            memset(y, 0, sizeof y);
        }
        double d = leaf_minimum(y);
        if (d < HUGE_VAL) {
            admissible_leaves++;
            note_top(volume_k / d);
        }
        return;
    }
    for (int f = 0; f < nf; f++) {
        facet_of[k] = f;
        npoints = k + 1;
        if (k == 1 && (branch++ % parts) != part) continue;
        /* b3 (k = 3) alone is free; b1+b2 and the fifth point are tied to
         * earlier points (the sixth: the complete assignment's own LP) */
        if ((k == 2 || k == 4) && !prefix_feasible()) continue;
        assign(k + 1);
    }
    npoints = k;
}

/* Representatives of the signed facets under the signed permutation
 * matrices that map D to itself. */
static int facet_representatives(int *rep) {
    int seen[MAXF] = {0}, nrep = 0,
        perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
    double group[48][3][3];
    int ngroup = 0;
    for (int p = 0; p < 6; p++)
        for (int s = 0; s < 8; s++) {
            double M[3][3] = {{0}};
            for (int i = 0; i < 3; i++) M[i][perms[p][i]] = (s >> i) & 1 ? -1 : 1;
            int ok = 1;
            for (int f = 0; f < nf && ok; f++) {
                double img[3];
                for (int i = 0; i < 3; i++) img[i] = dot3(M[i], A[f]);
                int hit = 0;
                for (int h = 0; h < nf && !hit; h++)
                    hit = fabs(img[0] - A[h][0]) + fabs(img[1] - A[h][1]) + fabs(img[2] - A[h][2]) <
                          1e-9;
                ok = hit;
            }
            if (ok) memcpy(group[ngroup++], M, sizeof M);
        }
    for (int f = 0; f < nf; f++) {
        if (seen[f]) continue;
        rep[nrep++] = f;
        for (int gi = 0; gi < ngroup; gi++) {
            double img[3];
            for (int i = 0; i < 3; i++) img[i] = dot3(group[gi][i], A[f]);
            for (int h = 0; h < nf; h++)
                if (fabs(img[0] - A[h][0]) + fabs(img[1] - A[h][1]) + fabs(img[2] - A[h][2]) < 1e-9)
                    seen[h] = 1;
        }
    }
    fprintf(stderr, "lattice_enum: %d facets of D, symmetry group of order %d, %d classes for b1\n",
            nf, ngroup, nrep);
    return nrep;
}

static int usage(void) {
    fprintf(stderr,
            "usage: lattice_enum FILE [--pattern chain|sums|both] [--starts N] [--part I/N]\n");
    return 2;
}

int main(int argc, char **argv) {
    if (argc < 2) return usage();
    int which = 2; /* both */
    parts = 1;
    for (int i = 2; i < argc; i++) {
        if (!strcmp(argv[i], "--pattern") && i + 1 < argc) {
            i++;
            which = !strcmp(argv[i], "chain")  ? 0
                    : !strcmp(argv[i], "sums") ? 1
                    : !strcmp(argv[i], "both") ? 2
                                               : -1;
            if (which < 0) return usage();
        } else if (!strcmp(argv[i], "--starts") && i + 1 < argc) {
            nstarts = atoi(argv[++i]);
            if (nstarts < 1) return usage();
        } else if (!strcmp(argv[i], "--part") && i + 1 < argc) {
            if (sscanf(argv[++i], "%d/%d", &part, &parts) != 2 || parts < 1 || part < 0 ||
                part >= parts)
                return usage();
        } else return usage();
    }
    FILE *fp = fopen(argv[1], "r");
    if (!fp) {
        fprintf(stderr, "lattice_enum: cannot open %s\n", argv[1]);
        return 1;
    }
    if (fscanf(fp, "%d %lf", &ng, &volume_k) != 2 || ng < 3 || ng > MAXG || !(volume_k > 0)) {
        fprintf(stderr, "lattice_enum: %s: expected \"M V\" with 3 <= M <= %d\n", argv[1], MAXG);
        fclose(fp);
        return 1;
    }
    for (int i = 0; i < ng; i++)
        if (fscanf(fp, "%lf %lf %lf", &G[i][0], &G[i][1], &G[i][2]) != 3) {
            fprintf(stderr, "lattice_enum: %s: row %d unreadable\n", argv[1], i + 1);
            fclose(fp);
            return 1;
        }
    fclose(fp);
    nf = 2 * ng;
    for (int i = 0; i < ng; i++)
        for (int q = 0; q < 3; q++) {
            A[2 * i][q] = G[i][q];
            A[2 * i + 1][q] = -G[i][q];
        }
    for (int a = -3; a <= 3; a++)
        for (int b = -3; b <= 3; b++)
            for (int c = -3; c <= 3; c++)
                if (a || b || c) {
                    Z3[nz3][0] = a;
                    Z3[nz3][1] = b;
                    Z3[nz3][2] = c;
                    nz3++;
                }
    force_tableau = getenv("LATTICE_ENUM_TABLEAU") && !strcmp(getenv("LATTICE_ENUM_TABLEAU"), "1");
    int rep[MAXF], nrep = facet_representatives(rep);
    clock_t t0 = clock();
    for (int pt = 0; pt < 2; pt++) {
        if (which != 2 && which != pt) continue;
        pattern = pt;
        long l0 = leaves, f0 = feasible_leaves, a0 = admissible_leaves;
        for (int r = 0; r < nrep; r++) {
            facet_of[0] = rep[r];
            npoints = 1;
            assign(1);
        }
        printf("pattern %s: %ld assignments, %ld feasible, %ld with an admissible lattice\n",
               PATTERN_NAME[pt], leaves - l0, feasible_leaves - f0, admissible_leaves - a0);
    }
    if (best_det == HUGE_VAL) {
        printf("no admissible lattice found\n");
        return 1;
    }
    printf("best fraction %.12f (det %.12f, volume %.12f)\n", volume_k / best_det, best_det,
           volume_k);
    printf("next distinct leaf optima:");
    for (int i = 1; i < ntop; i++) printf(" %.9f", top[i]);
    printf("\nbasis:\n");
    for (int i = 0; i < 3; i++)
        printf("  %.15f %.15f %.15f\n", best_B[i][0], best_B[i][1], best_B[i][2]);
    printf(
        "linear programs %ld (%ld retried, %ld by the tableau, %ld unresolved), Newton stalls %ld, "
        "cuts %ld, minima left inadmissible %ld, %.1f s CPU\n",
        lps, lp_failures, tableau_solves, lp_unresolved, newton_stalls, cuts, inadmissible,
        (double)(clock() - t0) / CLOCKS_PER_SEC);
    return 0;
}
