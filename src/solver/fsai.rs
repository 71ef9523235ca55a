//! Factorised sparse approximate inverse (FSAI) of `A = C_SS + diag(d)` on an attached
//! set: `M⁻¹ = Gᵀ G`, `G` lower triangular in site order on a local pattern (the site and
//! its attached neighbours of smaller index within `radius` cells). Row `i` of `G` solves
//! the small SPD system `A[P_i, P_i] g = e_i` and is scaled by `1/√g_i`, so `M⁻¹` is
//! symmetric positive definite by construction (projected CG stays valid).
//!
//! Why: `A` is an order −1 operator on a porous set, badly conditioned for Jacobi; a
//! local approximate inverse captures the strong coupling of neighbouring sites at the
//! cost of two sparse products per iteration, far less than the DCT product.
//!
//! The entries of `C` between nearby sites are exact: with the cosine basis of the plan,
//! `Ĝ[(a,i),(b,j)] = Σ K(s, t)` over `s ∈ {|a-b|, a+b+1}`, `t ∈ {|i-j|, i+j+1}` (the
//! image sums of the even reflection), `K(s,t) = ¼ Σ λ(p,m) cos(πps/Nx) cos(πmt/Ny)`,
//! tabulated once (`O(Nx Ny (Nx + Ny))`).
//!
//! Rows are cached per site with the pattern and compliances they were built from and
//! rebuilt only when these change: every row is a pure function of its own inputs, so
//! the preconditioner is a deterministic function of the set and the compliances (no
//! history; checkpoints resume bit for bit).

use super::parallel::{map_parts, Parallelism};
use crate::error::Result;
use crate::green::InfluencePlan;
use std::f64::consts::PI;

/// The exact entries of `C_s = scale (Ĝ - shift 11ᵀ)`.
#[derive(Debug, Clone)]
pub(crate) struct Entries {
    nx: usize,
    ny: usize,
    /// `K(s, t)`, row-major `2Ny x 2Nx`.
    k: Vec<f64>,
    scale: f64,
    shift: f64,
}

/// Tasks the rows of [`Entries::new`]'s two sums are cut into (more than threads, so that
/// they even out; each row is summed by one task, in the same order whatever the threads).
const ROW_TASKS: usize = 64;

impl Entries {
    /// The table `K` of `plan`'s eigenvalues, its two sums (`2 Nx Ny² + 4 Nx² Ny` terms,
    /// 4e11 on a 10 000 x 1 000 grid) over `parallelism`'s threads.
    /// Each entry is summed by one task in a fixed order: the same bits for any threads.
    ///
    /// # Errors
    /// [`Error::ThreadPool`](crate::Error::ThreadPool) when the threads cannot be started.
    pub(crate) fn new(
        plan: &InfluencePlan,
        scale: f64,
        shift: f64,
        parallelism: Parallelism,
    ) -> Result<Self> {
        let (nx, ny) = (plan.grid().nx(), plan.grid().ny());
        // cos(π k / N) for k mod 2N, exact multiples.
        let cos_table = |n: usize| -> Vec<f64> {
            (0..2 * n)
                .map(|k| (PI * k as f64 / n as f64).cos())
                .collect()
        };
        let (cx, cy) = (cos_table(nx), cos_table(ny));
        // Rows `lo .. hi` of `count` cut into the tasks.
        let rows = |count: usize, task: usize, tasks: usize| {
            task * count / tasks..(task + 1) * count / tasks
        };
        // H(p, t) = Σ_m λ(p,m) cos(πmt/Ny), t < 2Ny: rows p.
        let tasks = ROW_TASKS.min(nx);
        let h: Vec<f64> = map_parts(parallelism, tasks, |task| {
            let mut out = Vec::new();
            for p in rows(nx, task, tasks) {
                for t in 0..2 * ny {
                    let mut s = 0.0;
                    for m in 0..ny {
                        s += plan.lambda(p, m).unwrap_or(0.0) * cy[(m * t) % (2 * ny)];
                    }
                    out.push(s);
                }
            }
            out
        })?
        .concat();
        // K(s, t) = ¼ Σ_p H(p, t) cos(πps/Nx): rows t.
        let tasks = ROW_TASKS.min(2 * ny);
        let k: Vec<f64> = map_parts(parallelism, tasks, |task| {
            let mut out = Vec::new();
            for t in rows(2 * ny, task, tasks) {
                for s in 0..2 * nx {
                    let mut acc = 0.0;
                    for p in 0..nx {
                        acc += h[p * 2 * ny + t] * cx[(p * s) % (2 * nx)];
                    }
                    out.push(0.25 * acc);
                }
            }
            out
        })?
        .concat();
        Ok(Self {
            nx,
            ny,
            k,
            scale,
            shift,
        })
    }

