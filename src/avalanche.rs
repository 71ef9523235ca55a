//! What a run's events say about its avalanches and its damage (docs/statistics.md): one
//! [`Avalanche`] per load step, the ruptures between two stable states; and the
//! [`DamageFront`], the extent from the trailing edge of the columns that lost more than
//! half their contacts at zero shear, beside the paper's precursor length `ℓ`.
//!
//! Both only observe: they read the events a driver returns (or a run's `events.csv`,
//! where `RunTables::finish` derives `per_avalanche.csv` and `fronts.csv` from them), and
//! change nothing of the run.

use crate::driver::{Event, Load};
use crate::error::{Error, Result};
use crate::geometry::Grid;
use crate::interface::SiteState;

/// One avalanche: the ruptures from a raise of the load ([`Event::LoadRaised`]) to the
/// next stable state ([`Event::Stable`]), or to global slip for the last one.
///
/// ```
/// use precursors::{Avalanches, Drive, Lateral, Scene};
/// let scene = Scene::builder()
///     .block(0.010, 0.004, 0.010)       // Lx, Ly, Lz (m)
///     .cells(10, 4)                     // 1 mm cells
///     .normal_load(40.0)                // F_N (N)
///     .drive(Drive::Spring { stiffness: 4e6, lateral: Lateral::Side })
///     .build()?;
/// let mut avalanches = Avalanches::new(scene.grid());
/// let mut all = Vec::new();
/// for event in scene.driver()? {
///     all.extend(avalanches.observe(&event?));
/// }
/// // Every spring breaks once, in some avalanche; the last one is global slip.
/// assert_eq!(all.iter().map(|a| a.ruptures).sum::<usize>(), 40);
/// assert!(all.last().unwrap().global_slip);
/// // Under a driving spring the force drops in an avalanche (N).
/// assert!(all.iter().all(|a| a.force_drop() >= 0.0));
/// # Ok::<(), precursors::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[non_exhaustive]
pub struct Avalanche {
    /// The index (from 1, as `events.csv` numbers them) of its [`Event::LoadRaised`].
    pub start_event: usize,
    /// The index of the [`Event::Stable`] that ends it (of [`Event::GlobalSlip`] for the
    /// last).
    pub end_event: usize,
    /// Springs broken ([`Event::Rupture`]s), at least 1.
    pub ruptures: usize,
    /// The nominal area of the broken cells, `ruptures · ΔA` (m²).
    pub broken_area: f64,
    /// The load when it started (the breaking load of its first spring; N, and the drive
    /// displacement `U_S` in m under a driving spring).
    pub load_before: Load,
    /// The load when it ended: at its stable state, or at the last rupture for global
    /// slip.
    pub load_after: Load,
    /// The elastic energy `½ k_x u_x² ΔA` of its springs when they broke, summed (J).
    pub energy: f64,
    /// Sites that came back into contact ([`Event::Attach`]).
    pub attaches: usize,
    /// Sites that lost contact ([`Event::Detach`]).
    pub detaches: usize,
    /// Ruptures of a site that attached earlier in the same avalanche (flash contacts,
    /// docs/model.md section 5).
    pub flash_ruptures: usize,
    /// Whether it ended in global slip (the block slides): the run's last.
    pub global_slip: bool,
    /// Sites in contact (attached) when it started; `None` when the recorder was not
    /// told the contacts at zero shear ([`Avalanches::with_zero_shear`]).
    pub contacts_before: Option<usize>,
    /// Sites in contact when it ended (`None` as [`Avalanche::contacts_before`]).
    pub contacts_after: Option<usize>,
    /// Whether it is the run's spanning avalanche: the first that leaves at most half of
    /// the sites that were in contact when it started (`2 · contacts_after ≤
    /// contacts_before`), the one that takes the precursor across the interface
    /// (docs/statistics.md). A run has at most one; under top loading it is the last,
    /// global slip. `false` when the contacts are not known.
    pub spanning: bool,
    /// Whether it comes after the run's spanning avalanche (the few sites left carry the
    /// whole normal load: a regime of its own, which statistics leave out by default).
    pub after_spanning: bool,
    /// Its extent along `x` (m): from the trailing edge of the lowest column it broke a
    /// spring in to the leading edge of the highest, `(ix_max - ix_min + 1)·Δx`.
    pub extent: f64,
    /// Its centroid along `x` by ruptures (m): the mean of its broken cells' centres,
    /// `Δx·(⟨ix⟩ + ½)`. Not slip-weighted: the events carry no slip (docs/statistics.md).
    pub centroid: f64,
}

