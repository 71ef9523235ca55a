//! The coarse space of the two-level preconditioner (docs/performance.md, "A two-level
//! preconditioner"): **aggregates**, the attached sites of each `b x b` block of cells,
//! one coarse unknown per non-empty block (`Z` their indicators), and the coarse matrix
//! `E = Zᵀ A Z` with its Cholesky factor.
//!
//! Why: the slow modes of `A = C_SS + diag(d)` under a local preconditioner (FSAI) are a
//! fixed fraction of all modes, shaped by the set's holes; a coarse space that grows with
//! `N` and is local in space removes them, so the iteration count stops growing with `N`.
//!
//! The load constraint `1ᵀ f = total` is kept by a bordered coarse problem: the coarse
//! correction of a residual `r` is `Z y` with `E y + c μ = Zᵀ r`, `cᵀ y = 0` (`c = Zᵀ 1`,
//! the aggregates' site counts), so every correction has zero sum and a constant part of
//! `r` (the multiplier) changes nothing.
//!
//! Everything here is a pure function of the set and its compliances (no history):
//! `Zᵀ C_SS Z` is summed from the exact entries of `C` in a fixed order per pair of
//! aggregates, and `E` is factorised anew whenever it changes (`k³/3` flops, `k` at most
//! [`MAX_AGGREGATES`]). So a restored solver preconditions bit for bit as the original
//! (checkpoints).

use super::fsai::Entries;
use super::parallel::{map_parts, Parallelism};
use super::pcg::dot;
use crate::error::Result;
use crate::lock::{lock, read, write};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt;
use faer::{Mat, Par};
use std::sync::{Mutex, RwLock};

/// The most coarse unknowns: the block size doubles from [`MIN_BLOCK`] until the blocks
/// of the grid are at most this many. Why: the factor is recomputed when the set changes
/// (`k³/3` flops), which must stay small against a solve.
pub(crate) const MAX_AGGREGATES: usize = 512;
/// The smallest block (cells per side).
const MIN_BLOCK: usize = 8;
/// Tasks the entries of `E`'s changed rows are cut into: more than threads, so that
/// pairs of uneven cost (`|S_a| |S_b|` terms each) even out.
const PAIR_TASKS: usize = 16;

/// The aggregates of a grid: its `b x b` blocks of cells, and per block its sites on the
/// current set and their compliances (both backends' coarse spaces keep these).
#[derive(Debug)]
pub(crate) struct Aggregates {
    nx: usize,
    /// Cells per block side.
    block: usize,
    /// Blocks along x.
    bx: usize,
    /// Per block: its sites on the current set (ascending) and their compliances.
    members: Vec<Vec<usize>>,
    dmembers: Vec<Vec<f64>>,
    /// Per block: whether the last [`Aggregates::enter`] changed its sites, or its sites
    /// or their compliances.
    moved: Vec<bool>,
    touched: Vec<bool>,
    /// Scratch of [`Aggregates::enter`].
    fresh: Vec<Vec<usize>>,
    dfresh: Vec<Vec<f64>>,
}

impl Aggregates {
    /// The blocks of an `nx x ny` grid, no sites yet.
    pub(crate) fn new(nx: usize, ny: usize) -> Self {
        let mut block = MIN_BLOCK;
        while nx.div_ceil(block) * ny.div_ceil(block) > MAX_AGGREGATES {
            block *= 2;
        }
        let (bx, by) = (nx.div_ceil(block), ny.div_ceil(block));
        let count = bx * by;
        Self {
            nx,
            block,
            bx,
            members: vec![Vec::new(); count],
            dmembers: vec![Vec::new(); count],
            moved: vec![false; count],
            touched: vec![false; count],
            fresh: vec![Vec::new(); count],
            dfresh: vec![Vec::new(); count],
        }
    }

    /// The blocks (at most [`MAX_AGGREGATES`]).
    pub(crate) fn count(&self) -> usize {
        self.members.len()
    }

    /// Cells per block side.
    #[cfg(test)]
    pub(crate) fn block(&self) -> usize {
        self.block
    }

