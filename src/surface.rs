//! Gaussian random surfaces with a length scale (docs/model.md section 3.1): a continuum
//! field `g(x, y)` of unit variance synthesised from Fourier modes, mapped onto the
//! heights' truncated Gaussian (a Gaussian copula) and averaged over each cell.
//!
//! * **Modes.** `k = (2π p/Px, 2π q/Py)` on a period `P` larger than the block (at least
//!   `2L`, and `L` plus the spectrum's correlation reach, so that the block sees no
//!   periodicity), restricted to the half plane (`q > 0`, or `q = 0` and `p ≥ 0`; the
//!   mean mode with half the weight, as it stands for itself and not for `±k`) and to the
//!   wavenumbers the spectrum needs (a cut-off set by the spectrum, never by the grid).
//!   The field's covariance is then the prescription's periodisation over `P` (Poisson
//!   summation), up to the cut-off.
//! * **Coefficients.** Mode `(p, q)`'s pair of standard normals comes from a counter-based
//!   hash of `(seed, p, q)` (SplitMix64 mixing, Box-Muller), so a mode's value does not
//!   depend on the grid, on the other modes or on any order of evaluation; every function
//!   is `libm`'s (pure Rust) and every sum runs in a fixed order, so the heights are the
//!   same bit for bit on every IEEE-754 machine.
//! * **Cell averages.** A cell's height is the average of `u0 = F⁻¹(Φ(g))` over the cell,
//!   by a tensor Gauss-Legendre rule whose order follows the spectrum's shortest
//!   wavelengths against the cell size. The field on the rule's tensor grid of points is
//!   `Re(E_y C E_xᵀ)`: two matrix products, no FFT. So the same seed gives the same
//!   surface at every cell size, and a coarse cell's height is the mean of its fine
//!   cells' heights to the rule's error.

use crate::cost::check_memory;
use crate::error::{Error, Result};
use crate::geometry::Grid;
use std::f64::consts::{PI, SQRT_2, TAU};

/// The power spectrum of a Gaussian random surface ([`crate::Heights::random_surface`];
/// docs/model.md section 3.1): the spectral density `S(k)` of the field `g` before it
/// is normalised to unit variance, as a function of the wavenumber `k = |k|` (rad/m).
///
/// Built by its validated constructors; the variants' fields can be read by matching.
///
/// ```
/// use precursors::{Error, SurfaceSpectrum};
/// // Gaussian correlation C(r) = exp(-r²/ξ²) with ξ = 3 mm.
/// let gaussian = SurfaceSpectrum::gaussian(3e-3)?;
/// assert!(matches!(gaussian, SurfaceSpectrum::Gaussian { correlation_length, .. }
///     if correlation_length == 3e-3));
/// // Self-affine, H = 0.8: flat from 20 mm down to the 5 mm roll-off, then k^(-2(1+H))
/// // down to 0.5 mm.
/// let rough = SurfaceSpectrum::self_affine(0.8, 5e-3, 0.5e-3, 20e-3)?;
/// assert!(matches!(rough, SurfaceSpectrum::SelfAffine { hurst, .. } if hurst == 0.8));
/// // A short cut-off longer than the roll-off is refused.
/// let e = SurfaceSpectrum::self_affine(0.8, 1e-3, 2e-3, 20e-3).unwrap_err();
/// assert!(matches!(e, Error::InvalidParameter { name: "short_cutoff", .. }));
/// # Ok::<(), precursors::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(try_from = "SurfaceSpectrumFields", into = "SurfaceSpectrumFields")
)]
#[non_exhaustive]
pub enum SurfaceSpectrum {
    /// Gaussian correlation `C(r) = exp(-r²/ξ²)`: `S(k) ∝ exp(-k²ξ²/4)`.
    #[non_exhaustive]
    Gaussian {
        /// The correlation length `ξ` (m, finite and `> 0`).
        correlation_length: f64,
    },
    /// Self-affine with Hurst exponent `H`: `S(k) ∝ k^(-2(1+H))` between the roll-off
    /// wavenumber `k_r = 2π/λ_r` and the short-wavelength cut-off `k_s = 2π/λ_s`, flat
    /// from the long-wavelength cut-off `k_l = 2π/λ_l` up to `k_r`, zero below `k_l` and
    /// above `k_s`.
    #[non_exhaustive]
    SelfAffine {
        /// The Hurst exponent `H` (dimensionless, in `(0, 1]`).
        hurst: f64,
        /// The roll-off wavelength `λ_r` (m).
        roll_off: f64,
        /// The short-wavelength cut-off `λ_s` (m, `< λ_r`).
        short_cutoff: f64,
        /// The long-wavelength cut-off `λ_l` (m, `≥ λ_r`).
        long_cutoff: f64,
    },
}

/// A [`SurfaceSpectrum`] as serde sees it (feature `serde`): `{"kind": "gaussian",
/// "correlation_length": ξ}` or `{"kind": "self_affine", "hurst": H, "roll_off": λ_r,
/// "short_cutoff": λ_s, "long_cutoff": λ_l}` (the scene file's surface heights keys), read
/// back through [`SurfaceSpectrum::gaussian`] and [`SurfaceSpectrum::self_affine`].
#[cfg(feature = "serde")]
#[derive(serde::Serialize, serde::Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
enum SurfaceSpectrumFields {
    Gaussian {
        correlation_length: f64,
    },
    SelfAffine {
        hurst: f64,
        roll_off: f64,
        short_cutoff: f64,
        long_cutoff: f64,
    },
}

#[cfg(feature = "serde")]
impl From<SurfaceSpectrum> for SurfaceSpectrumFields {
    fn from(s: SurfaceSpectrum) -> Self {
        match s {
            SurfaceSpectrum::Gaussian { correlation_length } => {
                Self::Gaussian { correlation_length }
            }
            SurfaceSpectrum::SelfAffine {
                hurst,
                roll_off,
                short_cutoff,
                long_cutoff,
            } => Self::SelfAffine {
                hurst,
                roll_off,
                short_cutoff,
                long_cutoff,
            },
        }
    }
}