    /// `Σ_{i ∈ a} Σ_{j ∈ b} C_s[i, j]`, summed in a fixed order (row by row of `a`): a
    /// pure function of the two site lists (the coarse space's `Zᵀ C Z`).
    pub(crate) fn block_sum(&self, a: &[usize], b: &[usize]) -> f64 {
        let w = 2 * self.nx;
        // `b`'s cells once, not once per pair: the integer divisions cost about a third of
        // the sum's time.
        let cells: Vec<(usize, usize)> = b.iter().map(|&j| (j % self.nx, j / self.nx)).collect();
        let mut total = 0.0;
        for &i in a {
            let (x, y) = (i % self.nx, i / self.nx);
            let mut row = 0.0;
            for &(u, v) in &cells {
                let (s0, s1) = (x.abs_diff(u), x + u + 1);
                let (t0, t1) = (y.abs_diff(v) * w, (y + v + 1) * w);
                row += (self.k[t0 + s0] + self.k[t0 + s1]) + (self.k[t1 + s0] + self.k[t1 + s1]);
            }
            total += row;
        }
        self.scale * (total - self.shift * (a.len() * b.len()) as f64)
    }

    /// `C_s[i, j]` for sites `i`, `j`.
    pub(crate) fn get(&self, i: usize, j: usize) -> f64 {
        let (a, y) = (i % self.nx, i / self.nx);
        let (b, z) = (j % self.nx, j / self.nx);
        let s = [a.abs_diff(b), a + b + 1];
        let t = [y.abs_diff(z), y + z + 1];
        let w = 2 * self.nx;
        let mut g = 0.0;
        for tt in t {
            for ss in s {
                g += self.k[tt * w + ss];
            }
        }
        self.scale * (g - self.shift)
    }
}

/// Cells per block of the products (a block's values stay in L1 across the slots).
const BLOCK: usize = 256;

/// The cached factor `G` (rows per site) of one system kind (normal or tangential).
#[derive(Debug, Clone)]
pub(crate) struct Fsai {
    radius: usize,
    /// Pattern slots per row: the site and its lower neighbours in a `(2r+1)²` box.
    stride: usize,
    /// Site offset of each slot (`dy Nx + dx ≤ 0`; the last slot is the site itself).
    offsets: Vec<usize>,
    /// Per site: pattern length (0: no row cached).
    len: Vec<usize>,
    /// Per site, `stride` slots: pattern sites (ascending, the site last), their slots,
    /// the compliances they were built with and the row of `G`.
    cols: Vec<usize>,
    slots: Vec<usize>,
    diag: Vec<f64>,
    g: Vec<f64>,
    /// Per site: on the current set, its compliance there, and a visit mark.
    member: Vec<bool>,
    dsite: Vec<f64>,
    marked: Vec<bool>,
    /// Scratch of [`Fsai::update`]: changed sites, rows to visit.
    changed: Vec<usize>,
    dirty: Vec<usize>,
    /// The current set (ascending sites).
    sites: Vec<usize>,
    /// `G` of the current set on the full grid as one weight plane per slot: `(G r)_i =
    /// Σ_k w_k[i] r[i - offset_k]` (zero weight where a neighbour is missing). Why: the
    /// products become shifted, contiguous, vectorised passes instead of gathers.
    planes: Vec<f64>,
    /// The small matrix.
    small: Vec<f64>,
}

/// The pattern slots of a row for `radius`: the lower neighbours in the `(2r+1)²` box
/// (`r` rows of `2r+1`, then `r` on the site's row) and the site.
pub(crate) const fn pattern_slots(radius: usize) -> usize {
    radius * (2 * radius + 1) + radius + 1
}

