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
mod movie;
mod paper;
mod profiles;
mod selection;

pub use error::PlotError;
pub use figures::{draw, draw_with_options, draw_with_size, DrawOptions, Drawn, Format};
pub use movie::{Movie, MovieKind, MovieReport};

use crate::error::Error;
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::*;
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

/// The corner of the plotting area that holds a chart's legend.
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

/// How a chart colours its series.
///
/// ```
/// use precursors::plot::{Chart, Colours};
/// let dir = std::env::temp_dir().join(format!("precursors-doc-{}", std::process::id()));
/// std::fs::create_dir_all(&dir)?;
/// // The shear traction profile φ_x(x) (kPa) at three increasing loads: blue to red.
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
/// assert!(svg.contains("#2166AC") && svg.contains("#B2182B")); // first blue, last red
/// assert_eq!(Colours::default(), Colours::Distinct);           // Tableau 10 in turn
/// std::fs::remove_dir_all(&dir)?;
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum Colours {
    /// Ten distinct colours in turn (the default).
    #[default]
    Distinct,
    /// From blue (first series) through grey to red (last): an ordered family of curves,
    /// e.g. the same profile at increasing loads.
    Ordered,
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

/// The colour at `t ∈ [0, 1]` of the gradient through three stops (the middle at 0.5).
fn gradient(stops: [[f64; 3]; 3], t: f64) -> RGBColor {
    let (a, b, s) = if t < 0.5 {
        (stops[0], stops[1], 2.0 * t)
    } else {
        (stops[1], stops[2], 2.0 * t - 1.0)
    };
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
        }
    }

    /// A logarithmic x axis (base 10, for values spanning decades: a distribution's
    /// sizes): ticks labelled with the values; points with `x ≤ 0` are not drawn; a range
    /// given by [`Chart::x_range`] is in the data's units and must be positive.
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
    /// // The ticks print values: 10 on the x axis, powers of ten like 1e−4 on the y axis.
    /// assert!(texts.contains(&"10") && texts.iter().any(|t| t.starts_with("1e−")), "{texts:?}");
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

    /// The picture's size in pixels (PNG) or user units (SVG).
    pub fn size(mut self, width: u32, height: u32) -> Self {
        self.size = (width, height);
        self
    }

    /// Where the legend goes.
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
        match self.colours {
            Colours::Distinct => DISTINCT[k % DISTINCT.len()],
            Colours::Ordered => {
                // Blue, grey, red: every step visible on white (the diverging palette's
                // middle is white).
                let n = self.series.iter().filter(auto).count().max(2) - 1;
                let t = k as f64 / n as f64;
                gradient([[33.0, 102.0, 172.0], [110.0; 3], [178.0, 24.0, 43.0]], t)
            }
        }
    }

    /// Writes the chart to `path`: PNG for `.png`, SVG for `.svg`.
    ///
    /// # Errors
    /// [`PlotError::Figure`] for another extension, an axis range that is not finite and
    /// increasing, a size outside 200 x 150 to 16384 x 16384, a [`Style`] given before any
    /// series or a dashed style on markers, or a drawing backend that fails;
    /// [`Error::Io`] (in [`PlotError::Core`]) when the file cannot be written (it is written atomically: no half
    /// file is left under its name).
    pub fn save(&self, path: impl AsRef<Path>) -> Result<()> {
        let path = path.as_ref();
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
            }
            let (x, y) = drawn.ranges(path)?;
            return render(
                path,
                self.size,
                &ChartDrawing {
                    chart: &drawn,
                    x,
                    y,
                    log: self.log,
                },
            );
        }
        let (x, y) = self.ranges(path)?;
        render(
            path,
            self.size,
            &ChartDrawing {
                chart: self,
                x,
                y,
                log: (false, false),
            },
        )
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
    chart: &'a Chart,
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
        let (me, x, y) = (self.chart, self.x, self.y);
        let mut chart = axes(root, &me.title, x, y)?;
        draw_axes(
            root,
            &mut chart,
            (&me.x_label, x),
            (&me.y_label, y),
            (true, self.log),
        )?;
        let mut legend = Vec::new();
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
            let markers = s.kind == Kind::Markers;
            let dashed = s.style.dashed;
            if !s.label.is_empty() {
                let glyph = if markers {
                    Glyph::Marker
                } else if dashed {
                    Glyph::Dashed
                } else {
                    Glyph::Line
                };
                legend.push((s.label.clone(), glyph, colour));
            }
            if markers {
                let points = s
                    .points
                    .iter()
                    .filter(|p| p.0.is_finite() && p.1.is_finite());
                chart
                    .draw_series(points.map(|p| Circle::new(*p, 3, colour.filled())))
                    .map_err(|e| e.to_string())?;
                continue;
            }
            for run in finite_runs(&s.points, |p| [p.0, p.1]) {
                let line = if s.kind == Kind::Steps {
                    staircase(run)
                } else {
                    run.to_vec()
                };
                if dashed {
                    chart.draw_series(DashedLineSeries::new(line, DASH, GAP, style))
                } else {
                    chart.draw_series(LineSeries::new(line, style))
                }
                .map_err(|e| e.to_string())?;
            }
        }
        draw_legend(
            &chart.plotting_area().strip_coord_spec(),
            &legend,
            me.legend,
        )?;
        Ok(())
    }
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

    /// The picture's size in pixels (PNG) or user units (SVG).
    pub fn size(mut self, width: u32, height: u32) -> Self {
        self.size = (width, height);
        self
    }

    /// Says that x and y are lengths in the same unit (say mm, a face or a slab of the
    /// block): the line under the map then states how much the drawing stretches one
    /// against the other (`not to scale: y drawn 13.2 times stretched against x`), or
    /// that it is true to scale (within 5 %). Without it the axes are taken as
    /// different quantities (a position and a load) and no aspect is stated.
    pub fn same_unit_axes(mut self) -> Self {
        self.same_units = true;
        self
    }

    /// Writes the map to `path`: PNG for `.png`, SVG for `.svg`.
    ///
    /// # Errors
    /// [`PlotError::Figure`] for another extension, a range that is not finite and
    /// increasing, a size outside 200 x 150 to 16384 x 16384, or a drawing backend that
    /// fails; [`Error::Io`] (in [`PlotError::Core`]) when the file cannot be written (atomically, as
    /// [`Chart::save`]).
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
        render(path, self.size, &MapDrawing { map: self, x, y, c })
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
        self.draw_colour_bar(&bar)?;
        let (columns, rows) = chart.plotting_area().get_pixel_range();
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
    /// pass (the values there are drawn in the end colour: saturated).
    fn draw_colour_bar<DB: DrawingBackend>(
        &self,
        bar: &DrawingArea<DB, Shift>,
    ) -> std::result::Result<(), String> {
        let (me, c) = (self.map, self.c);
        let mut scale = ChartBuilder::on(bar)
            .margin_top(16 + 30)
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
    // The title typeset by hand (plotters' caption has no subscripts), in the room a
    // caption of this size takes.
    let mut builder = ChartBuilder::on(area);
    builder.margin(16).margin_top(16 + 34);
    if !title.is_empty() {
        let (width, _) = area.dim_in_pixel();
        let size = fitting(area, title, 22.0, width as i32 - 16)?;
        let left = (width as i32 - typeset_width(area, title, size)?) / 2;
        typeset(area, title, (left, 12), size, Reading::Across)?;
    }
    builder
        .x_label_area_size(X_LABEL_AREA)
        .y_label_area_size(Y_LABEL_AREA)
        .build_cartesian_2d(x.0..x.1, y.0..y.1)
        .map_err(|e| e.to_string())
}

