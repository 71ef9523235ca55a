//! What a [`Driver`] shows of its current state: the site states and breaking loads, the
//! tractions and displacements, the spring force, the stresses at the probes, the real
//! contact area (per cell, per column, in total) and the precursor length.

use super::Driver;
#[cfg(doc)] // the doc links
use super::{Checkpoint, Event};
use crate::error::{Error, Result};
use crate::interface::{Interface, SiteState};
use crate::probe::{ProbeInput, ProbeSpec, StressProbe, Stresses};
use crate::scene::Drive;

/// Relative slack of [`Driver::area_exceeds_nominal`]: the rounding of a sum of cell
/// areas, so a capped area of `ΔA` on every cell is not flagged.
const NOMINAL_AREA_SLACK: f64 = 1e-9;

/// The interface along `x`, averaged over `y` ([`Driver::slip_profile`]): one value per
/// column `ix`, from the trailing edge. Read it through its methods, as [`crate::Profile`]
/// (the fields stay readable through 1.x).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[non_exhaustive]
pub struct SlipProfile {
    /// `⟨u_x⟩_y`, the shear displacement of the bottom face (m).
    #[deprecated(since = "1.2.0", note = "use the method `SlipProfile::slip()`")]
    pub slip: Vec<f64>,
    /// `⟨φ_x⟩_y`, the shear traction (Pa; negative where the springs resist `+x`).
    #[deprecated(
        since = "1.2.0",
        note = "use the method `SlipProfile::shear_traction()`"
    )]
    pub shear_traction: Vec<f64>,
    /// `⟨φ_z⟩_y`, the normal traction (Pa; compressive positive).
    #[deprecated(
        since = "1.2.0",
        note = "use the method `SlipProfile::normal_traction()`"
    )]
    pub normal_traction: Vec<f64>,
    /// The columns' centres `(ix + 1/2)·Δx` (m); empty for a profile read from a serde
    /// value written before 1.2 (a field added later has a default:
    /// docs/compatibility.md).
    #[cfg_attr(feature = "serde", serde(default))]
    x: Vec<f64>,
}

// The fields stay readable through 1.x; the crate itself reads them only here.
#[allow(deprecated)]
impl SlipProfile {
    /// The centre `x = (ix + 1/2)·Δx` of each column `ix` (m), from `x = 0` at the
    /// trailing face: the abscissa of the other three. Empty only for a profile read from
    /// a serde value written before 1.2.
    pub fn x(&self) -> &[f64] {
        &self.x
    }

    /// `⟨u_x⟩_y`, the shear displacement of the bottom face in each column (m).
    pub fn slip(&self) -> &[f64] {
        &self.slip
    }

    /// `⟨φ_x⟩_y`, the shear traction of each column (Pa; negative where the springs resist
    /// `+x`; a detached or broken cell counts with zero).
    pub fn shear_traction(&self) -> &[f64] {
        &self.shear_traction
    }

    /// `⟨φ_z⟩_y`, the normal traction of each column (Pa; compressive positive; a detached
    /// or broken cell counts with zero).
    pub fn normal_traction(&self) -> &[f64] {
        &self.normal_traction
    }
}

/// The interface's slip per newton of shear load at the current attached set
/// ([`Driver::slip_per_newton`]): the tangential equilibrium is linear in the load `F` at
/// a fixed set, so the state at any load of the set is `F` times these. Differences between
/// two stable states give an avalanche's potency, its slip-weighted centroid and the energy
/// it releases (`per_avalanche.csv`, docs/statistics.md).
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct SlipPerNewton {
    /// `ΔA Σ_i u_x,i`, the potency of the bottom face per newton of load (m³/N), every
    /// cell counted (in contact or not).
    pub potency: f64,
    /// `ΔA Σ_i x_i u_x,i`, its first moment along `x` per newton (m⁴/N), `x_i` the cell
    /// centre from the trailing edge.
    pub potency_moment: f64,
    /// The displacement work-conjugate to the shear load, per newton (m/N), less the
    /// load's own compliance (a constant of the scene): `U + ΔA Σ_i φ_x,i e_i`, with `U`
    /// the block's offset, `φ_x` the interface tractions and `e` the load's displacement
    /// of the bottom face, both per newton (Betti's reciprocity). At a fixed load `F` the
    /// elastic energy is `½ F² (c + c₀)` (Clapeyron), so an avalanche at constant `F` from
    /// compliance `c_before` to `c_after` releases `½ F² (c_after - c_before)`.
    pub load_compliance: f64,
}

