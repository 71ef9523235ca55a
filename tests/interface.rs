//! Interface springs: seeded heights (pinned values and the truncated-Gaussian moments in
//! closed form), validation, the spring laws and the real contact area.

use precursors::{AreaLaw, HeightDistribution, Heights, Interface, Material, SiteState, SpringLaw};
use precursors::{Block, Error, Grid};

fn grid(nx: usize, ny: usize) -> Grid {
    Grid::new(
        Block::new(nx as f64 * 1e-3, ny as f64 * 1e-3, 0.01).unwrap(),
        nx,
        ny,
    )
    .unwrap()
}

/// Value stability: the same seed must give these heights on every platform and release.
/// A change here is a change of numerical behaviour and belongs in the CHANGELOG.
#[test]
fn seeded_heights_are_value_stable() {
    let h = Heights::truncated_gaussian(&grid(4, 2), HeightDistribution::default(), 42).unwrap();
    let pinned = [
        1.8343975468437958e-6,
        4.850370718527049e-7,
        2.40772757311975e-6,
        1.4644548612252356e-6,
        1.9536668702127305e-6,
        1.274115556349742e-6,
        1.4144533898735935e-6,
        3.903890291981803e-7,
    ];
    assert_eq!(h.values(), &pinned[..]);
    let again =
        Heights::truncated_gaussian(&grid(4, 2), HeightDistribution::default(), 42).unwrap();
    assert_eq!(h, again);
    let other =
        Heights::truncated_gaussian(&grid(4, 2), HeightDistribution::default(), 43).unwrap();
    assert_ne!(h, other);
}

/// Moments of N(μ, σ) truncated to (0, ∞), in closed form: with a = -μ/σ and
/// r = φ(a)/(1-Φ(a)), mean = μ + σ r and variance = σ²(1 + a r - r²).
#[test]
fn truncated_gaussian_moments_match_closed_form() {
    let g = grid(400, 250); // 1e5 sites
    let h = Heights::truncated_gaussian(&g, HeightDistribution::default(), 7).unwrap();
    let v = h.values();
    assert!(v.iter().all(|x| *x > 0.0 && x.is_finite()));
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
    // a = -1: φ(-1) = 0.24197072451914337, 1 - Φ(-1) = 0.8413447460685429.
    let r = 0.24197072451914337 / 0.8413447460685429;
    let mean_ref = 1e-6 * (1.0 + r);
    let var_ref = 1e-12 * (1.0 - r - r * r);
    // Standard errors: σ_t/√n ≈ 2.5e-9 m for the mean; a few % of the variance.
    assert!((mean - mean_ref).abs() < 1e-8, "mean {mean} vs {mean_ref}");
    assert!((var / var_ref - 1.0).abs() < 0.02, "var {var} vs {var_ref}");
}

#[test]
fn bad_heights_are_typed_errors() {
    let g = grid(3, 2);
    assert!(matches!(
        Heights::from_values(&g, vec![1e-6; 5]),
        Err(Error::LengthMismatch {
            found: 5,
            expected: 6,
            ..
        })
    ));
    assert!(matches!(
        Heights::from_values(&g, vec![1e-6, 1e-6, f64::NAN, 1e-6, 1e-6, 1e-6]),
        Err(Error::NonFinite { index: 2, .. })
    ));
    assert!(matches!(
        Heights::from_values(&g, vec![1e-6, 1e-6, 1e-6, 0.0, 1e-6, 1e-6]),
        Err(Error::NonPositiveHeight { index: 3, .. })
    ));
    assert!(matches!(
        Heights::from_values(&g, vec![1e-6, -1e-6, 1e-6, 1e-6, 1e-6, 1e-6]),
        Err(Error::NonPositiveHeight { index: 1, .. })
    ));
    for (mean, sd) in [
        (f64::NAN, 1e-6),
        (1e-6, -1.0),
        (1e-6, f64::INFINITY),
        (-4e-6, 1e-6),
        (0.0, 0.0),
    ] {
        assert!(
            matches!(
                HeightDistribution::new(mean, sd),
                Err(Error::InvalidParameter { .. })
            ),
            "mean {mean} sd {sd}"
        );
    }
    // sd = 0 with a positive mean is a flat substrate.
    let flat =
        Heights::truncated_gaussian(&g, HeightDistribution::new(2e-6, 0.0).unwrap(), 1).unwrap();
    assert!(flat.values().iter().all(|h| *h == 2e-6));
}

