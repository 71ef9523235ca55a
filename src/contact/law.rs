//! A downstream crate's contact rule: the [`ContactLaw`] trait, the [`SiteView`] it reads
//! and the [`CustomRule`] that carries it in a [`ContactRule`](super::ContactRule).

use crate::interface::SiteState;
use std::sync::Arc;

/// A contact rule written outside the crate: its own Coulomb threshold per site, whether
/// springs are anchored where their sites attach, and whether and when a broken site
/// re-forms. Give it to a scene as [`ContactRule::custom`](super::ContactRule::custom).
/// Every method but [`ContactLaw::name`] has a default, the paper's rule, so a law
/// overrides only what it changes (and a later version may add methods with defaults).
///
/// The protocol stays the paper's whatever the law: the load is raised to the smallest
/// breaking load of the attached sites, the site over its threshold with the largest
/// elastic energy `½ φ_x² ΔA / k_x` breaks first, the normal equilibrium (unique) decides
/// which available sites touch, and the block slides when every spring is broken.
///
/// # The threshold's contract
/// [`ContactLaw::threshold`] is asked once per site at every new equilibrium (after each
/// rupture, and after sites re-form), from that equilibrium's state, and holds until the
/// next one: the protocol inverts it for the load that breaks the site,
/// `λ_i = τ_i / |φ_x,i(1)|` (N; `φ_x,i(1)` the shear per newton of load), which is exact
/// only because `τ_i` does not move with the load between events. A threshold that
/// depended on the current shear or load would break sites at loads the inversion did
/// not predict. The answer must be finite and `>= 0` (Pa); another value fails the step
/// with [`Error::InvalidThreshold`](crate::Error::InvalidThreshold). It must not depend on
/// anything but the view and the law's own fixed parameters: the runs must be
/// reproducible, and the dense and spectral backends give the same events only if the law
/// does.
///
/// # What a custom rule gives up
/// Checkpoints, scene files and run directories: they record a scene by its scene-file
/// keys, and a law is Rust code. [`Scene::resume`](crate::Scene::resume),
/// `SceneBuilder::to_json` and `Checkpoint::to_json` (feature `serde`) and
/// [`RunTables`](crate::output::RunTables) refuse it with
/// [`Error::CustomContactRule`](crate::Error::CustomContactRule); sweeps and the Python
/// bindings, which read scene files, cannot name one. A custom rule that re-forms sites
/// without a load delay, or under a spring drive, may never reach global slip (re-formed
/// sites can break again at the same load for ever; the built-in re-forming rule is
/// refused under a spring): bound such a run yourself.
///
/// A law is shared by the scene's drivers, across threads: it is `Send + Sync` (and
/// `RefUnwindSafe`, as the scene and driver that hold it are), and answers from its
/// arguments and fixed parameters only.
///
/// ```
/// use precursors::{ContactLaw, ContactRule, Event, Scene, SiteView};
///
/// /// Slip weakening: a site whose spring broke before holds only μ_d φ_z (Pa) once it
/// /// re-forms, two stable states and a load increase `load` (N) after its rupture,
/// /// anchored where it attaches. (Without a load delay re-formed sites could break
/// /// again at the same load for ever under force control.)
/// #[derive(Debug)]
/// struct Weakening { dynamic: f64, load: f64 }
///
/// impl ContactLaw for Weakening {
///     fn name(&self) -> &str { "slip-weakening" }
///     fn threshold(&self, site: &SiteView) -> f64 {
///         let mu = if site.ruptures > 0 { self.dynamic } else { site.friction_coefficient };
///         mu * site.normal_traction // Pa
///     }
///     fn anchors(&self) -> bool { true }
///     fn reforms(&self, site: &SiteView) -> bool {
///         match (site.rupture_stable_states, site.rupture_force) {
///             (Some(at), Some(force)) => {
///                 site.stable_states >= at + 2 && site.force - force >= self.load
///             }
///             _ => false,
///         }
///     }
/// }
///
/// let scene = Scene::builder()
///     .block(0.012, 0.002, 0.010)
///     .cells(12, 2)
///     .normal_load(40.0)
///     .seed(1)
///     // μ_s = 0.5, μ F_N = 20 N: re-formation after 2 % of it.
///     .contact_rule(ContactRule::custom(Weakening { dynamic: 0.3, load: 0.4 }))
///     .build()?;
/// assert_eq!(scene.contact_rule().name(), "slip-weakening");
/// let events: Vec<Event> = scene.driver()?.collect::<Result<_, _>>()?;
/// assert!(matches!(events.last(), Some(Event::GlobalSlip { .. })));
/// // Re-formed sites break again: more ruptures than the 24 sites.
/// let ruptures = events.iter().filter(|e| matches!(e, Event::Rupture { .. })).count();
/// assert!(ruptures > 24);
/// # Ok::<(), precursors::Error>(())
/// ```
pub trait ContactLaw: Send + Sync + std::panic::RefUnwindSafe + std::fmt::Debug {
    /// The rule's name, for messages and reports (`precursors info` does not list it: it
    /// is not a scene-file value).
    fn name(&self) -> &str;

