# SPDX-License-Identifier: Apache-2.0
"""Dense lattice packings of the 13 Archimedean solids, searched numerically.

Regenerates src/core/lattice_archimedean.inc, the table of bases that
src/core/lattice_basis.c includes (printed on stdout: run it with the names
wanted and paste). Needs numpy only. Method (docs/lattices.md, "Archimedean
solids"): a lattice L packs a convex body K iff no non-zero vector of L lies
in the interior of the difference body D = K - K (Minkowski). The gauge of D
is max over the SAT axes n of |n.v| / w(n), w(n) the width of K along n
(for centrally symmetric K the face normals suffice). The packing fraction
of L scaled to contact is V(K) lambda1^3 / |det L|, lambda1 the least gauge
over non-zero lattice vectors. We maximise it by Nelder-Mead from many
starts, then polish: with the contact set fixed (lattice vector z, facet n
of D), the constraints n.(zB) = w(n) are linear in B, so the best lattice on
that set minimises |det| over an affine subspace (a vertex when it has nine
independent constraints). Usage: archimedean_lattices.py [name ...] [--starts N] [--seed N];
archimedean_lattices.py --check [name ...] tests the shipped bases for a
strict local optimum (KKT multipliers and the Hessian on the set that keeps
every contact); archimedean_lattices.py --diff-body NAME prints D = K - K
for scripts/lattice_enum.c, which enumerates Minkowski's configurations
(Betke & Henk's method) instead of searching
(the table: --starts 6 for most; 20 for the truncated cuboctahedron, 30
for the snub cube, which 6 starts leave short)
"""
import itertools
import math
import sys

import numpy as np

PHI = (1 + math.sqrt(5)) / 2


def perms(p, even_only):
    out = []
    for idx in itertools.permutations(range(3)):
        inv = sum(1 for i in range(3) for j in range(i + 1, 3) if idx[i] > idx[j])
        if even_only and inv % 2:
            continue
        out.append(([p[i] for i in idx], inv % 2))
    return out


def orbit(seeds, even_perm, sign_rule=None):
    """All (even) permutations and sign changes of each seed; sign_rule(perm
    parity, number of plus signs) -> keep, for the snub solids."""
    pts = []
    for s in seeds:
        for p, par in perms(s, even_perm):
            for sg in itertools.product((1, -1), repeat=3):
                if sign_rule is not None and not sign_rule(par, sum(1 for x in sg if x > 0)):
                    continue
                pts.append([a * b for a, b in zip(p, sg)])
    pts = np.array(pts, float)
    uniq = []
    for x in pts:
        if not any(np.linalg.norm(x - u) < 1e-9 for u in uniq):
            uniq.append(x)
    v = np.array(uniq)
    return v / np.linalg.norm(v, axis=1).max()