impl Avalanche {
    /// The drop of the shear force over the avalanche, `F_before - F_after` (N): the
    /// stress drop of a driving spring (displacement control); 0 under force control,
    /// where the force stays at the breaking load.
    pub fn force_drop(&self) -> f64 {
        self.load_before.force - self.load_after.force
    }
}

/// The avalanches of a run, from its events in order ([`Avalanches::observe`]).
#[derive(Debug, Clone)]
pub struct Avalanches {
    cell_area: f64,
    dx: f64,
    /// The lowest and highest column broken in the current avalanche, and the sum of the
    /// broken columns.
    columns: (usize, usize, usize),
    /// Events observed.
    events: usize,
    current: Option<Avalanche>,
    /// The sites that attached in the current avalanche.
    attached: Vec<usize>,
    /// Sites in contact now, when the zero-shear contacts were given.
    contacts: Option<usize>,
    /// Whether the spanning avalanche has ended.
    spanned: bool,
}

impl Avalanches {
    /// A recorder for a run on `grid`; feed it every event of the run from the first.
    pub fn new(grid: &Grid) -> Self {
        Self {
            cell_area: grid.cell_area(),
            dx: grid.dx(),
            columns: (usize::MAX, 0, 0),
            events: 0,
            current: None,
            attached: Vec::new(),
            contacts: None,
            spanned: false,
        }
    }

    /// A recorder that also counts the sites in contact, and so finds the spanning
    /// avalanche ([`Avalanche::spanning`]), for a run whose sites were in `zero_shear` at
    /// its first stable state (`driver.site_states()` after the first step, or
    /// [`DamageFront::zero_shear_states`] of a whole run's events).
    ///
    /// ```
    /// use precursors::{Avalanches, Scene};
    /// let scene = Scene::builder()
    ///     .block(0.012, 0.002, 0.010)
    ///     .cells(12, 2)
    ///     .normal_load(50.0)
    ///     .seed(0)
    ///     .build()?;
    /// let mut driver = scene.driver()?;
    /// let first = driver.step()?.unwrap();             // the stable state at zero shear
    /// let mut avalanches = Avalanches::with_zero_shear(driver.grid(), driver.site_states())?;
    /// avalanches.observe(&first);
    /// let mut all = Vec::new();
    /// while let Some(event) = driver.step()? {
    ///     all.extend(avalanches.observe(&event));
    /// }
    /// // One spanning avalanche; every later one is flagged as after it.
    /// let k = all.iter().position(|a| a.spanning).unwrap();
    /// assert_eq!(all.iter().filter(|a| a.spanning).count(), 1);
    /// assert!(all[k + 1..].iter().all(|a| a.after_spanning));
    /// assert!(all[..k].iter().all(|a| !a.after_spanning));
    /// let (before, after) = (all[k].contacts_before.unwrap(), all[k].contacts_after.unwrap());
    /// assert!(2 * after <= before);
    /// # Ok::<(), precursors::Error>(())
    /// ```
    ///
    /// # Errors
    /// [`Error::LengthMismatch`] when `zero_shear` does not hold one state per site.
    pub fn with_zero_shear(grid: &Grid, zero_shear: &[SiteState]) -> Result<Self> {
        check_zero_shear(grid, zero_shear)?;
        let mut out = Self::new(grid);
        out.contacts = Some(
            zero_shear
                .iter()
                .filter(|s| **s == SiteState::Attached)
                .count(),
        );
        Ok(out)
    }

