//! Figures (feature `plot`): line charts with legends and confidence bands, and maps with
//! a colour bar, written as PNG or SVG (chosen by the file's extension), with axes, tick
//! values and labels in an embedded font (DejaVu Sans, cut to the characters labels use:
//! Latin, Greek, super- and subscripts, `ℓ`, `−`, `≈`, `≤`, `∑`, `⟨ ⟩`; `assets/fonts`), so that no
//! system font is needed.
//!
//! [`Chart`] and [`Map`] are the building blocks; [`draw`] draws the standard figures
//! of a run or of a sweep directory (`precursors plot DIR`); [`Movie`] the paper's
//! movies of a run's recorded fields as animated GIFs (`precursors movie DIR`).
//!
//! Non-finite values are not drawn: a line is cut at a point with a `NaN` or infinite
//! coordinate (a band where its bounds are not finite), and a map cell holding one is
//! drawn grey; automatic axis ranges cover the finite values only.
//!
//! ```no_run
//! use precursors::plot::{Chart, Corner};
//! let curve: Vec<(f64, f64)> = (0..=100).map(|k| (k as f64 / 100.0, (k as f64 / 100.0).powi(8))).collect();
//! Chart::new("Precursor length", "F/(μF_N)", "ℓ/Lx")
//!     .x_range(0.0, 1.0)
//!     .y_range(0.0, 1.0)
//!     .steps("seed 1", &curve)
//!     .legend(Corner::UpperLeft)
//!     .save("precursors.png")?;
//! # Ok::<(), precursors::plot::PlotError>(())
//! ```

mod distributions;
mod error;
mod figures;
mod fronts;
mod movie;
mod paper;
mod profiles;
mod relations;
mod scaled;
mod selection;
mod tables;

pub use error::PlotError;
pub use figures::{draw, draw_with_options, draw_with_size, DrawOptions, Drawn, Format};
pub use movie::{Movie, MovieKind, MovieReport};

use crate::error::Error;
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::borrow::Cow;
use std::ops::Range;
use std::path::Path;
use std::sync::OnceLock;

/// The results of this module: its errors are [`PlotError`]s.
type Result<T, E = PlotError> = std::result::Result<T, E>;

/// DejaVu Sans cut to the characters the labels use (scripts/subset-font.sh; licence in
/// assets/fonts/LICENSE-DejaVu.txt).
const FONT: &[u8] = include_bytes!("../assets/fonts/DejaVuSans-subset.ttf");
const FAMILY: &str = "sans-serif";

/// Registers the embedded font once per process: plotters' text goes through it.
fn register_font() -> Result<()> {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    let ok = *REGISTERED
        .get_or_init(|| plotters::style::register_font(FAMILY, FontStyle::Normal, FONT).is_ok());
    if ok {
        Ok(())
    } else {
        Err(PlotError::Figure {
            path: None,
            reason: "the embedded font could not be read".into(),
        })
    }
}

/// A figure ready to draw on any plotters backend.
trait Draw {
    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
    ) -> std::result::Result<(), String>;
}

/// The corner of the plotting area a chart's legend is asked to go in ([`Chart::legend`]:
/// it goes elsewhere rather than cover data).
///
/// ```
/// use precursors::plot::{Chart, Corner};
/// let dir = std::env::temp_dir().join(format!("precursors-doc-{}", std::process::id()));
/// std::fs::create_dir_all(&dir)?;
/// // A curve falling from 1 to 0.5 leaves the lower left corner free.
/// let area: Vec<_> = (0..=10).map(|k| (k as f64 / 10.0, 1.0 - k as f64 / 20.0)).collect();
/// Chart::new("Real contact area", "F/(μF_N)", "A_R/A_R(0)")
///     .line("seed 1", &area)
///     .legend(Corner::LowerLeft)
///     .save(dir.join("area.svg"))?;
/// let svg = std::fs::read_to_string(dir.join("area.svg"))?;
/// assert!(svg.contains("seed 1"));                         // the legend's entry
/// assert_eq!(Corner::default(), Corner::UpperLeft);
/// std::fs::remove_dir_all(&dir)?;
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum Corner {
    /// Upper left (the default).
    #[default]
    UpperLeft,
    /// Upper right.
    UpperRight,
    /// Lower left.
    LowerLeft,
    /// Lower right.
    LowerRight,
}

/// How a chart colours its series: categorical colours for unordered things (drives,
/// observables, samples), a sequential map for an ordered family (the same curve at
/// increasing loads, cell sizes, heights or normal loads), so that the order of the
/// curves reads from their colours.
///
/// ```
/// use precursors::plot::{Chart, Colours};
/// let dir = std::env::temp_dir().join(format!("precursors-doc-{}", std::process::id()));
/// std::fs::create_dir_all(&dir)?;
/// // The shear traction profile φ_x(x) (kPa) at three increasing loads: dark to green.
/// let profile = |f: f64| -> Vec<(f64, f64)> {
///     (0..=20).map(|k| (k as f64 / 20.0, f * (-4.0 * k as f64 / 20.0).exp())).collect()
/// };
/// Chart::new("Shear traction", "x/Lx", "φ_x (kPa)")
///     .line("F = 10 N", &profile(1.0))
///     .line("F = 20 N", &profile(2.0))
///     .line("F = 30 N", &profile(3.0))
///     .colours(Colours::Ordered)
///     .save(dir.join("profiles.svg"))?;
/// let svg = std::fs::read_to_string(dir.join("profiles.svg"))?;
/// // viridis from its first colour (#440154) to its three-quarter point (#5EC962).
/// assert!(svg.contains("#440154") && svg.contains("#5EC962"));
/// assert_eq!(Colours::default(), Colours::Distinct);           // Tableau 10 in turn
/// std::fs::remove_dir_all(&dir)?;
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum Colours {
    /// Ten distinct colours in turn (the default): unordered series.
    #[default]
    Distinct,
    /// A sequential map for an ordered family of curves, first series to last: viridis
    /// (perceptually uniform, readable in grey and by colour-blind readers) from its dark
    /// end to its three-quarter point, which stays visible on white (its yellow end would
    /// not).
    Ordered,
}

/// viridis (matplotlib's, van der Walt and Smith) at `t = 0, 1/8, ..., 1`.
const VIRIDIS: [[f64; 3]; 9] = [
    [68.0, 1.0, 84.0],
    [71.0, 45.0, 123.0],
    [59.0, 82.0, 139.0],
    [44.0, 114.0, 142.0],
    [33.0, 145.0, 140.0],
    [40.0, 174.0, 128.0],
    [94.0, 201.0, 98.0],
    [173.0, 220.0, 48.0],
    [253.0, 231.0, 37.0],
];

/// Where an ordered family's last series sits on viridis.
const ORDERED_END: f64 = 0.75;

/// The colour of series `k` of `n` coloured by `colours`.
fn series_colour(colours: Colours, k: usize, n: usize) -> RGBColor {
    match colours {
        Colours::Distinct => DISTINCT[k % DISTINCT.len()],
        Colours::Ordered => {
            let t = if n > 1 {
                k as f64 / (n - 1) as f64
            } else {
                0.0
            };
            gradient(VIRIDIS, ORDERED_END * t)
        }
    }
}

/// How one series of a [`Chart`] is drawn ([`Chart::style`]): by default in the chart's
/// colouring ([`Colours`]), solid. A reference curve, say a zero line or a published
/// value, is typically grey and dashed:
/// `Style::new().colour(120, 120, 120).dashed()`.
///
/// ```
/// use precursors::plot::{Chart, PlotError, Style};
/// let dir = std::env::temp_dir().join(format!("precursors-doc-{}", std::process::id()));
/// std::fs::create_dir_all(&dir)?;
/// let ell = [(0.0, 0.0), (0.4, 0.1), (0.8, 0.5), (1.0, 1.0)];      // (F/(μF_N), ℓ/Lx)
/// Chart::new("Precursor length", "F/(μF_N)", "ℓ/Lx")
///     .steps("model", &ell)
///     .line("slip at ℓ = Lx", &[(0.0, 1.0), (1.0, 1.0)])
///     .style(Style::new().colour(120, 120, 120).dashed())           // grey, dashed
///     .save(dir.join("length.svg"))?;
/// let svg = std::fs::read_to_string(dir.join("length.svg"))?;
/// // The reference is grey (#787878); the model keeps the first colour (#1F77B4).
/// assert!(svg.contains("#787878") && svg.contains("#1F77B4"));
/// // Dashes are for lines: dashed markers are refused.
/// let e = Chart::new("Precursor length", "F/(μF_N)", "ℓ/Lx")
///     .markers("model", &ell)
///     .style(Style::new().dashed())
///     .save(dir.join("refused.svg"))
///     .unwrap_err();
/// assert!(matches!(e, PlotError::Figure { .. }));
/// std::fs::remove_dir_all(&dir)?;
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub struct Style {
    colour: Option<RGBColor>,
    dashed: bool,
}

impl Style {
    /// The default: the chart's colouring, a solid line.
    pub fn new() -> Self {
        Self::default()
    }

    /// A fixed colour (red, green, blue from 0 to 255). Series with a fixed colour are
    /// left out of the chart's colouring: the others keep their colours in turn (or
    /// their places on the [`Colours::Ordered`] gradient).
    pub fn colour(mut self, red: u8, green: u8, blue: u8) -> Self {
        self.colour = Some(RGBColor(red, green, blue));
        self
    }

    /// A dashed line (lines, staircases and bands' mean curves; refused on markers).
    pub fn dashed(mut self) -> Self {
        self.dashed = true;
        self
    }
}

/// The colour scale of a [`Map`].
///
/// ```
/// use precursors::plot::{Map, Palette};
/// let dir = std::env::temp_dir().join(format!("precursors-doc-{}", std::process::id()));
/// std::fs::create_dir_all(&dir)?;
/// // A signed shear stress τ (kPa) on 3 x 1 cells, centred on zero by the range.
/// Map::new(3, 1, vec![-2.0, 0.0, 2.0])?
///     .labels("Shear stress", "x (mm)", "y (mm)", "τ (kPa)")
///     .x_range(0.0, 3.0)
///     .colour_scale(Palette::Diverging, Some((-2.0, 2.0)))
///     .save(dir.join("tau.svg"))?;
/// let svg = std::fs::read_to_string(dir.join("tau.svg"))?;
/// // Blue at -2 kPa, white at 0, red at +2 kPa.
/// assert!(svg.contains("#2166AC") && svg.contains("#F7F7F7") && svg.contains("#B2182B"));
/// std::fs::remove_dir_all(&dir)?;
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum Palette {
    /// Blue (low) through white to red (high): signed quantities, centred on zero by the
    /// range given.
    Diverging,
    /// White (low) through blue to dark (high): quantities from zero up.
    Sequential,
}

impl Palette {
    /// The colour of `t ∈ [0, 1]` (clamped: values outside the map's range take the end
    /// colours, as the colour bar shows).
    fn colour(self, t: f64) -> RGBColor {
        let t = t.clamp(0.0, 1.0);
        match self {
            Palette::Diverging => gradient(
                [
                    [33.0, 102.0, 172.0],
                    [247.0, 247.0, 247.0],
                    [178.0, 24.0, 43.0],
                ],
                t,
            ),
            Palette::Sequential => gradient(
                [
                    [255.0, 255.0, 217.0],
                    [65.0, 182.0, 196.0],
                    [8.0, 29.0, 88.0],
                ],
                t,
            ),
        }
    }
}

/// The size (1/150 inch) and the PNGs' resolution every figure of a directory is drawn at.
#[derive(Debug, Clone, Copy)]
struct Canvas {
    size: (u32, u32),
    dpi: u32,
}

impl Canvas {
    /// An empty chart of this size and resolution.
    fn chart(self, title: &str, x_label: &str, y_label: &str) -> Chart {
        Chart::new(title, x_label, y_label)
            .size(self.size.0, self.size.1)
            .dpi(self.dpi)
    }
}

/// How a sweep's points (each its axes' values) are coloured and in which order they are
/// drawn: along the sequential map ([`Colours::Ordered`]), sorted by their values, when
/// every axis that differs between them holds numbers and they rise or fall together
/// along all of them (one axis, or axes zipped as Ly and Lz of the Fig. 6c study); else
/// distinct colours in the sweep's order (a product of axes, a kind of drive).
fn point_order(points: &[&[(String, String)]]) -> (Colours, Vec<usize>) {
    let given = (Colours::Distinct, (0..points.len()).collect());
    let Some(first) = points.first() else {
        return given;
    };
    let same_keys = points
        .iter()
        .all(|p| p.len() == first.len() && p.iter().zip(first.iter()).all(|(a, b)| a.0 == b.0));
    if !same_keys {
        return given;
    }
    let mut columns: Vec<Vec<f64>> = Vec::new();
    for axis in 0..first.len() {
        if points.iter().all(|p| p[axis].1 == first[axis].1) {
            continue;
        }
        let values: Option<Vec<f64>> = points
            .iter()
            .map(|p| p[axis].1.parse::<f64>().ok().filter(|v| v.is_finite()))
            .collect();
        match values {
            Some(values) => columns.push(values),
            None => return given,
        }
    }
    let Some(lead) = columns.first() else {
        return given;
    };
    let mut order: Vec<usize> = (0..points.len()).collect();
    order.sort_by(|&a, &b| lead[a].total_cmp(&lead[b]));
    let monotone = |column: &Vec<f64>, strict: bool| {
        let steps: Vec<f64> = order
            .windows(2)
            .map(|w| column[w[1]] - column[w[0]])
            .collect();
        let rising = steps
            .iter()
            .all(|d| if strict { *d > 0.0 } else { *d >= 0.0 });
        rising || (!strict && steps.iter().all(|d| *d <= 0.0))
    };
    if monotone(lead, true) && columns.iter().all(|c| monotone(c, false)) {
        (Colours::Ordered, order)
    } else {
        given
    }
}

/// The colour at `t ∈ [0, 1]` of the gradient through `N` evenly spaced stops.
fn gradient<const N: usize>(stops: [[f64; 3]; N], t: f64) -> RGBColor {
    let at = t.clamp(0.0, 1.0) * (N - 1) as f64;
    let k = (at.floor() as usize).min(N.saturating_sub(2));
    let s = at - k as f64;
    let (a, b) = (stops[k], stops[(k + 1).min(N - 1)]);
    RGBColor(
        (a[0] + (b[0] - a[0]) * s).round() as u8,
        (a[1] + (b[1] - a[1]) * s).round() as u8,
        (a[2] + (b[2] - a[2]) * s).round() as u8,
    )
}

