"""Prototype (issue 26, session 15; docs/performance.md "Prototype: a two-level
preconditioner with aggregates"): CG iteration counts for the normal set system
A = C_SS + diag(d_S), matrix-free: C = scale * G, G diagonal in the orthonormal 2-D DCT-II
basis with the crate's eigenvalues (mean mode lowered to the largest other, as
src/solver/mod.rs does; the load constraint is left out), from the files dump.rs writes to
/tmp/proto. Random right-hand side, relative residual 1e-12: cold solves, and a warm solve
after the site carrying the largest traction leaves the set (started from the old
tractions, as the crate does).
Preconditioners: Jacobi; the restricted spectral inverse W_SS = ((C + d_bar I)^-1)_SS; the
stiffness form (C^-1 + K) on the whole grid; FSAI radius 1 (as src/solver/fsai.rs); the
additive two-level M1 + Z E^-1 Z^T and A-DEF2 (Tang, Nabben, Vuik, Erlangga 2009):
  z = M1 r - Q A M1 r + Q r,   Q = Z E^-1 Z^T,   E = Z^T A Z,
with Z the indicators of the attached sites in b x b blocks of cells (aggregates).
Usage: python3 twolevel.py TAG K B1 B2 ...   (e.g. n4 3000 4 8 16; TAG.txt from dump.rs)
Needs numpy and scipy (pip install numpy scipy).
"""
import sys, numpy as np, scipy.fft as fft
tag, k = sys.argv[1], sys.argv[2]
nx, ny, scale = None, None, None
for line in open(f"/tmp/proto/{tag}.txt"):
    a = line.split()
    if len(a) == 5 and a[3] == k: nx, ny, scale = int(a[0]), int(a[1]), float(a[2])
n = nx * ny
lam = np.fromfile(f"/tmp/proto/{tag}_eig.bin").reshape(ny, nx).copy()
lam[0, 0] = min(lam[0, 0], lam.flatten()[1:].max())
d = np.fromfile(f"/tmp/proto/{tag}_{k}_d.bin")
att = np.fromfile(f"/tmp/proto/{tag}_{k}_att.bin") > 0.5
S = np.where(att)[0]
print(f"{tag} K={k}: {nx}x{ny}, attached {len(S)} of {n}")
def filt(table, x):
    return fft.idctn(table * fft.dctn(x.reshape(ny, nx), norm="ortho", workers=1), norm="ortho", workers=1).ravel()
C_tab = scale * lam
def Cfull(x): return filt(C_tab, x)
dS = d[S]
def A(x):
    X = np.zeros(n); X[S] = x
    return Cfull(X)[S] + dS * x
def pcg(Aop, b, M, tol=1e-12, maxit=3000):
    x = np.zeros_like(b); r = b.copy(); z = M(r); p = z.copy(); rz = r @ z; nb = np.linalg.norm(b)
    for it in range(1, maxit + 1):
        q = Aop(p); al = rz / (p @ q); x += al * p; r -= al * q
        if np.linalg.norm(r) < tol * nb: return it, x
        z = M(r); rz2 = r @ z; p = z + (rz2 / rz) * p; rz = rz2
    return maxit, x
rng = np.random.default_rng(0); b = rng.standard_normal(len(S))
diagC = C_tab.mean()
print(f"  mean diag C {diagC:.3e}, d on S: mean {dS.mean():.3e} min {dS.min():.3e} max {dS.max():.3e}")
res = {}
res["jacobi"] = pcg(A, b, lambda r: r / (diagC + dS))[0]
dbar = dS.mean()
W_tab = 1.0 / (C_tab + dbar)
def Wss(r):
    X = np.zeros(n); X[S] = r
    return filt(W_tab, X)[S]