#[cfg(feature = "serde")]
impl TryFrom<SurfaceSpectrumFields> for SurfaceSpectrum {
    type Error = Error;
    fn try_from(f: SurfaceSpectrumFields) -> Result<Self> {
        match f {
            SurfaceSpectrumFields::Gaussian { correlation_length } => {
                SurfaceSpectrum::gaussian(correlation_length)
            }
            SurfaceSpectrumFields::SelfAffine {
                hurst,
                roll_off,
                short_cutoff,
                long_cutoff,
            } => SurfaceSpectrum::self_affine(hurst, roll_off, short_cutoff, long_cutoff),
        }
    }
}

/// The Gaussian spectrum is cut where `S(k)/S(0) = exp(-k²ξ²/4)` falls to `1e-16`: the
/// variance left out is the same fraction, below the rounding of `g`.
const GAUSSIAN_CUTOFF: f64 = 1e-16;

/// The Gauss-Legendre rule's target: the estimated error of a cell average of `g`, in
/// units of its standard deviation.
const QUADRATURE_TOLERANCE: f64 = 1e-12;

/// The cell averages' target: two successive rules agree to this fraction of the
/// heights' standard deviation.
pub(crate) const CELL_TOLERANCE: f64 = 1e-10;

/// The largest Gauss-Legendre order per axis.
pub(crate) const MAX_ORDER: usize = 64;

/// The most Fourier modes a surface may hold (its bounding rectangle of modes).
pub(crate) const MAX_MODES: u64 = 1 << 22;

/// The most complex multiply-adds a surface's synthesis may take (about a minute on one
/// core).
pub(crate) const MAX_WORK: u64 = 20_000_000_000;

impl SurfaceSpectrum {
    /// Gaussian correlation `C(r) = exp(-r²/ξ²)` with correlation length `ξ` (m).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] (`correlation_length`) unless `ξ` is finite and `> 0`.
    pub fn gaussian(correlation_length: f64) -> Result<Self> {
        let s = SurfaceSpectrum::Gaussian { correlation_length };
        s.check()?;
        Ok(s)
    }

    /// Self-affine with Hurst exponent `H` (dimensionless), roll-off wavelength `λ_r`,
    /// short-wavelength cut-off `λ_s` and long-wavelength cut-off `λ_l` (m).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the first value out of range: `H` in `(0, 1]`,
    /// the wavelengths finite and `> 0` with `λ_s < λ_r ≤ λ_l`.
    pub fn self_affine(
        hurst: f64,
        roll_off: f64,
        short_cutoff: f64,
        long_cutoff: f64,
    ) -> Result<Self> {
        let s = SurfaceSpectrum::SelfAffine {
            hurst,
            roll_off,
            short_cutoff,
            long_cutoff,
        };
        s.check()?;
        Ok(s)
    }

    /// The constructors' checks.
    pub(crate) fn check(&self) -> Result<()> {
        let length = |name: &'static str, value: f64| {
            if value.is_finite() && value > 0.0 {
                Ok(())
            } else {
                Err(Error::InvalidParameter {
                    name,
                    value,
                    reason: "a surface's length must be finite and > 0 m",
                })
            }
        };
        match *self {
            SurfaceSpectrum::Gaussian { correlation_length } => {
                length("correlation_length", correlation_length)
            }
            SurfaceSpectrum::SelfAffine {
                hurst,
                roll_off,
                short_cutoff,
                long_cutoff,
            } => {
                if !(hurst > 0.0 && hurst <= 1.0) {
                    return Err(Error::InvalidParameter {
                        name: "hurst",
                        value: hurst,
                        reason: "the Hurst exponent must lie in (0, 1]",
                    });
                }
                length("roll_off", roll_off)?;
                length("short_cutoff", short_cutoff)?;
                length("long_cutoff", long_cutoff)?;
                if short_cutoff >= roll_off {
                    return Err(Error::InvalidParameter {
                        name: "short_cutoff",
                        value: short_cutoff,
                        reason: "the short-wavelength cut-off must be shorter than the \
                                 roll-off wavelength",
                    });
                }
                if long_cutoff < roll_off {
                    return Err(Error::InvalidParameter {
                        name: "long_cutoff",
                        value: long_cutoff,
                        reason: "the long-wavelength cut-off must be at least the roll-off \
                                 wavelength",
                    });
                }
                Ok(())
            }
        }
    }

    /// The spectral density `S(k)` (dimensionless: `S` at the flat part or at `k = 0` is
    /// 1) at wavenumber `k` (rad/m).
    pub(crate) fn density(&self, k: f64) -> f64 {
        match *self {
            SurfaceSpectrum::Gaussian { correlation_length } => {
                let x = k * correlation_length;
                libm::exp(-0.25 * x * x)
            }
            SurfaceSpectrum::SelfAffine {
                hurst,
                roll_off,
                short_cutoff,
                long_cutoff,
            } => {
                let (kl, kr, ks) = (TAU / long_cutoff, TAU / roll_off, TAU / short_cutoff);
                if k < kl || k > ks {
                    0.0
                } else if k <= kr {
                    1.0
                } else {
                    libm::pow(k / kr, -2.0 * (1.0 + hurst))
                }
            }
        }
    }

    /// The largest wavenumber of the mode set (rad/m).
    pub(crate) fn cutoff(&self) -> f64 {
        match *self {
            SurfaceSpectrum::Gaussian { correlation_length } => {
                2.0 * libm::sqrt(-libm::log(GAUSSIAN_CUTOFF)) / correlation_length
            }
            SurfaceSpectrum::SelfAffine { short_cutoff, .. } => TAU / short_cutoff,
        }
    }

    /// How far the field stays correlated (m): the period exceeds the block by at least
    /// this much, so that no point of the block sees another's periodic image.
    pub(crate) fn reach(&self) -> f64 {
        match *self {
            // C(6ξ) = e^-36.
            SurfaceSpectrum::Gaussian { correlation_length } => 6.0 * correlation_length,
            SurfaceSpectrum::SelfAffine { long_cutoff, .. } => long_cutoff,
        }
    }
}