    /// Takes the run's next event; returns the avalanche it ends, if it ends one (a
    /// stable state after a raise of the load, or global slip).
    pub fn observe(&mut self, event: &Event) -> Option<Avalanche> {
        self.events += 1;
        match *event {
            Event::LoadRaised { load } => {
                self.attached.clear();
                self.columns = (usize::MAX, 0, 0);
                self.current = Some(Avalanche {
                    start_event: self.events,
                    end_event: self.events,
                    ruptures: 0,
                    broken_area: 0.0,
                    load_before: load,
                    load_after: load,
                    energy: 0.0,
                    attaches: 0,
                    detaches: 0,
                    flash_ruptures: 0,
                    global_slip: false,
                    contacts_before: self.contacts,
                    contacts_after: self.contacts,
                    spanning: false,
                    after_spanning: false,
                    extent: 0.0,
                    centroid: 0.0,
                });
                None
            }
            Event::Rupture { site, load, energy } => {
                self.count(-1);
                if let Some(a) = &mut self.current {
                    let (low, high, sum) = &mut self.columns;
                    (*low, *high, *sum) =
                        ((*low).min(site.ix), (*high).max(site.ix), *sum + site.ix);
                    a.ruptures += 1;
                    a.broken_area += self.cell_area;
                    a.energy += energy;
                    a.load_after = load;
                    if self.attached.contains(&site.index) {
                        a.flash_ruptures += 1;
                    }
                }
                None
            }
            Event::Attach { site } => {
                self.count(1);
                if let Some(a) = &mut self.current {
                    a.attaches += 1;
                    self.attached.push(site.index);
                }
                None
            }
            Event::Detach { .. } => {
                self.count(-1);
                if let Some(a) = &mut self.current {
                    a.detaches += 1;
                }
                None
            }
            Event::Stable { load, .. } => self.end(load, false),
            Event::GlobalSlip { load } => self.end(load, true),
        }
    }

    fn end(&mut self, load: Load, global_slip: bool) -> Option<Avalanche> {
        let mut a = self.current.take()?;
        a.end_event = self.events;
        a.load_after = load;
        a.global_slip = global_slip;
        a.contacts_after = self.contacts;
        let (low, high, sum) = self.columns;
        if a.ruptures > 0 {
            a.extent = (high - low + 1) as f64 * self.dx;
            a.centroid = (sum as f64 / a.ruptures as f64 + 0.5) * self.dx;
        }
        if self.spanned {
            a.after_spanning = true;
        } else if let (Some(before), Some(after)) = (a.contacts_before, a.contacts_after) {
            a.spanning = 2 * after <= before;
            self.spanned = a.spanning;
        }
        Some(a)
    }

    /// A site came into (`+1`) or out of (`-1`) contact.
    fn count(&mut self, change: isize) {
        if let Some(n) = &mut self.contacts {
            *n = n.saturating_add_signed(change);
        }
    }
}

/// Refuses zero-shear states that are not one per site of `grid`.
fn check_zero_shear(grid: &Grid, zero_shear: &[SiteState]) -> Result<()> {
    if zero_shear.len() == grid.len() {
        Ok(())
    } else {
        Err(Error::LengthMismatch {
            name: "zero_shear",
            expected: grid.len(),
            found: zero_shear.len(),
        })
    }
}

/// The damage front: the extent `x_D` (m), from the trailing edge `x = 0`, of the run of
/// columns that have lost at least half of their contacts at zero shear (docs/statistics.md),
/// beside the paper's precursor length `ℓ`, the run of columns whose real contact area is
/// below its zero-shear value ([`crate::Driver::precursor_length`]). A column's contacts at
/// zero shear, `n₀(ix)`, are its sites attached in the first stable state; `n(ix)` are its
/// sites attached now (a site broken or detached is out of contact; one that attached since
/// counts). A column has lost half when `2 n(ix) ≤ n₀(ix)`, and `x_D = Δx · k` for the first
/// `k` columns that all have. A multiple of `Δx`, like `ℓ`; unlike `ℓ` it is blind to the
/// area law, by which the springs left standing in a damaged column lift its real contact
/// area above the zero-shear value (docs/model.md section 5), so `x_D` runs far ahead of
/// `ℓ` (docs/statistics.md).
///
/// ```
/// use precursors::{DamageFront, Event, Scene};
/// let scene = Scene::builder()
///     .block(0.012, 0.002, 0.010)
///     .cells(12, 2)
///     .normal_load(50.0)
///     .seed(0)
///     .build()?;
/// let mut driver = scene.driver()?;
/// driver.step()?;                                  // the stable state at zero shear
/// let mut front = DamageFront::new(driver.grid(), driver.site_states())?;
/// let mut positions = Vec::new();
/// while let Some(event) = driver.step()? {
///     front.observe(&event);
///     if let Event::Stable { .. } = event {
///         positions.push(front.position());      // m, a multiple of Δx = 1 mm
///     }
/// }
/// assert!(positions.iter().all(|x| (x / 1e-3 - (x / 1e-3).round()).abs() < 1e-9));
/// assert_eq!(front.position(), 0.012);             // at global slip every spring broke
/// # Ok::<(), precursors::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct DamageFront {
    nx: usize,
    dx: f64,
    /// Whether each site is attached now.
    attached: Vec<bool>,
    /// Contacts per column at zero shear, and now.
    initial: Vec<usize>,
    now: Vec<usize>,
}