/// Dash and gap lengths (pixels) of a dashed line.
const DASH: u32 = 9;
const GAP: u32 = 6;

/// Ten distinct line colours (Tableau 10).
const DISTINCT: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

#[derive(Debug, Clone, Copy, PartialEq)]
enum Kind {
    Line,
    Steps,
    Markers,
}

#[derive(Debug, Clone)]
struct Series {
    label: String,
    kind: Kind,
    points: Vec<(f64, f64)>,
    /// `(x, lower, upper)`: a shaded band under the line.
    band: Vec<(f64, f64, f64)>,
    /// `(x, lower, upper)`: a vertical error bar at each marker ([`Chart::error_bars`]).
    errors: Vec<(f64, f64, f64)>,
    style: Style,
}

/// A line chart: lines, staircases, markers and shaded bands over linear axes, with a
/// title, axis labels (give the units in them, e.g. `"x (mm)"`), tick values and a legend
/// of the labelled series.
///
/// ```
/// use precursors::plot::{Chart, Corner};
/// let dir = std::env::temp_dir().join(format!("precursors-doc-{}", std::process::id()));
/// std::fs::create_dir_all(&dir)?;
/// // ℓ/Lx at the stable states of a run (a staircase) with its 95 % band from a sweep.
/// let ell = [(0.0, 0.0), (0.6, 0.1), (0.8, 0.3), (0.95, 0.7), (1.0, 1.0)];
/// let band: Vec<_> = ell.iter().map(|&(f, l)| (f, l, 0.8 * l, 1.2 * l)).collect();
/// Chart::new("Precursor length", "F/(μF_N)", "ℓ/Lx")
///     .x_range(0.0, 1.0)
///     .y_range(0.0, 1.2)
///     .size(640, 480)
///     .band("mean over seeds, 95 %", &band)
///     .steps("seed 1", &ell)
///     .legend(Corner::UpperLeft)
///     .save(dir.join("precursors.png"))?;
/// let png = std::fs::read(dir.join("precursors.png"))?;
/// assert_eq!(&png[1..4], b"PNG");                              // PNG, 640 x 480 pixels
/// let width = u32::from_be_bytes([png[16], png[17], png[18], png[19]]);
/// let height = u32::from_be_bytes([png[20], png[21], png[22], png[23]]);
/// assert_eq!((width, height), (640, 480));
/// std::fs::remove_dir_all(&dir)?;
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone)]
pub struct Chart {
    title: String,
    x_label: String,
    y_label: String,
    x_range: Option<(f64, f64)>,
    y_range: Option<(f64, f64)>,
    size: (u32, u32),
    legend: Corner,
    colours: Colours,
    series: Vec<Series>,
    /// [`Chart::style`] was called with no series to apply to (refused by `save`).
    orphan_style: bool,
    /// Logarithmic x and y axes ([`Chart::log_x`], [`Chart::log_y`]).
    log: (bool, bool),
    /// Lines of text under the legend's entries ([`Chart::note`]).
    notes: Vec<String>,
    /// The PNG's resolution ([`Chart::dpi`]).
    dpi: u32,
}

impl Chart {
    /// An empty chart: 800 x 560 pixels, ranges fitted to the data, legend upper left.
    pub fn new(title: &str, x_label: &str, y_label: &str) -> Self {
        Self {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            x_range: None,
            y_range: None,
            size: (800, 560),
            legend: Corner::UpperLeft,
            colours: Colours::Distinct,
            series: Vec::new(),
            orphan_style: false,
            log: (false, false),
            notes: Vec::new(),
            dpi: DEFAULT_DPI,
        }
    }

    /// A logarithmic x axis (base 10, for values spanning decades: a distribution's
    /// sizes, a relative growth): ticks at the powers of ten, labelled `10⁻³`, `10⁰`,
    /// `10²` (over less than two decades at 1, 2 and 5 times them: `2×10⁻¹`), a light
    /// grid line at 2 and 5 times each; points with `x ≤ 0` are not drawn; a range given
    /// by [`Chart::x_range`] is in the data's units and must be positive. Give the
    /// quantity in the axis label, not its logarithm: `"S"`, not `"log₁₀ S"`.
    ///
    /// ```
    /// use precursors::plot::Chart;
    /// let dir = std::env::temp_dir().join(format!("precursors-doc-log-{}", std::process::id()));
    /// std::fs::create_dir_all(&dir)?;
    /// // P(S) ∝ S^-2 over three decades, on log-log axes.
    /// let p: Vec<(f64, f64)> = (0..=30).map(|k| 10f64.powf(k as f64 / 10.0))
    ///     .map(|s| (s, s.powi(-2))).collect();
    /// Chart::new("P(S)", "S", "P(S)").log_x().log_y().line("S^-2", &p)
    ///     .save(dir.join("p.svg"))?;
    /// let svg = std::fs::read_to_string(dir.join("p.svg"))?;
    /// let texts: Vec<&str> = svg.split("<text").skip(1)
    ///     .filter_map(|t| t.split_once('>')?.1.split_once("</text>").map(|x| x.0.trim()))
    ///     .collect();
    /// // The decades: 10⁰ to 10³ along x, 10⁻⁶ to 10⁰ along y.
    /// for decade in ["10⁰", "10¹", "10²", "10³", "10⁻⁶", "10⁻³"] {
    ///     assert!(texts.contains(&decade), "{decade} not in {texts:?}");
    /// }
    /// // A range on a log axis must be positive.
    /// assert!(Chart::new("t", "x", "y").log_x().x_range(0.0, 1.0).line("", &p)
    ///     .save(dir.join("bad.svg")).is_err());
    /// std::fs::remove_dir_all(&dir)?;
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn log_x(mut self) -> Self {
        self.log.0 = true;
        self
    }

    /// A logarithmic y axis (as [`Chart::log_x`]).
    pub fn log_y(mut self) -> Self {
        self.log.1 = true;
        self
    }

    /// The x axis spans `[low, high]` (in the data's units) instead of the data's extent.
    pub fn x_range(mut self, low: f64, high: f64) -> Self {
        self.x_range = Some((low, high));
        self
    }

    /// The y axis spans `[low, high]` instead of the data's extent.
    pub fn y_range(mut self, low: f64, high: f64) -> Self {
        self.y_range = Some((low, high));
        self
    }

    /// The picture's size in pixels at 150 dpi, that is in 1/150 inch (800 x 560: 5.33 x
    /// 3.73 inches); the SVG's user units, and a PNG's pixels at the default resolution
    /// ([`Chart::dpi`]).
    pub fn size(mut self, width: u32, height: u32) -> Self {
        self.size = (width, height);
        self
    }

    /// The PNG's resolution in dots per inch (default 150): the picture keeps its size in
    /// inches ([`Chart::size`]) and everything on it (text, lines, markers) its size
    /// relative to the picture, drawn with `dpi/150` times as many pixels along each side
    /// (800 x 560 at 300 dpi: 1600 x 1120 pixels). An SVG is drawn in its user units,
    /// whatever the resolution. [`Chart::save`] refuses a resolution outside 50 to 1200.
    ///
    /// ```
    /// use precursors::plot::{Chart, PlotError};
    /// let dir = std::env::temp_dir().join(format!("precursors-doc-dpi-{}", std::process::id()));
    /// std::fs::create_dir_all(&dir)?;
    /// let line = [(0.0, 0.0), (1.0, 1.0)];
    /// Chart::new("t", "x", "y").line("", &line).dpi(300).save(dir.join("print.png"))?;
    /// let png = std::fs::read(dir.join("print.png"))?;
    /// let width = u32::from_be_bytes([png[16], png[17], png[18], png[19]]);
    /// assert_eq!(width, 1600);                        // 800 · 300/150
    /// let e = Chart::new("t", "x", "y").dpi(20).save(dir.join("coarse.png")).unwrap_err();
    /// assert!(matches!(e, PlotError::InvalidDpi { dpi: 20, .. }));
    /// std::fs::remove_dir_all(&dir)?;
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn dpi(mut self, dpi: u32) -> Self {
        self.dpi = dpi;
        self
    }

    /// A line of text under the legend's entries (no glyph): what holds for several
    /// series, said once instead of in each entry ("no interval below 6 runs"). Notes
    /// are drawn in the order given, in the legend's box (with no entries, alone in it).
    ///
    /// ```
    /// use precursors::plot::Chart;
    /// let dir = std::env::temp_dir().join(format!("precursors-doc-note-{}", std::process::id()));
    /// std::fs::create_dir_all(&dir)?;
    /// // ℓ/Lx of two seeds, rising as the load to the fourth power.
    /// let seed = |s: f64| -> Vec<(f64, f64)> {
    ///     (0..=10).map(|k| (k as f64 / 10.0, s * (k as f64 / 10.0).powi(4))).collect()
    /// };
    /// Chart::new("Precursor length", "F/(μF_N)", "ℓ/Lx")
    ///     .line("seed 1", &seed(1.0))
    ///     .line("seed 2", &seed(0.8))
    ///     .note("no interval below 6 runs")
    ///     .save(dir.join("note.svg"))?;
    /// let svg = std::fs::read_to_string(dir.join("note.svg"))?;
    /// // The note comes after the entries, in the same box...
    /// let at = |text: &str| svg.find(text).unwrap_or_else(|| panic!("{text} not drawn"));
    /// assert!(at("seed 2") < at("no interval below 6 runs"));
    /// // ...and has no glyph: two sample lines (3 pixels wide), the entries'.
    /// assert_eq!(svg.matches("stroke-width=\"3\"").count(), 2);
    /// std::fs::remove_dir_all(&dir)?;
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn note(mut self, text: &str) -> Self {
        self.notes.push(text.into());
        self
    }

    /// Where the legend goes: in `corner` of the plotting area, unless its box would cover
    /// drawn data there (a line or a staircase, the edge of a band, a marker, an error
    /// bar, within 3 pixels of their drawn width); then in the first corner, in the order
    /// upper left, upper right, lower left, lower right, where it covers none. Where it
    /// would cover data in every corner, it goes below the plotting area (under the x
    /// axis's label, the plotting area shrunk to make room) as long as the plotting area
    /// keeps half its height; else in the corner where it covers the least (`corner` on
    /// ties).
    pub fn legend(mut self, corner: Corner) -> Self {
        self.legend = corner;
        self
    }

    /// How the series are coloured.
    pub fn colours(mut self, colours: Colours) -> Self {
        self.colours = colours;
        self
    }

    fn push(mut self, label: &str, kind: Kind, points: Vec<(f64, f64)>) -> Self {
        self.series.push(Series {
            label: label.into(),
            kind,
            points,
            band: Vec::new(),
            errors: Vec::new(),
            style: Style::default(),
        });
        self
    }

    /// Draws the series added last with `style` (a fixed colour, a dashed line):
    /// `chart.line("paper", &points).style(Style::new().dashed())`. Called before any
    /// series, [`Chart::save`] refuses the chart.
    pub fn style(mut self, style: Style) -> Self {
        match self.series.last_mut() {
            Some(series) => series.style = style,
            None => self.orphan_style = true,
        }
        self
    }

    /// A polyline through `points`; `label` goes into the legend (none if empty).
    pub fn line(self, label: &str, points: &[(f64, f64)]) -> Self {
        self.push(label, Kind::Line, points.to_vec())
    }

    /// A staircase: each value holds until the next point's x, where it jumps (a quantity
    /// known at discrete states, like ℓ at the stable states of a run).
    pub fn steps(self, label: &str, points: &[(f64, f64)]) -> Self {
        self.push(label, Kind::Steps, points.to_vec())
    }

    /// Markers at `points`, no line.
    pub fn markers(self, label: &str, points: &[(f64, f64)]) -> Self {
        self.push(label, Kind::Markers, points.to_vec())
    }

    /// Markers at `(x, y)` with vertical error bars from `lower` to `upper`: `(x, y, lower,
    /// upper)` (a density and its counting interval). Each bar is a line in the markers'
    /// colour with a short cap at each end; a `lower` that is not finite, or not positive
    /// on a logarithmic axis (the interval of a bin of one sample, `1 ± 1/√1`), runs the
    /// bar down to the bottom of the chart, without a cap there.
    ///
    /// ```
    /// use precursors::plot::Chart;
    /// let dir = std::env::temp_dir().join(format!("precursors-doc-bars-{}", std::process::id()));
    /// std::fs::create_dir_all(&dir)?;
    /// // P(S) at two sizes with the counting interval P (1 ± 1/√count): 25 and 1 samples.
    /// let rows = [(1.0, 0.5, 0.4, 0.6), (10.0, 0.01, 0.0, 0.02)];
    /// Chart::new("P(S)", "S", "P(S)").log_x().log_y().error_bars("counts", &rows)
    ///     .save(dir.join("bars.svg"))?;
    /// let svg = std::fs::read_to_string(dir.join("bars.svg"))?;
    /// assert!(svg.contains("counts"));
    /// // Two markers (radius 3) and, in their colour, one pixel wide: two bars, two caps
    /// // on the first and one on the second (its lower end, 0, is off the log axis).
    /// assert_eq!(svg.matches("r=\"3\"").count(), 2);
    /// let thin = svg.matches("stroke=\"#1F77B4\" stroke-width=\"1\"").count();
    /// assert_eq!(thin, 2 + 3);
    /// std::fs::remove_dir_all(&dir)?;
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn error_bars(self, label: &str, rows: &[(f64, f64, f64, f64)]) -> Self {
        let mut chart = self.push(
            label,
            Kind::Markers,
            rows.iter().map(|r| (r.0, r.1)).collect(),
        );
        if let Some(s) = chart.series.last_mut() {
            s.errors = rows.iter().map(|r| (r.0, r.2, r.3)).collect();
        }
        chart
    }

    /// A mean curve with its band: `(x, mean, lower, upper)`; the band is shaded in the
    /// line's colour.
    pub fn band(self, label: &str, rows: &[(f64, f64, f64, f64)]) -> Self {
        let mut chart = self.push(label, Kind::Line, rows.iter().map(|r| (r.0, r.1)).collect());
        if let Some(s) = chart.series.last_mut() {
            s.band = rows.iter().map(|r| (r.0, r.2, r.3)).collect();
        }
        chart
    }