/// The period `P` (m) of the synthesis along a side of length `l` (m).
pub(crate) fn period(l: f64, spectrum: &SurfaceSpectrum) -> f64 {
    (2.0 * l).max(l + spectrum.reach())
}

/// SplitMix64's step: the golden-ratio increment and the finaliser.
fn mix(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Separates the surfaces' stream from other uses of a seed (the white-noise heights).
const DOMAIN: u64 = 0x5355_5246_4143_4531;

/// A uniform in `(0, 1)` from the top 53 bits (never 0, so its logarithm is finite).
fn unit(bits: u64) -> f64 {
    ((bits >> 11) as f64 + 0.5) * (1.0 / (1u64 << 53) as f64)
}

/// The pair of independent standard normals of mode `(p, q)` of the surface `seed`:
/// `key = mix(mix(mix(seed ^ DOMAIN) ^ zigzag(p)) ^ q)`, uniforms from `mix(key ^ 1)`
/// and `mix(key ^ 2)`, Box-Muller.
pub(crate) fn mode_normals(seed: u64, p: i64, q: u64) -> (f64, f64) {
    let zigzag = ((p << 1) ^ (p >> 63)) as u64;
    let key = mix(mix(mix(seed ^ DOMAIN) ^ zigzag) ^ q);
    let (u1, u2) = (unit(mix(key ^ 1)), unit(mix(key ^ 2)));
    let r = libm::sqrt(-2.0 * libm::log(u1));
    let theta = TAU * u2;
    (r * libm::cos(theta), r * libm::sin(theta))
}

/// A surface's modes on the block: the periods, the bounding rectangle
/// `p ∈ [-pm, pm]`, `q ∈ [0, qm]`, and the normalised variances `a²` of the modes of the
/// set (zero outside it), row `q`, column `p + pm`.
pub(crate) struct Modes {
    px: f64,
    py: f64,
    pm: usize,
    qm: usize,
    variance: Vec<f64>,
}

impl Modes {
    /// The modes of `spectrum` on a block `lx x ly` (m).
    ///
    /// # Errors
    /// [`Error::SurfaceTooLarge`] for more than [`MAX_MODES`] modes;
    /// [`Error::OutOfMemory`].
    pub(crate) fn new(lx: f64, ly: f64, spectrum: &SurfaceSpectrum) -> Result<Modes> {
        let (px, py) = (period(lx, spectrum), period(ly, spectrum));
        let kc = spectrum.cutoff();
        let pm = (kc * px / TAU).floor();
        let qm = (kc * py / TAU).floor();
        let count = (2.0 * pm + 1.0) * (qm + 1.0);
        if count.is_nan() || count > MAX_MODES as f64 {
            return Err(Error::SurfaceTooLarge {
                what: "Fourier modes",
                needed: count,
                limit: MAX_MODES as f64,
                hint: "the surface's shortest wavelength is too small against the block: \
                       raise heights.correlation_length (gaussian_surface) or \
                       heights.short_cutoff (self_affine_surface), or use a smaller block",
            });
        }
        let (pm, qm) = (pm as usize, qm as usize);
        check_memory(
            || format!("a random surface of {count} Fourier modes"),
            24.0 * count,
            "use a longer correlation length or short cut-off",
        )?;
        let width = 2 * pm + 1;
        let mut variance = vec![0.0; width * (qm + 1)];
        let mut total = 0.0;
        for q in 0..=qm {
            for (column, v) in variance[q * width..(q + 1) * width].iter_mut().enumerate() {
                let p = column as i64 - pm as i64;
                if q == 0 && p < 0 {
                    continue;
                }
                let (fx, fy) = (p as f64 / px, q as f64 / py);
                let k = TAU * libm::sqrt(fx * fx + fy * fy);
                if k <= kc {
                    // The mean mode stands for itself; every other for itself and -k.
                    *v = spectrum.density(k) * if p == 0 && q == 0 { 0.5 } else { 1.0 };
                    total += *v;
                }
            }
        }
        if total.is_nan() || total <= 0.0 {
            return Err(Error::SurfaceTooLarge {
                what: "Fourier modes in the spectrum's band (it holds none: the band is \
                       narrower than the modes' spacing 2π/P)",
                needed: 1.0,
                limit: 0.0,
                hint: "widen the band between heights.long_cutoff and heights.short_cutoff \
                       (self_affine_surface)",
            });
        }
        variance.iter_mut().for_each(|v| *v /= total);
        Ok(Modes {
            px,
            py,
            pm,
            qm,
            variance,
        })
    }

    /// The number of modes of the set (`a² > 0`).
    #[cfg(test)]
    pub(crate) fn len(&self) -> usize {
        self.variance.iter().filter(|v| **v > 0.0).count()
    }

    /// The modes of the set: `(p, q, kx, ky, a²)`.
    #[cfg(test)]
    pub(crate) fn iter(&self) -> impl Iterator<Item = (i64, u64, f64, f64, f64)> + '_ {
        let width = 2 * self.pm + 1;
        self.variance
            .iter()
            .enumerate()
            .filter(|(_, v)| **v > 0.0)
            .map(move |(i, v)| {
                let (q, p) = (i / width, (i % width) as i64 - self.pm as i64);
                (
                    p,
                    q as u64,
                    TAU * p as f64 / self.px,
                    TAU * q as f64 / self.py,
                    *v,
                )
            })
    }

    /// The complex coefficients `c = a (ξ - iη)` of the surface `seed`, row `q`, column
    /// `p + pm` (zero outside the set).
    fn coefficients(&self, seed: u64) -> Vec<(f64, f64)> {
        let width = 2 * self.pm + 1;
        self.variance
            .iter()
            .enumerate()
            .map(|(i, v)| {
                if *v > 0.0 {
                    let (q, p) = (i / width, (i % width) as i64 - self.pm as i64);
                    let (xi, eta) = mode_normals(seed, p, q as u64);
                    let a = libm::sqrt(*v);
                    (a * xi, -a * eta)
                } else {
                    (0.0, 0.0)
                }
            })
            .collect()
    }

    /// The field `g` of the surface `seed` at the points `(xs[a], ys[b])` (m), row `b`:
    /// `g = Re Σ c e^{i(kx x + ky y)}`, the cheaper order of the two products.
    pub(crate) fn field(&self, seed: u64, xs: &[f64], ys: &[f64]) -> Vec<f64> {
        let c = self.coefficients(seed);
        let (np, nq) = (2 * self.pm + 1, self.qm + 1);
        let ex = phases(xs, self.px, self.pm as i64, np);
        let ey = phases(ys, self.py, 0, nq);
        let (nx, ny) = (xs.len(), ys.len());
        let mut g = vec![0.0; nx * ny];
        if nq * np * nx + ny * nq * nx <= ny * nq * np + ny * np * nx {
            // t[q][a] = Σ_p c[q][p] ex[a][p]; g[b][a] = Re Σ_q ey[b][q] t[q][a].
            let mut t = vec![(0.0, 0.0); nq * nx];
            for q in 0..nq {
                let row = &c[q * np..(q + 1) * np];
                if row.iter().all(|v| *v == (0.0, 0.0)) {
                    continue;
                }
                for a in 0..nx {
                    t[q * nx + a] = dot(row, &ex[a * np..(a + 1) * np]);
                }
            }
            for b in 0..ny {
                for a in 0..nx {
                    let mut re = 0.0;
                    for q in 0..nq {
                        let (e, v) = (ey[b * nq + q], t[q * nx + a]);
                        re += e.0 * v.0 - e.1 * v.1;
                    }
                    g[b * nx + a] = re;
                }
            }
        } else {
            // u[b][p] = Σ_q ey[b][q] c[q][p]; g[b][a] = Re Σ_p u[b][p] ex[a][p].
            let mut u = vec![(0.0, 0.0); ny * np];
            for b in 0..ny {
                for p in 0..np {
                    let (mut re, mut im) = (0.0, 0.0);
                    for q in 0..nq {
                        let (e, v) = (ey[b * nq + q], c[q * np + p]);
                        re += e.0 * v.0 - e.1 * v.1;
                        im += e.0 * v.1 + e.1 * v.0;
                    }
                    u[b * np + p] = (re, im);
                }
            }
            for b in 0..ny {
                for a in 0..nx {
                    g[b * nx + a] = dot(&u[b * np..(b + 1) * np], &ex[a * np..(a + 1) * np]).0;
                }
            }
        }
        g
    }

    /// The complex multiply-adds of [`Modes::field`] at `nx x ny` points.
    pub(crate) fn work(&self, nx: usize, ny: usize) -> f64 {
        let (np, nq) = ((2 * self.pm + 1) as f64, (self.qm + 1) as f64);
        let (nx, ny) = (nx as f64, ny as f64);
        (nq * np * nx + ny * nq * nx).min(ny * nq * np + ny * np * nx)
    }

    /// The smallest Gauss-Legendre order per axis whose estimated error of a cell average
    /// of `g` is below [`QUADRATURE_TOLERANCE`]: the rule's error on each mode's cell
    /// average `sinc(k Δ/2)`, weighted by the mode's variance.
    pub(crate) fn orders(&self, dx: f64, dy: f64) -> Result<(usize, usize)> {
        // Variance per column p and per row q (the error of a product of two averages is
        // bounded by the sum of the factors' errors: each average is at most 1).
        let width = 2 * self.pm + 1;
        let mut by_p = vec![0.0; width];
        let mut by_q = vec![0.0; self.qm + 1];
        for (i, v) in self.variance.iter().enumerate() {
            by_p[i % width] += v;
            by_q[i / width] += v;
        }
        let order = |weights: &[f64], k: &dyn Fn(usize) -> f64, half: f64, axis: &'static str| {
            for n in 1..=MAX_ORDER {
                let (nodes, w) = gauss_legendre(n);
                let error: f64 = weights
                    .iter()
                    .enumerate()
                    .filter(|(_, v)| **v > 0.0)
                    .map(|(i, v)| {
                        let x = k(i) * half;
                        let rule: f64 = nodes
                            .iter()
                            .zip(&w)
                            .map(|(t, w)| 0.5 * w * libm::cos(x * t))
                            .sum();
                        let exact = if x == 0.0 { 1.0 } else { libm::sin(x) / x };
                        v * (rule - exact) * (rule - exact)
                    })
                    .sum();
                if libm::sqrt(2.0 * error) <= 0.5 * QUADRATURE_TOLERANCE {
                    return Ok(n);
                }
            }
            Err(Error::SurfaceTooLarge {
                what: if axis == "x" {
                    "Gauss-Legendre points per cell along x"
                } else {
                    "Gauss-Legendre points per cell along y"
                },
                needed: MAX_ORDER as f64 + 1.0,
                limit: MAX_ORDER as f64,
                hint: "the cells are too large against the surface's shortest wavelength \
                       (correlation length or short cut-off): use smaller cells or a \
                       smoother surface",
            })
        };
        let pm = self.pm as f64;
        let nx = order(&by_p, &|i| TAU * (i as f64 - pm) / self.px, 0.5 * dx, "x")?;
        let ny = order(&by_q, &|i| TAU * i as f64 / self.py, 0.5 * dy, "y")?;
        Ok((nx, ny))
    }
}

