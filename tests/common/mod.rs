//! Shared test helpers: Gauss–Legendre quadrature (the independent reference for cell
//! averages and face integrals) and relative comparison.

pub mod events;
#[cfg(feature = "cli")]
pub mod program;

/// A new, empty directory for one test: `precursors-<pid>-<module>-<name>` under cargo's
/// scratch directory for integration tests (`target/tmp`, which `cargo clean` removes,
/// not the system's temporary directory), emptied if a run before left it. `module` is
/// the calling test file's name (`sweep` for tests/sweep.rs): the pid keeps two test
/// processes apart, `module` and `name` the tests of one process.
/// A copy of the directory `from` at `to`, its subdirectories included; whatever was at
/// `to` is removed first.
#[allow(dead_code)] // not every feature set has a test that copies a directory
pub fn copy_dir(from: &std::path::Path, to: &std::path::Path) {
    let _ = std::fs::remove_dir_all(to);
    std::fs::create_dir_all(to).unwrap();
    for entry in std::fs::read_dir(from).unwrap() {
        let entry = entry.unwrap();
        let target = to.join(entry.file_name());
        if entry.file_type().unwrap().is_dir() {
            copy_dir(&entry.path(), &target);
        } else {
            std::fs::copy(entry.path(), target).unwrap();
        }
    }
}

#[allow(dead_code)] // not every feature set has a test that writes files
#[track_caller]
pub fn scratch(name: &str) -> std::path::PathBuf {
    let caller = std::path::Path::new(std::panic::Location::caller().file());
    let module = caller
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("tests");
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("precursors-{}-{module}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Gauss–Legendre nodes and weights on [-1, 1] by Newton iteration on P_n.
pub fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, x);
            for k in 2..=n {
                let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                p0 = p1;
                p1 = p2;
            }
            dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
            let dx = p1 / dp;
            x -= dx;
            if dx.abs() < 1e-16 {
                break;
            }
        }
        out.push((x, 2.0 / ((1.0 - x * x) * dp * dp)));
    }
    out
}

/// Composite Gauss–Legendre rule on [a, b] with `panels` panels of `n` points.
pub fn rule(a: f64, b: f64, panels: usize, n: usize) -> Vec<(f64, f64)> {
    let base = gauss_legendre(n);
    let h = (b - a) / panels as f64;
    let mut out = Vec::with_capacity(panels * n);
    for k in 0..panels {
        let (lo, hi) = (a + k as f64 * h, a + (k + 1) as f64 * h);
        for &(x, w) in &base {
            out.push((0.5 * (lo + hi) + 0.5 * (hi - lo) * x, 0.5 * (hi - lo) * w));
        }
    }
    out
}

/// Integral of `f` over [a, b].
pub fn integrate(a: f64, b: f64, panels: usize, n: usize, mut f: impl FnMut(f64) -> f64) -> f64 {
    rule(a, b, panels, n)
        .into_iter()
        .map(|(x, w)| w * f(x))
        .sum()
}

/// |a - b| / max(|b|, floor)
pub fn rel(a: f64, b: f64, floor: f64) -> f64 {
    (a - b).abs() / b.abs().max(floor)
}

#[test]
fn gauss_legendre_integrates_polynomials_exactly() {
    // Degree 2n-1 exactness: ∫_0^2 x^9 dx = 2^10/10 with n = 5.
    let v = integrate(0.0, 2.0, 1, 5, |x| x.powi(9));
    assert!((v - 102.4).abs() < 1e-12);
}

/// A scene for the solver tests: a block with `nx x ny` cells of `cell` metres, height
/// `lz`, seeded paper heights.
pub struct TestScene {
    pub grid: precursors::Grid,
    pub plan: precursors::green::InfluencePlan,
    pub interface: precursors::Interface,
}

pub fn scene(nx: usize, ny: usize, cell: f64, lz: f64, seed: u64) -> TestScene {
    use precursors::*;
    let block = Block::new(nx as f64 * cell, ny as f64 * cell, lz).unwrap();
    let grid = Grid::new(block, nx, ny).unwrap();
    let plan = green::InfluencePlan::builder(grid)
        .plan_tolerance(1e-9)
        .build()
        .unwrap();
    let heights = Heights::truncated_gaussian(&grid, HeightDistribution::default(), seed).unwrap();
    let interface = Interface::new(grid, heights, SpringLaw::default()).unwrap();
    TestScene {
        grid,
        plan,
        interface,
    }
}