impl Driver {
    /// The spring force `K_S (U_S - ⟨u_x⟩)` (N) under displacement control, `None` under
    /// force control.
    pub fn spring_force(&self) -> Option<f64> {
        matches!(self.scene.drive(), Drive::Spring { .. }).then(|| self.force())
    }

    /// The interface (site states, heights, spring law).
    pub fn interface(&self) -> &Interface {
        &self.interface
    }

    /// Site states, in the paper's cell order.
    pub fn site_states(&self) -> &[SiteState] {
        self.interface.states()
    }

    /// Normal traction `φ_z` per cell (Pa).
    ///
    /// # Errors
    /// [`Error::NotSolved`] before the first event ([`Driver::event_count`] 0), never
    /// after it.
    pub fn normal_traction(&self) -> Result<&[f64]> {
        Ok(&self.normal()?.traction)
    }

    /// Normal displacement `u_z` of the bottom face per cell (m).
    ///
    /// # Errors
    /// [`Error::NotSolved`] before the first event ([`Driver::event_count`] 0), never
    /// after it.
    pub fn normal_displacement(&self) -> Result<&[f64]> {
        Ok(&self.normal()?.displacement)
    }

    /// Shear traction `φ_x` per cell (Pa; negative where the springs resist `+x`).
    ///
    /// # Errors
    /// [`Error::NotSolved`] before the first event ([`Driver::event_count`] 0), never
    /// after it.
    pub fn shear_traction(&self) -> Result<&[f64]> {
        self.response()?;
        Ok(&self.shear_traction)
    }

    /// Shear displacement `u_x` of the bottom face per cell (m).
    ///
    /// # Errors
    /// [`Error::NotSolved`] before the first event ([`Driver::event_count`] 0), never
    /// after it.
    pub fn shear_displacement(&self) -> Result<&[f64]> {
        self.response()?;
        Ok(&self.shear_displacement)
    }

    /// Mean shear displacement `⟨u_x⟩` of the block (m) (plus the top load's constant
    /// when a top shear acts).
    ///
    /// # Errors
    /// [`Error::NotSolved`] before the first event ([`Driver::event_count`] 0), never
    /// after it.
    pub fn mean_shear_displacement(&self) -> Result<f64> {
        let mean = self.force() * self.response()?.offset_per_newton;
        // No `+ 0.0` under the paper's rule: it would turn a `-0` into `+0`.
        Ok(match &self.anchor {
            Some(a) => mean + a.offset,
            None => mean,
        })
    }

    /// The interface's slip per newton of shear load at the current attached set
    /// ([`SlipPerNewton`]): the potency `ΔA Σ u_x`, its first moment along `x` and the
    /// load's work-conjugate compliance.
    ///
    /// ```
    /// use precursors::{Event, Scene};
    /// let scene = Scene::builder()
    ///     .block(0.020, 0.004, 0.010)
    ///     .cells(20, 4)
    ///     .normal_load(80.0)
    ///     .seed(0)
    ///     .build()?;
    /// let mut driver = scene.driver()?;
    /// while let Some(event) = driver.step()? {
    ///     if let Event::Stable { load, .. } = event {
    ///         if load.force > 0.0 {
    ///             // ΔA Σ u_x at this state is F times the potency per newton (m³).
    ///             let slip = driver.slip_per_newton()?;
    ///             let sum: f64 = driver.shear_displacement()?.iter().sum();
    ///             let potency = sum * driver.grid().cell_area();
    ///             assert!((load.force * slip.potency - potency).abs() <= 1e-9 * potency.abs());
    ///             break;
    ///         }
    ///     }
    /// }
    /// # Ok::<(), precursors::Error>(())
    /// ```
    ///
    /// # Errors
    /// [`Error::NotSolved`] before the first event ([`Driver::event_count`] 0), never
    /// after it.
    pub fn slip_per_newton(&self) -> Result<SlipPerNewton> {
        let response = self.response()?;
        let grid = self.grid();
        let (nx, dx, area) = (grid.nx(), grid.dx(), grid.cell_area());
        let (mut potency, mut moment, mut reciprocal) = (0.0, 0.0, 0.0);
        for (i, (&u, (&g, &e))) in response
            .displacement
            .iter()
            .zip(response.traction.iter().zip(&self.unit_load))
            .enumerate()
        {
            potency += u;
            moment += ((i % nx) as f64 + 0.5) * dx * u;
            reciprocal += g * e;
        }
        Ok(SlipPerNewton {
            potency: potency * area,
            potency_moment: moment * area,
            load_compliance: response.offset_per_newton + reciprocal * area,
        })
    }

