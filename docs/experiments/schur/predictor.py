"""Experiment (issue 13, session 10; docs/performance.md "Deflation and a local predictor"):
the warm normal solve after one rupture. The old equilibrium f (A f + U 1 = b, 1^T f = F)
loses site j; exactly, f' = f - (f_j / (A^-1)_jj) A^-1 e_j. The predictor replaces A^-1 e_j
by the solve on the attached sites within R cells of j (a dense local system) and starts
the projected CG (FSAI, the crate's constraint preconditioner and backward error, 1e-13)
from it; R = none is the crate's warm start (f itself).
Usage: python3 predictor.py NX NY SCALE   (after dump.rs; SCALE printed by dump.rs)
Needs numpy (pip install numpy).
"""
import numpy as np, sys
from common import load, fsai

nx, ny, scale = int(sys.argv[1]), int(sys.argv[2]), float(sys.argv[3])
C, d, att = load(nx, ny, scale)
ix, iy = np.arange(nx * ny) % nx, np.arange(nx * ny) // nx


def ppcg(A, b, total, f0, Minv, tol=1e-13, maxit=3000):
    m = len(b); one = np.ones(m); w = Minv(one); s1 = one @ w
    norm_a = np.abs(A).sum(1).max()
    f = f0 + (total - f0.sum()) / m
    r = b - A @ f; p = None; it = 0
    while True:
        z = Minv(r); U = (one @ z) / s1; z = z - U * w
        res = np.abs(r - U * one).max() / (norm_a * np.abs(f).max() + np.abs(b).max() + abs(U))
        if res <= tol or it >= maxit:
            return it
        rz = r @ z
        p = z.copy() if p is None else z + (rz / rz_old) * p
        q = A @ p; al = rz / (p @ q); f += al * p; r -= al * q; rz_old = rz; it += 1


S = np.where(att)[0]
A = C[np.ix_(S, S)] + np.diag(d[S])
rng = np.random.default_rng(1)
f_true = 3.5 * (1 + 0.5 * rng.standard_normal(len(S)))   # tractions of the right scale
b, total = A @ f_true, f_true.sum()
G = fsai(S, A, nx)
print('cold CG iterations:', ppcg(A, b, total, np.zeros(len(S)), lambda r: G.T @ (G @ r)))
radii = (None, 1, 2, 3, 5, 8, 12)
print('warm CG iterations after one rupture, predictor radius R =', radii)
for trial in range(4):
    k = rng.integers(len(S)); j = S[k]
    keep = np.arange(len(S)) != k
    A2 = A[np.ix_(keep, keep)]; G2 = fsai(S[keep], A2, nx)
    row = []
    for R in radii:
        x0 = f_true.copy()
        if R is not None:
            win = np.where((abs(ix[S] - ix[j]) <= R) & (abs(iy[S] - iy[j]) <= R))[0]
            z = np.linalg.solve(A[np.ix_(win, win)], (win == k).astype(float))
            x0[win] -= f_true[k] / z[win == k][0] * z
        row.append(ppcg(A2, b[keep], total, x0[keep], lambda r: G2.T @ (G2 @ r)))
    print(f'site {j}: f_j / mean f = {f_true[k] / f_true.mean():.2f}:', row)