impl DamageFront {
    /// The front of a run on `grid` whose sites were in `zero_shear` at its first stable
    /// state (`driver.site_states()` after the first step).
    ///
    /// # Errors
    /// [`Error::LengthMismatch`] when `zero_shear` does not hold one state per site.
    pub fn new(grid: &Grid, zero_shear: &[SiteState]) -> Result<Self> {
        check_zero_shear(grid, zero_shear)?;
        let nx = grid.nx();
        let attached: Vec<bool> = zero_shear
            .iter()
            .map(|s| *s == SiteState::Attached)
            .collect();
        let mut initial = vec![0; nx];
        for (i, a) in attached.iter().enumerate() {
            initial[i % nx] += usize::from(*a);
        }
        Ok(Self {
            nx,
            dx: grid.dx(),
            attached,
            now: initial.clone(),
            initial,
        })
    }

    /// The sites in contact at zero shear of a whole run, read from its events (every
    /// event from the first to global slip): a site's first event after the first stable
    /// state is a detachment or a rupture when it was attached then (only an attached
    /// spring breaks), an attachment when it was not; at global slip every spring broke,
    /// so every site has one.
    ///
    /// ```
    /// use precursors::{DamageFront, Scene};
    /// let scene = Scene::builder().block(0.012, 0.002, 0.010).normal_load(50.0).seed(0).build()?;
    /// let mut driver = scene.driver()?;
    /// // The first event is the stable state at zero shear.
    /// let mut events = vec![driver.next().unwrap()?];
    /// let at_zero_shear = driver.site_states().to_vec();
    /// for event in driver.by_ref() {
    ///     events.push(event?); // to global slip
    /// }
    /// assert_eq!(DamageFront::zero_shear_states(scene.grid(), &events)?, at_zero_shear);
    /// // A run cut short is not a whole run.
    /// assert!(DamageFront::zero_shear_states(scene.grid(), &events[..3]).is_err());
    /// # Ok::<(), precursors::Error>(())
    /// ```
    ///
    /// # Errors
    /// [`Error::LengthMismatch`] naming `events` when they do not end in global slip or a
    /// site has no event (not the whole run of a scene on `grid`).
    pub fn zero_shear_states(grid: &Grid, events: &[Event]) -> Result<Vec<SiteState>> {
        let mut states: Vec<Option<SiteState>> = vec![None; grid.len()];
        let mut seen = 0;
        for event in events {
            let (site, state) = match *event {
                Event::Rupture { site, .. } | Event::Detach { site } => (site, SiteState::Attached),
                Event::Attach { site } => (site, SiteState::Detached),
                _ => continue,
            };
            if let Some(slot) = states.get_mut(site.index) {
                if slot.is_none() {
                    *slot = Some(state);
                    seen += 1;
                }
            }
        }
        let whole = matches!(events.last(), Some(Event::GlobalSlip { .. }));
        if !whole || seen != grid.len() {
            return Err(Error::LengthMismatch {
                name: "events (sites with an event in a run that reached global slip)",
                expected: grid.len(),
                found: if whole { seen } else { 0 },
            });
        }
        Ok(states.into_iter().flatten().collect())
    }

    /// Takes the run's next event: a rupture or a detachment takes its site out of
    /// contact, an attachment brings it back; other events change nothing here.
    pub fn observe(&mut self, event: &Event) {
        let (site, attach) = match *event {
            Event::Rupture { site, .. } | Event::Detach { site } => (site, false),
            Event::Attach { site } => (site, true),
            _ => return,
        };
        let Some(state) = self.attached.get_mut(site.index) else {
            return;
        };
        if *state != attach {
            *state = attach;
            let column = &mut self.now[site.index % self.nx];
            *column = if attach {
                *column + 1
            } else {
                column.saturating_sub(1)
            };
        }
    }

    /// The damage front `x_D` (m).
    pub fn position(&self) -> f64 {
        let run = self
            .now
            .iter()
            .zip(&self.initial)
            .take_while(|(n, n0)| 2 * **n <= **n0)
            .count();
        run as f64 * self.dx
    }

