"""Experiment (issue 13, session 10; docs/performance.md "Deflation and a local predictor"):
the spectrum of the FSAI-preconditioned normal set system G A G^T and the CG iterations
(cold, random right-hand side, relative residual 1e-13) when the k smallest, the k
largest or k/2 of each of its exact eigenvectors are deflated (deflated CG of Saad, Yeung,
Erhel and Guyomarc'h, 2000). Exact eigenvectors: an upper bound of what recycled Ritz
vectors or a coarse space could give.
Usage: python3 deflation.py NX NY SCALE   (after dump.rs; SCALE printed by dump.rs)
Needs numpy (pip install numpy).
"""
import numpy as np, sys
from common import load, fsai

nx, ny, scale = int(sys.argv[1]), int(sys.argv[2]), float(sys.argv[3])
C, d, att = load(nx, ny, scale)
S = np.where(att)[0]
A = C[np.ix_(S, S)] + np.diag(d[S])
G = fsai(S, A, nx)
B = G @ A @ G.T
w, V = np.linalg.eigh(B)
print(f'attached {len(S)}; eigenvalues of G A G^T: min {w[0]:.3f}, max {w[-1]:.2f}, '
      f'kappa {w[-1] / w[0]:.1f}')
print('quantiles 1, 5, 50, 95, 99 %:', np.round(np.quantile(w, [.01, .05, .5, .95, .99]), 3))
print('largest 12:', np.round(w[-12:], 2))


def dcg(B, b, Z, tol=1e-13, maxit=3000):
    if Z.shape[1]:
        BZ = B @ Z; Ei = np.linalg.inv(Z.T @ BZ)
        proj = lambda v: v - BZ @ (Ei @ (Z.T @ v))
        x = Z @ (Ei @ (Z.T @ b))
    else:
        proj = lambda v: v; x = np.zeros_like(b)
    r = proj(b - B @ x); p = r.copy(); rr = r @ r; nb = np.linalg.norm(b)
    for it in range(1, maxit + 1):
        q = proj(B @ p); al = rr / (p @ q); x += al * p; r -= al * q
        if np.sqrt(r @ r) < tol * nb:
            return it
        rr2 = r @ r; p = r + (rr2 / rr) * p; rr = rr2
    return maxit


b = G @ np.random.default_rng(0).standard_normal(len(S))
m = len(S)
print('k, CG iterations with: no deflation / k smallest / k largest / k/2 of each')
print(0, dcg(B, b, np.zeros((m, 0))))
for k in (10, 20, 40, 80):
    print(k, '-', dcg(B, b, V[:, :k]), dcg(B, b, V[:, m - k:]),
          dcg(B, b, np.hstack([V[:, :k // 2], V[:, m - k // 2:]])))
