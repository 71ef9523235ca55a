"""Prototype (issue 13, session 9; docs/performance.md "Prototype: hole-based
preconditioners"): CG iteration counts, cold start from a random right-hand side to a
relative residual of 1e-12, for preconditioners of the normal set system
A = C_SS + diag(d_S), from the files dump.rs writes to /tmp/proto.
Usage: python3 inner.py NX NY SCALE   (SCALE = cell area / (E/(1+nu)), printed by dump.rs)
Needs numpy and scipy (pip install numpy scipy).
"""
import numpy as np, sys
from common import load
nx, ny, scale = int(sys.argv[1]), int(sys.argv[2]), float(sys.argv[3])
n = nx*ny
C, d, att = load(nx, ny, scale)
S = np.where(att)[0]; H = np.where(~att)[0]
dbar = d[S].mean()
W = np.linalg.inv(C + dbar*np.eye(n)); del C
Whh = W[np.ix_(H,H)]
ix = np.arange(n) % nx; iy = np.arange(n) // nx
def pcg(A, b, M, tol=1e-12, maxit=2000):
    x = np.zeros_like(b); r = b.copy(); z = M(r); p = z.copy(); rz = r@z; nb = np.linalg.norm(b)
    for it in range(1, maxit+1):
        q = A@p; al = rz/(p@q); x += al*p; r -= al*q
        if np.linalg.norm(r) < tol*nb: return it
        z = M(r); rz2 = r@z; p = z + (rz2/rz)*p; rz = rz2
    return maxit
rng = np.random.default_rng(0); b = rng.standard_normal(len(H))
hx, hy = ix[H], iy[H]
dist = np.maximum(np.abs(hx[:,None]-hx[None,:]), np.abs(hy[:,None]-hy[None,:]))
print(f'N={n} holes={len(H)}')
print('  W_HH, Jacobi:', pcg(Whh, b, lambda r: r/np.diag(Whh)))
for r0 in (1, 2):
    T = np.where(dist <= r0, Whh, 0.0)
    L = np.linalg.cholesky(T)
    from scipy.linalg import cho_solve
    print(f'  W_HH, truncated radius {r0} (exact sparse solve):', pcg(Whh, b, lambda r: cho_solve((L, True), r)))