#[test]
fn material_and_law_validation() {
    let m = Material::default();
    assert_eq!(m.young_modulus(), 3.833e9);
    assert!((m.modulus() - 3.833e9 / 1.38).abs() < 1e-3);
    assert!(Material::new(-1.0, 0.3, 0.5).is_err());
    assert!(Material::new(1e9, 0.6, 0.5).is_err());
    assert!(Material::new(1e9, -1.0, 0.5).is_err());
    assert!(Material::new(1e9, 0.3, f64::NAN).is_err());
    let law = SpringLaw::default();
    assert_eq!((law.c_x(), law.c_z()), (1.65e12, 1.65e8));
    assert!(SpringLaw::new(0.0, 1.0).is_err());
    assert!(SpringLaw::new(1.0, f64::INFINITY).is_err());
    let g = grid(3, 2);
    let h = Heights::from_values(&grid(2, 2), vec![1e-6; 4]).unwrap();
    assert!(matches!(
        Interface::new(g, h, law),
        Err(Error::LengthMismatch { .. })
    ));
}

#[test]
fn spring_laws_and_real_contact_area() {
    let g = grid(3, 1);
    let u0 = vec![1e-6, 2e-6, 4e-6];
    let law = SpringLaw::new(2e12, 3e8).unwrap();
    let mut iface = Interface::new(g, Heights::from_values(&g, u0.clone()).unwrap(), law).unwrap();
    let kz = iface.normal_stiffness();
    for i in 0..3 {
        assert!((kz[i] - 3e8 / u0[i]).abs() <= 1e-15 * kz[i]);
    }
    // u_z = u0 (touching), u_z = 0 (the substrate's mean plane), u_z = -u0 (penetration).
    let uz = vec![1e-6, 0.0, -4e-6];
    let kx = iface.tangential_stiffness(&uz).unwrap();
    let e = std::f64::consts::E;
    assert!((kx[0] - 2e12 / e).abs() < 1e-3);
    assert!((kx[1] - 2e12).abs() < 1e-3);
    assert!((kx[2] - 2e12 * e).abs() < 1e-2);
    let area = iface.cell_contact_area(&uz).unwrap();
    let da = g.cell_area();
    assert!(area[0].abs() < 1e-20, "touching site has no area yet");
    assert!(
        (area[1] - da).abs() < 1e-15 * da,
        "u_z = 0 gives the full cell"
    );
    let expected = da / (e - 1.0) * (e * e - 1.0); // exp(-(u-u0)/u0) = e² at u = -u0
    assert!((area[2] - expected).abs() < 1e-12 * expected);
    // Detached and broken sites carry neither area nor shear stiffness.
    iface.break_site(1).unwrap();
    assert_eq!(iface.states()[1], SiteState::Broken);
    assert_eq!(iface.cell_contact_area(&uz).unwrap()[1], 0.0);
    assert_eq!(iface.tangential_stiffness(&uz).unwrap()[1], 0.0);
    assert!(matches!(
        iface.break_site(3),
        Err(Error::SiteOutOfRange { index: 3, sites: 3 })
    ));
    // A huge penetration of a tiny asperity overflows: typed error, not inf.
    let tiny = Interface::new(g, Heights::from_values(&g, vec![1e-12; 3]).unwrap(), law).unwrap();
    assert!(matches!(
        tiny.tangential_stiffness(&[-1e-9, 0.0, 0.0]),
        Err(Error::NonFinite { index: 0, .. })
    ));
    assert!(matches!(
        tiny.cell_contact_area(&[0.0, -1e-9, 0.0]),
        Err(Error::NonFinite { index: 1, .. })
    ));
    iface.heal();
    assert_eq!(iface.broken_count(), 0);
}