    /// The damage front at another threshold (m): the first columns that have each lost
    /// at least the share `lost` of their contacts at zero shear, `n(ix) ≤ (1 - lost)
    /// n₀(ix)`. [`DamageFront::position`] is `lost = 0.5`; docs/statistics.md shows how
    /// the front moves with the threshold.
    ///
    /// ```
    /// use precursors::{DamageFront, Event, Scene};
    /// let scene = Scene::builder().block(0.012, 0.002, 0.010).cells(12, 2).normal_load(50.0).build()?;
    /// let mut driver = scene.driver()?;
    /// driver.step()?;
    /// let mut front = DamageFront::new(driver.grid(), driver.site_states())?;
    /// while let Some(event) = driver.step()? {
    ///     front.observe(&event);
    ///     if let Event::Stable { .. } = event {
    ///         // A stricter threshold is never ahead of a looser one.
    ///         assert!(front.position_at(0.75)? <= front.position_at(0.25)?);
    ///         assert_eq!(front.position_at(0.5)?, front.position());
    ///     }
    /// }
    /// assert!(front.position_at(1.5).is_err());
    /// # Ok::<(), precursors::Error>(())
    /// ```
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `lost` unless `0 < lost ≤ 1`.
    pub fn position_at(&self, lost: f64) -> Result<f64> {
        if !(lost > 0.0 && lost <= 1.0) {
            return Err(Error::InvalidParameter {
                name: "lost",
                value: lost,
                reason: "the share of a column's contacts lost is above 0 and at most 1",
            });
        }
        Ok(self.front_lost(lost))
    }