/// `Σ a_j b_j` of complex pairs.
fn dot(a: &[(f64, f64)], b: &[(f64, f64)]) -> (f64, f64) {
    let (mut re, mut im) = (0.0, 0.0);
    for (x, y) in a.iter().zip(b) {
        re += x.0 * y.0 - x.1 * y.1;
        im += x.0 * y.1 + x.1 * y.0;
    }
    (re, im)
}

/// `e^{i 2π (first + j) s / P}` for each point `s` (row) and `j in 0..count` (column).
fn phases(points: &[f64], period: f64, first: i64, count: usize) -> Vec<(f64, f64)> {
    let mut out = Vec::with_capacity(points.len() * count);
    for &s in points {
        let f = s / period;
        for j in 0..count {
            let mut turns = (j as i64 - first) as f64 * f;
            turns -= libm::round(turns);
            let theta = TAU * turns;
            out.push((libm::cos(theta), libm::sin(theta)));
        }
    }
    out
}

/// The `n`-point Gauss-Legendre rule on `[-1, 1]`: nodes (ascending) and weights, by
/// Newton's method on the Legendre polynomial.
pub(crate) fn gauss_legendre(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut nodes = vec![0.0; n];
    let mut weights = vec![0.0; n];
    for i in 0..n.div_ceil(2) {
        let mut z = libm::cos(PI * (i as f64 + 0.75) / (n as f64 + 0.5));
        let mut dp = 1.0;
        for _ in 0..100 {
            let (mut p1, mut p2) = (1.0, 0.0);
            for j in 1..=n {
                let p3 = p2;
                p2 = p1;
                p1 = ((2 * j - 1) as f64 * z * p2 - (j - 1) as f64 * p3) / j as f64;
            }
            dp = n as f64 * (z * p1 - p2) / (z * z - 1.0);
            let step = p1 / dp;
            z -= step;
            if step.abs() <= 1e-16 {
                break;
            }
        }
        let w = 2.0 / ((1.0 - z * z) * dp * dp);
        nodes[i] = -z;
        nodes[n - 1 - i] = z;
        weights[i] = w;
        weights[n - 1 - i] = w;
    }
    if n % 2 == 1 {
        nodes[n / 2] = 0.0;
    }
    (nodes, weights)
}