def vertices(name):
    p, r2 = PHI, math.sqrt(2)
    if name == "truncated-tetrahedron":
        return orbit([(3, 1, 1)], False, lambda par, plus: (3 - plus) % 2 == 0)
    if name == "cuboctahedron":
        return orbit([(1, 1, 0)], False)
    if name == "truncated-cube":
        return orbit([(r2 - 1, 1, 1)], False)
    if name == "truncated-octahedron":
        return orbit([(0, 1, 2)], False)
    if name == "rhombicuboctahedron":
        return orbit([(1, 1, 1 + r2)], False)
    if name == "truncated-cuboctahedron":
        return orbit([(1, 1 + r2, 1 + 2 * r2)], False)
    if name == "snub-cube":
        t = (1 + (19 + 3 * math.sqrt(33)) ** (1 / 3) + (19 - 3 * math.sqrt(33)) ** (1 / 3)) / 3
        return orbit([(1, 1 / t, t)], False, lambda par, plus: plus % 2 == par)
    if name == "icosidodecahedron":
        return orbit([(0, 0, p), (0.5, p / 2, p * p / 2)], True)
    if name == "truncated-dodecahedron":
        return orbit([(0, 1 / p, 2 + p), (1 / p, p, 2 * p), (p, 2, p + 1)], True)
    if name == "truncated-icosahedron":
        return orbit([(0, 1, 3 * p), (1, 2 + p, 2 * p), (p, 2, p ** 3)], True)
    if name == "rhombicosidodecahedron":
        return orbit([(1, 1, p ** 3), (p * p, p, 2 * p), (2 + p, 0, p * p)], True)
    if name == "truncated-icosidodecahedron":
        return orbit([(1 / p, 1 / p, 3 + p), (2 / p, p, 1 + 2 * p), (1 / p, p * p, 3 * p - 1),
                      (2 * p - 1, 2, 2 + p), (p, 3, 2 * p)], True)
    if name == "snub-dodecahedron":
        xi = 1.0
        for _ in range(100):  # xi^3 - 2 xi = phi
            xi -= (xi ** 3 - 2 * xi - p) / (3 * xi * xi - 2)
        a = xi - 1 / xi
        b = xi * p + p * p + p / xi
        seeds = [(2 * a, 2, 2 * b),
                 (a + b / p + p, -a * p + b + 1 / p, a / p + b * p - 1),
                 (a + b / p - p, a * p - b + 1 / p, a / p + b * p + 1),
                 (-a / p + b * p + 1, -a + b / p - p, a * p + b - 1 / p),
                 (-a / p + b * p - 1, a - b / p - p, a * p + b + 1 / p)]
        return orbit(seeds, True, lambda par, plus: plus % 2 == 0)
    raise ValueError(name)


NAMES = ["truncated-tetrahedron", "cuboctahedron", "truncated-cube", "truncated-octahedron",
         "rhombicuboctahedron", "truncated-cuboctahedron", "snub-cube", "icosidodecahedron",
         "truncated-dodecahedron", "truncated-icosahedron", "rhombicosidodecahedron",
         "truncated-icosidodecahedron", "snub-dodecahedron"]


def facets(v):
    """Outward unit normals and offsets of the hull of v (points in convex
    position), by brute force over vertex triples."""
    n = len(v)
    normals = []
    for i, j, k in itertools.combinations(range(n), 3):
        c = np.cross(v[j] - v[i], v[k] - v[i])
        l = np.linalg.norm(c)
        if l < 1e-9:
            continue
        c /= l
        d = v @ c - c @ v[i]
        if d.max() > 1e-9 and d.min() < -1e-9:
            continue
        if d.max() > 1e-9:
            c = -c
        if not any(c @ m > 1 - 1e-9 for m in normals):
            normals.append(c)
    normals = np.array(normals)
    return normals, (v @ normals.T).max(axis=0)


def volume(v, normals, h):
    """Sum of the pyramids over the faces from the origin (inside)."""
    vol = 0.0
    for nrm, hh in zip(normals, h):
        f = v[np.abs(v @ nrm - hh) < 1e-9]
        c = f.mean(axis=0)
        u = f[0] - c
        u /= np.linalg.norm(u)
        w = np.cross(nrm, u)
        ang = np.arctan2((f - c) @ w, (f - c) @ u)
        f = f[np.argsort(ang)]
        area = 0.5 * sum(np.cross(f[m], f[(m + 1) % len(f)]) @ nrm for m in range(len(f)))
        vol += hh * area / 3
    return vol