impl Fsai {
    pub(crate) fn new(nx: usize, n: usize, radius: usize) -> Self {
        let r = radius as isize;
        let mut offsets = Vec::new();
        for dy in -r..=0 {
            let hi = if dy == 0 { -1 } else { r };
            for dx in -r..=hi {
                offsets.push((-(dy * nx as isize + dx)) as usize);
            }
        }
        offsets.push(0);
        let stride = offsets.len();
        debug_assert_eq!(stride, pattern_slots(radius));
        Self {
            radius,
            stride,
            offsets,
            len: vec![0; n],
            cols: vec![0; n * stride],
            slots: vec![0; n * stride],
            diag: vec![0.0; n * stride],
            g: vec![0.0; n * stride],
            member: vec![false; n],
            dsite: vec![0.0; n],
            marked: vec![false; n],
            changed: Vec::new(),
            dirty: Vec::new(),
            sites: Vec::new(),
            planes: vec![0.0; n * stride],
            small: vec![0.0; stride * stride],
        }
    }

    /// Updates the factor for `set` (ascending sites) with compliances `d`. Only the rows
    /// whose pattern box holds a site that joined, left or changed compliance are visited
    /// (a rupture touches a few): the others are the same function of the same inputs.
    /// Why: visiting all rows cost about 0.4 ms per solve, on one thread.
    pub(crate) fn update(&mut self, entries: &Entries, set: &[usize], d: &[f64]) {
        let mut changed = std::mem::take(&mut self.changed);
        self.changed_sites(set, d, &mut changed);
        self.enter_set(set, d);
        let mut dirty = std::mem::take(&mut self.dirty);
        self.rows_seeing(&changed, entries.nx, entries.ny, &mut dirty);
        let mut pattern = Vec::with_capacity(self.stride);
        let mut slots = Vec::with_capacity(self.stride);
        for &i in &dirty {
            self.refresh_row(entries, i, &mut pattern, &mut slots);
        }
        self.changed = changed;
        self.dirty = dirty;
    }

    /// Sites that joined, left, or changed compliance between the current set and `set`
    /// (both ascending), into `changed`.
    fn changed_sites(&self, set: &[usize], d: &[f64], changed: &mut Vec<usize>) {
        changed.clear();
        let (old, mut a, mut b) = (&self.sites, 0, 0);
        while a < old.len() || b < set.len() {
            match (old.get(a), set.get(b)) {
                (Some(&i), Some(&j)) if i == j => {
                    if self.dsite[j].to_bits() != d[b].to_bits() {
                        changed.push(j);
                    }
                    a += 1;
                    b += 1;
                }
                (Some(&i), Some(&j)) if i < j => {
                    changed.push(i);
                    a += 1;
                }
                (Some(&i), None) => {
                    changed.push(i);
                    a += 1;
                }
                (_, Some(&j)) => {
                    changed.push(j);
                    b += 1;
                }
                (None, None) => break,
            }
        }
    }

    /// Makes `set` with compliances `d` the current set (membership, compliance per site).
    fn enter_set(&mut self, set: &[usize], d: &[f64]) {
        for &i in &self.sites {
            self.member[i] = false;
        }
        for (&i, &di) in set.iter().zip(d) {
            self.member[i] = true;
            self.dsite[i] = di;
        }
        self.sites.clear();
        self.sites.extend_from_slice(set);
    }

    /// Rows that may see a change, into `dirty` (each once, marked): the box of half-width
    /// `r` around each changed site.
    fn rows_seeing(&mut self, changed: &[usize], nx: usize, ny: usize, dirty: &mut Vec<usize>) {
        let r = self.radius as isize;
        dirty.clear();
        for &c in changed {
            let (x, y) = ((c % nx) as isize, (c / nx) as isize);
            for yy in (y - r).max(0)..=(y + r).min(ny as isize - 1) {
                for xx in (x - r).max(0)..=(x + r).min(nx as isize - 1) {
                    let i = yy as usize * nx + xx as usize;
                    if !self.marked[i] {
                        self.marked[i] = true;
                        dirty.push(i);
                    }
                }
            }
        }
    }