    /// The Coulomb threshold `τ_i` (Pa) of an attached site: its spring breaks once
    /// `|φ_x,i| >= τ_i`. Asked at every new equilibrium for each attached site, and held
    /// until the next (see the trait's contract). The default is the paper's,
    /// `μ φ_z,i` (`site.friction_coefficient * site.normal_traction`, in that order: with
    /// it a custom rule gives the paper's events bit for bit).
    fn threshold(&self, site: &SiteView) -> f64 {
        site.friction_coefficient * site.normal_traction
    }

    /// Whether a spring is anchored where its site attaches (`φ_x = -k_x (u_x - a)`, `a`
    /// the site's `u_x` when it attached, m: no shear at the attachment) rather than at
    /// `u_x = 0` (the paper's). Asked once, when the rule is made
    /// ([`ContactRule::custom`](super::ContactRule::custom)). Default `false`.
    fn anchors(&self) -> bool {
        false
    }

    /// Whether a broken site re-forms now (broken → detached; the normal equilibrium then
    /// decides whether it touches, and an attaching spring is anchored as
    /// [`ContactLaw::anchors`] says). Asked for each broken site at every move from a
    /// stable state to the next load (never inside an avalanche), after the clock
    /// [`SiteView::stable_states`] has ticked. Default `false`: a broken site never
    /// re-forms.
    fn reforms(&self, site: &SiteView) -> bool {
        let _ = site;
        false
    }
}

/// What a [`ContactLaw`] sees of one site when it is asked: its state and the fields of
/// the current equilibrium at it, and its history under the rule. Made by the driver;
/// fields may be added in later versions.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct SiteView {
    /// The site's index, cell order `i = iy·Nx + ix`.
    pub index: usize,
    /// Its state: attached when a threshold is asked, broken when a re-formation is.
    pub state: SiteState,
    /// The normal traction `φ_z` (Pa, `>= 0`) at the site in the current normal
    /// equilibrium (0 off the contact).
    pub normal_traction: f64,
    /// The normal displacement `u_z` (m) of the block's bottom at the site.
    pub normal_displacement: f64,
    /// The site's friction coefficient `μ` (dimensionless): the scene's friction map at
    /// the site where it has one (`SceneBuilder::friction_map`), else the material's.
    pub friction_coefficient: f64,
    /// The `u_x` (m) at which the site's spring carries no shear: where it attached under
    /// an anchoring rule, 0 otherwise (and off the attached sites).
    pub anchor: f64,
    /// How many times the site's spring has broken so far.
    pub ruptures: u64,
    /// The quasi-static clock: the moves from a stable state to the next load made so far.
    pub stable_states: u64,
    /// The clock at the site's last rupture, while it is broken (`None` otherwise).
    pub rupture_stable_states: Option<u64>,
    /// The shear force `F` (N) at the site's last rupture, while it is broken.
    pub rupture_force: Option<f64>,
    /// The shear force `F` (N) of the state the rule is asked in: of the new equilibrium
    /// for a threshold (which then holds whatever the load does until the next), of the
    /// stable state for a re-formation.
    pub force: f64,
}

/// A [`ContactLaw`] as a scene holds it ([`ContactRule::Custom`](super::ContactRule::Custom)),
/// made by [`ContactRule::custom`](super::ContactRule::custom). Cloning shares the law;
/// two rules are equal when they share it.
#[derive(Clone)]
pub struct CustomRule {
    law: Arc<dyn ContactLaw>,
    /// [`ContactLaw::anchors`], asked once.
    anchors: bool,
}

impl CustomRule {
    pub(super) fn new(law: Arc<dyn ContactLaw>) -> Self {
        let anchors = law.anchors();
        Self { law, anchors }
    }

    /// The law.
    pub fn law(&self) -> &dyn ContactLaw {
        &*self.law
    }

    /// Whether its springs are anchored where their sites attach.
    pub(super) fn anchors(&self) -> bool {
        self.anchors
    }
}

impl std::fmt::Debug for CustomRule {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("CustomRule")
            .field("law", &self.law)
            .field("anchors", &self.anchors)
            .finish()
    }
}

impl PartialEq for CustomRule {
    /// The same law (shared), not an equal one: a law need not be comparable.
    fn eq(&self, other: &Self) -> bool {
        Arc::ptr_eq(&self.law, &other.law)
    }
}
