"""Experiment (issue 13, session 10; docs/performance.md "What the targets would need"):
how many CG iterations a stale exact factor needs. The Cholesky factor of the normal set
system A_S (the attached set S of the dump) preconditions the system on S' = S minus m
sites (m ruptures later; z = (A_S^-1 [r; 0])_S', the removed sites padded with zero, so
M^-1 = (A_S^-1)_S'S' differs from A_S'^-1 by rank m). Cold CG from a random right-hand
side to a relative residual of 1e-13. This is what a fast direct (e.g. hierarchical)
factor refactorised every m ruptures would give.
Usage: python3 stale.py NX NY SCALE   (after dump.rs; SCALE printed by dump.rs)
Needs numpy and scipy (pip install numpy scipy).
"""
import numpy as np, sys
from scipy.linalg import cho_factor, cho_solve
from common import load

nx, ny, scale = int(sys.argv[1]), int(sys.argv[2]), float(sys.argv[3])
C, d, att = load(nx, ny, scale)
S = np.where(att)[0]
A = C[np.ix_(S, S)] + np.diag(d[S])
F = cho_factor(A)
rng = np.random.default_rng(2)


def pcg(A, b, M, tol=1e-13, maxit=3000):
    x = np.zeros_like(b); r = b.copy(); z = M(r); p = z.copy(); rz = r @ z; nb = np.linalg.norm(b)
    for it in range(1, maxit + 1):
        q = A @ p; al = rz / (p @ q); x += al * p; r -= al * q
        if np.linalg.norm(r) < tol * nb:
            return it
        z = M(r); rz2 = r @ z; p = z + (rz2 / rz) * p; rz = rz2
    return maxit


print('sites removed since the factor (m), CG iterations (three draws)')
for m in (0, 1, 2, 5, 10, 20, 40, 80):
    row = []
    for _ in range(3):
        keep = np.ones(len(S), bool); keep[rng.choice(len(S), m, replace=False)] = False
        A2 = A[np.ix_(keep, keep)]

        def M(r, keep=keep):
            pad = np.zeros(len(S)); pad[keep] = r
            return cho_solve(F, pad)[keep]
        row.append(pcg(A2, rng.standard_normal(keep.sum()), M))
    print(m, row)
