"""Shared by deflation.py and predictor.py: the dump of dump.rs (/tmp/proto), the normal
set system A = C_SS + diag(d_S) and the crate's FSAI factor (radius 1, as
src/solver/fsai.rs: row i on the attached sites j <= i within one cell, A[P,P] g = e_i,
scaled by 1/sqrt(g_i); M^-1 = G^T G)."""
import numpy as np


def load(nx, ny, scale):
    n = nx * ny
    C = scale * np.fromfile('/tmp/proto/g.bin').reshape(n, n)
    d = np.fromfile('/tmp/proto/d.bin')
    att = np.fromfile('/tmp/proto/att.bin') > 0.5
    return C, d, att


def fsai(S, A, nx):
    pos = {s: k for k, s in enumerate(S)}
    G = np.zeros((len(S), len(S)))
    for k, i in enumerate(S):
        P = [pos[j] for j in S[max(0, k - 2 * nx - 2):k + 1]
             if j <= i and abs(j % nx - i % nx) <= 1 and abs(j // nx - i // nx) <= 1]
        e = np.zeros(len(P)); e[P.index(k)] = 1.0
        g = np.linalg.solve(A[np.ix_(P, P)], e)
        G[k, P] = g / np.sqrt(g[P.index(k)])
    return G