    /// The blocks and which ones the last [`Aggregates::enter`] changed, as a device
    /// reads them (`layout.rs`).
    #[cfg(feature = "cuda")]
    pub(crate) fn layout(&self) -> super::layout::AggregateLayout<'_> {
        super::layout::AggregateLayout {
            block: self.block,
            blocks_x: self.bx,
            touched: &self.touched,
        }
    }

    /// The block of a site.
    pub(crate) fn aggregate(&self, site: usize) -> usize {
        let (x, y) = (site % self.nx, site / self.nx);
        (y / self.block) * self.bx + x / self.block
    }

    /// Block `a`'s sites on the current set, ascending.
    pub(crate) fn members(&self, a: usize) -> &[usize] {
        &self.members[a]
    }

    /// The sum of block `a`'s compliances (sites in order).
    fn dsum(&self, a: usize) -> f64 {
        self.dmembers[a].iter().sum()
    }

    /// Whether the last [`Aggregates::enter`] changed block `a`'s sites.
    fn moved(&self, a: usize) -> bool {
        self.moved[a]
    }

    /// Makes `set` (ascending sites) with compliances `d` the current one; returns the
    /// first block whose sites or compliances changed.
    pub(crate) fn enter(&mut self, set: &[usize], d: &[f64]) -> Option<usize> {
        let mut fresh = std::mem::take(&mut self.fresh);
        let mut dfresh = std::mem::take(&mut self.dfresh);
        fresh.iter_mut().for_each(Vec::clear);
        dfresh.iter_mut().for_each(Vec::clear);
        for (&i, &di) in set.iter().zip(d) {
            let a = self.aggregate(i);
            fresh[a].push(i);
            dfresh[a].push(di);
        }
        let mut first = None;
        for a in 0..self.count() {
            let sites = fresh[a] != self.members[a];
            let comp = sites
                || dfresh[a]
                    .iter()
                    .map(|x| x.to_bits())
                    .ne(self.dmembers[a].iter().map(|x| x.to_bits()));
            self.moved[a] = sites;
            self.touched[a] = comp;
            if comp && first.is_none() {
                first = Some(a);
            }
        }
        std::mem::swap(&mut self.members, &mut fresh);
        std::mem::swap(&mut self.dmembers, &mut dfresh);
        self.fresh = fresh;
        self.dfresh = dfresh;
        first
    }
}

/// Aggregates, `E`'s factor and the scratch of the coarse solves.
#[derive(Debug)]
pub(crate) struct Coarse {
    aggregates: Aggregates,
    /// `Zᵀ C_SS Z` over all blocks, row-major (zero rows for empty blocks).
    g: Vec<f64>,
    /// The coarse unknowns: the non-empty blocks, ascending.
    unknowns: Vec<usize>,
    /// `L` of `E = L Lᵀ`, row-major `k x k` (lower triangle used).
    lower: Vec<f64>,
    /// `E⁻¹ c` and `cᵀ E⁻¹ c`.
    w: Vec<f64>,
    cw: f64,
    /// Whether `E` was positive definite (the correction is skipped otherwise).
    valid: bool,
    /// Per part: its partial `Zᵀ t` per block.
    partial: Vec<Mutex<Vec<f64>>>,
    /// The coarse solution per block (zero on empty blocks).
    solution: RwLock<Vec<f64>>,
    /// The restriction per unknown, then the solution (the leader's scratch).
    rhs: Mutex<Vec<f64>>,
}

impl Coarse {
    /// The aggregates of an `nx x ny` grid whose solves run over `parts` parts.
    pub(crate) fn new(nx: usize, ny: usize, parts: usize) -> Self {
        let aggregates = Aggregates::new(nx, ny);
        let count = aggregates.count();
        Self {
            aggregates,
            g: vec![0.0; count * count],
            unknowns: Vec::new(),
            lower: Vec::new(),
            w: Vec::new(),
            cw: 0.0,
            valid: false,
            partial: (0..parts).map(|_| Mutex::new(vec![0.0; count])).collect(),
            solution: RwLock::new(vec![0.0; count]),
            rhs: Mutex::new(Vec::new()),
        }
    }

    /// Cells per block side.
    #[cfg(test)]
    pub(crate) fn block(&self) -> usize {
        self.aggregates.block()
    }

    /// The coarse unknowns (non-empty blocks) of the current set.
    #[cfg(test)]
    pub(crate) fn unknowns(&self) -> usize {
        self.unknowns.len()
    }

    /// The coarse solution per block of the last [`Coarse::solve`] (the CUDA backend's
    /// tests' reference).
    #[cfg(all(test, feature = "cuda"))]
    pub(crate) fn solution(&self) -> Vec<f64> {
        read(&self.solution).clone()
    }

    /// Whether the coarse correction applies (`E` positive definite).
    pub(crate) fn valid(&self) -> bool {
        self.valid
    }