    /// Row `i` of `G` on the current set and its weights in the planes (all zero off the
    /// set). The row is rebuilt only if its pattern or the compliances on it changed.
    fn refresh_row(
        &mut self,
        entries: &Entries,
        i: usize,
        pattern: &mut Vec<usize>,
        slots: &mut Vec<usize>,
    ) {
        let n = entries.nx * entries.ny;
        self.marked[i] = false;
        for q in 0..self.stride {
            self.planes[q * n + i] = 0.0;
        }
        if !self.member[i] {
            return;
        }
        self.lower_pattern(i, entries.nx, entries.ny, pattern, slots);
        let base = i * self.stride;
        let k = pattern.len();
        let same = self.len[i] == k
            && self.cols[base..base + k] == pattern[..]
            && pattern
                .iter()
                .zip(&self.diag[base..base + k])
                .all(|(&j, &dj)| self.dsite[j].to_bits() == dj.to_bits());
        if !same {
            self.len[i] = k;
            self.cols[base..base + k].copy_from_slice(pattern);
            self.slots[base..base + k].copy_from_slice(slots);
            for (slot, &j) in pattern.iter().enumerate() {
                self.diag[base + slot] = self.dsite[j];
            }
            build_row(
                entries,
                pattern,
                &self.diag[base..base + k],
                &mut self.small,
                &mut self.g[base..base + k],
            );
        }
        for q in 0..k {
            self.planes[self.slots[base + q] * n + i] = self.g[base + q];
        }
    }

    /// The pattern of row `i` (site `i` a member) and the slot of each of its sites: the
    /// members among its lower neighbours in site order (rows `y - r ..= y`, and on row
    /// `y` only `x' < x`), then `i` itself.
    fn lower_pattern(
        &self,
        i: usize,
        nx: usize,
        ny: usize,
        pattern: &mut Vec<usize>,
        slots: &mut Vec<usize>,
    ) {
        let r = self.radius as isize;
        let (x, y) = ((i % nx) as isize, (i / nx) as isize);
        pattern.clear();
        slots.clear();
        let mut slot = 0;
        for dy in -r..=0 {
            let hi = if dy == 0 { -1 } else { r };
            for dx in -r..=hi {
                let (xx, yy) = (x + dx, y + dy);
                if xx >= 0 && xx < nx as isize && yy >= 0 && yy < ny as isize {
                    let j = yy as usize * nx + xx as usize;
                    if self.member[j] {
                        pattern.push(j);
                        slots.push(slot);
                    }
                }
                slot += 1;
            }
        }
        pattern.push(i);
        slots.push(slot);
    }