    /// The colour of series `index`: its own, or its turn among the series without one.
    fn colour(&self, index: usize) -> RGBColor {
        if let Some(colour) = self.series[index].style.colour {
            return colour;
        }
        let auto = |s: &&Series| s.style.colour.is_none();
        let k = self.series[..index].iter().filter(auto).count();
        let n = self.series.iter().filter(auto).count();
        series_colour(self.colours, k, n)
    }

    /// Writes the chart to `path`: PNG for `.png`, SVG for `.svg`.
    ///
    /// # Errors
    /// [`PlotError::Figure`] for another extension, an axis range that is not finite and
    /// increasing, a size outside 200 x 150 to 16384 x 16384, a [`Style`] given before any
    /// series or a dashed style on markers, a PNG of more than 16384 pixels along a side at
    /// its resolution, or a drawing backend that fails; [`PlotError::InvalidDpi`] for a
    /// resolution outside 50 to 1200 dpi ([`Chart::dpi`]);
    /// [`Error::Io`] (in [`PlotError::Core`]) when the file cannot be written (it is written atomically: no half
    /// file is left under its name).
    pub fn save(&self, path: impl AsRef<Path>) -> Result<()> {
        let path = path.as_ref();
        render(path, (self.size, self.dpi), &self.settled(path)?)
    }

    /// The chart checked and ready to draw ([`Chart::save`]'s refusals, `path` naming
    /// the figure in them): on logarithmic axes, its data in `log10`.
    fn settled(&self, path: &Path) -> Result<ChartDrawing<'_>> {
        let refuse = |reason: String| PlotError::Figure {
            path: Some(path.to_path_buf()),
            reason,
        };
        if self.orphan_style {
            return Err(refuse(
                "Chart::style was called before any series: it styles the series added last".into(),
            ));
        }
        if let Some(s) = self
            .series
            .iter()
            .find(|s| s.kind == Kind::Markers && s.style.dashed)
        {
            return Err(refuse(format!(
                "the markers '{}' have a dashed style: dashes apply to lines only",
                s.label
            )));
        }
        if self.log.0 || self.log.1 {
            // Drawn in log10 of the data: a value <= 0 becomes NaN and is left out.
            let (lx, ly) = (axis_map(self.log.0), axis_map(self.log.1));
            let ranges = [
                (self.x_range, lx, "x", self.log.0),
                (self.y_range, ly, "y", self.log.1),
            ];
            for (range, _, axis, log) in ranges {
                if let (Some((low, high)), true) = (range, log) {
                    if !(low > 0.0 && high > low && high.is_finite()) {
                        return Err(refuse(format!(
                            "the {axis} range [{low}, {high}] is invalid on a logarithmic \
                             axis: both ends must be finite and positive, the first below \
                             the second"
                        )));
                    }
                }
            }
            let mut drawn = self.clone();
            drawn.log = (false, false);
            drawn.x_range = self.x_range.map(|(a, b)| (lx(a), lx(b)));
            drawn.y_range = self.y_range.map(|(a, b)| (ly(a), ly(b)));
            for s in &mut drawn.series {
                s.points.iter_mut().for_each(|p| *p = (lx(p.0), ly(p.1)));
                s.band
                    .iter_mut()
                    .for_each(|b| *b = (lx(b.0), ly(b.1), ly(b.2)));
                s.errors
                    .iter_mut()
                    .for_each(|b| *b = (lx(b.0), ly(b.1), ly(b.2)));
            }
            let (x, y) = drawn.ranges(path)?;
            return Ok(ChartDrawing {
                chart: Cow::Owned(drawn),
                x,
                y,
                log: self.log,
            });
        }
        let (x, y) = self.ranges(path)?;
        Ok(ChartDrawing {
            chart: Cow::Borrowed(self),
            x,
            y,
            log: (false, false),
        })
    }

    /// The axis ranges: given, or fitted to the data.
    fn ranges(&self, path: &Path) -> Result<((f64, f64), (f64, f64))> {
        let xs = self
            .series
            .iter()
            .flat_map(|s| s.points.iter().map(|p| p.0));
        let x = axis_range(path, "x", self.x_range, xs)?;
        let ys = self.series.iter().flat_map(|s| {
            s.points
                .iter()
                .map(|p| p.1)
                .chain(s.band.iter().flat_map(|b| [b.1, b.2]))
                .chain(s.errors.iter().flat_map(|b| [b.1, b.2]))
        });
        let y = axis_range(path, "y", self.y_range, ys)?;
        Ok((x, y))
    }
}

/// The map of a value onto a drawn axis: `log10` (NaN for `v <= 0`) on a logarithmic
/// axis, the value itself otherwise.
fn axis_map(log: bool) -> fn(f64) -> f64 {
    if log {
        |v| if v > 0.0 { v.log10() } else { f64::NAN }
    } else {
        |v| v
    }
}

/// A chart with its axis ranges settled.
struct ChartDrawing<'a> {
    chart: Cow<'a, Chart>,
    x: (f64, f64),
    y: (f64, f64),
    /// Whether the axes show `log10` of the data (their ticks then print `10^v`).
    log: (bool, bool),
}

impl Draw for ChartDrawing<'_> {
    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
    ) -> std::result::Result<(), String> {
        let (me, x, y) = (&*self.chart, self.x, self.y);
        // The legend's place is settled on the plotting area before anything is drawn
        // (building the coordinates draws nothing): a legend put below it shrinks it.
        let top = measured_title_room(root, &me.title)?;
        let (columns, rows) = frame(root, top, x, y, 0)?.plotting_area().get_pixel_range();
        let entries = me.legend_entries();
        let layout = legend_layout(root, columns.end - columns.start, &entries, &me.notes)?;
        let placement = match &layout {
            Some(layout) => {
                let ink = me.ink(((x, y), (&columns, &rows)));
                place(me.legend, layout.size, (&columns, &rows), &ink)
            }
            None => Placement::Corner(me.legend),
        };
        let below = match (&layout, placement) {
            (Some(layout), Placement::Below) => (layout.size.1 + 2 * LEGEND_GAP) as u32,
            _ => 0,
        };
        typeset_title(root, &me.title)?;
        let mut chart = frame(root, top, x, y, below)?;
        draw_axes(
            root,
            &mut chart,
            (&me.x_label, x),
            (&me.y_label, y),
            (true, self.log),
        )?;
        for (k, s) in me.series.iter().enumerate() {
            let colour = me.colour(k);
            for run in finite_runs(&s.band, |b| [b.0, b.1, b.2]) {
                let mut outline: Vec<(f64, f64)> = run.iter().map(|b| (b.0, b.2)).collect();
                outline.extend(run.iter().rev().map(|b| (b.0, b.1)));
                chart
                    .draw_series(std::iter::once(Polygon::new(
                        outline,
                        colour.mix(0.22).filled(),
                    )))
                    .map_err(|e| e.to_string())?;
            }
            let style = colour.stroke_width(2);
            if s.kind == Kind::Markers {
                let points = s
                    .points
                    .iter()
                    .filter(|p| p.0.is_finite() && p.1.is_finite());
                chart
                    .draw_series(points.map(|p| Circle::new(*p, 3, colour.filled())))
                    .map_err(|e| e.to_string())?;
                draw_error_bars(&mut chart, &s.errors, y.0, colour)?;
                continue;
            }
            for run in finite_runs(&s.points, |p| [p.0, p.1]) {
                let line = if s.kind == Kind::Steps {
                    staircase(run)
                } else {
                    run.to_vec()
                };
                if s.style.dashed {
                    chart.draw_series(DashedLineSeries::new(line, DASH, GAP, style))
                } else {
                    chart.draw_series(LineSeries::new(line, style))
                }
                .map_err(|e| e.to_string())?;
            }
        }
        if let Some(layout) = layout {
            let (columns, rows) = chart.plotting_area().get_pixel_range();
            let at = match placement {
                Placement::Corner(corner) => corner_box(corner, layout.size, (&columns, &rows)).0,
                Placement::Below => (columns.start, rows.end + X_LABEL_AREA + LEGEND_GAP),
            };
            // The pixel ranges are the picture's; the legend is drawn on `root`, a
            // panel's area away from the picture's origin.
            let (base_x, base_y) = root.get_base_pixel();
            draw_legend(root, &layout, (at.0 - base_x, at.1 - base_y))?;
        }
        Ok(())
    }
}

/// Charts side by side under one title and its notes: a grid of panels, each a chart
/// with its own title, axes and legend, as many columns as `⌈√n⌉` for `n` charts, the
/// rows filled left to right. A sweep's distributions (`plot/distributions.rs`) take it
/// for many points, whose curves and legends one chart cannot hold.
#[derive(Debug, Clone)]
struct Panels {
    title: String,
    /// Lines under the title: what holds for every panel.
    notes: Vec<String>,
    charts: Vec<Chart>,
    /// A panel's size (1/150 inch), as a chart's ([`Chart::size`]): shrunk where the
    /// grid would pass the largest picture.
    panel: (u32, u32),
    dpi: u32,
}

impl Panels {
    /// The grid's columns and rows.
    fn grid(&self) -> (usize, usize) {
        let n = self.charts.len().max(1);
        let columns = (1..=n).find(|c| c * c >= n).unwrap_or(n);
        (columns, n.div_ceil(columns))
    }

    /// The room above the panels (1/150 inch): the title on one line or two, the notes.
    fn head(&self) -> u32 {
        title_room(1, TITLE_SIZE).max(title_room(2, WRAPPED_TITLE_SIZE))
            + self.notes.len() as u32 * NOTE_LINE
    }

    /// Writes the figure to `path` as [`Chart::save`] does (its refusals for each panel).
    fn save(&self, path: &Path) -> Result<()> {
        let (columns, rows) = self.grid();
        let head = self.head();
        // The largest side the resolution allows, in 1/150 inch.
        let largest = (u64::from(LARGEST_SIDE) * u64::from(DEFAULT_DPI)
            / u64::from(self.dpi.max(DEFAULT_DPI))) as u32;
        let panel = (
            self.panel.0.min(largest / columns as u32),
            self.panel.1.min(largest.saturating_sub(head) / rows as u32),
        );
        let panels = self
            .charts
            .iter()
            .map(|c| c.settled(path))
            .collect::<Result<Vec<_>>>()?;
        let size = (panel.0 * columns as u32, panel.1 * rows as u32 + head);
        render(
            path,
            (size, self.dpi),
            &PanelsDrawing {
                title: &self.title,
                notes: &self.notes,
                panels,
                grid: (columns, rows),
                head,
            },
        )
    }
}

/// Panels with their charts settled.
struct PanelsDrawing<'a> {
    title: &'a str,
    notes: &'a [String],
    panels: Vec<ChartDrawing<'a>>,
    grid: (usize, usize),
    head: u32,
}

impl Draw for PanelsDrawing<'_> {
    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
    ) -> std::result::Result<(), String> {
        let room = typeset_title(root, self.title)?;
        let (head, body) = root.split_vertically(self.head);
        let (_, notes) = head.split_vertically(room.min(self.head));
        draw_notes(&notes, self.notes)?;
        let areas = body.split_evenly((self.grid.1, self.grid.0));
        for (panel, area) in self.panels.iter().zip(&areas) {
            panel.draw(area)?;
        }
        Ok(())
    }
}

impl Chart {
    /// The legend's entries: each labelled series' label, glyph and colour.
    fn legend_entries(&self) -> Vec<(String, Glyph, RGBColor)> {
        self.series
            .iter()
            .enumerate()
            .filter(|(_, s)| !s.label.is_empty())
            .map(|(k, s)| {
                let glyph = if s.kind == Kind::Markers {
                    Glyph::Marker
                } else if s.style.dashed {
                    Glyph::Dashed
                } else {
                    Glyph::Line
                };
                (s.label.clone(), glyph, self.colour(k))
            })
            .collect()
    }

    /// What a legend must not cover ([`Ink`]) of this chart's series (in their drawn
    /// units: `log10` of the data on a logarithmic axis) on a plotting area of pixels
    /// `columns` x `rows` showing the ranges `x` x `y`: each line's and staircase's
    /// segments, the edges of each band, each marker and error bar.
    fn ink(&self, ((x, y), (columns, rows)): (Ranges, (&Range<i32>, &Range<i32>))) -> Vec<Ink> {
        let (left, width) = (
            f64::from(columns.start),
            f64::from(columns.end - columns.start),
        );
        let (bottom, height) = (f64::from(rows.end), f64::from(rows.end - rows.start));
        let at = |(u, v): (f64, f64)| {
            (
                left + (u - x.0) / (x.1 - x.0) * width,
                bottom - (v - y.0) / (y.1 - y.0) * height,
            )
        };
        let mut ink = Vec::new();
        let polyline = |points: &[(f64, f64)], half: f64, ink: &mut Vec<Ink>| {
            for pair in points.windows(2) {
                ink.push((at(pair[0]), at(pair[1]), half));
            }
        };
        for s in &self.series {
            for run in finite_runs(&s.band, |b| [b.0, b.1, b.2]) {
                let upper: Vec<(f64, f64)> = run.iter().map(|b| (b.0, b.2)).collect();
                let lower: Vec<(f64, f64)> = run.iter().map(|b| (b.0, b.1)).collect();
                polyline(&upper, 1.0, &mut ink);
                polyline(&lower, 1.0, &mut ink);
            }
            if s.kind == Kind::Markers {
                for &p in s
                    .points
                    .iter()
                    .filter(|p| p.0.is_finite() && p.1.is_finite())
                {
                    ink.push((at(p), at(p), 3.0));
                }
                for &(u, lower, upper) in s
                    .errors
                    .iter()
                    .filter(|e| e.0.is_finite() && e.2.is_finite())
                {
                    let low = if lower.is_finite() { lower } else { y.0 };
                    ink.push((at((u, low)), at((u, upper)), f64::from(CAP)));
                }
                continue;
            }
            for run in finite_runs(&s.points, |p| [p.0, p.1]) {
                let line = if s.kind == Kind::Steps {
                    staircase(run)
                } else {
                    run.to_vec()
                };
                polyline(&line, 1.0, &mut ink);
            }
        }
        ink
    }
}

/// A chart's axis ranges `(x, y)` in drawn units.
type Ranges = ((f64, f64), (f64, f64));

/// A piece of drawn data in the picture's pixels: a segment (a marker: one of zero
/// length) and the half width it is drawn with.
type Ink = ((f64, f64), (f64, f64), f64);

/// Where a legend goes ([`place`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Placement {
    /// In a corner of the plotting area.
    Corner(Corner),
    /// Under the plotting area and its x label, the plotting area shrunk to make room.
    Below,
}