def diff_axes(v, normals):
    """Rows G with gauge_D(x) = max |G x| for D = K - K: the SAT axes
    (face normals, and edge cross products unless K = -K) over their width."""
    axes = [n for n in normals]
    sym = all(np.min(np.linalg.norm(v + x, axis=1)) < 1e-9 for x in v)
    if not sym:
        d = v[:, None, :] - v[None, :, :]
        l = np.linalg.norm(d, axis=2)
        emin = l[l > 1e-9].min()
        dirs = [d[i, j] / l[i, j] for i in range(len(v)) for j in range(i + 1, len(v))
                if abs(l[i, j] - emin) < 1e-9]
        for a, b in itertools.combinations(dirs, 2):
            c = np.cross(a, b)
            if np.linalg.norm(c) > 1e-6:
                axes.append(c / np.linalg.norm(c))
    axes = np.array(axes)
    # unique up to sign (canonical sign, then rounded keys)
    sgn = np.sign(axes[np.arange(len(axes)), np.argmax(np.abs(axes) > 1e-9, axis=1)])
    axes = axes * sgn[:, None]
    _, first = np.unique(np.round(axes, 9), axis=0, return_index=True)
    axes = axes[np.sort(first)]
    # keep the facet normals of D only: the support sets of K along n and
    # -n together span a 2-face (a face of K, or two edges)
    pr = v @ axes.T
    cp = (pr > pr.max(axis=0) - 1e-9).sum(axis=0)
    cm = (pr < pr.min(axis=0) + 1e-9).sum(axis=0)
    axes = axes[(cp >= 3) | (cm >= 3) | ((cp >= 2) & (cm >= 2))]
    pr = v @ axes.T
    w = pr.max(axis=0) - pr.min(axis=0)
    return axes / w[:, None], sym


Z2 = np.array([z for z in itertools.product(range(-2, 3), repeat=3) if any(z)], float)
Z3 = np.array([z for z in itertools.product(range(-3, 4), repeat=3) if any(z)], float)


def lll(B):
    B = B.copy()
    for _ in range(50):
        changed = False
        for i in range(3):
            for j in range(3):
                if i == j:
                    continue
                m = round(B[i] @ B[j] / (B[j] @ B[j]))
                if m:
                    B[i] -= m * B[j]
                    changed = True
        order = np.argsort(np.linalg.norm(B, axis=1))
        B = B[order]
        if not changed:
            break
    # also try sums/differences of pairs (a cheap step past pair reduction)
    return B


def lam1(G, B, Z=Z2):
    X = Z @ B
    g = np.abs(X @ G.T).max(axis=1)
    return g.min()


def neg_log_density(x, G, V):
    B = x.reshape(3, 3)
    d = abs(np.linalg.det(B))
    if d < 1e-12:
        return 50.0
    l = lam1(G, lll(B))
    return -math.log(V * l ** 3 / d)


def nelder_mead(f, x0, step, iters, tol=1e-13):
    n = len(x0)
    pts = [x0] + [x0 + step * np.eye(n)[i] for i in range(n)]
    vals = [f(p) for p in pts]
    for _ in range(iters):
        o = np.argsort(vals)
        pts = [pts[i] for i in o]
        vals = [vals[i] for i in o]
        if abs(vals[-1] - vals[0]) < tol:
            break
        c = np.mean(pts[:-1], axis=0)
        xr = c + (c - pts[-1])
        fr = f(xr)
        if fr < vals[0]:
            xe = c + 2 * (c - pts[-1])
            fe = f(xe)
            pts[-1], vals[-1] = (xe, fe) if fe < fr else (xr, fr)
        elif fr < vals[-2]:
            pts[-1], vals[-1] = xr, fr
        else:
            xc = c + 0.5 * (pts[-1] - c)
            fc = f(xc)
            if fc < vals[-1]:
                pts[-1], vals[-1] = xc, fc
            else:
                for i in range(1, n + 1):
                    pts[i] = pts[0] + 0.5 * (pts[i] - pts[0])
                    vals[i] = f(pts[i])
    i = int(np.argmin(vals))
    return pts[i], vals[i]


def contact(G, B, tol):
    """Active constraints (z, axis index, sign) of B at contact."""
    X = Z3 @ B
    P = X @ G.T
    act = []
    for zi in range(len(Z3)):
        row = P[zi]
        if abs(np.abs(row).max() - 1) >= tol:  # not at contact (gauge > 1)
            continue
        for ai in range(len(G)):
            for sg in (1, -1):
                if abs(sg * row[ai] - 1) < tol:
                    act.append((Z3[zi], ai, sg))
    return act


