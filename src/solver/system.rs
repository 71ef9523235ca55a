//! The set system both backends solve: `A = C_SS + diag(d)` on an attached set, with
//! `C_s = scale (Ĝ - shift 11ᵀ)` applied through the plan's staged product (part by
//! part, [`crate::green::Staging`]) and one of the preconditioners.

use super::coarse::Coarse;
use super::fsai::Fsai;
use super::pcg::{sum, SetSystem};
use crate::green::{Partition, SpectralTable, Staging};
use std::ops::Range;
use std::sync::{Mutex, RwLock};

/// The preconditioner of a set system.
pub(crate) enum Preconditioner<'a> {
    /// `z = r / (diag_c + d)`: the mean diagonal of `C_s` plus the compliance.
    Jacobi { diag_c: f64 },
    /// `z = Gᵀ G r` ([`Fsai`]), part by part with the buffers of `buffers`.
    Fsai {
        fsai: &'a Fsai,
        buffers: &'a FsaiBuffers,
    },
    /// The full-grid inverse `(C_s + d̄ I)⁻¹` restricted to the set: a staged product with
    /// another table (and buffers of its own, so the operator's last product stays).
    Spectral {
        staging: &'a Staging,
        table: &'a SpectralTable,
    },
    /// The dense backend's LDLᵀ factor (a system of one part).
    Factor(&'a (dyn ExactInverse + Sync)),
    /// FSAI corrected by a coarse space of aggregates ([`Coarse`], A-DEF2 in the CG);
    /// the coarse products run on buffers of their own.
    TwoLevel {
        fsai: &'a Fsai,
        buffers: &'a FsaiBuffers,
        coarse: &'a Coarse,
        staging: &'a Staging,
    },
}

/// `z = A_SS⁻¹ r` by a factor of the set's matrix (the dense backend's): a preconditioner
/// defined here and implemented by the backend, so the system does not depend on it.
pub(crate) trait ExactInverse {
    /// `z = A⁻¹ r` on the whole set.
    fn solve(&self, r: &[f64], z: &mut [f64]);
}

/// `A = C_SS + diag(d)` on `set` (ascending sites), part by part.
pub(crate) struct StagedSystem<'a> {
    staging: &'a Staging,
    table: &'a SpectralTable,
    set: &'a [usize],
    d: &'a [f64],
    /// Set positions of each part.
    ranges: Vec<Range<usize>>,
    scale: f64,
    shift: f64,
    norm: f64,
    precond: Preconditioner<'a>,
}

/// The constants of `C_s`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Compliance {
    /// `ΔA/M` (m/Pa per m⁻¹).
    pub scale: f64,
    /// The mean mode's lowering (module docs of [`super`]).
    pub shift: f64,
    /// `‖C_s‖₂` (m/Pa).
    pub norm: f64,
}

impl Compliance {
    /// The eigenvalue of `C_s` (m/Pa) for the DCT mode `(p', m')` of `Ĝ`'s `eigen` on a
    /// grid of `n` cells: `scale · eigen`, the mean mode lowered by `shift · n`.
    pub(crate) fn eigenvalue(&self, n: usize, p: usize, m: usize, eigen: f64) -> f64 {
        let e = if p == 0 && m == 0 {
            eigen - self.shift * n as f64
        } else {
            eigen
        };
        self.scale * e
    }

    /// The mean diagonal of `C_s` (m/Pa): `trace(Ĝ)/N` (the sum of the eigenvalues; the
    /// diagonal varies only near the edges) scaled and shifted. Jacobi's elastic part.
    pub(crate) fn mean_diagonal(&self, plan: &crate::green::InfluencePlan) -> f64 {
        let (nx, ny) = (plan.grid().nx(), plan.grid().ny());
        let mut trace = 0.0;
        for m in 0..ny {
            for p in 0..nx {
                trace += plan.eigenvalue(p, m).unwrap_or(0.0);
            }
        }
        self.scale * (trace / (nx * ny) as f64 - self.shift)
    }
}

impl<'a> StagedSystem<'a> {
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn new(
        staging: &'a Staging,
        table: &'a SpectralTable,
        compliance: Compliance,
        set: &'a [usize],
        d: &'a [f64],
        precond: Preconditioner<'a>,
    ) -> Self {
        let partition = staging.partition();
        let ranges = (0..partition.parts())
            .scan(0, |start, k| {
                let end = partition.cells(k).end;
                let stop = *start + set[*start..].partition_point(|&i| i < end);
                let range = *start..stop;
                *start = stop;
                Some(range)
            })
            .collect();
        let norm = compliance.norm + d.iter().fold(0.0f64, |m, x| m.max(*x));
        Self {
            staging,
            table,
            set,
            d,
            ranges,
            scale: compliance.scale,
            shift: compliance.shift,
            norm,
            precond,
        }
    }