/// The pixels a legend keeps clear of drawn data around its box.
const LEGEND_CLEARANCE: f64 = 3.0;
/// The gap (pixels) above and below a legend put under the plotting area, and the inset
/// of a legend from its corner of the plotting area.
const LEGEND_GAP: i32 = 5;

/// The top left corner and the far corner of a legend box of `size` in `corner` of the
/// plotting area of pixels `columns` x `rows`.
fn corner_box(
    corner: Corner,
    size: (i32, i32),
    (columns, rows): (&Range<i32>, &Range<i32>),
) -> ((i32, i32), (i32, i32)) {
    let left = match corner {
        Corner::UpperLeft | Corner::LowerLeft => columns.start + LEGEND_GAP,
        Corner::UpperRight | Corner::LowerRight => columns.end - size.0 - LEGEND_GAP,
    };
    let top = match corner {
        Corner::UpperLeft | Corner::UpperRight => rows.start + LEGEND_GAP,
        Corner::LowerLeft | Corner::LowerRight => rows.end - size.1 - LEGEND_GAP,
    };
    ((left, top), (left + size.0, top + size.1))
}

/// How many pieces of `ink` a legend box from `a` to `b` would cover (within
/// [`LEGEND_CLEARANCE`] of their drawn width).
fn covered(ink: &[Ink], (a, b): ((i32, i32), (i32, i32))) -> usize {
    ink.iter()
        .filter(|&&(p, q, half)| {
            let pad = half + LEGEND_CLEARANCE;
            let rect = [
                f64::from(a.0) - pad,
                f64::from(a.1) - pad,
                f64::from(b.0) + pad,
                f64::from(b.1) + pad,
            ];
            crosses(p, q, rect)
        })
        .count()
}

/// Whether the segment from `p` to `q` meets the rectangle `[x0, y0, x1, y1]`
/// (Liang-Barsky clipping: the segment's parameter interval inside each slab).
fn crosses(p: (f64, f64), q: (f64, f64), [x0, y0, x1, y1]: [f64; 4]) -> bool {
    let (dx, dy) = (q.0 - p.0, q.1 - p.1);
    let (mut enter, mut leave) = (0.0f64, 1.0f64);
    for (along, room) in [
        (-dx, p.0 - x0),
        (dx, x1 - p.0),
        (-dy, p.1 - y0),
        (dy, y1 - p.1),
    ] {
        if along == 0.0 {
            if room < 0.0 {
                return false;
            }
        } else if along < 0.0 {
            enter = enter.max(room / along);
        } else {
            leave = leave.min(room / along);
        }
    }
    enter <= leave
}

/// Where a legend box of `size` goes on the plotting area `plot` that shows `ink`: the
/// corner `asked` where it covers none of it, else the first corner that covers none in
/// the order upper left, upper right, lower left, lower right; where every corner would
/// cover data, below the plotting area, when the plotting area keeps at least half its
/// height; else the corner that covers the fewest pieces (`asked` first on ties).
fn place(
    asked: Corner,
    size: (i32, i32),
    plot: (&Range<i32>, &Range<i32>),
    ink: &[Ink],
) -> Placement {
    let mut order = vec![asked];
    for corner in [
        Corner::UpperLeft,
        Corner::UpperRight,
        Corner::LowerLeft,
        Corner::LowerRight,
    ] {
        if !order.contains(&corner) {
            order.push(corner);
        }
    }
    let counts: Vec<usize> = order
        .iter()
        .map(|&c| covered(ink, corner_box(c, size, plot)))
        .collect();
    if let Some(k) = counts.iter().position(|&n| n == 0) {
        return Placement::Corner(order[k]);
    }
    if 2 * (size.1 + 2 * LEGEND_GAP) <= plot.1.end - plot.1.start {
        return Placement::Below;
    }
    let fewest = (0..order.len()).min_by_key(|&k| counts[k]).unwrap_or(0);
    Placement::Corner(order[fewest])
}

/// The half width of an error bar's cap, in 1/150 inch.
const CAP: i32 = 4;

/// Vertical error bars `(x, lower, upper)` in the chart's drawn units: a line from
/// `lower` (or `bottom` where `lower` is not finite) to `upper`, a cap at each finite end.
fn draw_error_bars<DB: DrawingBackend>(
    chart: &mut ChartContext<'_, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    errors: &[(f64, f64, f64)],
    bottom: f64,
    colour: RGBColor,
) -> std::result::Result<(), String> {
    let style = colour.stroke_width(1);
    for &(x, lower, upper) in errors.iter().filter(|e| e.0.is_finite() && e.2.is_finite()) {
        let low = if lower.is_finite() { lower } else { bottom };
        chart
            .draw_series(std::iter::once(PathElement::new(
                vec![(x, low), (x, upper)],
                style,
            )))
            .map_err(|e| e.to_string())?;
        let ends = std::iter::once(upper).chain(lower.is_finite().then_some(lower));
        chart
            .draw_series(ends.map(|y| {
                EmptyElement::at((x, y)) + PathElement::new(vec![(-CAP, 0), (CAP, 0)], style)
            }))
            .map_err(|e| e.to_string())?;
    }
    Ok(())
}

/// A map of values on a regular grid of cells over `[x0, x1] x [y0, y1]`, with a colour
/// bar labelled with the quantity and its unit.
///
/// Values beyond the colour scale are drawn in its end colours (saturated): the bar then
/// carries a triangle in the end colour beyond each end the values pass, and a line under
/// the map gives the share of the cells beyond each end and the extreme value there
/// (`colour scale saturated: 3.1 % of the cells above 2.26 (up to 16.04)`). A map of
/// lengths ([`Map::same_unit_axes`]) states its aspect on that line.
///
/// ```
/// use precursors::plot::{Map, Palette, PlotError};
/// use precursors::Error;
/// let dir = std::env::temp_dir().join(format!("precursors-doc-{}", std::process::id()));
/// std::fs::create_dir_all(&dir)?;
/// // Real contact area per cell (µm²) of a 4 x 2 mm face, row 0 at y = 0.
/// let area = vec![0.0, 120.0, 340.0, 80.0, 10.0, 260.0, 500.0, 40.0];
/// Map::new(4, 2, area)?
///     .labels("Real contact area", "x (mm)", "y (mm)", "A_R (µm²)")
///     .x_range(0.0, 4.0)
///     .y_range(0.0, 2.0)
///     .colour_scale(Palette::Sequential, Some((0.0, 500.0)))     // 0 to 500 µm²
///     .save(dir.join("area.svg"))?;
/// let svg = std::fs::read_to_string(dir.join("area.svg"))?;
/// assert!(svg.contains("#FFFFD9") && svg.contains("#081D58")); // light at 0, dark at 500
/// // 7 values do not fill 4 x 2 cells.
/// let e = Map::new(4, 2, vec![0.0; 7]).unwrap_err();
/// assert!(matches!(e, PlotError::Core(Error::LengthMismatch { expected: 8, found: 7, .. })));
/// std::fs::remove_dir_all(&dir)?;
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone)]
pub struct Map {
    title: String,
    x_label: String,
    y_label: String,
    colour_label: String,
    columns: usize,
    rows: usize,
    values: Vec<f64>,
    x_range: (f64, f64),
    y_range: (f64, f64),
    colour_range: Option<(f64, f64)>,
    palette: Palette,
    size: (u32, u32),
    /// The rows' edges (`rows + 1` increasing values) when they are not evenly spaced
    /// over the y range (a movie's planes).
    row_edges: Option<Vec<f64>>,
    /// Lines drawn over the cells in black (a movie's precursor front), in axis units.
    overlay: Vec<Vec<(f64, f64)>>,
    /// Lines drawn over the cells in black dashes (the damage front over a contact map).
    dashed_overlay: Vec<Vec<(f64, f64)>>,
    /// Lines of text under the figure (a movie frame's scene line), above the line the
    /// map writes itself (saturation, aspect).
    notes: Vec<String>,
    /// The ends of the colour scale marked saturated on the bar (below, above) when not
    /// this map's own (a movie marks the ends its whole run saturates, on every frame).
    extend: Option<(bool, bool)>,
    /// Whether x and y are lengths in one unit: the figure then states its aspect.
    same_units: bool,
    /// The PNG's resolution ([`Map::dpi`]).
    dpi: u32,
}

impl Map {
    /// A map of `values`, `columns x rows` cells in row-major order, row 0 at the bottom
    /// (`values[r·columns + c]`), over the unit square until [`Map::x_range`] and
    /// [`Map::y_range`] say otherwise; sequential palette over the values' range.
    ///
    /// # Errors
    /// In [`PlotError::Core`]: [`Error::LengthMismatch`] when `values` does not hold
    /// `columns·rows` numbers, [`Error::InvalidCount`] for zero columns or rows.
    pub fn new(columns: usize, rows: usize, values: Vec<f64>) -> Result<Self> {
        for (name, n) in [("map columns", columns), ("map rows", rows)] {
            if n == 0 {
                return Err(Error::InvalidCount {
                    name,
                    value: 0,
                    reason: "a map needs at least one cell along each axis",
                }
                .into());
            }
        }
        let expected = columns.saturating_mul(rows);
        if values.len() != expected {
            return Err(Error::LengthMismatch {
                name: "map values",
                expected,
                found: values.len(),
            }
            .into());
        }
        Ok(Self {
            title: String::new(),
            x_label: String::new(),
            y_label: String::new(),
            colour_label: String::new(),
            columns,
            rows,
            values,
            x_range: (0.0, 1.0),
            y_range: (0.0, 1.0),
            colour_range: None,
            palette: Palette::Sequential,
            size: (900, 560),
            row_edges: None,
            overlay: Vec::new(),
            dashed_overlay: Vec::new(),
            notes: Vec::new(),
            extend: None,
            same_units: false,
            dpi: DEFAULT_DPI,
        })
    }

    /// The title and the labels of the axes and of the colour bar (with units).
    pub fn labels(mut self, title: &str, x: &str, y: &str, colour: &str) -> Self {
        self.title = title.into();
        self.x_label = x.into();
        self.y_label = y.into();
        self.colour_label = colour.into();
        self
    }

    /// The cells span `[low, high]` along x (the left edge of column 0 to the right edge
    /// of the last).
    pub fn x_range(mut self, low: f64, high: f64) -> Self {
        self.x_range = (low, high);
        self
    }

    /// The cells span `[low, high]` along y (the bottom edge of row 0 to the top edge of
    /// the last).
    pub fn y_range(mut self, low: f64, high: f64) -> Self {
        self.y_range = (low, high);
        self
    }

    /// The palette, and the values at its two ends (`None`: the finite values' range).
    pub fn colour_scale(mut self, palette: Palette, range: Option<(f64, f64)>) -> Self {
        self.palette = palette;
        self.colour_range = range;
        self
    }

    /// The picture's size in 1/150 inch, as [`Chart::size`].
    pub fn size(mut self, width: u32, height: u32) -> Self {
        self.size = (width, height);
        self
    }

    /// Says that x and y are lengths in the same unit (say mm, a face or a slab of the
    /// block): the line under the map then states how much the drawing stretches one
    /// against the other (`not to scale: y drawn 13.2 times stretched against x`), or
    /// that it is true to scale (within 5 %). Without it the axes are taken as
    /// different quantities (a position and a load) and no aspect is stated.
    ///
    /// ```
    /// use precursors::plot::Map;
    /// let dir = std::env::temp_dir().join(format!("precursors-doc-aspect-{}", std::process::id()));
    /// std::fs::create_dir_all(&dir)?;
    /// // A 40 x 2 mm face drawn in a 4:3 picture: y is stretched, and the map says so.
    /// let face = |map: Map| map.x_range(0.0, 40.0).y_range(0.0, 2.0).size(600, 450);
    /// face(Map::new(4, 2, vec![1.0; 8])?.same_unit_axes()).save(dir.join("face.svg"))?;
    /// let svg = std::fs::read_to_string(dir.join("face.svg"))?;
    /// assert!(svg.contains("not to scale: y drawn"));
    /// // Without it, no aspect is stated.
    /// face(Map::new(4, 2, vec![1.0; 8])?).save(dir.join("plain.svg"))?;
    /// assert!(!std::fs::read_to_string(dir.join("plain.svg"))?.contains("to scale"));
    /// std::fs::remove_dir_all(&dir)?;
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn same_unit_axes(mut self) -> Self {
        self.same_units = true;
        self
    }

    /// The PNG's resolution in dots per inch (default 150), as [`Chart::dpi`].
    ///
    /// ```
    /// use precursors::plot::{Map, PlotError};
    /// let dir = std::env::temp_dir().join(format!("precursors-doc-map-dpi-{}", std::process::id()));
    /// std::fs::create_dir_all(&dir)?;
    /// let map = Map::new(4, 2, vec![0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0])?.size(600, 450);
    /// map.clone().dpi(300).save(dir.join("print.png"))?;
    /// let png = std::fs::read(dir.join("print.png"))?;
    /// let width = u32::from_be_bytes([png[16], png[17], png[18], png[19]]);
    /// assert_eq!(width, 1200);                        // 600 · 300/150
    /// let e = map.dpi(20).save(dir.join("coarse.png")).unwrap_err();
    /// assert!(matches!(e, PlotError::InvalidDpi { dpi: 20, .. }));
    /// std::fs::remove_dir_all(&dir)?;
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn dpi(mut self, dpi: u32) -> Self {
        self.dpi = dpi;
        self
    }

    /// Writes the map to `path`: PNG for `.png`, SVG for `.svg`.
    ///
    /// # Errors
    /// [`PlotError::Figure`] for another extension, a range that is not finite and
    /// increasing, a size outside 200 x 150 to 16384 x 16384 (a PNG's pixels at its
    /// resolution too), or a drawing backend that fails; [`PlotError::InvalidDpi`] for a
    /// resolution outside 50 to 1200 dpi; [`Error::Io`] (in [`PlotError::Core`]) when the
    /// file cannot be written (atomically, as [`Chart::save`]).
    pub fn save(&self, path: impl AsRef<Path>) -> Result<()> {
        let path = path.as_ref();
        let x = axis_range(path, "x", Some(self.x_range), std::iter::empty())?;
        let y = axis_range(path, "y", Some(self.y_range), std::iter::empty())?;
        let c = axis_range(
            path,
            "colour",
            self.colour_range,
            self.values.iter().copied(),
        )?;
        render(
            path,
            (self.size, self.dpi),
            &MapDrawing { map: self, x, y, c },
        )
    }
}