res["spectral W_SS"] = pcg(A, b, Wss)[0]
# Stiffness form on the whole grid: (C^-1 + K) u = K b_u; holes K = 0.
K = np.zeros(n); K[S] = 1.0 / dS
Cinv_tab = 1.0 / C_tab
def B(u): return filt(Cinv_tab, u) + K * u
bu = np.zeros(n); bu[S] = rng.standard_normal(len(S))
kbar = K.mean()
P_tab = 1.0 / (Cinv_tab + kbar)
res["stiffness form, (C^-1 + mean K)^-1"] = pcg(B, bu, lambda r: filt(P_tab, r))[0]
kbarS = K[S].mean()
P2_tab = 1.0 / (Cinv_tab + kbarS)
res["stiffness form, (C^-1 + mean K_S)^-1"] = pcg(B, bu, lambda r: filt(P2_tab, r))[0]
for name, it in res.items(): print(f"  {name}: {it}")

# Two-level additive: M = M1 + Z Ac^-1 Z^T, Z = indicators of the attached sites in b x b blocks.
def coarse(b):
    bx = (np.arange(n) % nx) // b; by = (np.arange(n) // nx) // b
    nbx = (nx + b - 1) // b
    blk = by * nbx + bx
    ids = np.unique(blk[S]); col = np.searchsorted(ids, blk[S])  # coarse index of each set position
    kc = len(ids)
    Ac = np.zeros((kc, kc))
    for s0 in range(0, kc, 256):
        cols = range(s0, min(kc, s0 + 256))
        X = np.zeros((len(cols), n))
        for j, c in enumerate(cols): X[j, S[col == c]] = 1.0
        Y = fft.idctn(C_tab * fft.dctn(X.reshape(-1, ny, nx), axes=(1, 2), norm="ortho", workers=2), axes=(1, 2), norm="ortho", workers=2).reshape(-1, n)
        AZ = Y[:, S] + X[:, S] * dS
        for j, c in enumerate(cols): Ac[:, c] = np.bincount(col, weights=AZ[j], minlength=kc)
    L = np.linalg.cholesky(Ac)
    import scipy.linalg as sl
    def Q(r):
        rc = np.bincount(col, weights=r, minlength=kc)
        yc = sl.cho_solve((L, True), rc)
        return yc[col]
    return Q, kc
jac = 1.0 / (diagC + dS)
for bsz in [int(v) for v in sys.argv[3:]]:
    Q, kc = coarse(bsz)
    it = pcg(A, b, lambda r: jac * r + Q(r))[0]
    print(f"  two-level additive, Jacobi + aggregates {bsz}x{bsz} ({kc} coarse): {it}")
    it = pcg(A, b, lambda r: Wss(r) + Q(r))[0]
    print(f"  two-level additive, W_SS + aggregates {bsz}x{bsz}: {it}")

def pcg_x0(Aop, b, M, x0, tol=1e-12, maxit=3000):
    x = x0.copy(); r = b - Aop(x); z = M(r); p = z.copy(); rz = r @ z; nb = np.linalg.norm(b)
    for it in range(1, maxit + 1):
        q = Aop(p); al = rz / (p @ q); x += al * p; r -= al * q
        if np.linalg.norm(r) < tol * nb: return it
        z = M(r); rz2 = r @ z; p = z + (rz2 / rz) * p; rz = rz2
    return maxit
for bsz in [int(v) for v in sys.argv[3:]]:
    Q, kc = coarse(bsz)
    for name, M1 in [("Jacobi", lambda r: jac * r), ("W_SS", Wss)]:
        def M(r, M1=M1):
            y = M1(r)
            return y - Q(A(y)) + Q(r)
        it = pcg_x0(A, b, M, Q(b))
        print(f"  A-DEF2, {name} + aggregates {bsz}x{bsz} ({kc} coarse): {it} (2 products per iteration)")

# FSAI radius 1 as src/solver/fsai.rs (docs/experiments/schur/common.py), entries of C exact.
import scipy.sparse as sp
def phi(n_):
    x = np.arange(n_); p = np.arange(n_)[:, None]
    F = np.sqrt(2.0 / n_) * np.cos(np.pi * p * (x + 0.5) / n_); F[0] /= np.sqrt(2.0)
    return F