/// `Φ(x)`, the standard normal CDF.
pub(crate) fn normal_cdf(x: f64) -> f64 {
    0.5 * libm::erfc(-x / SQRT_2)
}

/// `φ(x)`, the standard normal density.
fn normal_pdf(x: f64) -> f64 {
    libm::exp(-0.5 * x * x) / libm::sqrt(TAU)
}

/// `z ≤ 0` with `Φ(z) = p`, for `p` in `(0, 0.5]`: Abramowitz-Stegun 26.2.23 (error below
/// `4.5e-4`) refined by Halley's method on `Φ(z) - p`, which converges cubically.
fn lower_quantile(p: f64) -> f64 {
    let t = libm::sqrt(-2.0 * libm::log(p));
    let mut z = -(t
        - (2.515_517 + 0.802_853 * t + 0.010_328 * t * t)
            / (1.0 + 1.432_788 * t + 0.189_269 * t * t + 0.001_308 * t * t * t));
    for _ in 0..8 {
        let density = normal_pdf(z);
        if density.is_nan() || density <= 0.0 {
            break;
        }
        let r = (normal_cdf(z) - p) / density;
        let step = r / (1.0 + 0.5 * z * r);
        z -= step;
        if step.abs() <= 1e-16 * z.abs().max(1.0) {
            break;
        }
    }
    z
}

/// The heights' marginal: a Gaussian of mean `m` and standard deviation `s` (m)
/// truncated at 0, and the copula `u0 = F⁻¹(Φ(g))` onto it.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Truncated {
    mean: f64,
    std_dev: f64,
    /// The truncation point in standard units, `a = -m/s`.
    a: f64,
    /// `Φ(a)`, `Q(a) = 1 - Φ(a)`, `φ(a)`.
    cdf_a: f64,
    tail_a: f64,
    pdf_a: f64,
}

impl Truncated {
    /// The truncated Gaussian of mean `mean` and standard deviation `std_dev` (m) before
    /// truncation (a valid `HeightDistribution`'s).
    pub(crate) fn new(mean: f64, std_dev: f64) -> Truncated {
        let a = if std_dev > 0.0 { -mean / std_dev } else { 0.0 };
        Truncated {
            mean,
            std_dev,
            a,
            cdf_a: normal_cdf(a),
            tail_a: normal_cdf(-a),
            pdf_a: normal_pdf(a),
        }
    }

    /// The height `u0 = F⁻¹(Φ(g))` (m) of a standard normal value `g`, as `s·d` with
    /// `d = z - a` computed without cancellation: from the upper tail when `z ≥ 0`, from
    /// the lower one otherwise, and from the series of `Φ(a + d) - Φ(a)` when `d` is small.
    pub(crate) fn quantile(&self, g: f64) -> f64 {
        if self.std_dev == 0.0 {
            return self.mean;
        }
        let a = self.a;
        // The probability between a and z, and beyond z.
        let between = normal_cdf(g) * self.tail_a;
        let beyond = normal_cdf(-g) * self.tail_a;
        let d0 = between / self.pdf_a;
        let d = if self.pdf_a > 0.0 && d0 < 1e-4 && a.abs() * d0 < 1e-4 {
            // Φ(a+d) - Φ(a) = φ(a) d S(d), S = ∫_0^1 exp(-a d v - d² v²/2) dv, to d³.
            let mut d = d0;
            for _ in 0..4 {
                let w = -a * d;
                let s = 1.0
                    + 0.5 * w
                    + (w * w - d * d) / 6.0
                    + (w * w * w / 6.0 - 0.5 * w * d * d) / 4.0;
                d = d0 / s;
            }
            d
        } else if beyond <= 0.5 {
            -lower_quantile(beyond) - a
        } else {
            lower_quantile(self.cdf_a + between) - a
        };
        self.std_dev * d
    }
}