/// A map with its ranges settled.
struct MapDrawing<'a> {
    map: &'a Map,
    x: (f64, f64),
    y: (f64, f64),
    c: (f64, f64),
}

impl Draw for MapDrawing<'_> {
    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
    ) -> std::result::Result<(), String> {
        let (me, x, y) = (self.map, self.x, self.y);
        let (width, height) = root.dim_in_pixel();
        // Room under the figure for its notes and its own line (saturation, aspect).
        let saturation = self.saturation_note();
        let own = u32::from(saturation.is_some() || me.same_units);
        let lines = me.notes.len() as u32 + own;
        let footer = if lines == 0 {
            0
        } else {
            (lines * NOTE_LINE + 6).min(height / 4)
        };
        let (upper, under) = root.split_vertically(height - footer);
        let bar_width = 130.min(width / 3);
        let (main, bar) = upper.split_horizontally(width - bar_width);
        let mut chart = axes(&main, &me.title, x, y)?;
        self.draw_cells(&mut chart)?;
        for line in &me.overlay {
            chart
                .draw_series(std::iter::once(PathElement::new(
                    line.clone(),
                    BLACK.stroke_width(3),
                )))
                .map_err(|e| e.to_string())?;
        }
        for line in &me.dashed_overlay {
            chart
                .draw_series(DashedLineSeries::new(
                    line.clone(),
                    DASH,
                    GAP,
                    BLACK.stroke_width(3),
                ))
                .map_err(|e| e.to_string())?;
        }
        draw_axes(
            &main,
            &mut chart,
            (&me.x_label, x),
            (&me.y_label, y),
            (false, (false, false)),
        )?;
        let (columns, rows) = chart.plotting_area().get_pixel_range();
        // The bar's top level with the map's, under a title of one line or two.
        self.draw_colour_bar(&bar, rows.start.max(0) as u32)?;
        let plot = (columns.end - columns.start, rows.end - rows.start);
        let mut notes = me.notes.clone();
        notes.push(
            [saturation, self.aspect_note(plot)]
                .into_iter()
                .flatten()
                .collect::<Vec<_>>()
                .join("; "),
        );
        draw_notes(&under, &notes)
    }
}

/// The height of a line of notes under a map (pixels).
const NOTE_LINE: u32 = 19;

impl MapDrawing<'_> {
    /// The cells, each in its colour on the scale (grey where not finite).
    fn draw_cells<DB: DrawingBackend>(
        &self,
        chart: &mut ChartContext<'_, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    ) -> std::result::Result<(), String> {
        let (me, x, y, c) = (self.map, self.x, self.y, self.c);
        let (dx, dy) = (
            (x.1 - x.0) / me.columns as f64,
            (y.1 - y.0) / me.rows as f64,
        );
        let grey = RGBColor(200, 200, 200);
        chart
            .draw_series((0..me.rows).flat_map(|r| {
                (0..me.columns).map(move |col| {
                    let v = me.values[r * me.columns + col];
                    let fill = if v.is_finite() {
                        me.palette.colour((v - c.0) / (c.1 - c.0))
                    } else {
                        grey
                    };
                    let x0 = x.0 + col as f64 * dx;
                    let (y0, y1) = match &me.row_edges {
                        Some(edges) => (edges[r], edges[r + 1]),
                        None => (y.0 + r as f64 * dy, y.0 + (r + 1) as f64 * dy),
                    };
                    Rectangle::new([(x0, y0), (x0 + dx, y1)], fill.filled())
                })
            }))
            .map_err(|e| e.to_string())?;
        Ok(())
    }

    /// The ends of the scale the values pass (below its low end, above its high end).
    fn saturated(&self) -> (usize, usize) {
        let c = self.c;
        let finite = || self.map.values.iter().filter(|v| v.is_finite());
        (
            finite().filter(|v| **v < c.0).count(),
            finite().filter(|v| **v > c.1).count(),
        )
    }

    /// The colour bar: a one-column chart of the colour scale, its values on the right,
    /// its label right of them, a triangle in the end colour beyond each end the values
    /// pass (the values there are drawn in the end colour: saturated); its top `top`
    /// pixels below the picture's.
    fn draw_colour_bar<DB: DrawingBackend>(
        &self,
        bar: &DrawingArea<DB, Shift>,
        top: u32,
    ) -> std::result::Result<(), String> {
        let (me, c) = (self.map, self.c);
        let mut scale = ChartBuilder::on(bar)
            .margin_top(top)
            .margin_bottom(16 + 52)
            .margin_left(8)
            .margin_right(8)
            .right_y_label_area_size(80)
            .build_cartesian_2d(0.0..1.0, c.0..c.1)
            .map_err(|e| e.to_string())?;
        let steps = 200;
        scale
            .draw_series((0..steps).map(|k| {
                let (a, b) = (k as f64 / steps as f64, (k + 1) as f64 / steps as f64);
                let (v0, v1) = (c.0 + a * (c.1 - c.0), c.0 + b * (c.1 - c.0));
                let fill = me.palette.colour((a + b) / 2.0);
                Rectangle::new([(0.0, v0), (1.0, v1)], fill.filled())
            }))
            .map_err(|e| e.to_string())?;
        scale
            .configure_mesh()
            .disable_mesh()
            .disable_x_axis()
            .label_style((FAMILY, 14.0).into_font())
            .y_labels(8)
            .y_label_formatter(&|v| tick(*v, c))
            .draw()
            .map_err(|e| e.to_string())?;
        let (base_x, base_y) = bar.get_base_pixel();
        let (columns, rows) = scale.plotting_area().get_pixel_range();
        let (x0, x1) = (columns.start - base_x, columns.end - base_x);
        let (y0, y1) = (rows.start - base_y, rows.end - base_y);
        let (below, above) = me.extend.unwrap_or_else(|| {
            let (below, above) = self.saturated();
            (below > 0, above > 0)
        });
        // Triangles as tall as the bar is wide, pointing away from it.
        let tall = (x1 - x0).min(28);
        for (on, base, tip, t) in [
            (above, y0 - 3, y0 - 3 - tall, 1.0),
            (below, y1 + 2, y1 + 2 + tall, 0.0),
        ] {
            if on {
                let points = vec![(x0, base), (x1, base), ((x0 + x1) / 2, tip)];
                bar.draw(&Polygon::new(points.clone(), me.palette.colour(t).filled()))
                    .map_err(|e| e.to_string())?;
                let mut outline = points;
                outline.push(outline[0]);
                bar.draw(&PathElement::new(outline, BLACK.stroke_width(1)))
                    .map_err(|e| e.to_string())?;
            }
        }
        // The label where plotters puts a right axis' label, reading up along the bar.
        if !me.colour_label.is_empty() {
            let size = fitting(bar, &me.colour_label, 16.0, y1 - y0)?;
            let width = typeset_width(bar, &me.colour_label, size)?;
            let (bar_width, _) = bar.dim_in_pixel();
            let left = bar_width as i32 - 8 - (1.15 * size) as i32;
            typeset(
                bar,
                &me.colour_label,
                (left, (y0 + y1 + width) / 2),
                size,
                Reading::Up,
            )?;
        }
        Ok(())
    }

    /// What the colour scale leaves out, as its line under the map says it: the share of
    /// the cells beyond each end and the extreme value there; `None` when nothing is.
    fn saturation_note(&self) -> Option<String> {
        let c = self.c;
        let finite: Vec<f64> = self
            .map
            .values
            .iter()
            .copied()
            .filter(|v| v.is_finite())
            .collect();
        let (below, above) = self.saturated();
        let share = |n: usize| {
            let percent = 100.0 * n as f64 / finite.len() as f64;
            if percent < 0.1 {
                "< 0.1 %".to_string()
            } else {
                format!("{percent:.1} %")
            }
        };
        // The scale's ends as its ticks; an extreme far beyond in scientific notation
        // (the area law near slip reaches 1e10 times the zero-shear area).
        let extreme = |v: f64| {
            if (1e-3..1e4).contains(&v.abs()) {
                tick(v, c)
            } else {
                format!("{v:.2e}").replace('-', "−")
            }
        };
        let mut parts = Vec::new();
        if above > 0 {
            let top = finite.iter().copied().fold(f64::MIN, f64::max);
            parts.push(format!(
                "{} of the cells above {} (up to {})",
                share(above),
                tick(c.1, c),
                extreme(top)
            ));
        }
        if below > 0 {
            let bottom = finite.iter().copied().fold(f64::MAX, f64::min);
            parts.push(format!(
                "{} below {} (down to {})",
                share(below),
                tick(c.0, c),
                extreme(bottom)
            ));
        }
        (!parts.is_empty()).then(|| format!("colour scale saturated: {}", parts.join(", ")))
    }

    /// The aspect of a map of lengths (`plot`: the plotting area's pixels): how much the
    /// drawing stretches y against x, or that it is true to scale; `None` for axes of
    /// different quantities.
    fn aspect_note(&self, plot: (i32, i32)) -> Option<String> {
        if !self.map.same_units {
            return None;
        }
        let (x, y) = (self.x, self.y);
        let per_x = f64::from(plot.0) / (x.1 - x.0);
        let per_y = f64::from(plot.1) / (y.1 - y.0);
        let stretch = per_y / per_x;
        Some(if (0.95..=1.0 / 0.95).contains(&stretch) {
            "true to scale".to_string()
        } else if stretch > 1.0 {
            format!("not to scale: y drawn {stretch:.1} times stretched against x")
        } else {
            format!(
                "not to scale: x drawn {:.1} times stretched against y",
                1.0 / stretch
            )
        })
    }
}

/// Draws `notes` (one line each, typeset, left-aligned, shrunk to fit) on `area`.
fn draw_notes<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    notes: &[String],
) -> std::result::Result<(), String> {
    let (width, _) = area.dim_in_pixel();
    for (k, note) in notes.iter().enumerate().filter(|(_, n)| !n.is_empty()) {
        let size = fitting(area, note, 13.0, width as i32 - 24)?;
        typeset(
            area,
            note,
            (12, (k as u32 * NOTE_LINE) as i32 + 2),
            size,
            Reading::Across,
        )?;
    }
    Ok(())
}

/// A titled plotting area with room for tick values and axis labels.
fn axes<'a, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
    title: &str,
    x: (f64, f64),
    y: (f64, f64),
) -> std::result::Result<ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>, String>
{
    // The title typeset by hand (plotters' caption has no subscripts), on one line or two,
    // above the plotting area.
    let top = typeset_title(area, title)?;
    frame(area, top, x, y, 0)
}

/// Typesets `title` above the plotting area (one line or two, [`title_lines`]) and
/// returns the room it takes ([`title_room`]).
fn typeset_title<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    title: &str,
) -> std::result::Result<u32, String> {
    let (width, _) = area.dim_in_pixel();
    let (lines, size) = title_lines(area, title, width as i32 - 16)?;
    let line_height = (1.25 * size) as i32;
    for (k, line) in lines.iter().enumerate() {
        let left = (width as i32 - typeset_width(area, line, size)?) / 2;
        let top = TITLE_TOP + k as i32 * line_height;
        typeset(area, line, (left, top), size, Reading::Across)?;
    }
    Ok(title_room(lines.len(), size))
}

/// The room above the plotting area the title of `area` will take (measured, not drawn).
fn measured_title_room<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    title: &str,
) -> std::result::Result<u32, String> {
    let (width, _) = area.dim_in_pixel();
    let (lines, size) = title_lines(area, title, width as i32 - 16)?;
    Ok(title_room(lines.len(), size))
}

/// The chart's coordinates on `area`: `top` pixels above the plotting area for the title,
/// the tick values' and labels' areas, and `below` more pixels under them (a legend put
/// below the plotting area). Draws nothing: it can be built to measure the plotting area.
fn frame<'a, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
    top: u32,
    x: (f64, f64),
    y: (f64, f64),
    below: u32,
) -> std::result::Result<ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>, String>
{
    ChartBuilder::on(area)
        .margin(16)
        .margin_top(top)
        .margin_bottom(16 + below)
        .x_label_area_size(X_LABEL_AREA)
        .y_label_area_size(Y_LABEL_AREA)
        .build_cartesian_2d(x.0..x.1, y.0..y.1)
        .map_err(|e| e.to_string())
}

/// The top of a title's first line (pixels from the picture's top).
const TITLE_TOP: i32 = 12;
/// A title's size (pixels) when it fits the picture's width.
const TITLE_SIZE: f64 = 22.0;
/// The largest size of a title on two lines (the tick values' size and a bit).
const WRAPPED_TITLE_SIZE: f64 = 16.0;
/// The smallest size (pixels at 150 dpi: 6.7 points) a title, an axis label or a legend
/// entry is set at: a title that would be smaller on one line goes on two, a text that
/// does not fit even so is shortened with `…`.
const SMALLEST_TEXT: f64 = 14.0;

/// The room above the plotting area for a title of `lines` lines at `size` (50 pixels for
/// none or one line at the full size, as plotters' caption of that size).
fn title_room(lines: usize, size: f64) -> u32 {
    let used = TITLE_TOP + lines as i32 * (1.25 * size) as i32 + 10;
    used.max(16 + 34) as u32
}

