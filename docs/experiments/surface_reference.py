#!/usr/bin/env python3
"""Independent reference values for the random surfaces (src/surface.rs, docs/model.md 3.1).

Written from the specification in docs/model.md section 3.1, not from the Rust code:
pure Python integers for the hash, Python floats with math.fsum for the field, and mpmath
at 40 digits for the copula onto the truncated Gaussian (its quantile by erfinv) and for
the Gauss-Legendre nodes; each cell average by a rule of far higher order than the
crate's (so the reference is the exact cell average to about 1e-15).

    python3 docs/experiments/surface_reference.py          # needs mpmath (1.3)

prints the values pinned in tests/surfaces.rs (`pinned_*`), tests/maps.rs
(`pinned_drawn_maps`: a map is the heights' generator with its own marginal) and in src/surface.rs
(`the_copula_is_the_truncated_gaussian_quantile`).
"""
import math

import mpmath as mp

mp.mp.dps = 30
MASK = (1 << 64) - 1
DOMAIN = 0x5355_5246_4143_4531


def mix(x):
    """SplitMix64: the golden-ratio increment and the finaliser (64-bit wrapping)."""
    z = (x + 0x9E3779B97F4A7C15) & MASK
    z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & MASK
    z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & MASK
    return z ^ (z >> 31)


def unit(bits):
    return ((bits >> 11) + 0.5) / 2.0**53


def mode_normals(seed, p, q):
    zigzag = ((p << 1) ^ (p >> 63)) & MASK
    key = mix(mix(mix(seed ^ DOMAIN) ^ zigzag) ^ q)
    u1, u2 = unit(mix(key ^ 1)), unit(mix(key ^ 2))
    r = math.sqrt(-2.0 * math.log(u1))
    theta = 2.0 * math.pi * u2
    return r * math.cos(theta), r * math.sin(theta)


def gaussian(xi):
    return dict(
        density=lambda k: math.exp(-0.25 * (k * xi) ** 2),
        cutoff=2.0 * math.sqrt(-math.log(1e-16)) / xi,
        reach=6.0 * xi,
    )


def self_affine(h, lr, ls, ll):
    kl, kr, ks = 2 * math.pi / ll, 2 * math.pi / lr, 2 * math.pi / ls

    def density(k):
        if k < kl or k > ks:
            return 0.0
        return 1.0 if k <= kr else (k / kr) ** (-2.0 * (1.0 + h))

    return dict(density=density, cutoff=ks, reach=ll)


def modes(lx, ly, spec):
    """(kx, ky, a², p, q) of the half-plane modes (q > 0, or q = 0 and p >= 0) within the
    cut-off, a² normalised."""
    px = max(2 * lx, lx + spec["reach"])
    py = max(2 * ly, ly + spec["reach"])
    kc = spec["cutoff"]
    pm, qm = math.floor(kc * px / (2 * math.pi)), math.floor(kc * py / (2 * math.pi))
    out = []
    for q in range(qm + 1):
        for p in range(-pm, pm + 1):
            if q == 0 and p < 0:
                continue
            kx, ky = 2 * math.pi * p / px, 2 * math.pi * q / py
            k = math.hypot(kx, ky)
            if k <= kc:
                # The mean mode (p, q) = (0, 0) stands for itself, the others for +-k.
                s = spec["density"](k) * (0.5 if p == q == 0 else 1.0)
                if s > 0:
                    out.append([kx, ky, s, p, q])
    total = math.fsum(m[2] for m in out)
    for m in out:
        m[2] /= total
    return out


def field(ms, seed, x, y):
    terms = []
    for kx, ky, v, p, q in ms:
        xi, eta = mode_normals(seed, p, q)
        theta = kx * x + ky * y
        terms.append(math.sqrt(v) * (xi * math.cos(theta) + eta * math.sin(theta)))
    return math.fsum(terms)