/// `work` (complex multiply-adds of the synthesis) within [`MAX_WORK`].
fn check_work(work: f64, what: &'static str) -> Result<()> {
    if work.is_nan() || work > MAX_WORK as f64 {
        return Err(Error::SurfaceTooLarge {
            what,
            needed: work,
            limit: MAX_WORK as f64,
            hint: "the grid has too many cells or the surface too many modes: use fewer \
                   cells or a smoother surface",
        });
    }
    Ok(())
}

/// The surface's plan on a grid: modes, Gauss-Legendre orders, points and work; checked
/// against the limits without drawing anything.
pub(crate) struct Plan {
    modes: Modes,
    orders: (usize, usize),
}

impl Plan {
    /// The plan of `spectrum` on `grid`.
    ///
    /// # Errors
    /// [`Error::SurfaceTooLarge`] (modes, quadrature order, work); [`Error::OutOfMemory`].
    pub(crate) fn new(grid: &Grid, spectrum: &SurfaceSpectrum) -> Result<Plan> {
        spectrum.check()?;
        let block = grid.block();
        let modes = Modes::new(block.lx(), block.ly(), spectrum)?;
        let orders = modes.orders(grid.dx(), grid.dy())?;
        let (nx, ny) = (grid.nx() * orders.0, grid.ny() * orders.1);
        check_work(modes.work(nx, ny), "complex multiply-adds")?;
        let (np, nq) = ((2 * modes.pm + 1) as f64, (modes.qm + 1) as f64);
        let (fx, fy) = (nx as f64, ny as f64);
        check_memory(
            || format!("a random surface on {fx} x {fy} quadrature points"),
            16.0 * (fx * np + fy * nq + nq * fx + fy * np) + 8.0 * fx * fy,
            "use fewer cells or a smoother surface",
        )?;
        Ok(Plan { modes, orders })
    }

    /// The Gauss-Legendre orders along x and y.
    #[cfg(test)]
    pub(crate) fn orders(&self) -> (usize, usize) {
        self.orders
    }

    /// The cell averages of `u0 = marginal.quantile(g)` (m) for the surface `seed`, in
    /// cell order `i = iy·Nx + ix`, to [`CELL_TOLERANCE`] of the standard deviation: the
    /// plan's orders (from `g`'s spectrum) are raised by half until two successive rules
    /// agree to it (the copula is not linear: `u0` has shorter wavelengths than `g`,
    /// more so where `g` is steep against the cell), and the higher one is returned.
    ///
    /// # Errors
    /// [`Error::SurfaceTooLarge`] when the rules reach [`MAX_ORDER`] or [`MAX_WORK`]
    /// before they agree.
    pub(crate) fn cell_averages(
        &self,
        grid: &Grid,
        marginal: &Truncated,
        seed: u64,
    ) -> Result<Vec<f64>> {
        // Heights without spread (`std_dev` 0, documented as valid) are the mean in every
        // cell: no rule to converge (the rules' sums differ in their last bits, which a
        // tolerance of 0 never accepts).
        if marginal.std_dev == 0.0 {
            return Ok(vec![marginal.mean; grid.len()]);
        }
        let (mut ox, mut oy) = self.orders;
        let mut previous = self.cell_averages_with(grid, marginal, seed, (ox, oy));
        loop {
            if ox == MAX_ORDER && oy == MAX_ORDER {
                return Err(Error::SurfaceTooLarge {
                    what: "Gauss-Legendre points per cell and axis (the cell averages did \
                           not converge within the limit)",
                    needed: MAX_ORDER as f64 + 1.0,
                    limit: MAX_ORDER as f64,
                    hint: "the cells are too large against the surface's shortest \
                           wavelength: use smaller cells (cells.dx, cells.dy) or a smoother \
                           surface (a longer heights.correlation_length or \
                           heights.short_cutoff)",
                });
            }
            (ox, oy) = (
                (ox + ox / 2 + 2).min(MAX_ORDER),
                (oy + oy / 2 + 2).min(MAX_ORDER),
            );
            check_work(
                self.modes.work(grid.nx() * ox, grid.ny() * oy),
                "complex multiply-adds (the cell averages' rule)",
            )?;
            let next = self.cell_averages_with(grid, marginal, seed, (ox, oy));
            let change = previous
                .iter()
                .zip(&next)
                .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
            // Two rules' sums differ by their rounding, a few ulps of the heights: with a
            // spread below about 1e-6 of the mean that floor exceeds the target, and the
            // rules would be raised to the limit and refused as "cells too large".
            let largest = next.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let rounding = 64.0 * f64::EPSILON * largest;
            if change <= CELL_TOLERANCE * marginal.std_dev + rounding {
                return Ok(next);
            }
            previous = next;
        }
    }