    fn aggregate(&self, site: usize) -> usize {
        self.aggregates.aggregate(site)
    }

    /// Brings `E` and its factor up to date for `set` (ascending sites) with compliances
    /// `d`: the rows of `Zᵀ C_SS Z` of blocks whose sites changed, then the factor from
    /// the first unknown whose row of `E` changed. The rows' entries are shared among
    /// `parallelism`'s threads (each entry is summed by one task: the same bits for any
    /// thread count).
    ///
    /// # Errors
    /// [`Error::ThreadPool`](crate::Error::ThreadPool) when the threads cannot be started.
    pub(crate) fn update(
        &mut self,
        entries: &Entries,
        set: &[usize],
        d: &[f64],
        parallelism: Parallelism,
    ) -> Result<()> {
        let count = self.aggregates.count();
        let first = self.aggregates.enter(set, d); // first block whose row of E changed
        let Some(first) = first else {
            return Ok(());
        };
        // A pair of changed blocks once (the first build: every pair once).
        let aggregates = &self.aggregates;
        let pairs: Vec<(usize, usize)> = (0..count)
            .filter(|&a| aggregates.moved(a))
            .flat_map(|a| {
                (0..count)
                    .filter(move |&b| !(aggregates.moved(b) && b < a))
                    .map(move |b| (a.min(b), a.max(b)))
            })
            .collect();
        let tasks = PAIR_TASKS.min(pairs.len());
        let chunk = |t: usize| &pairs[t * pairs.len() / tasks..(t + 1) * pairs.len() / tasks];
        let sums = map_parts(parallelism, tasks, |t| {
            chunk(t)
                .iter()
                .map(|&(a, b)| self.pair(entries, a, b))
                .collect::<Vec<f64>>()
        })?;
        for (&(a, b), v) in pairs.iter().zip(sums.into_iter().flatten()) {
            self.g[a * count + b] = v;
            self.g[b * count + a] = v;
        }
        let from = self.unknowns.partition_point(|&u| u < first);
        self.unknowns.truncate(from);
        self.unknowns
            .extend((first..count).filter(|&a| !self.aggregates.members(a).is_empty()));
        self.factor();
        Ok(())
    }

    /// `1_{S_a}ᵀ C 1_{S_b}` (`a ≤ b`): a pure function of the two blocks' sites.
    fn pair(&self, entries: &Entries, a: usize, b: usize) -> f64 {
        entries.block_sum(self.aggregates.members(a), self.aggregates.members(b))
    }

    /// `E`'s diagonal compliance term of block `a` (sites in order).
    fn dsum(&self, a: usize) -> f64 {
        self.aggregates.dsum(a)
    }

    /// The Cholesky factor of `E` (faer's, one thread: a pure function of `E`), then
    /// `w = E⁻¹ c`.
    fn factor(&mut self) {
        let k = self.unknowns.len();
        let count = self.aggregates.count();
        let mut e = Mat::<f64>::zeros(k, k);
        for (q, &uq) in self.unknowns.iter().enumerate() {
            let col = e.col_as_slice_mut(q);
            for (p, &up) in self.unknowns.iter().enumerate().skip(q) {
                col[p] = self.g[up * count + uq];
            }
            col[q] += self.dsum(uq);
        }
        let mut mem = MemBuffer::new(llt::factor::cholesky_in_place_scratch::<f64>(
            k,
            Par::Seq,
            Default::default(),
        ));
        let result = llt::factor::cholesky_in_place(
            e.as_mut(),
            Default::default(),
            Par::Seq,
            MemStack::new(&mut mem),
            Default::default(),
        );
        // Row-major `L` for the substitutions (rows are contiguous in the forward one).
        self.lower.clear();
        self.lower.resize(k * k, 0.0);
        for q in 0..k {
            for (p, v) in e.col_as_slice(q).iter().enumerate().skip(q) {
                self.lower[p * k + q] = *v;
            }
        }
        let pivots_ok = (0..k).all(|p| {
            let v = self.lower[p * k + p];
            v > 0.0 && v.is_finite()
        });
        let c: Vec<f64> = self
            .unknowns
            .iter()
            .map(|&a| self.aggregates.members(a).len() as f64)
            .collect();
        let mut w = c.clone();
        self.valid = result.is_ok() && pivots_ok;
        if self.valid {
            self.solve_in_place(&mut w);
        }
        self.cw = dot(&c, &w);
        self.w = w;
        self.valid = self.valid && self.cw > 0.0 && self.cw.is_finite();
    }