def quantile(mean, sd, g):
    """u0 = F^-1(Phi(g)) for the Gaussian (mean, sd) truncated at 0, at 40 digits."""
    mean, sd, g = mp.mpf(mean), mp.mpf(sd), mp.mpf(g)
    a = -mean / sd
    cdf = lambda x: mp.ncdf(x)
    target = cdf(a) + cdf(g) * (1 - cdf(a))
    z = mp.sqrt(2) * mp.erfinv(2 * target - 1)
    return mean + sd * z


def legendre(n):
    """The n-point Gauss-Legendre rule at 40 digits: Newton on P_n (three-term
    recurrence), P_n' from P_n and P_{n-1}."""
    nodes, weights = [], []
    for i in range(n):
        t = mp.cos(mp.pi * (i + mp.mpf(0.75)) / (n + mp.mpf(0.5)))
        for _ in range(100):
            p0, p1 = mp.mpf(1), t
            for k in range(2, n + 1):
                p0, p1 = p1, ((2 * k - 1) * t * p1 - (k - 1) * p0) / k
            dp = n * (t * p1 - p0) / (t * t - 1)
            step = p1 / dp
            t -= step
            if abs(step) < mp.mpf(10) ** -38:
                break
        nodes.append(float(t))
        weights.append(float(2 / ((1 - t * t) * dp * dp)))
    return nodes, weights


def heights(lx, ly, nx, ny, spec, mean, sd, seed, order):
    ms = modes(lx, ly, spec)
    t, w = legendre(order)
    dx, dy = lx / nx, ly / ny
    xs = [[dx * (i + 0.5 + 0.5 * tj) for tj in t] for i in range(nx)]
    ys = [[dy * (j + 0.5 + 0.5 * tj) for tj in t] for j in range(ny)]
    out = []
    for iy in range(ny):
        for ix in range(nx):
            terms = []
            for y, wy in zip(ys[iy], w):
                for x, wx in zip(xs[ix], w):
                    g = field(ms, seed, x, y)
                    terms.append(0.25 * wx * wy * float(quantile(mean, sd, g)))
            out.append(math.fsum(terms))
    return out


if __name__ == "__main__":
    print("copula (mean, sd, g, u0):")
    for m, s, g in [(1e-6, 1e-6, 0.0), (1e-6, 1e-6, -3.0), (1e-6, 1e-6, -6.0),
                    (1e-6, 1e-6, 5.0), (1e-6, 1e-6, -1.0), (5e-6, 1e-6, 1.0),
                    (5e-6, 1e-6, -2.5), (-2e-6, 1e-6, 0.0), (-2e-6, 1e-6, -7.0)]:
        print(f"    ({m:e}, {s:e}, {g}, {float(quantile(m, s, g))!r}),")
    print("modes of the pinned Gaussian surface:", len(modes(0.008, 0.004, gaussian(2e-3))))
    print("pinned_gaussian_surface (8 x 4 mm, 4 x 2 cells, xi = 2 mm, seed 7, default marginal):")
    for v in heights(0.008, 0.004, 4, 2, gaussian(2e-3), 1e-6, 1e-6, 7, 16):
        print(f"    {v!r},")
    print("pinned_self_affine_surface (8 x 4 mm, 4 x 2 cells, H 0.7, 3 / 0.6 / 5 mm, seed 11,"
          " mean 2 um, sd 1 um):")
    for v in heights(0.008, 0.004, 4, 2, self_affine(0.7, 3e-3, 0.6e-3, 5e-3), 2e-6, 1e-6, 11, 64):
        print(f"    {v!r},")
    print("pinned_drawn_maps, mu (8 x 4 mm, 4 x 2 cells, xi = 2 mm, seed 13, mean 0.5, sd 0.1):")
    for v in heights(0.008, 0.004, 4, 2, gaussian(2e-3), 0.5, 0.1, 13, 16):
        print(f"    {v!r},")
    print("pinned_drawn_maps, c_x (xi = 1.5 mm, seed 21, mean 1.65e12, sd 0.5e12 N/m^3):")
    for v in heights(0.008, 0.004, 4, 2, gaussian(1.5e-3), 1.65e12, 0.5e12, 21, 16):
        print(f"    {v!r},")