#[test]
fn capped_area_law_caps_each_site_at_its_cell() {
    // References: the paper's formula A = ΔA/(e-1) (exp(-(u-u0)/u0) - 1) written out here,
    // and its cap min(A, ΔA).
    let g = grid(4, 1);
    let u0 = vec![1e-6, 2e-6, 4e-6, 1e-12];
    let heights = Heights::from_values(&g, u0.clone()).unwrap();
    let paper = SpringLaw::new(2e12, 3e8).unwrap();
    assert_eq!(
        paper.area_law(),
        AreaLaw::Paper,
        "the paper's law is the default"
    );
    assert_eq!(SpringLaw::default().area_law(), AreaLaw::Paper);
    let capped = paper.with_area_law(AreaLaw::Capped);
    let p = Interface::new(g, heights.clone(), paper).unwrap();
    let c = Interface::new(g, heights, capped).unwrap();
    let e = std::f64::consts::E;
    let da = g.cell_area();
    // Half-way up the asperity, the mean plane, a penetration of u0, a huge one.
    let uz = vec![0.5e-6, 0.0, -4e-6, -1e-9];
    let formula = |i: usize| da / (e - 1.0) * ((-(uz[i] - u0[i]) / u0[i]).exp() - 1.0);
    let a = c.cell_contact_area(&uz).unwrap();
    assert!((a[0] - formula(0)).abs() <= 1e-15 * da && a[0] < da);
    assert!((a[1] - da).abs() <= 1e-15 * da);
    assert!(
        formula(2) > 2.0 * da,
        "the paper's law exceeds the cell here"
    );
    assert_eq!(a[2], da);
    assert_eq!(a[3], da, "an overflow is capped, not an error");
    let b = p.cell_contact_area(&uz[..3].iter().chain([&0.0]).copied().collect::<Vec<_>>());
    let b = b.unwrap();
    assert!((b[2] - formula(2)).abs() <= 1e-12 * formula(2));
    assert!(matches!(
        p.cell_contact_area(&uz),
        Err(Error::NonFinite { index: 3, .. })
    ));
}

/// The Coulomb rule's breaking loads, bit for bit (issue 55: the rule moved into one
/// component, whose paper rule must keep the 1.x events): `λ_i = (μ f_i) / |g_i|`,
/// rounded in that order, `+∞` where `g_i` is zero (either sign), on random tractions
/// over many decades, signs, subnormals and the extremes. Reference: IEEE 754's
/// correctly rounded product and quotient in that order, written out here; the other
/// order (`μ (f / |g|)`) gives other bits for some of the same inputs, so the check sees
/// the order.
#[test]
fn breaking_loads_are_the_coulomb_quotient_bit_for_bit() {
    let n = 4096;
    let grid = grid(64, 64);
    let interface = Interface::new(
        grid,
        Heights::from_values(&grid, vec![1e-6; n]).unwrap(),
        SpringLaw::default(),
    )
    .unwrap();
    // splitmix64: a fixed stream of bits, no dependency.
    let mut state = 0x9e37_79b9_7f4a_7c15_u64;
    let mut next = move || {
        state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    };
    // A finite value of any sign and exponent, or one of the special values.
    let mut value = |special: &[f64]| {
        let bits = next();
        match bits % 16 {
            0 => special[(bits >> 8) as usize % special.len()],
            _ => {
                let exponent = ((bits >> 52) & 0x7ff) % 0x7ff; // all ones is inf or NaN
                f64::from_bits((bits & (1 << 63)) | (exponent << 52) | (bits & ((1 << 52) - 1)))
            }
        }
    };
    let specials = [
        0.0,
        -0.0,
        5e-324,
        -5e-324,
        f64::MIN_POSITIVE,
        f64::MAX,
        -f64::MAX,
        1.0,
    ];
    let f: Vec<f64> = (0..n).map(|_| value(&specials)).collect();
    let g: Vec<f64> = (0..n).map(|_| value(&specials)).collect();
    let mut reordered = 0;
    for mu in [0.5, 0.3, 0.0, 1.7e-3, 9.9e2] {
        let loads = interface.breaking_loads(&f, &g, mu).unwrap();
        for i in 0..n {
            let expected = if g[i] == 0.0 {
                f64::INFINITY
            } else {
                (mu * f[i]) / g[i].abs()
            };
            assert_eq!(
                loads[i].to_bits(),
                expected.to_bits(),
                "site {i}: mu {mu:e}, f {:e}, g {:e}",
                f[i],
                g[i]
            );
            if g[i] != 0.0 && (mu * (f[i] / g[i].abs())).to_bits() != expected.to_bits() {
                reordered += 1;
            }
        }
    }
    assert!(
        reordered > 100,
        "only {reordered} inputs tell the orders apart"
    );
}
