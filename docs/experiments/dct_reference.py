"""Time of one operator application with scipy.fft (pocketfft), one thread: a 2-D DCT-II,
a multiplication by a table, a 2-D DCT-III (the inverse), on Nx x Ny grids.

Reference for issue 26 item 2 (docs/performance.md): the crate's InfluencePlan::apply
on the same grid, measured side by side. Run: python3 dct_reference.py
(needs numpy and scipy: pip install numpy scipy).
"""
import sys, time
import numpy as np
import scipy.fft as fft

def best(f, reps):
    ts = []
    for _ in range(reps):
        t = time.perf_counter(); f(); ts.append(time.perf_counter() - t)
    ts.sort()
    return ts[0], ts[len(ts) // 2]

for nx, ny in [(140, 7), (200, 50), (1000, 100)]:
    v = np.sin(np.arange(nx * ny) * 0.37).reshape(ny, nx)
    table = 1.0 / (1.0 + np.add.outer(np.arange(ny), np.arange(nx)))
    def op():
        s = fft.dctn(v, type=2, norm="ortho", workers=1)
        s *= table
        return fft.idctn(s, type=2, norm="ortho", workers=1, overwrite_x=True)
    reps = 2000 if nx * ny < 2e4 else 300
    b, m = best(op, reps)
    print(f"{nx}x{ny}: best {b*1e6:.1f} us, median {m*1e6:.1f} us")