    /// `x = E⁻¹ x` by the factor.
    fn solve_in_place(&self, x: &mut [f64]) {
        let k = x.len();
        let l = &self.lower;
        for p in 0..k {
            x[p] = (x[p] - dot(&l[p * k..p * k + p], &x[..p])) / l[p * k + p];
        }
        for p in (0..k).rev() {
            let mut s = x[p];
            for q in p + 1..k {
                s -= l[q * k + p] * x[q];
            }
            x[p] = s / l[p * k + p];
        }
    }

    /// Part `part`'s share of `Zᵀ t`: `t = r - a` (`a` given) or `t = r`, on the part's
    /// `sites`.
    pub(crate) fn restrict(&self, part: usize, sites: &[usize], r: &[f64], a: Option<&[f64]>) {
        let mut partial = lock(&self.partial[part]);
        partial.fill(0.0);
        match a {
            Some(a) => {
                for ((&i, ri), ai) in sites.iter().zip(r).zip(a) {
                    partial[self.aggregate(i)] += ri - ai;
                }
            }
            None => {
                for (&i, ri) in sites.iter().zip(r) {
                    partial[self.aggregate(i)] += ri;
                }
            }
        }
    }

    /// Adds the parts' shares in part order and solves the bordered coarse problem
    /// (module docs); the solution waits for [`Coarse::prolong`].
    pub(crate) fn solve(&self) {
        let mut rhs = lock(&self.rhs);
        rhs.clear();
        rhs.resize(self.unknowns.len(), 0.0);
        for part in &self.partial {
            let partial = lock(part);
            for (x, &a) in rhs.iter_mut().zip(&self.unknowns) {
                *x += partial[a];
            }
        }
        self.solve_in_place(&mut rhs);
        let mu = self
            .unknowns
            .iter()
            .zip(rhs.iter())
            .fold(0.0, |s, (&a, y)| {
                s + self.aggregates.members(a).len() as f64 * y
            })
            / self.cw;
        let mut solution = write(&self.solution);
        for ((&a, y), w) in self.unknowns.iter().zip(rhs.iter()).zip(&self.w) {
            solution[a] = y - mu * w;
        }
    }

    /// `x += sign Z y` on a part's `sites`.
    pub(crate) fn prolong(&self, sites: &[usize], x: &mut [f64], sign: f64) {
        let solution = read(&self.solution);
        for (xi, &i) in x.iter_mut().zip(sites) {
            *xi += sign * solution[self.aggregate(i)];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{Block, Grid};
    use crate::green::InfluencePlan;

    fn plan(nx: usize, ny: usize) -> InfluencePlan {
        let block = Block::new(nx as f64 * 1e-3, ny as f64 * 1e-3, 0.075).unwrap();
        InfluencePlan::builder(Grid::new(block, nx, ny).unwrap())
            .build()
            .unwrap()
    }

    fn set_of(n: usize, key: usize) -> Vec<usize> {
        (0..n).filter(|i| (i * 7919 + key) % 10 < 5).collect()
    }

    /// `E = Zᵀ (C_SS + D) Z` equals the sums of `InfluencePlan::dense` (explicit cosine
    /// sums, not the kernel table the coarse space reads) over the blocks' sites.
    #[test]
    fn coarse_matrix_is_the_aggregated_dense_matrix() {
        let (nx, ny) = (40, 20);
        let plan = plan(nx, ny);
        let n = nx * ny;
        let scale = 3.6e-16;
        let entries = Entries::new(&plan, scale, 0.0, Parallelism::Sequential).unwrap();
        let dense = plan.dense().unwrap();
        let set = set_of(n, 3);
        let d: Vec<f64> = set.iter().map(|i| 1e-13 * (1.0 + (i % 3) as f64)).collect();
        let mut coarse = Coarse::new(nx, ny, 1);
        assert_eq!(coarse.block(), MIN_BLOCK);
        // Two threads: the entries are summed in tasks shared between them.
        coarse
            .update(&entries, &set, &d, Parallelism::Threads(2))
            .unwrap();
        let count = coarse.aggregates.count();
        let mut e = vec![0.0; count * count];
        for (p, &i) in set.iter().enumerate() {
            for (q, &j) in set.iter().enumerate() {
                let v = scale * dense[i * n + j] + if p == q { d[p] } else { 0.0 };
                e[coarse.aggregate(i) * count + coarse.aggregate(j)] += v;
            }
        }
        // L Lᵀ against the dense sums.
        let k = coarse.unknowns();
        assert_eq!(k, count);
        let top = e.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        for p in 0..k {
            for q in 0..k {
                let l = &coarse.lower;
                let llt: f64 = (0..=p.min(q)).map(|r| l[p * k + r] * l[q * k + r]).sum();
                let want = e[coarse.unknowns[p] * count + coarse.unknowns[q]];
                assert!((llt - want).abs() < 1e-10 * top, "{p} {q}: {llt} {want}");
            }
        }
    }

    /// After any history of sets the factor is the same bits as a fresh one's, whatever
    /// the threads (the walked one's rows are summed on two, the fresh one's on one).
    #[test]
    fn factor_is_history_free() {
        let (nx, ny) = (48, 24);
        let plan = plan(nx, ny);
        let entries = Entries::new(&plan, 3.6e-16, 1e-3, Parallelism::Sequential).unwrap();
        let dof = |set: &[usize]| -> Vec<f64> {
            set.iter().map(|i| 1e-13 * (1.0 + (i % 5) as f64)).collect()
        };
        let mut walked = Coarse::new(nx, ny, 2);
        let mut set = set_of(nx * ny, 1);
        let two = Parallelism::Threads(2);
        walked.update(&entries, &set, &dof(&set), two).unwrap();
        // Sites leave and join, a block empties and fills again.
        for step in 0..6 {
            let drop = set[(step * 37) % set.len()];
            set.retain(|&i| i != drop && !(step == 2 && i % nx < 8 && i / nx < 8));
            if step == 4 {
                set.extend([0, 1, 9 * nx + 2]);
                set.sort_unstable();
                set.dedup();
            }
            walked.update(&entries, &set, &dof(&set), two).unwrap();
            let mut fresh = Coarse::new(nx, ny, 2);
            fresh
                .update(&entries, &set, &dof(&set), Parallelism::Sequential)
                .unwrap();
            assert_eq!(walked.unknowns, fresh.unknowns);
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&walked.lower), bits(&fresh.lower), "step {step}");
            assert_eq!(bits(&walked.w), bits(&fresh.w));
            assert!(walked.valid());
        }
    }