/// `title` laid out in `room` pixels: one line at up to [`TITLE_SIZE`], or, where that
/// would be smaller than [`SMALLEST_TEXT`], two lines of up to [`WRAPPED_TITLE_SIZE`] cut
/// after the `,`, `:` or `;` (else the space) that lets them be set largest; never
/// smaller than [`SMALLEST_TEXT`], a line still too long shortened with `…`. No lines for
/// an empty title.
fn title_lines<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    title: &str,
    room: i32,
) -> std::result::Result<(Vec<String>, f64), String> {
    if title.is_empty() {
        return Ok((Vec::new(), TITLE_SIZE));
    }
    let one = fitting(area, title, TITLE_SIZE, room)?;
    if one >= SMALLEST_TEXT {
        return Ok((vec![title.to_string()], one));
    }
    let cuts = |punctuated: bool| {
        title
            .char_indices()
            .filter(move |&(k, c)| {
                c == ' ' && k > 0 && (!punctuated || title[..k].ends_with([',', ':', ';']))
            })
            .map(|(k, _)| k)
            .collect::<Vec<usize>>()
    };
    let mut candidates = cuts(true);
    if candidates.is_empty() {
        candidates = cuts(false);
    }
    // The cut that lets the lines be set largest; of those, the one that balances them
    // best (its longer line the shortest).
    let mut best: Option<(Vec<String>, f64, i32)> = None;
    for k in candidates {
        let lines = vec![title[..k].to_string(), title[k + 1..].to_string()];
        let (mut size, mut longest) = (WRAPPED_TITLE_SIZE, 0);
        for line in &lines {
            size = size.min(fitting(area, line, WRAPPED_TITLE_SIZE, room)?);
            longest = longest.max(typeset_width(area, line, WRAPPED_TITLE_SIZE)?);
        }
        if best
            .as_ref()
            .is_none_or(|b| size > b.1 || (size == b.1 && longest < b.2))
        {
            best = Some((lines, size, longest));
        }
    }
    let (mut lines, size) = match best {
        Some((lines, size, _)) if size > one => (lines, size),
        _ => (vec![title.to_string()], one),
    };
    let size = size.max(SMALLEST_TEXT);
    if lines.len() == 2 && typeset_width(area, &lines[0], size)? > room {
        // Too long for two balanced lines even at the smallest size: the first line as
        // long as fits, the rest shortened on the second.
        let mut first = 0;
        for k in cuts(false) {
            if typeset_width(area, &title[..k], size)? <= room {
                first = k;
            }
        }
        if first > 0 {
            lines = vec![title[..first].to_string(), title[first + 1..].to_string()];
        }
    }
    let mut shortened = Vec::with_capacity(lines.len());
    for line in &lines {
        shortened.push(abbreviated(area, line, size, room)?);
    }
    Ok((shortened, size))
}

/// `text` as it fits `room` pixels at `size`: whole, or cut (at a space where one is near
/// the end) and ended with `…`.
fn abbreviated<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    text: &str,
    size: f64,
    room: i32,
) -> std::result::Result<String, String> {
    if typeset_width(area, text, size)? <= room {
        return Ok(text.to_string());
    }
    let ends: Vec<usize> = text.char_indices().map(|(k, _)| k).collect();
    // The longest prefix that fits with the ellipsis (widths grow with the prefix).
    let (mut fits, mut fails) = (0, ends.len());
    while fails - fits > 1 {
        let mid = (fits + fails) / 2;
        let candidate = format!("{}…", &text[..ends[mid]]);
        if typeset_width(area, &candidate, size)? <= room {
            fits = mid;
        } else {
            fails = mid;
        }
    }
    let prefix = &text[..ends[fits]];
    // A cut at a word's end when one lies in the last fifth of the prefix.
    let prefix = match prefix.rfind(' ') {
        Some(space) if 5 * space >= 4 * prefix.len() => &prefix[..space],
        _ => prefix,
    };
    Ok(format!(
        "{}…",
        prefix.trim_end_matches([' ', ',', ':', ';', '_'])
    ))
}

/// `text` set at `size`, or smaller (not below [`SMALLEST_TEXT`]) to fit `room` pixels,
/// shortened with `…` where it does not fit even so: the text and its size.
fn fitted<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    text: &str,
    size: f64,
    room: i32,
) -> std::result::Result<(String, f64), String> {
    let size = fitting(area, text, size, room)?.max(SMALLEST_TEXT.min(size));
    Ok((abbreviated(area, text, size, room)?, size))
}

/// The room below the plotting area for the x tick values and label (pixels).
const X_LABEL_AREA: i32 = 52;
/// The room left of the plotting area for the y tick values and label (pixels).
const Y_LABEL_AREA: i32 = 72;
/// The size of the axis labels' font (pixels).
const AXIS_LABEL_SIZE: f64 = 18.0;
/// The size of the tick values' font (pixels).
const TICK_SIZE: f64 = 15.0;
/// The grid: lines at the labelled ticks, and light ones between them.
const GRID: RGBColor = RGBColor(218, 218, 218);
const LIGHT_GRID: RGBColor = RGBColor(242, 242, 242);

/// The axes' tick values and labels, with a light grid when `grid` (charts; not on maps);
/// a logarithmic axis (`log`, its values `log10` of the data's) with ticks at the powers
/// of ten ([`log_ticks`]). The labels are typeset on `area`, the area the chart was built
/// on.
fn draw_axes<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    chart: &mut ChartContext<'_, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    (x_label, x): (&str, (f64, f64)),
    (y_label, y): (&str, (f64, f64)),
    (grid, log): (bool, (bool, bool)),
) -> std::result::Result<(), String> {
    let font = |size: f64| (FAMILY, size).into_font();
    let x_ticks = |v: &f64| tick(*v, x);
    let y_ticks = |v: &f64| tick(*v, y);
    let mut mesh = chart.configure_mesh();
    if grid {
        // One light line between two labelled ticks at most: a dense minor grid hides the
        // curves.
        mesh.light_line_style(LIGHT_GRID)
            .bold_line_style(GRID)
            .max_light_lines(2);
    } else {
        mesh.disable_mesh();
    }
    // A logarithmic axis gets its ticks from `draw_log_ticks`: none from plotters.
    mesh.label_style(font(TICK_SIZE))
        .x_labels(if log.0 { 0 } else { 8 })
        .y_labels(if log.1 { 0 } else { 8 })
        .x_label_formatter(&x_ticks)
        .y_label_formatter(&y_ticks)
        .draw()
        .map_err(|e| e.to_string())?;
    draw_log_ticks(area, chart, (x, y), log, grid)?;
    // The labels where plotters puts its own: the x label at the bottom of its room,
    // centred under the plotting area; the y label at the left edge of its room, reading
    // up, centred along the plotting area.
    let (base_x, base_y) = area.get_base_pixel();
    let (columns, rows) = chart.plotting_area().get_pixel_range();
    let (x0, x1) = (columns.start - base_x, columns.end - base_x);
    let (y0, y1) = (rows.start - base_y, rows.end - base_y);
    if !x_label.is_empty() {
        let (text, size) = fitted(area, x_label, AXIS_LABEL_SIZE, x1 - x0)?;
        let width = typeset_width(area, &text, size)?;
        let top = y1 + X_LABEL_AREA - (1.25 * size) as i32;
        typeset(
            area,
            &text,
            ((x0 + x1 - width) / 2, top),
            size,
            Reading::Across,
        )?;
    }
    if !y_label.is_empty() {
        let (text, size) = fitted(area, y_label, AXIS_LABEL_SIZE, y1 - y0)?;
        let width = typeset_width(area, &text, size)?;
        let left = (x0 - Y_LABEL_AREA).max(0);
        typeset(
            area,
            &text,
            (left, (y0 + y1 + width) / 2),
            size,
            Reading::Up,
        )?;
    }
    Ok(())
}

/// The ticks of the logarithmic axes among `log` (x, y), whose ranges `(x, y)` are in
/// `log10` of the data: grid lines (with `grid`), tick marks and the values of
/// [`log_ticks`], as plotters draws a linear axis'.
fn draw_log_ticks<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    chart: &mut ChartContext<'_, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    (x, y): ((f64, f64), (f64, f64)),
    log: (bool, bool),
    grid: bool,
) -> std::result::Result<(), String> {
    const MARK: i32 = 5;
    let (base_x, base_y) = area.get_base_pixel();
    let font = (FAMILY, TICK_SIZE).into_font().color(&BLACK);
    for (is_x, range) in [(true, x), (false, y)] {
        if !(if is_x { log.0 } else { log.1 }) {
            continue;
        }
        for (v, label) in log_ticks(range) {
            let ends = if is_x {
                [(v, y.0), (v, y.1)]
            } else {
                [(x.0, v), (x.1, v)]
            };
            if grid {
                let colour = if label.is_some() { GRID } else { LIGHT_GRID };
                chart
                    .draw_series(std::iter::once(PathElement::new(ends.to_vec(), colour)))
                    .map_err(|e| e.to_string())?;
            }
            let Some(label) = label else { continue };
            let (px, py) = chart.backend_coord(&ends[0]);
            let (px, py) = (px - base_x, py - base_y);
            let (mark, at, anchor) = if is_x {
                (
                    [(px, py), (px, py + MARK)],
                    (px, py + MARK + 3),
                    Pos::new(HPos::Center, VPos::Top),
                )
            } else {
                (
                    [(px - MARK, py), (px, py)],
                    (px - MARK - 3, py),
                    Pos::new(HPos::Right, VPos::Center),
                )
            };
            area.draw(&PathElement::new(mark.to_vec(), BLACK))
                .map_err(|e| e.to_string())?;
            area.draw(&Text::new(label, at, font.pos(anchor)))
                .map_err(|e| e.to_string())?;
        }
    }
    Ok(())
}

/// How a legend entry shows its series.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Glyph {
    Line,
    Dashed,
    Marker,
}

/// A legend laid out ([`legend_layout`]): its entries (label as it fits, glyph,
/// colour), its notes as they fit, and its box's size in pixels.
struct LegendLayout {
    entries: Vec<(String, Glyph, RGBColor)>,
    notes: Vec<String>,
    size: (i32, i32),
}

/// The size of a legend's text (pixels).
const LEGEND_TEXT: f64 = 15.0;
/// The margin inside a legend's frame (pixels).
const LEGEND_MARGIN: i32 = 10;
/// The room of an entry's glyph before its label (pixels).
const GLYPH_ROOM: i32 = 30;

/// The legend of `entries` (label, glyph, colour) and, under them, `notes` (text without
/// a glyph) on a plotting area `width` pixels wide: each text shortened with `…` where
/// the area is too narrow for it; `None` with neither.
fn legend_layout<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    width: i32,
    entries: &[(String, Glyph, RGBColor)],
    notes: &[String],
) -> std::result::Result<Option<LegendLayout>, String> {
    if entries.is_empty() && notes.is_empty() {
        return Ok(None);
    }
    // A row holds a letter and its lowered subscript.
    let row = (1.5 * LEGEND_TEXT) as i32;
    let room = width - 10 - 2 * LEGEND_MARGIN;
    let mut widest = 0;
    let mut fitted = Vec::with_capacity(entries.len());
    for (label, glyph, colour) in entries {
        let label = abbreviated(area, label, LEGEND_TEXT, room - GLYPH_ROOM)?;
        widest = widest.max(GLYPH_ROOM + typeset_width(area, &label, LEGEND_TEXT)?);
        fitted.push((label, *glyph, *colour));
    }
    let mut lines = Vec::with_capacity(notes.len());
    for note in notes {
        let line = abbreviated(area, note, LEGEND_TEXT, room)?;
        widest = widest.max(typeset_width(area, &line, LEGEND_TEXT)?);
        lines.push(line);
    }
    let height = (fitted.len() + lines.len()) as i32 * row + 2 * LEGEND_MARGIN;
    Ok(Some(LegendLayout {
        entries: fitted,
        notes: lines,
        size: (widest + 2 * LEGEND_MARGIN, height),
    }))
}

/// Draws `legend` on `area` with its box's top left corner at `(left, top)`: a framed,
/// almost opaque box as plotters draws its own, with the labels typeset (plotters'
/// legend draws them as plain text).
fn draw_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    legend: &LegendLayout,
    (left, top): (i32, i32),
) -> std::result::Result<(), String> {
    let row = (1.5 * LEGEND_TEXT) as i32;
    let frame = [(left, top), (left + legend.size.0, top + legend.size.1)];
    area.draw(&Rectangle::new(frame, WHITE.mix(0.85).filled()))
        .map_err(|e| e.to_string())?;
    area.draw(&Rectangle::new(frame, RGBColor(160, 160, 160)))
        .map_err(|e| e.to_string())?;
    let (_, letter) = area
        .estimate_text_size("0", &piece_font(LEGEND_TEXT, false, Reading::Across))
        .map_err(|e| e.to_string())?;
    for (k, (label, glyph, colour)) in legend.entries.iter().enumerate() {
        let (x, y) = (
            left + LEGEND_MARGIN,
            top + LEGEND_MARGIN + k as i32 * row + row / 2,
        );
        let drawn = match glyph {
            Glyph::Marker => area.draw(&Circle::new((x + 11, y), 4, colour.filled())),
            Glyph::Dashed => area.draw(&DashedPathElement::new(
                vec![(x, y), (x + 22, y)],
                DASH,
                GAP,
                colour.stroke_width(3),
            )),
            Glyph::Line => area.draw(&PathElement::new(
                vec![(x, y), (x + 22, y)],
                colour.stroke_width(3),
            )),
        };
        drawn.map_err(|e| e.to_string())?;
        let start = (x + GLYPH_ROOM, y - letter as i32 / 2);
        typeset(area, label, start, LEGEND_TEXT, Reading::Across)?;
    }
    for (k, line) in legend.notes.iter().enumerate() {
        let y = top + LEGEND_MARGIN + (legend.entries.len() + k) as i32 * row + row / 2;
        typeset(
            area,
            line,
            (left + LEGEND_MARGIN, y - letter as i32 / 2),
            LEGEND_TEXT,
            Reading::Across,
        )?;
    }
    Ok(())
}

/// The largest picture side (pixels): a PNG is drawn in memory first, 3 bytes a pixel.
pub(crate) const LARGEST_SIDE: u32 = 16384;

/// Which way a typeset text reads: across (left to right) or up (bottom to top, turned a
/// quarter turn anticlockwise: a y axis or a colour bar label).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Reading {
    Across,
    Up,
}

/// The font of a typeset piece: a subscript is 0.7 times the size.
fn piece_font(size: f64, sub: bool, reading: Reading) -> TextStyle<'static> {
    let font = (FAMILY, if sub { 0.7 * size } else { size }).into_font();
    let font = match reading {
        Reading::Across => font,
        Reading::Up => font.transform(FontTransform::Rotate270),
    };
    font.color(&BLACK)
}

/// The pieces of `text` (see [`subscripts`]) with their widths (pixels) at `size`.
fn measure<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    text: &str,
    size: f64,
) -> std::result::Result<Vec<(String, bool, i32)>, String> {
    subscripts(text)
        .into_iter()
        .map(|(piece, sub)| {
            let (width, _) = area
                .estimate_text_size(&piece, &piece_font(size, sub, Reading::Across))
                .map_err(|e| e.to_string())?;
            Ok((piece, sub, width as i32))
        })
        .collect()
}