    fn partition(&self) -> &Partition {
        self.staging.partition()
    }

    /// `Σ x` as the product's first stage adds it (part by part, in part order).
    pub(crate) fn input_sum(&self, x: &[f64]) -> f64 {
        self.ranges.iter().fold(0.0, |s, r| s + sum(&x[r.clone()]))
    }

    /// `C_s x` on every cell, `x` the input of the last operator product and `sum_x` its
    /// sum ([`StagedSystem::input_sum`]).
    pub(crate) fn grid_product(&self, sum_x: f64, out: &mut [f64]) {
        self.staging.result(out);
        let (s, c) = (self.scale, self.shift * sum_x);
        out.iter_mut().for_each(|o| *o = s * (*o - c));
    }

    /// Stages 0 and 1 of a staged product of `x` (part `k`'s slice) with `table`.
    fn staged_head(
        &self,
        staging: &Staging,
        table: &SpectralTable,
        stage: usize,
        k: usize,
        x: &[f64],
        carry: f64,
    ) -> f64 {
        match stage {
            0 => {
                let base = self.partition().cells(k).start;
                let sites = &self.set[self.ranges[k].clone()];
                staging.forward_rows(k, |rows| {
                    for (&i, &v) in sites.iter().zip(x) {
                        rows[i - base] = v;
                    }
                });
                sum(x)
            }
            _ => {
                staging.filter_columns(k, table);
                // Pass the input's sum on to the last stage (part 0 carries it, exactly).
                if k == 0 {
                    carry
                } else {
                    0.0
                }
            }
        }
    }
}

impl SetSystem for StagedSystem<'_> {
    fn parts(&self) -> usize {
        self.ranges.len()
    }

    fn range(&self, k: usize) -> Range<usize> {
        self.ranges[k].clone()
    }

    fn product_stages(&self) -> usize {
        3
    }

    fn product(&self, stage: usize, k: usize, x: &[f64], y: &mut [f64], carry: f64) -> f64 {
        self.staged_product(self.staging, stage, k, x, y, carry)
    }

    fn precondition_stages(&self) -> usize {
        match self.precond {
            Preconditioner::Jacobi { .. } | Preconditioner::Factor(_) => 1,
            Preconditioner::Fsai { .. }
            | Preconditioner::Spectral { .. }
            | Preconditioner::TwoLevel { .. } => 3,
        }
    }

    fn precondition(&self, stage: usize, k: usize, r: &[f64], z: &mut [f64], carry: f64) -> f64 {
        let range = self.ranges[k].clone();
        match &self.precond {
            Preconditioner::Jacobi { diag_c } => {
                for (zi, (ri, d)) in z.iter_mut().zip(r.iter().zip(&self.d[range])) {
                    *zi = ri / (diag_c + d);
                }
            }
            Preconditioner::Factor(factor) => factor.solve(r, z),
            Preconditioner::Spectral { staging, table } => {
                if stage < 2 {
                    self.staged_head(staging, table, stage, k, r, carry);
                } else {
                    let base = self.partition().cells(k).start;
                    let sites = &self.set[range];
                    staging.inverse_rows(k, |rows| {
                        for (za, &i) in z.iter_mut().zip(sites) {
                            *za = rows[i - base];
                        }
                    });
                }
            }
            Preconditioner::Fsai { fsai, buffers }
            | Preconditioner::TwoLevel { fsai, buffers, .. } => {
                let cells = self.partition().cells(k);
                let sites = &self.set[range];
                buffers.stage(fsai, self.partition(), stage, k, cells, sites, r, z);
            }
        }
        0.0
    }

    fn norm_bound(&self) -> f64 {
        self.norm
    }

    fn has_coarse(&self) -> bool {
        matches!(self.precond, Preconditioner::TwoLevel { coarse, .. } if coarse.valid())
    }

    fn coarse_product(&self, stage: usize, k: usize, x: &[f64], y: &mut [f64], carry: f64) -> f64 {
        match self.precond {
            Preconditioner::TwoLevel { staging, .. } => {
                self.staged_product(staging, stage, k, x, y, carry)
            }
            _ => 0.0,
        }
    }

    fn restrict(&self, k: usize, r: &[f64], a: Option<&[f64]>) {
        if let Preconditioner::TwoLevel { coarse, .. } = self.precond {
            coarse.restrict(k, &self.set[self.ranges[k].clone()], r, a);
        }
    }

    fn coarse_solve(&self) {
        if let Preconditioner::TwoLevel { coarse, .. } = self.precond {
            coarse.solve();
        }
    }

    fn prolong(&self, k: usize, x: &mut [f64], sign: f64) {
        if let Preconditioner::TwoLevel { coarse, .. } = self.precond {
            coarse.prolong(&self.set[self.ranges[k].clone()], x, sign);
        }
    }
}