    /// The planes and the rows the last update wrote, as a device copies them
    /// (`layout.rs`).
    #[cfg(feature = "cuda")]
    pub(crate) fn layout(&self) -> super::layout::FsaiLayout<'_> {
        super::layout::FsaiLayout {
            stride: self.stride,
            offsets: &self.offsets,
            planes: &self.planes,
            refreshed: &self.dirty,
        }
    }

    /// Cells `G` reaches back (and `Gᵀ` forward): the largest slot offset.
    pub(crate) fn halo(&self) -> usize {
        self.offsets.iter().copied().max().unwrap_or(0)
    }

    /// `y = G r` on the cells `lo .. lo + y.len()`: `y_i = Σ_k w_k[i] r[i - o_k]`.
    /// `r_ext[halo + c - lo]` holds `r` at cell `c` for `c` in `lo - halo .. lo + y.len()`
    /// (zeros before the grid). Runs blocks of cells with all the slots while the block
    /// stays in L1 (a pass per slot over a whole part streams the weight planes: 2.5x
    /// slower).
    pub(crate) fn g(&self, lo: usize, r_ext: &[f64], y: &mut [f64]) {
        let n = self.member.len();
        let halo = self.halo();
        // The slot of the site itself first (offset 0, never clipped): it assigns, the
        // others add, so no buffer needs zeroing.
        let slots = || self.planes.chunks_exact(n).zip(&self.offsets).rev();
        for (b, y) in y.chunks_mut(BLOCK).enumerate() {
            let a = b * BLOCK; // local cell index of the block
            let e = a + y.len();
            for (k, (w, &o)) in slots().enumerate() {
                let terms = w[lo + a..lo + e]
                    .iter()
                    .zip(&r_ext[halo + a - o..halo + e - o]);
                if k == 0 {
                    y.iter_mut().zip(terms).for_each(|(y, (w, x))| *y = w * x);
                } else {
                    y.iter_mut().zip(terms).for_each(|(y, (w, x))| *y += w * x);
                }
            }
        }
    }

    /// `z = Gᵀ y` on the cells `lo .. lo + z.len()`: `z_j = Σ_k w_k[j + o_k] y[j + o_k]`.
    /// `y_ext[c - lo]` holds `y` at cell `c` for `c` in `lo .. lo + z.len() + halo` (cells
    /// past the grid carry no weight and are not read).
    pub(crate) fn gt(&self, lo: usize, y_ext: &[f64], z: &mut [f64]) {
        let n = self.member.len();
        let slots = || self.planes.chunks_exact(n).zip(&self.offsets).rev();
        for (b, z) in z.chunks_mut(BLOCK).enumerate() {
            let a = b * BLOCK;
            for (k, (w, &o)) in slots().enumerate() {
                let e = (a + z.len()).min(n.saturating_sub(lo + o));
                if e <= a {
                    continue;
                }
                let terms = w[lo + a + o..lo + e + o].iter().zip(&y_ext[a + o..e + o]);
                if k == 0 {
                    z.iter_mut().zip(terms).for_each(|(z, (w, y))| *z = w * y);
                } else {
                    z[..e - a]
                        .iter_mut()
                        .zip(terms)
                        .for_each(|(z, (w, y))| *z += w * y);
                }
            }
        }
    }

    /// `z = Gᵀ G r` on the current set through [`Fsai::g`] and [`Fsai::gt`] over the whole
    /// grid as one part (the solver runs the same functions part by part).
    #[cfg(test)]
    pub(crate) fn apply(&self, r: &[f64], z: &mut [f64]) {
        let n = self.member.len();
        let halo = self.halo();
        let mut r_ext = vec![0.0; halo + n];
        for (&i, &ri) in self.sites.iter().zip(r) {
            r_ext[halo + i] = ri;
        }
        let mut y_ext = vec![0.0; n + halo];
        self.g(0, &r_ext, &mut y_ext[..n]);
        let mut zf = vec![0.0; n];
        self.gt(0, &y_ext, &mut zf);
        for (zi, &i) in z.iter_mut().zip(&self.sites) {
            *zi = zf[i];
        }
    }
}