/// The size at which `text` fits in `room` pixels: `size`, or smaller for a text wider than
/// its room (a text running off the picture's edge would be shifted by the backend and
/// overlap its subscripts).
fn fitting<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    text: &str,
    size: f64,
    room: i32,
) -> std::result::Result<f64, String> {
    let natural: i32 = measure(area, text, size)?.iter().map(|p| p.2).sum();
    let room = room.max(1) as f64;
    Ok(if natural as f64 > room {
        size * room / natural as f64
    } else {
        size
    })
}

/// The width (pixels) of `text` typeset at `size`.
fn typeset_width<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    text: &str,
    size: f64,
) -> std::result::Result<i32, String> {
    Ok(measure(area, text, size)?.iter().map(|p| p.2).sum())
}

/// Draws `text` at `size` with `X_Y` (one character) and `X_{...}` typeset as subscripts
/// (`F_N`, `A_R`, `τ_C`): smaller, lowered. `start` (pixels in `area`) is the top left
/// corner of the first letter as the text is read (for [`Reading::Up`] the text's top
/// points left: `start` is its left bottom corner on the picture). Every text of a figure
/// goes through here (titles, axis and colour-bar labels, legends) except tick values.
fn typeset<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    text: &str,
    start: (i32, i32),
    size: f64,
    reading: Reading,
) -> std::result::Result<(), String> {
    let mut along = 0;
    for (piece, sub, width) in measure(area, text, size)? {
        // A piece's leading spaces as an advance: an SVG viewer drops them from a text.
        let body = piece.trim_start();
        let font = piece_font(size, sub, reading);
        let body_width = if body.is_empty() {
            0
        } else {
            area.estimate_text_size(body, &piece_font(size, sub, Reading::Across))
                .map_err(|e| e.to_string())?
                .0 as i32
        };
        let lead = (width - body_width).max(0);
        let lowered = if sub { (0.45 * size) as i32 } else { 0 };
        let at = match reading {
            Reading::Across => (start.0 + along + lead, start.1 + lowered),
            Reading::Up => (start.0 + lowered, start.1 - along - lead),
        };
        if !body.is_empty() {
            area.draw(&Text::new(body.to_string(), at, font))
                .map_err(|e| e.to_string())?;
        }
        along += width;
    }
    Ok(())
}

/// `text` cut into pieces, each `(text, is a subscript)`: `_X` makes the one character `X`
/// a subscript, `_{...}` the braces' text; an `_` at the end, or before a space, stays, and
/// `\_` is an `_` as written (a name: `movie\_s1\_rod`).
fn subscripts(text: &str) -> Vec<(String, bool)> {
    let mut pieces: Vec<(String, bool)> = Vec::new();
    let mut normal = String::new();
    let mut chars = text.chars().peekable();
    while let Some(c) = chars.next() {
        let sub = match (c, chars.peek()) {
            // `\_`: an underscore as written (a directory's name in a scene line).
            ('\\', Some('_')) => {
                chars.next();
                normal.push('_');
                continue;
            }
            ('_', Some('{')) => {
                chars.next();
                let inner: String = chars.by_ref().take_while(|&c| c != '}').collect();
                Some(inner)
            }
            ('_', Some(&next)) if !next.is_whitespace() => {
                chars.next();
                Some(next.to_string())
            }
            _ => None,
        };
        match sub {
            Some(sub) => {
                if !normal.is_empty() {
                    pieces.push((std::mem::take(&mut normal), false));
                }
                pieces.push((sub, true));
            }
            None => normal.push(c),
        }
    }
    if !normal.is_empty() {
        pieces.push((normal, false));
    }
    pieces
}

/// The resolution at which a figure's size in pixels is its size in 1/150 inch, the
/// default of [`Chart::dpi`], [`Map::dpi`] and [`DrawOptions::dpi`].
const DEFAULT_DPI: u32 = 150;

/// The resolutions a PNG may be drawn at (dots per inch).
pub(crate) const DPI_RANGE: std::ops::RangeInclusive<u32> = 50..=1200;

/// Refuses a resolution outside [`DPI_RANGE`].
fn check_dpi(dpi: u32) -> Result<()> {
    if DPI_RANGE.contains(&dpi) {
        Ok(())
    } else {
        Err(PlotError::InvalidDpi {
            dpi,
            low: *DPI_RANGE.start(),
            high: *DPI_RANGE.end(),
        })
    }
}

/// The pixels of a PNG of `size` (in 1/150 inch) at `dpi`: each side `· dpi/150`, rounded.
fn png_pixels(size: (u32, u32), dpi: u32) -> (u32, u32) {
    let side = |n: u32| ((u64::from(n) * u64::from(dpi) + 75) / 150) as u32;
    (side(size.0), side(size.1))
}

/// Refuses a figure size outside 200 x 150 to [`LARGEST_SIDE`] squared.
fn check_size(path: &Path, size: (u32, u32)) -> Result<()> {
    let fail = |reason: String| PlotError::Figure {
        path: Some(path.to_path_buf()),
        reason,
    };
    if size.0 < 200 || size.1 < 150 {
        return Err(fail(format!(
            "{} x {} is too small for a figure with axes and labels: at least 200 x 150",
            size.0, size.1
        )));
    }
    if size.0 > LARGEST_SIDE || size.1 > LARGEST_SIDE {
        return Err(fail(format!(
            "{} x {} is too large for a figure: at most {LARGEST_SIDE} x {LARGEST_SIDE}",
            size.0, size.1
        )));
    }
    Ok(())
}

/// Draws in memory through the backend that `path`'s extension names, then writes the
/// file atomically (temporary file and rename, as checkpoints): a full disk or a kill
/// never leaves a half or empty figure under its name. `size` is the figure's in 1/150
/// inch (an SVG's user units); a PNG has `size · dpi/150` pixels ([`png_pixels`]), the
/// figure drawn at that scale ([`scaled::Scaled`]).
fn render(path: &Path, (size, dpi): ((u32, u32), u32), figure: &impl Draw) -> Result<()> {
    register_font()?;
    let fail = |reason: String| PlotError::Figure {
        path: Some(path.to_path_buf()),
        reason,
    };
    check_dpi(dpi)?;
    check_size(path, size)?;
    let extension = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let bytes = match extension.as_deref() {
        Some("png") => {
            let pixels_size = png_pixels(size, dpi);
            if pixels_size.0 > LARGEST_SIDE || pixels_size.1 > LARGEST_SIDE {
                return Err(fail(format!(
                    "{} x {} at {dpi} dpi is a PNG of {} x {} pixels: at most \
                     {LARGEST_SIDE} x {LARGEST_SIDE}",
                    size.0, size.1, pixels_size.0, pixels_size.1
                )));
            }
            let mut pixels = vec![0u8; 3 * pixels_size.0 as usize * pixels_size.1 as usize];
            let backend = BitMapBackend::with_buffer(&mut pixels, pixels_size);
            let scale = f64::from(dpi) / f64::from(DEFAULT_DPI);
            paint(
                scaled::Scaled::new(backend, size, scale).into_drawing_area(),
                figure,
            )
            .map_err(fail)?;
            encode_png(&pixels, pixels_size).map_err(|e| fail(format!("encoding the PNG: {e}")))?
        }
        Some("svg") => {
            let mut text = String::new();
            paint(
                SVGBackend::with_string(&mut text, size).into_drawing_area(),
                figure,
            )
            .map_err(fail)?;
            embed_font(&text).into_bytes()
        }
        _ => {
            return Err(fail(
                "the file name must end in .png or .svg (the format is chosen by it)".into(),
            ))
        }
    };
    Ok(crate::files::write_atomically(
        path,
        &bytes,
        "writing figure",
    )?)
}

/// The family name of the font an SVG carries: a name no system font has, so that a viewer
/// uses the embedded one (system DejaVu Sans, then any sans-serif, where a viewer reads no
/// CSS fonts).
const SVG_FAMILY: &str = "precursors-DejaVuSans";

/// `svg` (as plotters writes it) carrying the embedded font: an `@font-face` with the TTF
/// as base64 in a `<style>` (about 68 kB), its family set on every text (a CSS rule, which
/// overrides plotters' `font-family` attribute), so that the text looks as in the PNG in
/// any browser. The positions of the typeset pieces are computed with this font's widths.
fn embed_font(svg: &str) -> String {
    static STYLE: OnceLock<String> = OnceLock::new();
    let style = STYLE.get_or_init(|| {
        format!(
            "<style>@font-face{{font-family:\"{SVG_FAMILY}\";\
             src:url(data:font/ttf;base64,{})format(\"truetype\");}}\
             text{{font-family:\"{SVG_FAMILY}\",\"DejaVu Sans\",sans-serif;}}</style>\n",
            base64(FONT)
        )
    });
    let svg = svg.replace(
        &format!("font-family=\"{FAMILY}\""),
        "font-family=\"DejaVu Sans, sans-serif\"",
    );
    let svg = rescale_font_sizes(&svg);
    // After the opening <svg ...> tag.
    match svg
        .find("<svg")
        .and_then(|start| svg[start..].find('>').map(|end| start + end + 1))
    {
        Some(at) => format!("{}\n{style}{}", &svg[..at], &svg[at..]),
        None => svg,
    }
}

/// `svg` with every `font-size` set as the PNG draws it. plotters writes `size / 1.24` em,
/// but draws a PNG's text with the font's height (ascender − descender, 1.164 em for
/// DejaVu Sans) scaled to `size` pixels: unscaled, the SVG's text is 6 % smaller than the
/// PNG's and the typeset pieces, placed by the PNG's widths, drift apart.
fn rescale_font_sizes(svg: &str) -> String {
    const ATTRIBUTE: &str = "font-size=\"";
    let factor = 1.24 / font_height_em();
    let mut out = String::with_capacity(svg.len());
    let mut rest = svg;
    while let Some(at) = rest.find(ATTRIBUTE) {
        let (head, tail) = rest.split_at(at + ATTRIBUTE.len());
        out.push_str(head);
        let end = tail.find('"').unwrap_or(tail.len());
        match tail[..end].parse::<f64>() {
            Ok(size) => out.push_str(&format!("{}", size * factor)),
            Err(_) => out.push_str(&tail[..end]),
        }
        rest = &tail[end..];
    }
    out.push_str(rest);
    out
}

/// The embedded font's height (hhea ascender − descender) in em, as its renderer (ab_glyph)
/// scales it; 1.24 (plotters' own assumption) if the tables cannot be read.
fn font_height_em() -> f64 {
    let u16_at = |at: usize| {
        FONT.get(at..at + 2)
            .map(|b| u16::from_be_bytes([b[0], b[1]]))
    };
    let table = |tag: &[u8; 4]| -> Option<usize> {
        let tables = usize::from(u16_at(4)?);
        (0..tables).find_map(|k| {
            let entry = 12 + 16 * k;
            (FONT.get(entry..entry + 4)? == tag).then(|| {
                let b = &FONT[entry + 8..entry + 12];
                u32::from_be_bytes([b[0], b[1], b[2], b[3]]) as usize
            })
        })
    };
    let height = || -> Option<f64> {
        let (hhea, head) = (table(b"hhea")?, table(b"head")?);
        let ascender = u16_at(hhea + 4)? as i16;
        let descender = u16_at(hhea + 6)? as i16;
        let units = u16_at(head + 18)?;
        Some((f64::from(ascender) - f64::from(descender)) / f64::from(units))
    };
    height().filter(|h| *h > 0.0).unwrap_or(1.24)
}

