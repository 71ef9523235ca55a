//! Special functions of the alternatives' likelihoods (`alternatives.rs`): the generalized
//! exponential integral `E_p(z) = ∫_1^∞ t^(-p) e^(-z t) dt`, which is the upper incomplete
//! gamma function `Γ(1-p, z) = z^(1-p) E_p(z)` of the cut-off law's normalisation, and
//! `ln erfcx` for the truncated log-normal.

/// The Euler–Mascheroni constant.
const EULER_GAMMA: f64 = 0.577_215_664_901_532_9;

/// `e^z E_p(z)` for `z > 1` and any real `p`: Legendre's continued fraction for
/// `Γ(1-p, z)` in its even contraction (Numerical Recipes eq. 6.3.5), evaluated by the
/// modified Lentz method to about 1e-16 relative. A numerator of 0 (`p` a non-positive
/// integer) ends the fraction exactly.
fn scaled_expint_cf(p: f64, z: f64) -> f64 {
    const TINY: f64 = 1e-300;
    let mut b = z + p;
    let mut c = 1.0 / TINY;
    let mut d = 1.0 / b;
    let mut h = d;
    for i in 1..=2000 {
        let i = i as f64;
        let a = -i * (p - 1.0 + i);
        b += 2.0;
        d = a * d + b;
        if d.abs() < TINY {
            d = TINY;
        }
        c = b + a / c;
        if c.abs() < TINY {
            c = TINY;
        }
        d = 1.0 / d;
        let delta = c * d;
        h *= delta;
        if (delta - 1.0).abs() <= 1e-16 {
            break;
        }
    }
    h
}

/// `ln Γ(1 + ε) / ε` for `|ε| ≤ 1/2` (`-γ` at 0): `ε` is taken as `(1 + ε) - 1`, the value
/// `lgamma` sees, so the quotient has no rounding of its own to amplify.
fn lgamma1p_over(eps: f64) -> (f64, f64) {
    let x = 1.0 + eps;
    let e = x - 1.0;
    if e == 0.0 {
        (0.0, -EULER_GAMMA)
    } else {
        (e, libm::lgamma(x) / e)
    }
}

/// `E_p(z)` for `0 < z ≤ 1` and `p ∈ [0, 1.5)` by the series
/// `E_p(z) = Γ(1-p) z^(p-1) - Σ_{k≥0} (-z)^k / (k! (1-p+k))`. For `p ∈ [0.5, 1.5)` the pole
/// of `Γ(1-p)` at `p = 1` and that of the `k = 0` term cancel: with `ε = 1 - p`, their sum
/// is `(Γ(1+ε) z^(-ε) - 1)/ε = expm1(ε (lnΓ(1+ε)/ε - ln z))/ε`, exact in the limit
/// (`E_1(z) = -γ - ln z - …`).
fn expint_series(p: f64, z: f64) -> f64 {
    let eps = 1.0 - p;
    let mut sum = 0.0;
    let mut term = 1.0; // (-z)^k / k!
    for k in 1..200 {
        term *= -z / k as f64;
        let t = term / (eps + k as f64);
        sum += t;
        if t.abs() <= 1e-17 * sum.abs() {
            break;
        }
    }
    let head = if p >= 0.5 {
        let (e, g) = lgamma1p_over(eps);
        let h = g - z.ln();
        if e == 0.0 {
            h
        } else {
            (e * h).exp_m1() / e
        }
    } else {
        // ε ∈ (1/2, 1]: no pole; Γ(ε) = Γ(1 + (ε - 1)).
        libm::tgamma(eps) * z.powf(-eps) - 1.0 / eps
    };
    head - sum
}

/// `E_p(z)` for `0 < z ≤ 1` and `p ≥ 0`: the series at `p - m ∈ [0.5, 1.5)` (or at `p`
/// itself below 0.5), then `m` steps of `E_(q+1) = (e^(-z) - z E_q)/q` upwards, which
/// subtract at most `z/(z + q - 1)` of the first term.
fn expint_small(p: f64, z: f64) -> f64 {
    if p < 1.5 {
        return expint_series(p, z);
    }
    let m = (p - 0.5).floor();
    let mut q = p - m;
    let mut e = expint_series(q, z);
    let ez = (-z).exp();
    for _ in 0..m as usize {
        e = (ez - z * e) / q;
        q += 1.0;
    }
    e
}

/// `ln E_p(z)`, `E_p(z) = ∫_1^∞ t^(-p) e^(-z t) dt`, for `p ∈ [0, 40]` and `z ≥ 0`
/// (`E_p(0) = 1/(p - 1)` for `p > 1`, infinite otherwise). About 1e-14 relative in `E_p`
/// (tests: against mpmath's `expint`).
pub(crate) fn ln_expint(p: f64, z: f64) -> f64 {
    if z <= 0.0 {
        return if p > 1.0 {
            -(p - 1.0).ln()
        } else {
            f64::INFINITY
        };
    }
    if z > 1.0 {
        scaled_expint_cf(p, z).ln() - z
    } else {
        expint_small(p, z).ln()
    }
}