def polish(G, B, V, tol=1e-6):
    """Minimise |det| on the affine set where the contacts of B stay contacts."""
    B = lll(B)
    B = B / lam1(G, B, Z3)
    best = B
    for _round in range(6):
        act = contact(G, best, tol)
        M = np.array([np.kron(z, sg * G[ai]) for z, ai, sg in act])  # row . vec(B) (row-major)
        rhs = np.ones(len(act))
        # particular solution nearest to best, then the null space
        x0 = best.reshape(9)
        r = rhs - M @ x0
        dx = np.linalg.lstsq(M, r, rcond=None)[0]
        x0 = x0 + dx
        u, s, vt = np.linalg.svd(M)
        rank = int((s > 1e-9 * s[0]).sum())
        N = vt[rank:].T
        if N.shape[1] == 0:
            cand = x0.reshape(3, 3)
        else:
            def f(y):
                Bc = (x0 + N @ y).reshape(3, 3)
                l = lam1(G, lll(Bc), Z2)
                if l < 1 - 1e-12:
                    return 10.0 + (1 - l)
                return math.log(abs(np.linalg.det(Bc)))
            y, _ = nelder_mead(f, np.zeros(N.shape[1]), 1e-4, 4000, 1e-16)
            cand = (x0 + N @ y).reshape(3, 3)
        cand = lll(cand)
        cand = cand / lam1(G, cand, Z3)
        if abs(np.linalg.det(cand)) <= abs(np.linalg.det(best)) * (1 + 1e-15):
            best = cand
        tol = 1e-9
    return best


def search(name, starts, rng):
    v = vertices(name)
    normals, h = facets(v)
    V = volume(v, normals, h)
    G, sym = diff_axes(v, normals)
    f = lambda x: neg_log_density(x, G, V)
    inits = [np.array([[0, 1, 1], [1, 0, 1], [1, 1, 0]], float),
             np.array([[-1, 1, 1], [1, -1, 1], [1, 1, -1]], float), np.eye(3),
             np.array([[2, 0, 0], [1, math.sqrt(3), 0], [0, 0, 2]], float)]
    while len(inits) < starts:
        inits.append(rng.normal(size=(3, 3)))
    best = (1e9, None)
    for B0 in inits:
        B0 = lll(B0)
        x, val = nelder_mead(f, B0.reshape(9), 0.2, 3000)
        for _ in range(3):
            x, val = nelder_mead(f, x, 0.02, 3000)
        if val < best[0]:
            best = (val, x)
    B = polish(G, best[1].reshape(3, 3), V)
    if np.linalg.det(B) < 0:
        B[[1, 2]] = B[[2, 1]]
    dens = V * lam1(G, B, Z3) ** 3 / abs(np.linalg.det(B))
    ncont = len({tuple(z) for z, _, _ in contact(G, B, 1e-9)})
    return B, dens, V, ncont, len(v), len(normals)


def shipped_basis(name):
    """The basis src/core/lattice_archimedean.inc ships for name."""
    import os
    import re
    inc = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "src", "core",
                       "lattice_archimedean.inc")
    text = open(inc).read()
    enum = "VP_SHAPE_" + name.upper().replace("-", "_")
    m = re.search(re.escape(enum) + r",\s*\{(.*?)\}\}\}", text, re.S)
    nums = [float(x) for x in re.findall(r"[-+0-9.eE]+", m.group(1))]
    return np.array(nums, float).reshape(3, 3)


def nnls(A, b, iters=500):
    """min |A x - b| over x >= 0 (Lawson and Hanson); returns x, residual."""
    n = A.shape[1]
    P = np.zeros(n, bool)
    x = np.zeros(n)
    for _ in range(iters):
        w = A.T @ (b - A @ x)
        if P.all() or w[~P].max() <= 1e-12:
            break
        P[int(np.argmax(np.where(~P, w, -np.inf)))] = True
        while True:
            z = np.zeros(n)
            z[P] = np.linalg.lstsq(A[:, P], b, rcond=None)[0]
            if (z[P] > 0).all():
                x = z
                break
            m = P & (z <= 0)
            x = x + np.min(x[m] / (x[m] - z[m])) * (z - x)
            P &= x > 1e-15
    return x, np.linalg.norm(A @ x - b)