    /// [`DamageFront::position_at`] for a share `lost` the caller has checked.
    pub(crate) fn front_lost(&self, lost: f64) -> f64 {
        let kept = 1.0 - lost;
        let run = self
            .now
            .iter()
            .zip(&self.initial)
            .take_while(|(n, n0)| **n as f64 <= kept * **n0 as f64)
            .count();
        run as f64 * self.dx
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::driver::Site;
    use crate::geometry::Block;

    fn grid() -> Grid {
        Grid::new(Block::new(0.004, 0.002, 0.01).unwrap(), 4, 2).unwrap()
    }

    fn site(g: &Grid, ix: usize, iy: usize) -> Site {
        Site {
            index: iy * g.nx() + ix,
            ix,
            iy,
        }
    }

    fn load(force: f64) -> Load {
        Load {
            force,
            drive_displacement: None,
        }
    }

    #[test]
    fn the_front_is_the_run_of_columns_that_lost_half_their_contacts() {
        let g = grid();
        use SiteState::{Attached as A, Detached as D};
        // Zero shear, columns 0..4 (rows iy = 0 then 1): column 0 two contacts, column 1
        // one, column 2 none, column 3 two.
        let zero = [A, A, D, A, A, D, D, A];
        let mut front = DamageFront::new(&g, &zero).unwrap();
        let rupture = |ix, iy| Event::Rupture {
            site: site(&g, ix, iy),
            load: load(1.0),
            energy: 1.0,
        };
        // Column 0 keeps both: no front, whatever the columns beyond.
        front.observe(&rupture(1, 0));
        front.observe(&rupture(3, 1));
        assert_eq!(front.position(), 0.0);
        // One of two lost is half: columns 0 and 1 (0 of 1 left) and 2 (none at zero
        // shear, none now) have lost half; column 3 keeps 1 of 2, also half: all four.
        front.observe(&Event::Detach {
            site: site(&g, 0, 1),
        });
        assert!((front.position() - 0.004).abs() < 1e-15);
        // A site that attached counts as a contact: column 2 gains one it had not.
        front.observe(&Event::Attach {
            site: site(&g, 2, 1),
        });
        assert!((front.position() - 0.002).abs() < 1e-15);
        // Column 0's detached site comes back: the front is gone.
        front.observe(&Event::Attach {
            site: site(&g, 0, 1),
        });
        assert_eq!(front.position(), 0.0);
    }

    #[test]
    fn zero_shear_states_come_from_each_sites_first_event() {
        let g = grid();
        let mut events = vec![Event::Stable {
            load: load(0.0),
            ruptures: 0,
        }];
        events.push(Event::LoadRaised { load: load(1.0) });
        for i in 0..g.len() {
            let s = site(&g, i % 4, i / 4);
            if i % 3 == 0 {
                events.push(Event::Attach { site: s });
            } else if i % 3 == 1 {
                events.push(Event::Detach { site: s });
                events.push(Event::Attach { site: s });
            }
            events.push(Event::Rupture {
                site: s,
                load: load(1.0),
                energy: 1.0,
            });
        }
        assert!(DamageFront::zero_shear_states(&g, &events).is_err());
        events.push(Event::GlobalSlip { load: load(1.0) });
        let states = DamageFront::zero_shear_states(&g, &events).unwrap();
        for (i, s) in states.iter().enumerate() {
            let expected = if i % 3 == 0 {
                SiteState::Detached
            } else {
                SiteState::Attached
            };
            assert_eq!(*s, expected, "site {i}");
        }
    }

    #[test]
    fn the_spanning_avalanche_is_the_first_that_leaves_half_the_contacts() {
        let g = grid();
        let all = [SiteState::Attached; 8];
        let rupture = |i: usize| Event::Rupture {
            site: site(&g, i % 4, i / 4),
            load: load(1.0),
            energy: 1.0,
        };
        let raise = Event::LoadRaised { load: load(1.0) };
        let stable = Event::Stable {
            load: load(1.0),
            ruptures: 0,
        };
        let detach = |i: usize| Event::Detach {
            site: site(&g, i % 4, i / 4),
        };
        let attach = |i: usize| Event::Attach {
            site: site(&g, i % 4, i / 4),
        };
        // 8 -> 7; 7 -> 4 (three ruptures, a detachment and an attachment: 2·4 > 7);
        // 4 -> 2 (2·2 ≤ 4: spanning); 2 -> 1 after it; 1 -> 0 global slip after it.
        let events = [
            stable,
            raise,
            rupture(0),
            stable,
            raise,
            rupture(1),
            detach(5),
            rupture(2),
            attach(5),
            rupture(3),
            stable,
            raise,
            rupture(4),
            rupture(5),
            stable,
            raise,
            rupture(6),
            stable,
            raise,
            rupture(7),
            Event::GlobalSlip { load: load(1.0) },
        ];
        let mut rec = Avalanches::with_zero_shear(&g, &all).unwrap();
        let out: Vec<Avalanche> = events.iter().filter_map(|e| rec.observe(e)).collect();
        let contacts: Vec<(Option<usize>, Option<usize>)> = out
            .iter()
            .map(|a| (a.contacts_before, a.contacts_after))
            .collect();
        let some = |a, b| (Some(a), Some(b));
        assert_eq!(
            contacts,
            [some(8, 7), some(7, 4), some(4, 2), some(2, 1), some(1, 0)]
        );
        let spanning: Vec<bool> = out.iter().map(|a| a.spanning).collect();
        let after: Vec<bool> = out.iter().map(|a| a.after_spanning).collect();
        assert_eq!(spanning, [false, false, true, false, false]);
        assert_eq!(after, [false, false, false, true, true]);
        // Without the zero-shear contacts nothing is known, and nothing flagged.
        let mut blind = Avalanches::new(&g);
        let out: Vec<Avalanche> = events.iter().filter_map(|e| blind.observe(e)).collect();
        assert!(out
            .iter()
            .all(|a| a.contacts_before.is_none() && !a.spanning));
        assert!(Avalanches::with_zero_shear(&g, &all[..7]).is_err());
    }

    #[test]
    fn avalanches_count_flash_contacts_and_drops() {
        let g = grid();
        let spring = |f: f64, u: f64| Load {
            force: f,
            drive_displacement: Some(u),
        };
        let mut rec = Avalanches::new(&g);
        let events = [
            Event::Stable {
                load: load(0.0),
                ruptures: 0,
            },
            Event::LoadRaised {
                load: spring(2.0, 1e-6),
            },
            Event::Rupture {
                site: site(&g, 0, 0),
                load: spring(2.0, 1e-6),
                energy: 0.5,
            },
            Event::Attach {
                site: site(&g, 2, 1),
            },
            Event::Detach {
                site: site(&g, 3, 1),
            },
            Event::Rupture {
                site: site(&g, 2, 1),
                load: spring(1.8, 1e-6),
                energy: 0.25,
            },
            Event::Stable {
                load: spring(1.5, 1e-6),
                ruptures: 2,
            },
        ];
        let out: Vec<Avalanche> = events.iter().filter_map(|e| rec.observe(e)).collect();
        assert_eq!(out.len(), 1);
        let a = out[0];
        assert_eq!((a.start_event, a.end_event, a.ruptures), (2, 7, 2));
        assert_eq!((a.attaches, a.detaches, a.flash_ruptures), (1, 1, 1));
        assert_eq!(a.energy, 0.75);
        assert_eq!(a.force_drop(), 0.5);
        assert!((a.broken_area - 2.0 * g.cell_area()).abs() < 1e-20);
        assert!(!a.global_slip);
    }
}