    /// The bordered solve: `E y + c μ = Zᵀ r`, `cᵀ y = 0`, and adding a constant to `r`
    /// changes nothing.
    #[test]
    fn coarse_correction_solves_the_bordered_problem() {
        let (nx, ny) = (40, 20);
        let plan = plan(nx, ny);
        let entries = Entries::new(&plan, 3.6e-16, 0.0, Parallelism::Sequential).unwrap();
        let set = set_of(nx * ny, 7);
        let d = vec![2e-13; set.len()];
        let mut coarse = Coarse::new(nx, ny, 1);
        coarse
            .update(&entries, &set, &d, Parallelism::Sequential)
            .unwrap();
        let r: Vec<f64> = set.iter().map(|i| ((i * 31) % 17) as f64 - 8.0).collect();
        coarse.restrict(0, &set, &r, None);
        coarse.solve();
        let y = read(&coarse.solution).clone();
        let count = coarse.aggregates.count();
        let c: Vec<f64> = (0..count)
            .map(|a| coarse.aggregates.members(a).len() as f64)
            .collect();
        let mut g = vec![0.0; count];
        for (&i, ri) in set.iter().zip(&r) {
            g[coarse.aggregate(i)] += ri;
        }
        let e = |a: usize, b: usize| {
            coarse.g[a * count + b] + if a == b { coarse.dsum(a) } else { 0.0 }
        };
        let ey: Vec<f64> = (0..count)
            .map(|a| (0..count).map(|b| e(a, b) * y[b]).sum())
            .collect();
        // μ from any block, then every block agrees.
        let mu = (g[0] - ey[0]) / c[0];
        for a in 0..count {
            let scale = g.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            assert!((ey[a] + c[a] * mu - g[a]).abs() < 1e-10 * scale, "{a}");
        }
        let cy: f64 = c.iter().zip(&y).map(|(c, y)| c * y).sum();
        let ymax = y.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        assert!(cy.abs() < 1e-10 * ymax * set.len() as f64);
        let shifted: Vec<f64> = r.iter().map(|x| x + 3.0).collect();
        coarse.restrict(0, &set, &shifted, None);
        coarse.solve();
        let y2 = read(&coarse.solution).clone();
        for (a, b) in y.iter().zip(&y2) {
            assert!((a - b).abs() < 1e-9 * ymax);
        }
    }
}