impl StagedSystem<'_> {
    /// Stage `stage` of `y = A x` on part `k` through `staging`'s buffers.
    fn staged_product(
        &self,
        staging: &Staging,
        stage: usize,
        k: usize,
        x: &[f64],
        y: &mut [f64],
        carry: f64,
    ) -> f64 {
        if stage < 2 {
            return self.staged_head(staging, self.table, stage, k, x, carry);
        }
        let base = self.partition().cells(k).start;
        let range = self.ranges[k].clone();
        let (sites, d) = (&self.set[range.clone()], &self.d[range]);
        let (s, c) = (self.scale, self.shift * carry);
        staging.inverse_rows(k, |rows| {
            for (((ya, &i), da), xa) in y.iter_mut().zip(sites).zip(d).zip(x) {
                *ya = s * (rows[i - base] - c) + da * xa;
            }
        });
        carry
    }
}

/// Grid buffers of the FSAI product, per part: `r` on the halo before the part and on its
/// cells; `G r` on its cells and the halo after them; `Gᵀ G r` on its cells. Each stage
/// copies only the halo from its neighbours.
#[derive(Debug)]
pub(crate) struct FsaiBuffers {
    r: Vec<RwLock<Vec<f64>>>,
    y: Vec<RwLock<Vec<f64>>>,
    /// Per part: `Gᵀ G r` on its cells, and the halo values on their way in.
    z: Vec<Mutex<(Vec<f64>, Vec<f64>)>>,
}

impl FsaiBuffers {
    pub(crate) fn new(partition: &Partition, halo: usize) -> Self {
        let parts = partition.parts();
        let cells = |k: usize| partition.cells(k).len();
        Self {
            r: (0..parts)
                .map(|k| RwLock::new(vec![0.0; halo + cells(k)]))
                .collect(),
            y: (0..parts)
                .map(|k| RwLock::new(vec![0.0; cells(k) + halo]))
                .collect(),
            z: (0..parts)
                .map(|k| Mutex::new((vec![0.0; cells(k)], vec![0.0; halo])))
                .collect(),
        }
    }

    /// Stage 0: `r` on the part's cells; 1: the halo before the part from the parts before
    /// it, then `y = G r` on the part's cells; 2: the halo after the part from the parts
    /// after it, then `z = Gᵀ y` on its cells, gathered on its sites.
    #[allow(clippy::too_many_arguments)]
    fn stage(
        &self,
        fsai: &Fsai,
        partition: &Partition,
        stage: usize,
        k: usize,
        cells: Range<usize>,
        sites: &[usize],
        r: &[f64],
        z: &mut [f64],
    ) {
        let halo = fsai.halo();
        let base = cells.start;
        let n = cells.len();
        match stage {
            0 => {
                let mut buf = super::write(&self.r[k]);
                buf[halo..].fill(0.0);
                for (&i, &v) in sites.iter().zip(r) {
                    buf[halo + i - base] = v;
                }
            }
            1 => {
                // The halo first (read locks on the parts before, no lock of our own held
                // meanwhile: they read ours at the same time), then our own buffer.
                let mut scratch = super::lock(&self.z[k]);
                let temp = &mut scratch.1;
                temp.fill(0.0); // cells before the grid
                let lo = base.saturating_sub(halo);
                gather(&self.r, partition, lo, base, temp, halo - (base - lo), halo);
                super::write(&self.r[k])[..halo].copy_from_slice(temp);
                let buf = super::read(&self.r[k]);
                fsai.g(base, &buf, &mut super::write(&self.y[k])[..n]);
            }
            _ => {
                let mut scratch = super::lock(&self.z[k]);
                let (zc, temp) = &mut *scratch;
                temp.fill(0.0); // cells past the grid
                let hi = (cells.end + halo).min(partition.len());
                gather(&self.y, partition, cells.end, hi, temp, 0, 0);
                super::write(&self.y[k])[n..].copy_from_slice(temp);
                let y = super::read(&self.y[k]);
                fsai.gt(base, &y, zc);
                for (za, &i) in z.iter_mut().zip(sites) {
                    *za = zc[i - base];
                }
            }
        }
    }
}

/// Copies the cells `lo..hi` of other parts' buffers into `out[at..]`; a part's cells
/// start at `offset` in its buffer.
fn gather(
    buffers: &[RwLock<Vec<f64>>],
    partition: &Partition,
    lo: usize,
    hi: usize,
    out: &mut [f64],
    at: usize,
    offset: usize,
) {
    for (j, buffer) in buffers.iter().enumerate() {
        let cells = partition.cells(j);
        let (a, b) = (cells.start.max(lo), cells.end.min(hi));
        if a < b {
            let buf = super::read(buffer);
            let src = &buf[offset + a - cells.start..offset + b - cells.start];
            out[at + a - lo..at + b - lo].copy_from_slice(src);
        }
    }
}