    /// The interface's profiles along `x`, averaged over `y` (one value per column `ix`,
    /// from the trailing edge): the slip `⟨u_x⟩_y` (m) and the tractions `⟨φ_x⟩_y`,
    /// `⟨φ_z⟩_y` (Pa; a detached or broken cell counts with zero traction). The paper's
    /// interface `τ(x, 0)` and `σ(x, 0)` up to their signs (docs/model.md section 1).
    ///
    /// ```
    /// use precursors::{Event, Scene};
    /// let scene = Scene::builder()
    ///     .block(0.020, 0.004, 0.010)
    ///     .cells(20, 4)
    ///     .normal_load(80.0)
    ///     .seed(0)
    ///     .build()?;
    /// let mut driver = scene.driver()?;
    /// while let Some(event) = driver.step()? {
    ///     if let Event::Stable { load, .. } = event {
    ///         if load.force > 0.0 {
    ///             break; // the first stable state under shear
    ///         }
    ///     }
    /// }
    /// let profile = driver.slip_profile()?;
    /// assert_eq!(profile.slip().len(), 20);
    /// assert_eq!(profile.x()[3], 3.5e-3);             // 1 mm columns: centre of column 3 (m)
    /// // The column averages carry the load: Σ ⟨φ_z⟩_y Δx Ly = F_N (N).
    /// let carried: f64 = profile.normal_traction().iter().sum::<f64>() * 0.001 * 0.004;
    /// assert!((carried - 80.0).abs() < 1e-6 * 80.0);
    /// # Ok::<(), precursors::Error>(())
    /// ```
    ///
    /// # Errors
    /// [`Error::NotSolved`] before the first event ([`Driver::event_count`] 0), never
    /// after it.
    pub fn slip_profile(&self) -> Result<SlipProfile> {
        let nx = self.grid().nx();
        let ny = self.grid().ny() as f64;
        let average = |field: &[f64]| {
            let mut columns = vec![0.0; nx];
            for row in field.chunks_exact(nx) {
                columns.iter_mut().zip(row).for_each(|(c, v)| *c += v);
            }
            columns.iter_mut().for_each(|c| *c /= ny);
            columns
        };
        let dx = self.grid().dx();
        #[allow(deprecated)] // the fields stay filled through 1.x
        Ok(SlipProfile {
            x: (0..nx).map(|ix| (ix as f64 + 0.5) * dx).collect(),
            slip: average(self.shear_displacement()?),
            shear_traction: average(self.shear_traction()?),
            normal_traction: average(self.normal_traction()?),
        })
    }

    /// Breaking load `λ_i` (N) of each site in the current state (`+∞` off contact).
    pub fn breaking_loads(&self) -> &[f64] {
        &self.breaking
    }

    /// Adds stress probes (planes and points), planned now on the scene's operator and
    /// read by [`Driver::stresses`] after the scene's own ([`crate::SceneBuilder::probes`]),
    /// in the order they were added. Probes observe: they change neither the events nor
    /// the scene's identity, so they may be added at any time, and a
    /// [`Checkpoint`] resumes whatever probes either driver has (a checkpoint does not
    /// hold them: add them again to the resumed driver). An empty `spec` adds nothing.
    ///
    /// ```
    /// use precursors::{ProbeSpec, Scene};
    /// let scene = Scene::builder()
    ///     .block(0.020, 0.004, 0.010)
    ///     .normal_load(80.0)
    ///     .seed(0)
    ///     .build()?;
    /// let mut driver = scene.driver()?;
    /// driver.step()?;
    /// driver.add_probes(&ProbeSpec::default().with_plane(2e-3))?;
    /// let plane = &driver.stresses()?.planes[0];
    /// assert_eq!((plane.nx(), plane.ny()), (20, 4));
    /// # Ok::<(), precursors::Error>(())
    /// ```
    ///
    /// # Errors
    /// As [`StressProbe::new`]: a plane or point outside the block, a bad tolerance.
    pub fn add_probes(&mut self, spec: &ProbeSpec) -> Result<()> {
        let planned =
            crate::scene::plan_probes(self.scene.plan(), spec, self.scene.lateral_load())?;
        self.probes.extend(planned);
        Ok(())
    }