def optimality(name):
    """Whether the shipped basis is a strict local optimum: the gradient of
    log|det| in the cone of the contacts' constraint normals (KKT, by
    NNLS), and log|det| convex on the bases that keep every contact
    (Hessian by central differences on that affine set)."""
    v = vertices(name)
    normals, h = facets(v)
    V = volume(v, normals, h)
    G, _ = diff_axes(v, normals)
    B = shipped_basis(name)
    B = B / lam1(G, B, Z3)
    act = contact(G, B, 1e-7)
    M = np.array([np.kron(z, sg * G[ai]) for z, ai, sg in act])
    g = np.linalg.inv(B).T.reshape(9)
    mu, res = nnls(M.T, g)
    u, s, vt = np.linalg.svd(M)
    N = vt[int((s > 1e-9 * s[0]).sum()):].T
    x0 = B.reshape(9)
    f = lambda y: math.log(abs(np.linalg.det((x0 + N @ y).reshape(3, 3))))
    k, eps = N.shape[1], 1e-4
    H = np.zeros((k, k))
    for i in range(k):
        for j in range(k):
            a, b = np.eye(k)[i] * eps, np.eye(k)[j] * eps
            H[i, j] = (f(a + b) - f(a - b) - f(b - a) + f(-a - b)) / (4 * eps * eps)
    pairs = len({tuple(z if z[np.nonzero(z)[0][0]] > 0 else -z) for z, _, _ in act})
    eig = np.linalg.eigvalsh(H) if k else np.array([])
    dens = V * lam1(G, B, Z3) ** 3 / abs(np.linalg.det(B))
    print(f"{name}: fraction {dens:.12f}, {pairs} touching pairs +-z, {len(act)} constraints; "
          f"KKT residual {res:.2g} (|gradient| {np.linalg.norm(g):.3g}), least multiplier "
          f"{mu.min():.3g}; Hessian on the {k}-dim set keeping the contacts: "
          + (", ".join(f"{e:.3g}" for e in eig) if k else "none (a vertex)"))


def diff_body(name):
    """Prints what scripts/lattice_enum.c reads: "M V(K)", then the M rows g
    of D = K - K with gauge_D(x) = max |g . x| (K as this script scales it)."""
    v = vertices(name)
    normals, h = facets(v)
    G, _ = diff_axes(v, normals)
    print(len(G), repr(volume(v, normals, h)))
    for g in G:
        print("%.17g %.17g %.17g" % tuple(g))


def main():
    args = sys.argv[1:]
    if "--diff-body" in args:
        diff_body(args[args.index("--diff-body") + 1])
        return
    if "--check" in args:
        args.remove("--check")
        for name in args or NAMES:
            optimality(name)
        return
    starts = 24
    if "--starts" in args:
        i = args.index("--starts")
        starts = int(args[i + 1])
        del args[i:i + 2]
    seed = 1
    if "--seed" in args:
        i = args.index("--seed")
        seed = int(args[i + 1])
        del args[i:i + 2]
    names = args or NAMES
    rng = np.random.default_rng(seed)
    for name in names:
        B, dens, V, nc, nv, nf = search(name, starts, rng)
        print(f"/* {name}: {nv} vertices, {nf} faces, volume {V:.15f}, "
              f"fraction {dens:.12f}, {nc} contacts */")
        enum = "VP_SHAPE_" + name.upper().replace("-", "_")
        rows = ",\n      ".join("{%.17g, %.17g, %.17g}" % tuple(r) for r in B)
        print(f"{{{enum},\n     {{{rows}}}}},")
        sys.stdout.flush()


if __name__ == "__main__":
    main()