/// `bytes` in base64 (RFC 4648, with padding).
fn base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            *chunk.get(1).unwrap_or(&0),
            *chunk.get(2).unwrap_or(&0),
        ];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(ALPHABET[((n >> (18 - 6 * k)) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// 8-bit RGB `pixels` (rows from the top) as a PNG file's bytes.
fn encode_png(
    pixels: &[u8],
    (width, height): (u32, u32),
) -> std::result::Result<Vec<u8>, png::EncodingError> {
    let mut bytes = Vec::new();
    let mut encoder = png::Encoder::new(&mut bytes, width, height);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    // As image's PNG encoder (which plotters used): a filter chosen per row, a quarter
    // of the size of one fixed filter for these flat-coloured pictures.
    encoder.set_compression(png::Compression::Default);
    encoder.set_filter(png::FilterType::Sub);
    encoder.set_adaptive_filter(png::AdaptiveFilterType::Adaptive);
    let mut writer = encoder.write_header()?;
    writer.write_image_data(pixels)?;
    writer.finish()?;
    Ok(bytes)
}

/// Draws `figure` on a white `root` and finishes it (`present`).
fn paint<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    figure: &impl Draw,
) -> std::result::Result<(), String> {
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    figure.draw(&root)?;
    root.present().map_err(|e| e.to_string())
}

/// The range of an axis: the one given (checked), or the finite values' extent with 4 %
/// room on each side (`[0, 1]` without finite values, `v ± 1` or `v ± 5 %` for a single
/// value `v`).
fn axis_range(
    path: &Path,
    axis: &str,
    given: Option<(f64, f64)>,
    values: impl Iterator<Item = f64>,
) -> Result<(f64, f64)> {
    if let Some((low, high)) = given {
        if low.is_finite() && high.is_finite() && low < high {
            return Ok((low, high));
        }
        return Err(PlotError::Figure {
            path: Some(path.to_path_buf()),
            reason: format!(
                "the {axis} range [{low}, {high}] is invalid: both ends must be finite and \
                 the first below the second"
            ),
        });
    }
    let (low, high) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    Ok(if low > high {
        (0.0, 1.0)
    } else if low == high {
        let pad = if low == 0.0 { 1.0 } else { 0.05 * low.abs() };
        (low - pad, high + pad)
    } else {
        let pad = 0.04 * (high - low);
        (low - pad, high + pad)
    })
}

/// A tick value printed with as many decimals as the axis span needs; `−` as the minus.
fn tick(v: f64, range: (f64, f64)) -> String {
    let span = (range.1 - range.0).abs();
    let scale = range.0.abs().max(range.1.abs());
    let text = if !(1e-3..1e5).contains(&scale) && scale > 0.0 {
        let digits = ((scale / span).log10().ceil().max(1.0) as usize).min(6);
        if v == 0.0 {
            "0".to_string()
        } else {
            format!("{v:.digits$e}")
        }
    } else {
        let digits = (1.0 - (span / 8.0).log10().floor()).clamp(0.0, 8.0) as usize;
        let digits = digits.saturating_sub(1);
        format!("{v:.digits$}")
    };
    // "-0.0" for a tick at rounding distance below zero.
    let text = if text
        .trim_start_matches('-')
        .chars()
        .all(|c| "0.".contains(c))
    {
        text.trim_start_matches('-').to_string()
    } else {
        text
    };
    text.replace('-', "−")
}

/// The ticks of a logarithmic axis over `range` (in `log10` of the data): `(log10 of the
/// value, its label)`, unlabelled where `None` (a grid line only). Over two decades and
/// more, the powers of ten, labelled `10⁻³`, `10⁰`, `10²` (every second, fifth, ... one
/// where more than eight would crowd the axis), with unlabelled lines at 2 and 5 times
/// each up to seven decades (a sparse minor grid); over less, 1, 2 and 5 times the powers
/// of ten, all labelled (`0.2`, `1`, `50`, and `2×10⁻⁶` outside `[10⁻³, 10⁴)`).
fn log_ticks(range: (f64, f64)) -> Vec<(f64, Option<String>)> {
    if !(range.0.is_finite() && range.1.is_finite()) {
        return Vec::new();
    }
    let (low, high) = (range.0.min(range.1), range.0.max(range.1));
    let inside = |v: f64| v >= low - 1e-9 && v <= high + 1e-9;
    let (first, last) = (low.floor() as i64, high.ceil() as i64);
    let decades: Vec<i64> = (first..=last).filter(|&d| inside(d as f64)).collect();
    let mut ticks = Vec::new();
    if decades.len() >= 2 {
        let every = decades.len().div_ceil(8) as i64;
        let every = [1, 2, 5, 10, 20, 50, 100]
            .into_iter()
            .find(|&e| e >= every)
            .unwrap_or(every);
        let minor = decades.len() <= 7;
        for d in first..=last {
            if inside(d as f64) {
                let label = (d.rem_euclid(every) == 0).then(|| power_of_ten(1, d));
                ticks.push((d as f64, label));
            }
            for m in [2, 5].into_iter().filter(|_| minor) {
                let v = d as f64 + f64::from(m).log10();
                if inside(v) {
                    ticks.push((v, None));
                }
            }
        }
    } else {
        for d in first..=last {
            for m in [1, 2, 5] {
                let v = d as f64 + f64::from(m).log10();
                // Numbers where they are short: 0.2, 1, 50.
                let value = f64::from(m) * 10f64.powf(d as f64);
                let label = if (1e-3..1e4).contains(&value) {
                    short(value)
                } else {
                    power_of_ten(m, d)
                };
                if inside(v) {
                    ticks.push((v, Some(label)));
                }
            }
        }
    }
    ticks
}

/// `m × 10^d` as a tick value: `10⁻³`, `10⁰`, `2×10⁴` (superscript digits and minus).
fn power_of_ten(m: u32, d: i64) -> String {
    const DIGITS: [char; 10] = ['⁰', '¹', '²', '³', '⁴', '⁵', '⁶', '⁷', '⁸', '⁹'];
    let exponent: String = d
        .to_string()
        .chars()
        .map(|c| match c.to_digit(10) {
            Some(k) => DIGITS[k as usize],
            None => '⁻',
        })
        .collect();
    if m == 1 {
        format!("10{exponent}")
    } else {
        format!("{m}×10{exponent}")
    }
}

/// `v` in a label: up to four significant digits, trailing zeros dropped (`140`, `19.4`,
/// `0.25`, `0.3512`), powers of ten outside `[10⁻³, 10⁴)` (`7.3e−5`, `2.5e6`); `−` as the
/// minus. The one number format of the figures' titles and legends.
fn short(v: f64) -> String {
    if !v.is_finite() {
        return format!("{v}");
    }
    let text = if v == 0.0 {
        "0".to_string()
    } else if (1e-3..1e4).contains(&v.abs()) {
        let digits = (3.0 - v.abs().log10().floor()).max(0.0) as usize;
        trim_zeros(&format!("{v:.digits$}")).to_string()
    } else {
        let text = format!("{v:.3e}");
        let (mantissa, exponent) = text.split_once('e').unwrap_or((&text, "0"));
        format!("{}e{exponent}", trim_zeros(mantissa))
    };
    text.replace('-', "−")
}

/// A decimal's trailing zeros (and point) dropped: `0.2500` to `0.25`, `3.000` to `3`.
fn trim_zeros(text: &str) -> &str {
    if text.contains('.') {
        text.trim_end_matches('0').trim_end_matches('.')
    } else {
        text
    }
}

/// The maximal runs of consecutive items whose coordinates are all finite.
fn finite_runs<T: Copy, const K: usize>(items: &[T], coords: impl Fn(&T) -> [f64; K]) -> Vec<&[T]> {
    items
        .split(|t| coords(t).iter().any(|v| !v.is_finite()))
        .filter(|run| !run.is_empty())
        .collect()
}

/// The staircase through `points`: each value holds until the next x.
fn staircase(points: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let mut out = Vec::with_capacity(2 * points.len());
    for (k, p) in points.iter().enumerate() {
        if k > 0 {
            out.push((p.0, points[k - 1].1));
        }
        out.push(*p);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// RFC 4648's test vectors (section 10).
    #[test]
    fn base64_is_rfc_4648() {
        for (text, code) in [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ] {
            assert_eq!(base64(text.as_bytes()), code);
        }
        assert_eq!(base64(&[0xfb, 0xff, 0xbf]), "+/+/");
    }

    /// DejaVu Sans' metrics (hhea ascender 1901, descender −483, 2048 units per em: the
    /// font's source, DejaVuSans.sfd); an SVG font size scaled by 1.24 / 1.1640625.
    #[test]
    fn svg_font_sizes_are_the_pngs() {
        assert_eq!(font_height_em(), 2384.0 / 2048.0);
        // plotters writes 10 for a size of 12.4 (pixels of font height in the PNG): 12.4
        // pixels of height are 12.4 · 2048/2384 pixels per em.
        let svg = r#"<text font-size="10" x="1">a</text><text font-size="x">"#;
        let scaled = rescale_font_sizes(svg);
        let size: f64 = scaled.split('"').nth(1).unwrap().parse().unwrap();
        assert!((size - 12.4 * 2048.0 / 2384.0).abs() < 1e-9, "{scaled}");
        assert!(scaled.ends_with(r#"<text font-size="x">"#));
    }

    #[test]
    fn subscripts_are_cut_where_the_underscores_say() {
        let piece = |t: &str, sub: bool| (t.to_string(), sub);
        assert_eq!(
            subscripts("F/(μF_N) = 0.5"),
            [
                piece("F/(μF", false),
                piece("N", true),
                piece(") = 0.5", false)
            ]
        );
        assert_eq!(
            subscripts("τ_{C,max} at z_P"),
            [
                piece("τ", false),
                piece("C,max", true),
                piece(" at z", false),
                piece("P", true)
            ]
        );
        // Left as written: no character after it, or a space, or escaped.
        assert_eq!(subscripts("a_ b_"), [piece("a_ b_", false)]);
        assert_eq!(
            subscripts("movie\\_s1\\_rod, F_N"),
            [piece("movie_s1_rod, F", false), piece("N", true)]
        );
        assert!(subscripts("").is_empty());
    }

    /// Decades written out by hand: 10⁻³ to 10² over [1e-3, 1e2], with the minor lines at
    /// log10(2) and log10(5) between; a narrow range gets 1, 2 and 5 times the powers of ten.
    #[test]
    fn log_ticks_are_the_powers_of_ten() {
        let labels = |range: (f64, f64)| -> Vec<String> {
            log_ticks(range).into_iter().filter_map(|t| t.1).collect()
        };
        assert_eq!(
            labels((-3.0, 2.0)),
            ["10⁻³", "10⁻²", "10⁻¹", "10⁰", "10¹", "10²"]
        );
        let all = log_ticks((-3.0, 2.0));
        // 6 decades and 2 minor lines in each of the 5 decades between.
        assert_eq!(all.len(), 6 + 5 * 2);
        assert!(all
            .iter()
            .any(|t| (t.0 - (-3.0 + 2f64.log10())).abs() < 1e-12 && t.1.is_none()));
        // 17 decades: every fifth labelled (more than eight would crowd), no minor lines.
        assert_eq!(labels((-5.0, 12.0)), ["10⁻⁵", "10⁰", "10⁵", "10¹⁰"]);
        assert_eq!(log_ticks((-5.0, 12.0)).len(), 18);
        // Less than two decades: 1, 2, 5 times, as numbers between the powers of ten.
        assert_eq!(
            labels((0.2f64.log10(), 3f64.log10())),
            ["0.2", "0.5", "1", "2"]
        );
        assert_eq!(labels((-6.0, -5.5)), ["10⁻⁶", "2×10⁻⁶"]);
        assert!(log_ticks((f64::NAN, 1.0)).is_empty());
    }

    #[test]
    fn ticks_have_the_decimals_the_span_needs() {
        assert_eq!(tick(0.5, (0.0, 1.0)), "0.5");
        assert_eq!(tick(0.25, (0.0, 1.0)), "0.2"); // eight ticks over 1: one decimal
        assert_eq!(tick(-2.0, (-5.0, 5.0)), "−2"); // ticks every 2: no decimals
        assert_eq!(tick(120.0, (0.0, 140.0)), "120");
        assert_eq!(tick(2.5e-6, (0.0, 5e-6)), "2.5e−6");
        assert_eq!(tick(5e5, (-1e6, 1e6)), "5.0e5");
        assert_eq!(tick(0.0, (-1e6, 1e6)), "0");
        assert_eq!(tick(-1e-17, (-1.0, 1.0)), "0.0");
    }

    /// matplotlib's viridis: #440154 at 0, #2C728E at 0.375, #5EC962 at 0.75 (its
    /// published colour table); three ordered series take 0, 0.375 and 0.75 of it.
    #[test]
    fn ordered_colours_run_along_viridis() {
        let chart = Chart::new("", "", "")
            .colours(Colours::Ordered)
            .line("a", &[])
            .line("b", &[])
            .line("c", &[]);
        assert_eq!(chart.colour(0), RGBColor(0x44, 0x01, 0x54));
        assert_eq!(chart.colour(2), RGBColor(0x5e, 0xc9, 0x62));
        // viridis at 0.375: #2C728E.
        assert_eq!(chart.colour(1), RGBColor(0x2c, 0x72, 0x8e));
        assert_eq!(
            series_colour(Colours::Ordered, 0, 1),
            RGBColor(0x44, 0x01, 0x54)
        );
        // The diverging palette keeps its white middle.
        assert_eq!(Palette::Diverging.colour(0.5), RGBColor(247, 247, 247));
    }

    /// A sweep's points: ordered along one numeric axis (given out of order) or along
    /// axes that rise together; categorical for a product of axes or words.
    #[test]
    fn points_are_ordered_when_their_axes_rise_together() {
        let point = |pairs: &[(&str, &str)]| -> Vec<(String, String)> {
            pairs
                .iter()
                .map(|(k, v)| (k.to_string(), v.to_string()))
                .collect()
        };
        let order = |points: &[Vec<(String, String)>]| {
            point_order(&points.iter().map(|p| &p[..]).collect::<Vec<_>>())
        };
        let heights = [
            point(&[("drive.height", "0.006"), ("normal_load", "100")]),
            point(&[("drive.height", "0.002"), ("normal_load", "100")]),
            point(&[("drive.height", "0.004"), ("normal_load", "100")]),
        ];
        assert_eq!(order(&heights), (Colours::Ordered, vec![1, 2, 0]));
        let zipped = [
            point(&[("block.ly", "0.007"), ("block.lz", "0.0194")]),
            point(&[("block.ly", "0.014"), ("block.lz", "0.0389")]),
        ];
        assert_eq!(order(&zipped), (Colours::Ordered, vec![0, 1]));
        let product = [
            point(&[("a", "1"), ("b", "1")]),
            point(&[("a", "1"), ("b", "2")]),
            point(&[("a", "2"), ("b", "1")]),
            point(&[("a", "2"), ("b", "2")]),
        ];
        assert_eq!(order(&product), (Colours::Distinct, vec![0, 1, 2, 3]));
        let words = [
            point(&[("drive.kind", "\"rod\"")]),
            point(&[("drive.kind", "\"top\"")]),
        ];
        assert_eq!(order(&words), (Colours::Distinct, vec![0, 1]));
        assert_eq!(order(&heights[..1]), (Colours::Distinct, vec![0]));
    }

    #[test]
    fn numbers_are_short() {
        assert_eq!(short(140.0), "140");
        assert_eq!(short(19.400000000000002), "19.4");
        assert_eq!(short(0.25), "0.25");
        assert_eq!(short(-0.0), "0");
        assert_eq!(short(0.351_23), "0.3512");
        assert_eq!(short(7.3e-5), "7.3e−5");
        assert_eq!(short(2.5e6), "2.5e6");
        assert_eq!(short(12346.0), "1.235e4");
        assert_eq!(short(f64::NAN), "NaN");
    }

    #[test]
    fn staircase_holds_each_value_until_the_next_x() {
        let s = staircase(&[(0.0, 1.0), (1.0, 2.0), (3.0, 0.5)]);
        assert_eq!(
            s,
            vec![(0.0, 1.0), (1.0, 1.0), (1.0, 2.0), (3.0, 2.0), (3.0, 0.5)]
        );
    }

    #[test]
    fn lines_are_cut_at_non_finite_points() {
        let p = [
            (0.0, 1.0),
            (1.0, f64::NAN),
            (2.0, 2.0),
            (3.0, 3.0),
            (f64::INFINITY, 0.0),
        ];
        let runs = finite_runs(&p, |q| [q.0, q.1]);
        assert_eq!(runs.len(), 2);
        assert_eq!(runs[0], &p[0..1]);
        assert_eq!(runs[1], &p[2..4]);
    }

    #[test]
    fn automatic_ranges_cover_the_finite_values() {
        let p = Path::new("f.png");
        let r = axis_range(p, "x", None, [1.0, f64::NAN, 3.0].into_iter()).unwrap();
        assert!((r.0 - 0.92).abs() < 1e-12 && (r.1 - 3.08).abs() < 1e-12);
        assert_eq!(
            axis_range(p, "x", None, std::iter::empty()).unwrap(),
            (0.0, 1.0)
        );
        assert_eq!(
            axis_range(p, "x", None, [0.0].into_iter()).unwrap(),
            (-1.0, 1.0)
        );
        assert!(axis_range(p, "x", Some((1.0, 1.0)), std::iter::empty()).is_err());
        assert!(axis_range(p, "x", Some((0.0, f64::NAN)), std::iter::empty()).is_err());
    }
}