/// `C = (ΔA/M) Ĝ` (m/Pa), row-major, from the naive dense assembly of the plan.
pub fn compliance_matrix(plan: &precursors::green::InfluencePlan, modulus: f64) -> Vec<f64> {
    let scale = plan.grid().cell_area() / modulus;
    plan.dense()
        .unwrap()
        .into_iter()
        .map(|g| g * scale)
        .collect()
}

/// Solves the bordered system `[C_SS + diag(d), 1; 1ᵀ, 0] [f; U] = [b; total]` with faer's
/// full-pivoting LU (a method the crate's solvers do not use).
pub fn bordered_solve(
    c: &[f64],
    n: usize,
    set: &[usize],
    d: &[f64],
    b: &[f64],
    total: f64,
) -> (Vec<f64>, f64) {
    use faer::prelude::*;
    let m = set.len();
    let a = faer::Mat::<f64>::from_fn(m + 1, m + 1, |i, j| match (i < m, j < m) {
        (true, true) => c[set[i] * n + set[j]] + if i == j { d[i] } else { 0.0 },
        (true, false) | (false, true) => 1.0,
        (false, false) => 0.0,
    });
    let rhs = faer::Mat::<f64>::from_fn(m + 1, 1, |i, _| if i < m { b[i] } else { total });
    let x = a.full_piv_lu().solve(&rhs);
    ((0..m).map(|i| x[(i, 0)]).collect(), x[(m, 0)])
}

/// Largest |a - b| over the largest |a|.
pub fn max_rel_diff(a: &[f64], b: &[f64]) -> f64 {
    let scale = a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    a.iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
        / scale
}

/// Allocations made by the current thread, counted by the test crate's global allocator
/// (the system allocator plus a per-thread counter): tests assert that a hot path
/// allocates nothing.
pub mod allocations {
    use std::alloc::{GlobalAlloc, Layout, System};
    use std::cell::Cell;

    struct Counting;

    thread_local! {
        static COUNT: Cell<u64> = const { Cell::new(0) };
    }

    // SAFETY: forwards to the system allocator; the counter is a const-initialised
    // thread-local `Cell`, which does not allocate.
    unsafe impl GlobalAlloc for Counting {
        unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
            let _ = COUNT.try_with(|c| c.set(c.get() + 1));
            unsafe { System.alloc(layout) }
        }
        unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
            unsafe { System.dealloc(ptr, layout) }
        }
        unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
            let _ = COUNT.try_with(|c| c.set(c.get() + 1));
            unsafe { System.realloc(ptr, layout, new_size) }
        }
    }

    #[global_allocator]
    static GLOBAL: Counting = Counting;

    /// Allocations (and reallocations) of this thread so far.
    pub fn count() -> u64 {
        COUNT.with(Cell::get)
    }
}

/// `e` and its causes ([`std::error::Error::source`]) joined by ": ", as `anyhow` prints
/// `{:#}`: where a test looks for a cause's text (the parser's, the system's), since an
/// error's own `Display` leaves its cause out.
#[allow(dead_code)] // not every feature set has a test of a cause's text
pub fn chain(e: &(dyn std::error::Error + 'static)) -> String {
    let mut text = e.to_string();
    let mut source = e.source();
    while let Some(cause) = source {
        text.push_str(": ");
        text.push_str(&cause.to_string());
        source = cause.source();
    }
    text
}

/// A run of `scene` into `dir` killed `after` events past a checkpoint taken at its
/// `stable`-th stable state (its tables flushed there, as the program does): the tables
/// are left `.partial` with rows beyond the checkpoint. Returns the checkpoint.
#[cfg(feature = "serde")]
#[allow(dead_code)] // not every feature set has a resume test
pub fn killed_after_checkpoint(
    scene: &precursors::Scene,
    dir: &std::path::Path,
    stable: usize,
    after: usize,
) -> precursors::Checkpoint {
    let mut driver = scene.driver().unwrap();
    let mut tables = precursors::output::RunTables::create(dir, &driver).unwrap();
    let (mut checkpoint, mut states, mut past) = (None, 0, 0);
    while let Some(event) = driver.step().unwrap() {
        tables.record(&driver, &event).unwrap();
        if checkpoint.is_some() {
            past += 1;
            if past == after {
                break;
            }
        } else if matches!(event, precursors::Event::Stable { .. }) {
            states += 1;
            if states == stable {
                checkpoint = Some(tables.checkpoint(&driver).unwrap());
            }
        }
    }
    tables.flush().unwrap();
    checkpoint.expect("the run reached the checkpoint's stable state")
}