    /// Shear, normal and Coulomb stresses (Pa) at the probes (the scene's,
    /// [`crate::SceneBuilder::probes`], then those of [`Driver::add_probes`], planes and
    /// points each in request order) in the current state, with every load term. Call
    /// it at the states you want: after the [`Event::LoadRaised`] that precedes the first
    /// [`Event::Rupture`] for "just before the first rupture", at each [`Event::Stable`]
    /// for the quasi-static evolution.
    ///
    /// # Errors
    /// [`Error::NoProbes`] when the driver has no probes ([`crate::SceneBuilder::probes`],
    /// [`Driver::add_probes`]); [`Error::NotSolved`] before the first event (call
    /// [`Driver::step`] first).
    pub fn stresses(&self) -> Result<Stresses> {
        if self.probes.is_empty() {
            return Err(Error::NoProbes);
        }
        self.stresses_at(&self.probes)
    }

    /// The stresses at `probes` (planned on this driver's scene) in the current state, as
    /// [`Driver::stresses`] reads its own: the run tables' recorded fields use it.
    pub(crate) fn stresses_at(&self, probes: &[StressProbe]) -> Result<Stresses> {
        let force = self.force();
        // (F_top, F_lat) per newton of F.
        let split = self.scene.load_split();
        let input = ProbeInput::new(self.shear_traction()?, self.normal_traction()?)
            .with_loads(force * split.0, force * split.1, self.normal_load())?
            .with_friction_coefficient(self.friction_coefficient())?;
        let mut all = Stresses {
            planes: Vec::new(),
            points: Vec::new(),
        };
        for probe in probes {
            let stresses = probe.evaluate(&input)?;
            all.planes.extend(stresses.planes);
            all.points.extend(stresses.points);
        }
        Ok(all)
    }

    /// The real contact area `A_R` (m²): the total over the interface, the paper's
    /// `A_R` (its value at zero shear is the calibration target of
    /// [`crate::calibration::fit_normal_stiffness`]). Per cell:
    /// [`Driver::cell_contact_area`]; per column: [`Driver::column_contact_area`].
    ///
    /// **The value is not bounded by the nominal area `Lx·Ly`.** Under the paper's area
    /// law ([`crate::AreaLaw::Paper`], the default) asperities pressed below the
    /// substrate's mean plane give areas above it (e.g. 0.107 m² on a 0.002 m² face in a
    /// top-drive run), physically meaningless as areas. A loop that records this value
    /// should check [`Driver::area_exceeds_nominal`] (or compare with
    /// [`Driver::nominal_area`]), or bound the law with [`crate::AreaLaw::Capped`]
    /// ([`crate::SceneBuilder::area_law`]).
    ///
    /// # Errors
    /// [`Error::NotSolved`] before the first event ([`Driver::event_count`] 0);
    /// [`Error::NonFinite`] when a cell's area overflows (under [`crate::AreaLaw::Paper`]
    /// only: [`crate::AreaLaw::Capped`] caps it).
    pub fn real_contact_area(&self) -> Result<f64> {
        Ok(self.cell_contact_area()?.iter().sum())
    }

    /// The real contact area of each cell (m², in cell order `i = iy·Nx + ix`;
    /// [`crate::Interface::cell_contact_area`] at the current displacements). The total
    /// is [`Driver::real_contact_area`].
    ///
    /// # Errors
    /// As [`Driver::real_contact_area`].
    pub fn cell_contact_area(&self) -> Result<Vec<f64>> {
        self.interface
            .cell_contact_area(&self.normal()?.displacement)
    }