    /// The cell averages of `u0` with the rules of these orders along x and y.
    pub(crate) fn cell_averages_with(
        &self,
        grid: &Grid,
        marginal: &Truncated,
        seed: u64,
        orders: (usize, usize),
    ) -> Vec<f64> {
        let (ox, oy) = orders;
        let (tx, wx) = gauss_legendre(ox);
        let (ty, wy) = gauss_legendre(oy);
        let points = |n: usize, step: f64, t: &[f64]| -> Vec<f64> {
            (0..n)
                .flat_map(|i| t.iter().map(move |t| step * (i as f64 + 0.5 + 0.5 * t)))
                .collect()
        };
        let xs = points(grid.nx(), grid.dx(), &tx);
        let ys = points(grid.ny(), grid.dy(), &ty);
        let g = self.modes.field(seed, &xs, &ys);
        let nxp = xs.len();
        let mut out = Vec::with_capacity(grid.len());
        for iy in 0..grid.ny() {
            for ix in 0..grid.nx() {
                let mut sum = 0.0;
                for (jy, wy) in wy.iter().enumerate() {
                    let row = (iy * oy + jy) * nxp + ix * ox;
                    let mut line = 0.0;
                    for (jx, wx) in wx.iter().enumerate() {
                        line += wx * marginal.quantile(g[row + jx]);
                    }
                    sum += wy * line;
                }
                out.push(0.25 * sum);
            }
        }
        out
    }