/// `ln erfcx(a) = a² + ln erfc(a)` for any real `a`, without overflow or underflow:
/// `libm::erfc` up to `a = 5`, then `erfcx(a) = a e^(a²) E_(1/2)(a²) / √π` (since
/// `Γ(1/2, a²) = √π erfc(a)`) by the continued fraction, and `1/(a√π) (1 - 1/(2a²))` beyond
/// `a = 1e8`, where the next term is below 1e-32.
pub(crate) fn ln_erfcx(a: f64) -> f64 {
    const LN_SQRT_PI: f64 = 0.572_364_942_924_700_1;
    if a < 5.0 {
        a * a + libm::erfc(a).ln()
    } else if a < 1e8 {
        a.ln() + scaled_expint_cf(0.5, a * a).ln() - LN_SQRT_PI
    } else {
        -a.ln() - LN_SQRT_PI + (-0.5 / (a * a)).ln_1p()
    }
}

/// The two-sided normal p-value `P(|N(0,1)| ≥ |v|) = erfc(|v|/√2)` (0 for an infinite `v`).
pub(crate) fn normal_two_sided(v: f64) -> f64 {
    libm::erfc(v.abs() / std::f64::consts::SQRT_2)
}

/// `P(χ²₁ ≥ 2|r|) = erfc(√|r|)`: the chi-square survival function with one degree of
/// freedom at twice a log-likelihood ratio `r`.
pub(crate) fn chi2_one_survival_of_twice(r: f64) -> f64 {
    libm::erfc(r.abs().sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64, rel: f64) -> bool {
        (a - b).abs() <= rel * b.abs()
    }

    #[test]
    fn expint_matches_mpmath() {
        // mpmath.expint(p, z) at 30 digits (mp.dps = 30), independent of this code: both
        // branches (z ≤ 1, z > 1), the pole-free p = 1 limit and its neighbours, the
        // upward recurrence (p up to 20), and p < 1/2.
        for (p, z, expected) in [
            (1.0, 0.5, 0.559_773_594_776_160_8),
            (1.0, 2.0, 0.048_900_510_708_061_12),
            (1.5, 1e-3, 1.889_899_842_405_362_9),
            (1.5, 0.7, 0.291_076_295_079_985_9),
            (1.48, 2.5e-4, 2.017_484_198_931_877),
            (1.000_000_01, 0.3, 0.905_676_644_379_350_8),
            (0.999_999_99, 0.3, 0.905_676_658_972_342_8),
            (2.0, 1e-6, 0.999_985_761_704_606_9),
            (2.7, 0.05, 0.528_094_325_831_058_1),
            (20.0, 0.9, 0.020_382_119_331_468_755),
            (0.5, 1.0, 0.278_805_585_280_661_98),
            (0.5, 25.0, 5.450_153_066_492_747e-13),
            (0.2, 0.01, 45.104_357_462_734_55),
            (0.0, 3.0, 0.016_595_689_455_954_65),
            (3.3, 150.0, 4.681_076_982_953_528e-68),
        ] {
            let e = ln_expint(p, z).exp();
            assert!(
                close(e, expected, 1e-13),
                "E_{p}({z}) = {e}, expected {expected}"
            );
        }
        assert_eq!(ln_expint(3.0, 0.0), -(2f64.ln()));
        assert_eq!(ln_expint(1.0, 0.0), f64::INFINITY);
        // Far beyond exp's range the logarithm stays finite: mpmath's e^z E_2(z) at 1e4.
        let l = ln_expint(2.0, 1e4);
        assert!(
            close(l, 9.998_000_599_760_12e-5f64.ln() - 1e4, 1e-15),
            "{l}"
        );
    }

    #[test]
    fn ln_erfcx_matches_erfc_and_its_asymptotics() {
        // Where both hold, the continued fraction and libm's erfc agree.
        for a in [5.0, 6.0, 9.5, 20.0] {
            let direct = a * a + libm::erfc(a).ln();
            assert!(close(ln_erfcx(a), direct, 1e-13), "{a}");
        }
        // mpmath: log(erfc(a)) + a² at 30 digits.
        assert!(close(ln_erfcx(-3.0), 9.693_136_135_250_447, 1e-15));
        assert!(close(ln_erfcx(1e6), -14.387_875_500_889_474, 1e-14));
        assert!(close(ln_erfcx(1e9), -21.295_630_779_871_09, 1e-14));
        assert!(close(normal_two_sided(1.959_963_984_540_054), 0.05, 1e-14));
        assert!(close(
            chi2_one_survival_of_twice(1.920_729_410_347_062),
            0.05,
            1e-13
        ));
    }
}
