"""Prototype (issue 13, session 9; docs/performance.md "Prototype: hole-based
preconditioners"): CG iteration counts, cold start from a random right-hand side to a
relative residual of 1e-12, for preconditioners of the normal set system
A = C_SS + diag(d_S), from the files dump.rs writes to /tmp/proto.
Usage: python3 outer.py NX NY SCALE   (SCALE = cell area / (E/(1+nu)), printed by dump.rs)
Needs numpy and scipy (pip install numpy scipy).
"""
import numpy as np, sys
from common import load, fsai
nx, ny, scale = int(sys.argv[1]), int(sys.argv[2]), float(sys.argv[3])
n = nx*ny
C, d, att = load(nx, ny, scale)
S = np.where(att)[0]; H = np.where(~att)[0]
A = C[np.ix_(S,S)] + np.diag(d[S])
dbar = d[S].mean()
W = np.linalg.inv(C + dbar*np.eye(n))
def pcg(A, b, M, tol=1e-12, maxit=2000):
    x = np.zeros_like(b); r = b.copy(); z = M(r); p = z.copy(); rz = r@z; nb = np.linalg.norm(b)
    for it in range(1, maxit+1):
        q = A@p; al = rz/(p@q); x += al*p; r -= al*q
        if np.linalg.norm(r) < tol*nb: return it
        z = M(r); rz2 = r@z; p = z + (rz2/rz)*p; rz = rz2
    return maxit
rng = np.random.default_rng(0); b = rng.standard_normal(len(S))
jac = 1/np.diag(A)
Wss = W[np.ix_(S,S)]; Wsh = W[np.ix_(S,H)]; Whh = W[np.ix_(H,H)]
whh_d = np.diag(Whh)
schur_exact = Wss - Wsh @ np.linalg.solve(Whh, Wsh.T)
def jacobi_sweeps(k):
    def solve(v):
        y = v/whh_d
        for _ in range(k-1): y = y + (v - Whh@y)/whh_d
        return y
    return solve
res = {}
res['jacobi'] = pcg(A, b, lambda r: jac*r)
# FSAI as in src/solver/fsai.rs (common.fsai).
Gf = fsai(S, A, nx)
res['FSAI radius 1 (as the crate)'] = pcg(A, b, lambda r: Gf.T @ (Gf @ r))
res['restricted spectral W_SS'] = pcg(A, b, lambda r: Wss@r)
res['schur exact W_HH^-1'] = pcg(A, b, lambda r: schur_exact@r)
for k in (1, 2, 4, 8):
    s = jacobi_sweeps(k)
    res[f'schur, W_HH by {k} Jacobi sweeps'] = pcg(A, b, lambda r, s=s: Wss@r - Wsh@s(Wsh.T@r))
print(f'N={n} attached={len(S)} ({len(S)/n:.0%})  d/diag(C)={dbar/np.diag(C).mean():.3f}')
for k, v in res.items(): print(f'  {k:40s} {v}')
# Truncated W: entries within grid distance r0 (Chebyshev) kept; P = Schur complement of Ŵ on S.
ix = np.arange(n) % nx; iy = np.arange(n) // nx
dist = np.maximum(np.abs(ix[:,None]-ix[None,:]), np.abs(iy[:,None]-iy[None,:]))
for r0 in (1, 3):
    Wt = np.where(dist <= r0, W, 0.0)
    P = Wt[np.ix_(S,S)] - Wt[np.ix_(S,H)] @ np.linalg.solve(Wt[np.ix_(H,H)], Wt[np.ix_(H,S)])
    print(f'  truncated W, radius {r0}: schur iterations', pcg(A, b, lambda r: P@r))