/// Row of `G` on `pattern` (the site last): `A[P, P] g = e_last`, `g /= √g_last`.
fn build_row(entries: &Entries, pattern: &[usize], d: &[f64], small: &mut [f64], g: &mut [f64]) {
    let k = pattern.len();
    let l = &mut small[..k * k];
    for (r, &i) in pattern.iter().enumerate() {
        for (c, &j) in pattern.iter().enumerate().take(r + 1) {
            let mut v = entries.get(i, j);
            if r == c {
                v += d[r];
            }
            l[r * k + c] = v;
        }
    }
    // In-place Cholesky (lower).
    for c in 0..k {
        let mut piv = l[c * k + c];
        for q in 0..c {
            piv -= l[c * k + q] * l[c * k + q];
        }
        if piv.is_nan() || piv <= 0.0 {
            // Not SPD (cannot happen with exact entries): fall back to the Jacobi row.
            g.fill(0.0);
            g[k - 1] = 1.0 / (entries.get(pattern[k - 1], pattern[k - 1]) + d[k - 1]).sqrt();
            return;
        }
        let piv = piv.sqrt();
        l[c * k + c] = piv;
        for r in c + 1..k {
            let mut v = l[r * k + c];
            for q in 0..c {
                v -= l[r * k + q] * l[c * k + q];
            }
            l[r * k + c] = v / piv;
        }
    }
    // L y = e_last → y = e_last / L_kk; Lᵀ x = y; g = x / √x_last with x_last = 1/L_kk².
    // So g = L_kk x, i.e. solve Lᵀ g = e_last.
    g.fill(0.0);
    g[k - 1] = 1.0;
    for r in (0..k).rev() {
        let mut v = g[r];
        for q in r + 1..k {
            v -= l[q * k + r] * g[q];
        }
        g[r] = v / l[r * k + r];
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{Block, Grid};

    /// The table's rows are summed by tasks shared among threads: the same bits on one
    /// thread and on three.
    #[test]
    fn entries_are_the_same_bits_on_any_threads() {
        let block = Block::new(0.037, 0.021, 0.02).unwrap();
        let plan = InfluencePlan::builder(Grid::new(block, 37, 21).unwrap())
            .build()
            .unwrap();
        let one = Entries::new(&plan, 1e-9, 0.2, Parallelism::Sequential).unwrap();
        let three = Entries::new(&plan, 1e-9, 0.2, Parallelism::Threads(3)).unwrap();
        let bits = |e: &Entries| e.k.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&one), bits(&three));
    }

    #[test]
    fn entries_match_operator_columns() {
        let grid = Grid::new(Block::new(0.012, 0.010, 0.075).unwrap(), 12, 10).unwrap();
        let plan = InfluencePlan::builder(grid).build().unwrap();
        let n = 120;
        let (scale, shift) = (2.0, 0.1);
        let e = Entries::new(&plan, scale, shift, Parallelism::Sequential).unwrap();
        for j in [0, 5, 13, 57, 119] {
            let mut v = vec![0.0; n];
            v[j] = 1.0;
            let mut out = vec![0.0; n];
            plan.apply(&v, &mut out).unwrap();
            for (i, o) in out.iter().enumerate() {
                let want = scale * (o - shift);
                let got = e.get(i, j);
                assert!(
                    (want - got).abs() <= 1e-12 * want.abs().max(1.0),
                    "{i} {j}: {want} {got}"
                );
            }
        }
    }

    #[test]
    fn factor_is_spd_and_history_free() {
        let grid = Grid::new(Block::new(0.016, 0.012, 0.075).unwrap(), 16, 12).unwrap();
        let plan = InfluencePlan::builder(grid).build().unwrap();
        let e = Entries::new(&plan, 3.6e-16, 0.0, Parallelism::Sequential).unwrap();
        let set_a: Vec<usize> = (0..192).filter(|i| (i * 7919) % 10 < 6).collect();
        let set_b: Vec<usize> = (0..192)
            .filter(|i| (i * 7919) % 10 < 6 && i % 17 != 3)
            .collect();
        let d = |set: &[usize]| -> Vec<f64> {
            set.iter()
                .map(|&i| 1e-14 * (1.0 + (i % 5) as f64))
                .collect()
        };
        for radius in [1, 2] {
            // Updated through set A, then set B, against a fresh factor of set B.
            let mut warm = Fsai::new(16, 192, radius);
            warm.update(&e, &set_a, &d(&set_a));
            warm.update(&e, &set_b, &d(&set_b));
            let mut fresh = Fsai::new(16, 192, radius);
            fresh.update(&e, &set_b, &d(&set_b));
            assert_eq!(warm.planes, fresh.planes);
            // A sequence of small changes (sites leave, join, change compliance), as in a
            // run: the incremental update equals a fresh build at every step.
            let mut member: Vec<bool> = (0..192).map(|i| set_b.contains(&i)).collect();
            let mut comp: Vec<f64> = (0..192).map(|i| 1e-14 * (1.0 + (i % 5) as f64)).collect();
            for step in 0..30usize {
                for k in 0..3 {
                    let i = (step * 37 + k * 71 + 5) % 192;
                    member[i] = !member[i];
                }
                comp[(step * 53) % 192] *= 1.5;
                let set: Vec<usize> = (0..192).filter(|&i| member[i]).collect();
                let d: Vec<f64> = set.iter().map(|&i| comp[i]).collect();
                warm.update(&e, &set, &d);
                let mut fresh = Fsai::new(16, 192, radius);
                fresh.update(&e, &set, &d);
                assert_eq!(warm.planes, fresh.planes, "radius {radius}, step {step}");
            }
            let m = set_b.len();
            let x: Vec<f64> = (0..m).map(|i| ((i * 31) % 7) as f64 - 3.0).collect();
            let y: Vec<f64> = (0..m).map(|i| ((i * 17) % 5) as f64 - 2.0).collect();
            let (mut mx, mut my) = (vec![0.0; m], vec![0.0; m]);
            fresh.apply(&x, &mut mx);
            fresh.apply(&y, &mut my);
            let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(p, q)| p * q).sum::<f64>();
            let (xy, yx, xx) = (dot(&y, &mx), dot(&x, &my), dot(&x, &mx));
            assert!((xy - yx).abs() <= 1e-12 * xx, "{xy} {yx}");
            assert!(xx > 0.0);
        }
    }
}