    /// The modes.
    #[cfg(test)]
    pub(crate) fn modes(&self) -> &Modes {
        &self.modes
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Block;

    #[test]
    fn gauss_legendre_integrates_polynomials_of_degree_2n_minus_1() {
        for n in 1..=12 {
            let (t, w) = gauss_legendre(n);
            for degree in 0..2 * n {
                let rule: f64 = t
                    .iter()
                    .zip(&w)
                    .map(|(t, w)| w * t.powi(degree as i32))
                    .sum();
                // ∫_{-1}^{1} t^d dt = 2/(d+1) for even d, 0 for odd d.
                let exact = if degree % 2 == 0 {
                    2.0 / (degree as f64 + 1.0)
                } else {
                    0.0
                };
                assert!(
                    (rule - exact).abs() < 1e-14,
                    "n {n} degree {degree}: {rule}"
                );
            }
        }
    }

    #[test]
    fn the_normal_quantile_inverts_the_cdf_to_rounding() {
        for p in [
            1e-300, 1e-100, 1e-20, 1e-8, 1e-3, 0.02, 0.1, 0.3, 0.4999, 0.5,
        ] {
            let z = lower_quantile(p);
            assert!(z <= 0.0);
            let back = normal_cdf(z);
            assert!(
                ((back - p) / p).abs() < 1e-14 * z.abs().max(1.0),
                "{p}: {back}"
            );
        }
    }

    #[test]
    fn the_coefficients_are_standard_normal_pairs() {
        // 40000 pairs: means within 4 sd (0.02), variances within 4 sd (0.028), no
        // correlation between the pair's members or with the neighbouring mode.
        let m = 20_000;
        let (mut s, mut s2, mut sxy, mut snext) = ([0.0; 2], [0.0; 2], 0.0, 0.0);
        let mut previous = 0.0;
        for i in 0..m {
            let (x, y) = mode_normals(5, i as i64 - 10_000, (i % 7) as u64);
            s[0] += x;
            s[1] += y;
            s2[0] += x * x;
            s2[1] += y * y;
            sxy += x * y;
            snext += previous * x;
            previous = x;
        }
        let m = m as f64;
        for k in 0..2 {
            assert!((s[k] / m).abs() < 4.0 / m.sqrt());
            assert!((s2[k] / m - 1.0).abs() < 4.0 * (2.0 / m).sqrt());
        }
        assert!((sxy / m).abs() < 4.0 / m.sqrt());
        assert!((snext / m).abs() < 4.0 / m.sqrt());
    }

    /// The correlation of the Gaussian surface's `g` between points `r` apart along x and
    /// along y, over many seeds, against `exp(-r²/ξ²)` (the period's images are `e^-36`
    /// away): 20000 independent pairs per distance, so the estimate's standard deviation
    /// is at most `sqrt((1 + ρ²)/20000) ≤ 0.01`; tolerance 4 sd.
    #[test]
    fn the_gaussian_field_has_unit_variance_and_the_prescribed_correlation() {
        let xi = 2e-3;
        let modes = Modes::new(0.008, 0.004, &SurfaceSpectrum::gaussian(xi).unwrap()).unwrap();
        let total: f64 = modes.iter().map(|m| m.4).sum();
        assert!((total - 1.0).abs() < 1e-12);
        let seeds = 20_000;
        for r in [0.0, 0.5 * xi, xi, 1.5 * xi] {
            let expected = (-(r / xi) * (r / xi)).exp();
            for along_x in [true, false] {
                let (mut c, mut v) = (0.0, 0.0);
                for seed in 0..seeds {
                    let (xs, ys) = if along_x {
                        (vec![1e-3, 1e-3 + r], vec![2e-3])
                    } else {
                        (vec![3e-3], vec![0.5e-3, 0.5e-3 + r])
                    };
                    let g = modes.field(seed, &xs, &ys);
                    c += g[0] * g[1];
                    v += g[0] * g[0];
                }
                let (c, v) = (c / seeds as f64, v / seeds as f64);
                let sd = ((1.0 + expected * expected) / seeds as f64).sqrt();
                assert!(
                    (c - expected).abs() < 4.0 * sd,
                    "r {r} x {along_x}: {c} vs {expected}"
                );
                assert!((v - 1.0).abs() < 4.0 * (2.0 / seeds as f64).sqrt(), "{v}");
            }
        }
    }

    /// The self-affine field's covariance against the prescription summed on the mode
    /// lattice, written out here from the spectrum's definition (docs/model.md 3.1):
    /// `C(r) = Σ S(k) cos(k·r) / Σ S(k)` over the half plane of `k = 2π(p/Px, q/Py)` with
    /// `2π/λ_l ≤ |k| ≤ 2π/λ_s`; 20000 seeds, tolerance 4 sd.
    #[test]
    fn the_self_affine_field_has_the_prescribed_covariance() {
        let (h, lr, ls, ll) = (0.7, 3e-3, 0.6e-3, 5e-3);
        let spectrum = SurfaceSpectrum::self_affine(h, lr, ls, ll).unwrap();
        let (lx, ly) = (0.008, 0.004);
        let modes = Modes::new(lx, ly, &spectrum).unwrap();
        let (px, py) = ((2.0 * lx).max(lx + ll), (2.0 * ly).max(ly + ll));
        let covariance = |rx: f64, ry: f64| {
            let (mut num, mut den) = (0.0, 0.0);
            for q in 0..200i64 {
                for p in -400i64..=400 {
                    if q == 0 && p <= 0 {
                        continue;
                    }
                    let (kx, ky) = (TAU * p as f64 / px, TAU * q as f64 / py);
                    let k = kx.hypot(ky);
                    if k < TAU / ll || k > TAU / ls {
                        continue;
                    }
                    let s = if k <= TAU / lr {
                        1.0
                    } else {
                        (k * lr / TAU).powf(-2.0 * (1.0 + h))
                    };
                    num += s * (kx * rx + ky * ry).cos();
                    den += s;
                }
            }
            num / den
        };
        let seeds = 20_000;
        for (rx, ry) in [(0.0, 0.0), (0.4e-3, 0.0), (1.5e-3, 0.0), (0.0, 0.8e-3)] {
            let expected = covariance(rx, ry);
            let mut c = 0.0;
            for seed in 0..seeds {
                let g0 = modes.field(seed, &[1e-3], &[1e-3])[0];
                let g1 = modes.field(seed, &[1e-3 + rx], &[1e-3 + ry])[0];
                c += g0 * g1;
            }
            let c = c / seeds as f64;
            let sd = ((1.0 + expected * expected) / seeds as f64).sqrt();
            assert!(
                (c - expected).abs() < 4.0 * sd,
                "({rx}, {ry}): {c} vs {expected}"
            );
        }
    }

    /// The two orders of the product give the same field (to rounding).
    #[test]
    fn both_product_orders_agree() {
        let modes = Modes::new(0.008, 0.004, &SurfaceSpectrum::gaussian(1e-3).unwrap()).unwrap();
        let xs: Vec<f64> = (0..50).map(|i| i as f64 * 1.6e-4).collect();
        let ys: Vec<f64> = (0..3).map(|i| i as f64 * 1.3e-3).collect();
        let g = modes.field(3, &xs, &ys);
        // Point by point: one row and one column, the other order.
        for (b, y) in ys.iter().enumerate() {
            for (a, x) in xs.iter().enumerate() {
                let one = modes.field(3, &[*x], &[*y])[0];
                let direct: f64 = modes
                    .iter()
                    .map(|(p, q, kx, ky, v)| {
                        let (xi, eta) = mode_normals(3, p, q);
                        let theta = kx * x + ky * y;
                        v.sqrt() * (xi * theta.cos() + eta * theta.sin())
                    })
                    .sum();
                assert!((g[b * xs.len() + a] - one).abs() < 1e-12);
                assert!((one - direct).abs() < 1e-12, "{one} vs {direct}");
            }
        }
    }

    /// The copula maps `g` onto the truncated Gaussian: its quantiles at `Φ(g)` against
    /// values computed with mpmath at 50 digits (docs/experiments/surface_reference.py,
    /// `quantiles`), for the default distribution, a mean far above the truncation and one
    /// below it.
    #[test]
    fn the_copula_is_the_truncated_gaussian_quantile() {
        let cases: [(f64, f64, f64, f64); 9] = [
            // (mean, std_dev, g, u0)
            (1e-6, 1e-6, 0.0, 1.200173686166891e-06),
            (1e-6, 1e-6, -3.0, 4.682701589512545e-09),
            (1e-6, 1e-6, -6.0, 3.4304163526989315e-15),
            (1e-6, 1e-6, 5.0, 6.0332054959289565e-06),
            (1e-6, 1e-6, -1.0, 4.528534248863529e-07),
            (5e-6, 1e-6, 1.0, 6.000000187951589e-06),
            (5e-6, 1e-6, -2.5, 2.500016251762379e-06),
            (-2e-6, 1e-6, 0.0, 2.776048388094589e-07),
            (-2e-6, 1e-6, -7.0, 5.392736252506494e-19),
        ];
        for (m, s, g, expected) in cases {
            let u0 = Truncated::new(m, s).quantile(g);
            assert!(
                ((u0 - expected) / expected).abs() < 1e-11,
                "{m} {s} {g}: {u0:e} vs {expected:e}"
            );
        }
    }

    #[test]
    fn limits_are_typed_errors() {
        let e = Modes::new(0.14, 0.007, &SurfaceSpectrum::gaussian(1e-6).unwrap())
            .err()
            .unwrap();
        assert!(
            matches!(
                e,
                Error::SurfaceTooLarge {
                    what: "Fourier modes",
                    ..
                }
            ),
            "{e}"
        );
        let grid = Grid::new(Block::new(0.14, 0.007, 0.075).unwrap(), 2, 1).unwrap();
        let e = Plan::new(&grid, &SurfaceSpectrum::gaussian(1e-4).unwrap())
            .err()
            .unwrap();
        assert!(matches!(e, Error::SurfaceTooLarge { .. }), "{e}");
    }

    #[test]
    fn the_order_follows_the_shortest_wavelength_against_the_cell() {
        let block = Block::new(0.016, 0.004, 0.01).unwrap();
        let spectrum = SurfaceSpectrum::gaussian(2e-3).unwrap();
        let coarse = Plan::new(&Grid::new(block, 8, 2).unwrap(), &spectrum).unwrap();
        let fine = Plan::new(&Grid::new(block, 32, 8).unwrap(), &spectrum).unwrap();
        assert!(
            coarse.orders().0 > fine.orders().0,
            "{:?} {:?}",
            coarse.orders(),
            fine.orders()
        );
        assert!(coarse.modes().len() == fine.modes().len());
    }
}