/// The room below the plotting area for the x tick values and label (pixels).
const X_LABEL_AREA: i32 = 52;
/// The room left of the plotting area for the y tick values and label (pixels).
const Y_LABEL_AREA: i32 = 72;
/// The size of the axis labels' font (pixels).
const AXIS_LABEL_SIZE: f64 = 18.0;

/// The axes' tick values and labels, with a light grid when `grid` (charts; not on maps).
/// The labels are typeset on `area`, the area the chart was built on.
fn draw_axes<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    chart: &mut ChartContext<'_, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    (x_label, x): (&str, (f64, f64)),
    (y_label, y): (&str, (f64, f64)),
    (grid, log): (bool, (bool, bool)),
) -> std::result::Result<(), String> {
    let font = |size: f64| (FAMILY, size).into_font();
    let x_ticks = |v: &f64| if log.0 { log_tick(*v) } else { tick(*v, x) };
    let y_ticks = |v: &f64| if log.1 { log_tick(*v) } else { tick(*v, y) };
    let mut mesh = chart.configure_mesh();
    if grid {
        mesh.light_line_style(RGBColor(235, 235, 235))
            .bold_line_style(RGBColor(215, 215, 215));
    } else {
        mesh.disable_mesh();
    }
    mesh.label_style(font(15.0))
        .x_labels(8)
        .y_labels(8)
        .x_label_formatter(&x_ticks)
        .y_label_formatter(&y_ticks)
        .draw()
        .map_err(|e| e.to_string())?;
    // The labels where plotters puts its own: the x label at the bottom of its room,
    // centred under the plotting area; the y label at the left edge of its room, reading
    // up, centred along the plotting area.
    let (base_x, base_y) = area.get_base_pixel();
    let (columns, rows) = chart.plotting_area().get_pixel_range();
    let (x0, x1) = (columns.start - base_x, columns.end - base_x);
    let (y0, y1) = (rows.start - base_y, rows.end - base_y);
    if !x_label.is_empty() {
        let size = fitting(area, x_label, AXIS_LABEL_SIZE, x1 - x0)?;
        let width = typeset_width(area, x_label, size)?;
        let top = y1 + X_LABEL_AREA - (1.25 * size) as i32;
        typeset(
            area,
            x_label,
            ((x0 + x1 - width) / 2, top),
            size,
            Reading::Across,
        )?;
    }
    if !y_label.is_empty() {
        let size = fitting(area, y_label, AXIS_LABEL_SIZE, y1 - y0)?;
        let width = typeset_width(area, y_label, size)?;
        let left = (x0 - Y_LABEL_AREA).max(0);
        typeset(
            area,
            y_label,
            (left, (y0 + y1 + width) / 2),
            size,
            Reading::Up,
        )?;
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

/// Draws a legend of `entries` (label, glyph, colour) in `corner` of `area` (a chart's
/// plotting area): a framed, almost opaque box as plotters draws its own, with the labels
/// typeset (plotters' legend draws them as plain text).
fn draw_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    entries: &[(String, Glyph, RGBColor)],
    corner: Corner,
) -> std::result::Result<(), String> {
    const SIZE: f64 = 15.0;
    const MARGIN: i32 = 10;
    const GLYPH_ROOM: i32 = 30;
    // A row holds a letter and its lowered subscript.
    let row = (1.5 * SIZE) as i32;
    if entries.is_empty() {
        return Ok(());
    }
    let mut widest = 0;
    for (label, _, _) in entries {
        widest = widest.max(typeset_width(area, label, SIZE)?);
    }
    let width = widest + GLYPH_ROOM + 2 * MARGIN;
    let height = entries.len() as i32 * row + 2 * MARGIN;
    let (area_width, area_height) = area.dim_in_pixel();
    let left = match corner {
        Corner::UpperLeft | Corner::LowerLeft => 5,
        Corner::UpperRight | Corner::LowerRight => area_width as i32 - width - 5,
    };
    let top = match corner {
        Corner::UpperLeft | Corner::UpperRight => 5,
        Corner::LowerLeft | Corner::LowerRight => area_height as i32 - height - 5,
    };
    let frame = [(left, top), (left + width, top + height)];
    area.draw(&Rectangle::new(frame, WHITE.mix(0.85).filled()))
        .map_err(|e| e.to_string())?;
    area.draw(&Rectangle::new(frame, RGBColor(160, 160, 160)))
        .map_err(|e| e.to_string())?;
    let (_, letter) = area
        .estimate_text_size("0", &piece_font(SIZE, false, Reading::Across))
        .map_err(|e| e.to_string())?;
    for (k, (label, glyph, colour)) in entries.iter().enumerate() {
        let (x, y) = (left + MARGIN, top + MARGIN + k as i32 * row + row / 2);
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
        typeset(area, label, start, SIZE, Reading::Across)?;
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
/// never leaves a half or empty figure under its name.
fn render(path: &Path, size: (u32, u32), figure: &impl Draw) -> Result<()> {
    register_font()?;
    let fail = |reason: String| PlotError::Figure {
        path: Some(path.to_path_buf()),
        reason,
    };
    check_size(path, size)?;
    let extension = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let bytes = match extension.as_deref() {
        Some("png") => {
            let mut pixels = vec![0u8; 3 * size.0 as usize * size.1 as usize];
            paint(
                BitMapBackend::with_buffer(&mut pixels, size).into_drawing_area(),
                figure,
            )
            .map_err(fail)?;
            encode_png(&pixels, size).map_err(|e| fail(format!("encoding the PNG: {e}")))?
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

/// The tick at `v = log10(x)` of a logarithmic axis: the value `x`, with two significant
/// digits (`1e−3`, `0.02`, `300`, `2.5e4`); `−` as the minus.
fn log_tick(v: f64) -> String {
    let x = 10f64.powf(v);
    let text = if (1e-2..1e4).contains(&x) {
        let digits = (1.0 - x.log10().floor()).max(0.0) as usize;
        let t = format!("{x:.digits$}");
        if t.contains('.') {
            t.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            t
        }
    } else {
        let t = format!("{x:.1e}");
        t.replace(".0e", "e")
    };
    text.replace('-', "−")
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

    #[test]
    fn log_ticks_print_the_values() {
        assert_eq!(log_tick(0.0), "1");
        assert_eq!(log_tick(2.0), "100");
        assert_eq!(log_tick(-1.0), "0.1");
        assert_eq!(log_tick(-3.0), "1e−3");
        assert_eq!(log_tick(5.0), "1e5");
        assert_eq!(log_tick(0.5), "3.2");
        assert_eq!(log_tick(4.5_f64.log10() + 4.0), "4.5e4");
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

    #[test]
    fn ordered_colours_run_blue_grey_red_and_stay_visible() {
        let chart = Chart::new("", "", "")
            .colours(Colours::Ordered)
            .line("a", &[])
            .line("b", &[])
            .line("c", &[]);
        assert_eq!(chart.colour(0), RGBColor(33, 102, 172));
        assert_eq!(chart.colour(1), RGBColor(110, 110, 110));
        assert_eq!(chart.colour(2), RGBColor(178, 24, 43));
        assert_eq!(Palette::Diverging.colour(0.5), RGBColor(247, 247, 247));
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