Fx, Fy = phi(nx), phi(ny)
def entries(ox, oy):
    E = np.full((ny, nx), np.nan)
    xs = np.arange(max(0, -ox), min(nx, nx - ox)); ys = np.arange(max(0, -oy), min(ny, ny - oy))
    Ex = Fx[:, xs] * Fx[:, xs + ox]; Ey = Fy[:, ys] * Fy[:, ys + oy]
    E[np.ix_(ys, xs)] = Ey.T @ C_tab @ Ex
    return E
offs = [(-1, -1), (0, -1), (1, -1), (-1, 0), (0, 0)]
ent = {(ox, oy): entries(ox, oy) for ox in range(-2, 3) for oy in (-1, 0, 1)}
pos = -np.ones(n, dtype=int); pos[S] = np.arange(len(S))
rows, cols, vals = [], [], []
for k_, i in enumerate(S):
    yi, xi = divmod(i, nx)
    P = []
    for ox, oy in offs:
        xj, yj = xi + ox, yi + oy
        if 0 <= xj < nx and 0 <= yj < ny and att[yj * nx + xj]: P.append((xj, yj))
    m_ = len(P)
    Ap = np.empty((m_, m_))
    for a_, (xa, ya) in enumerate(P):
        for b_, (xb, yb) in enumerate(P):
            Ap[a_, b_] = ent[(xb - xa, yb - ya)][ya, xa]
        Ap[a_, a_] += d[ya * nx + xa]
    e = np.zeros(m_); e[-1] = 1.0
    g = np.linalg.solve(Ap, e); g /= np.sqrt(g[-1])
    for a_, (xa, ya) in enumerate(P):
        rows.append(k_); cols.append(pos[ya * nx + xa]); vals.append(g[a_])
G = sp.csr_matrix((vals, (rows, cols)), shape=(len(S), len(S))); GT = G.T.tocsr()
fsai = lambda r: GT @ (G @ r)
print(f"  FSAI radius 1: {pcg(A, b, fsai)[0]}")
for bsz in [int(v) for v in sys.argv[3:]]:
    Q, kc = coarse(bsz)
    def M(r):
        y = fsai(r)
        return y - Q(A(y)) + Q(r)
    print(f"  A-DEF2, FSAI + aggregates {bsz}x{bsz} ({kc} coarse): {pcg_x0(A, b, M, Q(b))} (2 products per iteration)")

# Warm solves after a rupture: solve on S (tight), remove the site carrying the largest
# traction, solve again on S' from the old tractions (the crate's warm start).
def restricted(Sx, dx):
    def Aop(x):
        X = np.zeros(n); X[Sx] = x
        return Cfull(X)[Sx] + dx * x
    return Aop
rhs_full = rng.standard_normal(n)
_, f_old = pcg(A, rhs_full[S], fsai, tol=1e-15)
j = np.argmax(np.abs(f_old)); keep = np.ones(len(S), bool); keep[j] = False
S2 = S[keep]; d2 = dS[keep]; A2 = restricted(S2, d2); b2 = rhs_full[S2]; x_w = f_old[keep]
# FSAI on S' (the rows near j change; rebuilt here as the sub-factor for simplicity: drop row/col j)
G2 = G[keep][:, keep]; G2T = G2.T.tocsr(); fsai2 = lambda r: G2T @ (G2 @ r)
def pcg_warm(Aop, b_, M, x0, tol=1e-12, maxit=3000):
    return pcg_x0(Aop, b_, M, x0, tol, maxit)
print(f"  warm (site {S[j]} removed): FSAI from old tractions: {pcg_warm(A2, b2, fsai2, x_w)}, cold {pcg_warm(A2, b2, fsai2, 0*x_w)}")
Sbak, dSbak = S, dS
for bsz in [int(v) for v in sys.argv[3:]]:
    S, dS = S2, d2  # coarse() reads the globals
    Q, kc = coarse(bsz)
    S, dS = Sbak, dSbak
    def M(r):
        y = fsai2(r)
        return y - Q(A2(y)) + Q(r)
    x0 = x_w + Q(b2 - A2(x_w))
    print(f"  warm, A-DEF2 FSAI + aggregates {bsz}x{bsz}: {pcg_warm(A2, b2, M, x0)}")