    /// The nominal area `Lx·Ly` of the interface (m²).
    pub fn nominal_area(&self) -> f64 {
        let block = self.grid().block();
        block.lx() * block.ly()
    }

    /// Whether the total real contact area of the current state exceeds the nominal
    /// area `Lx·Ly` ([`Driver::nominal_area`]) by more than `1e-9` relative (the rounding
    /// of the sum): a state the paper's unbounded area law ([`crate::AreaLaw::Paper`])
    /// reaches when asperities are pressed below the substrate's mean plane, physically
    /// meaningless as an area. An area whose exponential overflows
    /// ([`Error::NonFinite`] from [`Driver::real_contact_area`]) exceeds it too. Never
    /// true under [`crate::AreaLaw::Capped`].
    ///
    /// # Errors
    /// [`Error::NotSolved`] before the first event ([`Driver::event_count`] 0), never
    /// after it (an overflowing area exceeds the nominal one: `Ok(true)`).
    pub fn area_exceeds_nominal(&self) -> Result<bool> {
        match self.real_contact_area() {
            Ok(total) => Ok(total > self.nominal_area() * (1.0 + NOMINAL_AREA_SLACK)),
            Err(Error::NonFinite {
                name: "real contact area",
                ..
            }) => Ok(true),
            Err(e) => Err(e),
        }
    }

    /// Real contact area per column `ix` (summed over `y`, m²).
    ///
    /// # Errors
    /// As [`Driver::real_contact_area`].
    pub fn column_contact_area(&self) -> Result<Vec<f64>> {
        let area = self.cell_contact_area()?;
        let nx = self.grid().nx();
        let mut columns = vec![0.0; nx];
        for row in area.chunks_exact(nx) {
            columns.iter_mut().zip(row).for_each(|(c, a)| *c += a);
        }
        Ok(columns)
    }

    /// Real contact area per column at zero shear (m²), the reference of the precursor.
    pub fn initial_column_contact_area(&self) -> &[f64] {
        &self.initial_columns
    }

    /// The block (lengths `Lx`, `Ly`, `Lz` in m): e.g. the precursor length relative to
    /// the block, `ℓ/Lx = driver.precursor_length()? / driver.block().lx()`.
    pub fn block(&self) -> &crate::geometry::Block {
        self.grid().block()
    }

    /// Precursor length `ℓ` in metres (not relative to `Lx`: divide by
    /// [`Driver::block`]`().lx()` for the paper's `ℓ/Lx`): the extent, from the trailing
    /// edge `x = 0`, of the run of columns whose real contact area is below its value at
    /// zero shear (docs/model.md section 5; paper Fig. 2b). A multiple of `Δx`.
    ///
    /// # Errors
    /// As [`Driver::real_contact_area`].
    pub fn precursor_length(&self) -> Result<f64> {
        let columns = self.column_contact_area()?;
        let run = columns
            .iter()
            .zip(&self.initial_columns)
            .take_while(|(now, then)| now < then)
            .count();
        Ok(run as f64 * self.grid().dx())
    }

    /// A noise-robust precursor length (m, as [`Driver::precursor_length`]): the extent, from the trailing edge, of the
    /// run of columns whose real contact area fell below `(1 - drop)` times its value at
    /// zero shear. `drop` (dimensionless, in `[0, 1)`) is the relative fall that counts;
    /// `drop = 0` is the paper's definition ([`Driver::precursor_length`]) exactly; a
    /// larger `drop` never gives a longer front: a column counts only once it lost that
    /// fraction of its area, so smaller fluctuations do not extend the front. A multiple
    /// of `Δx`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for a `drop` outside `[0, 1)` (or NaN); as
    /// [`Driver::real_contact_area`].
    pub fn precursor_length_with_threshold(&self, drop: f64) -> Result<f64> {
        if !(0.0..1.0).contains(&drop) {
            return Err(Error::InvalidParameter {
                name: "drop",
                value: drop,
                reason: "the relative drop of a column's contact area must lie in [0, 1)",
            });
        }
        let keep = 1.0 - drop;
        let columns = self.column_contact_area()?;
        let run = columns
            .iter()
            .zip(&self.initial_columns)
            .take_while(|(now, then)| **now < keep * **then)
            .count();
        Ok(run as f64 * self.grid().dx())
    }
}
