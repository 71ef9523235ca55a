//! The paper's Supplementary Movies drawn from a run directory (`precursors movie DIR`):
//! the fields a run recorded (`fields.csv`; the scene
//! key `fields`, [`crate::RunOptions::record_fields`]) as an animated GIF, one frame per
//! recorded stable state (or every k-th), on one colour scale for the whole movie.
//!
//! * [`MovieKind::ContactArea`] (Movie S1): the real contact area `A_R` of each cell over
//!   the interface (x right, y up), the front `x = ℓ` as a vertical black line.
//! * [`MovieKind::CoulombStress`] (Movie S2): the y-averaged Coulomb stress `τ_C(x, z)`
//!   over the x-z slab of the recorded planes, the boundary of the region `τ_C > 0` (the
//!   `τ_C = 0` contour, drawn along the cells' edges) and the interface's precursor `ℓ`
//!   (a black bar along the bottom from `x = 0` to `x = ℓ`).
//!
//! Every frame carries a scene line (the directory, the block, `F_N`, the drive, the
//! cells) and states its aspect (a face 140 x 7 mm is drawn stretched); the colour bar
//! marks the ends the movie saturates, and each frame gives the share of its cells beyond
//! them.
//!
//! The GIF is encoded in memory on one palette built from the colour map (192 colours
//! along it, greys for the text, no banding), each frame after the first holding only
//! the pixels that changed (the others transparent), and written atomically: no half
//! movie is left on a full disk. The frames can also be written as numbered PNGs
//! ([`Movie::png_frames`]).

use super::{
    axis_range, encode_png, paint, register_font, Map, MapDrawing, Palette, PlotError, Result,
};
use crate::error::Error;
use crate::output::check::{fields_row, RunRecord};
use crate::output::RUN_SCENE;
use crate::output::{fields_header, FIELDS_FILE, PARTIAL};
use plotters::prelude::*;
use std::ops::ControlFlow;
use std::path::{Path, PathBuf};

/// Which of the paper's movies [`Movie`] draws.
///
/// ```
/// use precursors::plot::MovieKind;
/// assert_eq!(MovieKind::default(), MovieKind::ContactArea);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum MovieKind {
    /// Movie S1: the real contact area `A_R` per cell over the interface (mm²), the
    /// precursor front `x = ℓ` drawn as a vertical line (the default).
    #[default]
    ContactArea,
    /// Movie S2: the y-averaged Coulomb stress `τ_C(x, z)` (MPa) over the recorded planes,
    /// its zero contour and the interface's `ℓ` drawn; needs recorded planes
    /// (`fields.planes`).
    CoulombStress,
}

/// What [`Movie::save`] drew.
///
/// ```
/// use precursors::plot::MovieReport;
/// fn say(report: &MovieReport) -> String {
///     format!("{} frames of {} recorded states (every {}-th)", report.frames, report.states, report.stride)
/// }
/// ```
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct MovieReport {
    /// Frames drawn.
    pub frames: usize,
    /// Stable states recorded in `fields.csv`.
    pub states: usize,
    /// Every how many recorded states a frame is drawn (the last state always is).
    pub stride: usize,
    /// The events (indices of `events.csv`) of the states drawn, in order.
    pub events: Vec<usize>,
    /// The colour scale of every frame (mm² for the contact area, MPa for `τ_C`).
    pub colour_range: (f64, f64),
    /// The PNG frames of an older movie of the same name that this one did not overwrite,
    /// removed from the frames' directory ([`Movie::png_frames`]); empty without PNG
    /// frames.
    pub stale_frames_removed: Vec<PathBuf>,
}

/// One recorded stable state.
#[derive(Debug, Clone)]
struct State {
    event: usize,
    load: f64,
    ell: f64,
    /// `A_R` per cell (m², cell order `iy·Nx + ix`).
    area: Vec<f64>,
    /// `τ_C` per plane and column (Pa, order `k·Nx + ix`).
    coulomb: Vec<f64>,
}

/// The recorded fields of a run directory.
#[derive(Debug)]
struct Recording {
    nx: usize,
    ny: usize,
    /// `Lx, Ly, Lz` (m).
    lx: f64,
    ly: f64,
    lz: f64,
    planes: Vec<f64>,
    /// The scene in a line: the directory, the block, `F_N`, the drive, the cells.
    scene: String,
    states: Vec<State>,
}

/// An animated GIF of the fields a run recorded: Movie S1 or S2 of the paper
/// ([`MovieKind`]), one frame per recorded stable state (every
/// [`Movie::every`]-th, at most [`Movie::max_frames`]: a longer run is drawn every k-th
/// state with k raised until the frames fit, the last state always drawn), each titled
/// `F/(μF_N) = …, ℓ/Lx = …`, on one colour scale for the whole movie (a colour bar with its
/// unit, a triangle beyond each end the movie saturates), with the precursor front drawn.
/// Under each frame: a scene line (the directory, the block, `F_N`, the drive, the cells),
/// the share of the frame's cells beyond the colour scale, and the aspect (`not to scale:
/// y drawn 13.2 times stretched against x`). The axes end at the block's faces. Text is in
/// the embedded font. [`Movie::png_frames`] writes the frames as numbered PNGs too.
///
/// ```
/// use precursors::output::RunTables;
/// use precursors::plot::{Movie, MovieKind, PlotError};
/// use precursors::{RunOptions, Scene};
/// let dir = std::env::temp_dir().join(format!("precursors-doc-movie-{}", std::process::id()));
/// std::fs::create_dir_all(&dir)?;
/// // Record the fields of every 2nd stable state, with two planes for τ_C.
/// let scene = Scene::builder()
///     .block(0.010, 0.004, 0.010)
///     .normal_load(100.0)
///     .run_options(RunOptions::new().record_fields(2, &[0.0, 0.005]))
///     .build()?;
/// let mut driver = scene.driver()?;
/// RunTables::create(&dir, &driver)?.run_to_slip(&mut driver, None, |_, _| {})?;
/// let report = Movie::new(&dir, MovieKind::CoulombStress)
///     .max_frames(5)?
///     .size(480, 300)
///     .save(dir.join("s2.gif"))?;
/// assert!(report.frames <= 5 && report.frames >= 2);
/// assert!(std::fs::read(dir.join("s2.gif"))?.starts_with(b"GIF89a"));
/// // Without recorded fields: refused, saying how to record them.
/// std::fs::remove_file(dir.join("fields.csv"))?;
/// let e = Movie::new(&dir, MovieKind::ContactArea).save(dir.join("s1.gif")).unwrap_err();
/// assert!(matches!(e, PlotError::NoFields { .. }) && e.to_string().contains("\"fields\""));
/// std::fs::remove_dir_all(&dir)?;
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone)]
pub struct Movie {
    dir: PathBuf,
    kind: MovieKind,
    every: usize,
    max_frames: usize,
    size: (u32, u32),
    delay: u16,
    colour_range: Option<(f64, f64)>,
    png_frames: Option<PathBuf>,
}

/// The default bound on a movie's frames.
const MAX_FRAMES: usize = 200;

impl Movie {
    /// The movie `kind` of the run directory `dir` (which holds `scene.json` and
    /// `fields.csv`): every recorded state, at most 200 frames, 900 x 560 pixels, 0.1 s
    /// per frame, the colour scale from the whole run.
    pub fn new(dir: impl AsRef<Path>, kind: MovieKind) -> Self {
        Self {
            dir: dir.as_ref().to_path_buf(),
            kind,
            every: 1,
            max_frames: MAX_FRAMES,
            size: (900, 560),
            delay: 10,
            colour_range: None,
            png_frames: None,
        }
    }

    /// Draws every `every`-th recorded state (and the last).
    ///
    /// ```
    /// use precursors::output::RunTables;
    /// use precursors::plot::{Movie, MovieKind};
    /// use precursors::{RunOptions, Scene};
    /// let dir = std::env::temp_dir().join(format!("precursors-doc-every-{}", std::process::id()));
    /// std::fs::create_dir_all(&dir)?;
    /// let scene = Scene::builder()
    ///     .block(0.010, 0.004, 0.010)
    ///     .normal_load(100.0)
    ///     .run_options(RunOptions::new().record_fields(1, &[]))   // every stable state
    ///     .build()?;
    /// let mut driver = scene.driver()?;
    /// RunTables::create(&dir, &driver)?.run_to_slip(&mut driver, None, |_, _| {})?;
    /// let all = Movie::new(&dir, MovieKind::ContactArea).size(480, 300).save(dir.join("all.gif"))?;
    /// let third = Movie::new(&dir, MovieKind::ContactArea)
    ///     .every(3)?
    ///     .size(480, 300)
    ///     .save(dir.join("third.gif"))?;
    /// // The states 0, 3, 6, ... of the recording, and its last.
    /// let mut expected: Vec<usize> = all.events.iter().step_by(3).copied().collect();
    /// if expected.last() != all.events.last() {
    ///     expected.extend(all.events.last());
    /// }
    /// assert_eq!((third.stride, &third.events), (3, &expected));
    /// assert!(Movie::new(&dir, MovieKind::ContactArea).every(0).is_err());
    /// std::fs::remove_dir_all(&dir)?;
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    ///
    /// # Errors
    /// [`PlotError::Figure`] for `every = 0`.
    pub fn every(mut self, every: usize) -> Result<Self> {
        if every == 0 {
            return Err(self.refuse("a movie draws every k-th recorded state, k >= 1: not 0"));
        }
        self.every = every;
        Ok(self)
    }

    /// At most `frames` frames (default 200): a run with more recorded states is drawn
    /// every k-th state, k the smallest that fits (the last state always drawn).
    ///
    /// # Errors
    /// [`PlotError::Figure`] for fewer than 2 frames.
    pub fn max_frames(mut self, frames: usize) -> Result<Self> {
        if frames < 2 {
            return Err(self.refuse(&format!(
                "a movie has at least 2 frames (its first and last states): not {frames}"
            )));
        }
        self.max_frames = frames;
        Ok(self)
    }

    /// The frame size in pixels (default 900 x 560; from 200 x 150 to 16384 x 16384).
    pub fn size(mut self, width: u32, height: u32) -> Self {
        self.size = (width, height);
        self
    }

    /// Seconds each frame is shown (default 0.1; GIF counts hundredths: from 0.01 to 655 s).
    ///
    /// ```
    /// use precursors::output::RunTables;
    /// use precursors::plot::{Movie, MovieKind};
    /// use precursors::{RunOptions, Scene};
    /// let dir = std::env::temp_dir().join(format!("precursors-doc-duration-{}", std::process::id()));
    /// std::fs::create_dir_all(&dir)?;
    /// let scene = Scene::builder()
    ///     .block(0.010, 0.004, 0.010)
    ///     .normal_load(100.0)
    ///     .run_options(RunOptions::new().record_fields(1, &[]))   // every stable state
    ///     .build()?;
    /// let mut driver = scene.driver()?;
    /// RunTables::create(&dir, &driver)?.run_to_slip(&mut driver, None, |_, _| {})?;
    /// Movie::new(&dir, MovieKind::ContactArea)
    ///     .frame_duration(0.25)?
    ///     .size(480, 300)
    ///     .save(dir.join("slow.gif"))?;
    /// // The GIF's first graphic control block: 21 F9 04, flags, the delay in hundredths.
    /// let gif = std::fs::read(dir.join("slow.gif"))?;
    /// let at = gif.windows(3).position(|w| w == [0x21, 0xF9, 0x04]).unwrap();
    /// assert_eq!(u16::from_le_bytes([gif[at + 4], gif[at + 5]]), 25);
    /// assert!(Movie::new(&dir, MovieKind::ContactArea).frame_duration(0.001).is_err());
    /// std::fs::remove_dir_all(&dir)?;
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    ///
    /// # Errors
    /// [`PlotError::Figure`] outside that range (or not finite).
    pub fn frame_duration(mut self, seconds: f64) -> Result<Self> {
        let hundredths = (seconds * 100.0).round();
        if !(1.0..=65535.0).contains(&hundredths) {
            return Err(self.refuse(&format!(
                "a frame's duration is 0.01 to 655 s (GIF counts hundredths): not {seconds} s"
            )));
        }
        self.delay = hundredths as u16;
        Ok(self)
    }

    /// A fixed colour scale (mm² for the contact area, MPa for `τ_C`) instead of the
    /// one from the run (contact area: 0 to the 98th percentile of the cells' values over
    /// the movie; `τ_C`: symmetric about 0, to the 98th percentile of `|τ_C|`; both
    /// saturating beyond). Checked
    /// when the movie is drawn (finite, increasing).
    ///
    /// ```
    /// use precursors::output::RunTables;
    /// use precursors::plot::{Movie, MovieKind};
    /// use precursors::{RunOptions, Scene};
    /// let dir = std::env::temp_dir().join(format!("precursors-doc-range-{}", std::process::id()));
    /// std::fs::create_dir_all(&dir)?;
    /// let scene = Scene::builder()
    ///     .block(0.010, 0.004, 0.010)
    ///     .normal_load(100.0)
    ///     .run_options(RunOptions::new().record_fields(1, &[]))   // every stable state
    ///     .build()?;
    /// let mut driver = scene.driver()?;
    /// RunTables::create(&dir, &driver)?.run_to_slip(&mut driver, None, |_, _| {})?;
    /// let report = Movie::new(&dir, MovieKind::ContactArea)
    ///     .colour_range(0.0, 0.5)                         // mm² of contact per cell
    ///     .size(480, 300)
    ///     .save(dir.join("fixed.gif"))?;
    /// assert_eq!(report.colour_range, (0.0, 0.5));
    /// // Checked when drawn: a decreasing range is refused.
    /// let reversed = Movie::new(&dir, MovieKind::ContactArea).colour_range(0.5, 0.0);
    /// assert!(reversed.save(dir.join("reversed.gif")).is_err());
    /// std::fs::remove_dir_all(&dir)?;
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn colour_range(mut self, low: f64, high: f64) -> Self {
        self.colour_range = Some((low, high));
        self
    }

    /// Also writes every frame of the GIF as a PNG of the frame's size into the directory
    /// `dir` (made if missing), numbered from 0 in the order shown, for an encoder of the
    /// user's choice: `STEM_0000.png`, `STEM_0001.png`, … (`STEM` the GIF's file stem, as
    /// many digits as the last number needs, at least 4; e.g. `ffmpeg -framerate 10 -i
    /// contact_area_%04d.png movie.mp4`). The directory is the movie's: once every frame
    /// is written, the frames `STEM_<number>.png` of an older movie of the same name that
    /// these did not overwrite (a longer one's last frames, which the encoder would show
    /// after these) are removed and listed in [`MovieReport::stale_frames_removed`]; files
    /// of other names stay. A movie stopped by [`Movie::save_until`] leaves the frames
    /// written so far, and removes none. A frame's name that is a symbolic link is
    /// refused, never written through.
    ///
    /// ```
    /// use precursors::output::RunTables;
    /// use precursors::plot::{Movie, MovieKind};
    /// use precursors::{RunOptions, Scene};
    /// let dir = std::env::temp_dir().join(format!("precursors-doc-png-{}", std::process::id()));
    /// std::fs::create_dir_all(&dir)?;
    /// let scene = Scene::builder()
    ///     .block(0.010, 0.004, 0.010)
    ///     .normal_load(100.0)
    ///     .run_options(RunOptions::new().record_fields(2, &[]))
    ///     .build()?;
    /// let mut driver = scene.driver()?;
    /// RunTables::create(&dir, &driver)?.run_to_slip(&mut driver, None, |_, _| {})?;
    /// let report = Movie::new(&dir, MovieKind::ContactArea)
    ///     .max_frames(3)?
    ///     .size(480, 300)
    ///     .png_frames(dir.join("frames"))
    ///     .save(dir.join("s1.gif"))?;
    /// // One PNG per frame of the GIF, numbered from 0 after the GIF's stem.
    /// for k in 0..report.frames {
    ///     let png = std::fs::read(dir.join("frames").join(format!("s1_{k:04}.png")))?;
    ///     assert!(png.starts_with(b"\x89PNG"));
    /// }
    /// assert!(!dir.join("frames").join(format!("s1_{:04}.png", report.frames)).exists());
    /// std::fs::remove_dir_all(&dir)?;
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn png_frames(mut self, dir: impl AsRef<Path>) -> Self {
        self.png_frames = Some(dir.as_ref().to_path_buf());
        self
    }

    fn refuse(&self, reason: &str) -> PlotError {
        PlotError::Figure {
            path: Some(self.dir.clone()),
            reason: reason.to_string(),
        }
    }

    /// Draws the movie into `path` (an animated GIF; the name must end in `.gif`).
    ///
    /// # Errors
    /// As [`Movie::save_with_progress`].
    pub fn save(&self, path: impl AsRef<Path>) -> Result<MovieReport> {
        self.save_with_progress(path, |_, _| {})
    }

    /// [`Movie::save`], calling `progress(drawn, frames)` after each frame drawn (a
    /// progress bar).
    ///
    /// ```
    /// use precursors::output::RunTables;
    /// use precursors::plot::{Movie, MovieKind};
    /// use precursors::{RunOptions, Scene};
    /// let dir = std::env::temp_dir().join(format!("precursors-doc-progress-{}", std::process::id()));
    /// std::fs::create_dir_all(&dir)?;
    /// let scene = Scene::builder()
    ///     .block(0.010, 0.004, 0.010)
    ///     .normal_load(100.0)
    ///     .run_options(RunOptions::new().record_fields(1, &[]))   // every stable state
    ///     .build()?;
    /// let mut driver = scene.driver()?;
    /// RunTables::create(&dir, &driver)?.run_to_slip(&mut driver, None, |_, _| {})?;
    /// let mut calls = Vec::new();
    /// let report = Movie::new(&dir, MovieKind::ContactArea)
    ///     .size(480, 300)
    ///     .save_with_progress(dir.join("s1.gif"), |drawn, frames| calls.push((drawn, frames)))?;
    /// // Once per frame, counting up to the movie's frames.
    /// let expected: Vec<(usize, usize)> = (1..=report.frames).map(|k| (k, report.frames)).collect();
    /// assert_eq!(calls, expected);
    /// std::fs::remove_dir_all(&dir)?;
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    ///
    /// # Errors
    /// [`PlotError::NoFields`] when the directory has no recorded fields (no
    /// `fields.csv`, or, for [`MovieKind::CoulombStress`], no planes recorded); in
    /// [`PlotError::Core`]: [`Error::Io`] (a file that cannot be read or written: the GIF is
    /// written atomically), [`Error::CorruptTable`] or [`Error::NonFiniteCell`] for a
    /// damaged `fields.csv`, the scene record's errors, a PNG frame that cannot be
    /// written ([`Movie::png_frames`]); [`PlotError::Figure`] for a name not ending in
    /// `.gif`, a size or colour range out of range.
    pub fn save_with_progress(
        &self,
        path: impl AsRef<Path>,
        mut progress: impl FnMut(usize, usize),
    ) -> Result<MovieReport> {
        let report = self.save_until(path, |drawn, frames| {
            progress(drawn, frames);
            ControlFlow::Continue(())
        })?;
        // The callback never stops the movie.
        report.ok_or_else(|| self.refuse("the movie was stopped"))
    }

    /// [`Movie::save`], calling `progress(drawn, frames)` after each frame drawn, which
    /// may stop it (`ControlFlow::Break`: a cancel button, Ctrl-C): then nothing is
    /// written and `Ok(None)` is returned.
    ///
    /// ```
    /// use precursors::output::RunTables;
    /// use precursors::plot::{Movie, MovieKind};
    /// use precursors::{RunOptions, Scene};
    /// use std::ops::ControlFlow;
    /// let dir = std::env::temp_dir().join(format!("precursors-doc-stop-{}", std::process::id()));
    /// std::fs::create_dir_all(&dir)?;
    /// let scene = Scene::builder()
    ///     .block(0.010, 0.004, 0.010)
    ///     .normal_load(100.0)
    ///     .run_options(RunOptions::new().record_fields(2, &[]))
    ///     .build()?;
    /// let mut driver = scene.driver()?;
    /// RunTables::create(&dir, &driver)?.run_to_slip(&mut driver, None, |_, _| {})?;
    /// let movie = Movie::new(&dir, MovieKind::ContactArea).max_frames(4)?.size(480, 300);
    /// // Stopped after the first frame drawn (a cancel button): nothing is written.
    /// let stopped = movie.save_until(dir.join("s1.gif"), |drawn, _frames| {
    ///     if drawn >= 1 { ControlFlow::Break(()) } else { ControlFlow::Continue(()) }
    /// })?;
    /// assert!(stopped.is_none() && !dir.join("s1.gif").exists());
    /// // Let through, it is the movie `save` draws.
    /// let report = movie.save_until(dir.join("s1.gif"), |_, _| ControlFlow::Continue(()))?;
    /// assert!(report.is_some_and(|r| r.frames >= 2) && dir.join("s1.gif").exists());
    /// std::fs::remove_dir_all(&dir)?;
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    ///
    /// # Errors
    /// As [`Movie::save_with_progress`].
    pub fn save_until(
        &self,
        path: impl AsRef<Path>,
        mut progress: impl FnMut(usize, usize) -> ControlFlow<()>,
    ) -> Result<Option<MovieReport>> {
        let path = path.as_ref();
        // A reader of the run directory: no run writes it while the movie is drawn.
        let _lock = crate::lock::ReadLock::lock(&self.dir)?;
        let is_gif = path
            .extension()
            .and_then(|e| e.to_str())
            .is_some_and(|e| e.eq_ignore_ascii_case("gif"));
        if !is_gif {
            return Err(PlotError::Figure {
                path: Some(path.to_path_buf()),
                reason: "a movie is an animated GIF: the file name must end in .gif".into(),
            });
        }
        super::check_size(path, self.size)?;
        let (recording, report) = self.plan()?;
        let extend = saturated_ends(self.kind, &recording, report.colour_range);
        let frames_dir = self.png_frames_dir()?;
        let stem = path
            .file_stem()
            .map_or_else(|| "frame".into(), |s| s.to_string_lossy().into_owned());
        let digits = (report.frames.saturating_sub(1)).to_string().len().max(4);
        let mut gif = GifWriter::new(path, self.size, self.delay, self.palette())?;
        let states = report.events.len();
        for (k, state) in self.frames(&recording, &report).enumerate() {
            let map = self.frame_map(&recording, state, report.colour_range, extend)?;
            let pixels = map_pixels(&map, path)?;
            if let Some(dir) = &frames_dir {
                let png = dir.join(format!("{stem}_{k:0digits$}.png"));
                let bytes = encode_png(&pixels, self.size).map_err(|e| PlotError::Figure {
                    path: Some(png.clone()),
                    reason: format!("encoding the PNG: {e}"),
                })?;
                crate::files::write_atomically(&png, &bytes, "writing movie frame")?;
            }
            gif.push(&pixels)?;
            if progress(k + 1, states).is_break() {
                return Ok(None);
            }
        }
        let stale_frames_removed = match &frames_dir {
            Some(dir) => remove_stale_frames(dir, &stem, report.frames, digits)?,
            None => Vec::new(),
        };
        let bytes = gif.finish()?;
        crate::files::write_atomically(path, &bytes, "writing movie")?;
        Ok(Some(MovieReport {
            stale_frames_removed,
            ..report
        }))
    }

    /// The directory of the PNG frames, made if missing (`None`: no PNG frames).
    fn png_frames_dir(&self) -> Result<Option<PathBuf>> {
        let Some(dir) = &self.png_frames else {
            return Ok(None);
        };
        std::fs::create_dir_all(dir)
            .map_err(|e| Error::io("making the directory of the movie's PNG frames", dir, e))?;
        Ok(Some(dir.clone()))
    }

    /// The colour map of this movie's kind.
    fn palette(&self) -> Palette {
        match self.kind {
            MovieKind::CoulombStress => Palette::Diverging,
            _ => Palette::Sequential,
        }
    }

    /// Draws frame `frame` (0-based, of the frames [`Movie::save`] draws) as a still PNG
    /// or SVG (chosen by the extension), e.g. to show a few frames in a document.
    ///
    /// ```
    /// use precursors::output::RunTables;
    /// use precursors::plot::{Movie, MovieKind};
    /// use precursors::{RunOptions, Scene};
    /// let dir = std::env::temp_dir().join(format!("precursors-doc-still-{}", std::process::id()));
    /// std::fs::create_dir_all(&dir)?;
    /// let scene = Scene::builder()
    ///     .block(0.010, 0.004, 0.010)
    ///     .normal_load(100.0)
    ///     .run_options(RunOptions::new().record_fields(1, &[]))   // every stable state
    ///     .build()?;
    /// let mut driver = scene.driver()?;
    /// RunTables::create(&dir, &driver)?.run_to_slip(&mut driver, None, |_, _| {})?;
    /// let movie = Movie::new(&dir, MovieKind::ContactArea).size(480, 300);
    /// let report = movie.save_frame(0, dir.join("first.png"))?;
    /// assert!(std::fs::read(dir.join("first.png"))?.starts_with(b"\x89PNG"));
    /// movie.save_frame(report.frames - 1, dir.join("last.svg"))?;   // the last frame, as SVG
    /// assert!(std::fs::read_to_string(dir.join("last.svg"))?.contains("<svg"));
    /// assert!(movie.save_frame(report.frames, dir.join("past.png")).is_err());
    /// std::fs::remove_dir_all(&dir)?;
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    ///
    /// # Errors
    /// As [`Movie::save_with_progress`]; [`PlotError::Figure`] for a frame past the last.
    pub fn save_frame(&self, frame: usize, path: impl AsRef<Path>) -> Result<MovieReport> {
        let _lock = crate::lock::ReadLock::lock(&self.dir)?;
        let (recording, report) = self.plan()?;
        let Some(state) = self.frames(&recording, &report).nth(frame) else {
            return Err(self.refuse(&format!(
                "the movie has {} frames (0 to {}): no frame {frame}",
                report.frames,
                report.frames - 1
            )));
        };
        let extend = saturated_ends(self.kind, &recording, report.colour_range);
        self.frame_map(&recording, state, report.colour_range, extend)?
            .save(path)?;
        Ok(report)
    }

    /// The recording, the frames' states and the colour scale.
    fn plan(&self) -> Result<(Recording, MovieReport)> {
        let recording = read_recording(&self.dir)?;
        if self.kind == MovieKind::CoulombStress && recording.planes.is_empty() {
            return Err(PlotError::NoFields {
                dir: self.dir.clone(),
                reason: format!(
                    "its {FIELDS_FILE} holds the contact area only: the scene recorded no \
                     planes of the Coulomb stress (`fields.planes`)"
                ),
            });
        }
        let n = recording.states.len();
        // The smallest stride (a multiple of nothing: any k >= every) whose frames, the
        // last state added, fit.
        let mut stride = self.every;
        while frame_count(n, stride) > self.max_frames {
            stride = stride.max(n.div_ceil(self.max_frames - 1)).max(stride + 1);
        }
        let indices = frame_indices(n, stride);
        let range = match self.colour_range {
            Some(range) => axis_range(&self.dir, "colour", Some(range), std::iter::empty())?,
            None => self.automatic_range(&recording),
        };
        let report = MovieReport {
            frames: indices.len(),
            states: n,
            stride,
            events: indices.iter().map(|&i| recording.states[i].event).collect(),
            colour_range: range,
            stale_frames_removed: Vec::new(),
        };
        Ok((recording, report))
    }

    fn frames<'a>(
        &self,
        recording: &'a Recording,
        report: &MovieReport,
    ) -> impl Iterator<Item = &'a State> {
        frame_indices(recording.states.len(), report.stride)
            .into_iter()
            .map(move |i| &recording.states[i])
    }

    /// The colour scale of the whole movie: `A_R` from 0 to the 98th percentile of the
    /// cells' values (mm²), `τ_C` symmetric about 0 to the 98th percentile of `|τ_C|`
    /// (MPa); both saturate beyond.
    fn automatic_range(&self, recording: &Recording) -> (f64, f64) {
        match self.kind {
            MovieKind::CoulombStress => {
                let magnitudes = recording
                    .states
                    .iter()
                    .flat_map(|s| s.coulomb.iter().map(|v| v.abs() / 1e6));
                let top = percentile_98(magnitudes.collect());
                let top = if top > 0.0 { top } else { 1.0 };
                (-top, top)
            }
            _ => {
                // Not the largest: near global slip the last attached sites of the paper's
                // area law reach areas far beyond their cell's, which would leave every
                // other cell at the bottom of the scale.
                let values = recording
                    .states
                    .iter()
                    .flat_map(|s| s.area.iter().map(|a| a * 1e6));
                let top = percentile_98(values.collect());
                (0.0, if top > 0.0 { top } else { 1.0 })
            }
        }
    }

    /// The map of one frame (`extend`: the ends of the colour scale the movie saturates).
    fn frame_map(
        &self,
        r: &Recording,
        state: &State,
        range: (f64, f64),
        extend: (bool, bool),
    ) -> Result<Map> {
        let (lx, ly) = (r.lx * 1e3, r.ly * 1e3);
        let title = format!(
            "F/(μF_N) = {:.3}, ℓ/Lx = {:.3}  (event {})",
            state.load, state.ell, state.event
        );
        let ell = state.ell * lx;
        let mut map = match self.kind {
            MovieKind::CoulombStress => {
                let np = r.planes.len();
                let values: Vec<f64> = state.coulomb.iter().map(|v| v / 1e6).collect();
                let edges = plane_edges(&r.planes, r.lz);
                let mut overlay = zero_contour(&values, r.nx, &edges, lx);
                // The interface's precursor: a bar along the bottom, a tick at its tip.
                let (bottom, top) = (edges[0], edges[np]);
                let tick = 0.04 * (top - bottom);
                overlay.push(vec![(0.0, bottom), (ell, bottom)]);
                overlay.push(vec![(ell, bottom), (ell, bottom + tick)]);
                let mut map = Map::new(r.nx, np, values)?
                    .labels(&title, "x (mm)", "z (mm)", "τ_C = |τ| − μ|σ| (MPa)")
                    .x_range(0.0, lx)
                    .y_range(bottom, top)
                    .colour_scale(Palette::Diverging, Some(range));
                map.row_edges = Some(edges);
                map.overlay = overlay;
                map
            }
            _ => {
                let values: Vec<f64> = state.area.iter().map(|a| a * 1e6).collect();
                let mut map = Map::new(r.nx, r.ny, values)?
                    .labels(&title, "x (mm)", "y (mm)", "A_R per cell (mm²)")
                    .x_range(0.0, lx)
                    .y_range(0.0, ly)
                    .colour_scale(Palette::Sequential, Some(range));
                map.overlay = vec![vec![(ell, 0.0), (ell, ly)]];
                map
            }
        };
        map.notes = vec![r.scene.clone()];
        map.extend = Some(extend);
        Ok(map.same_unit_axes().size(self.size.0, self.size.1))
    }
}

/// The ends of the colour scale `range` (below, above) that some recorded value of the
/// movie passes: marked on every frame's colour bar, so that the bar stays the same.
fn saturated_ends(kind: MovieKind, r: &Recording, range: (f64, f64)) -> (bool, bool) {
    let values = r.states.iter().flat_map(|s| match kind {
        MovieKind::CoulombStress => s.coulomb.iter().map(|v| v / 1e6).collect::<Vec<_>>(),
        _ => s.area.iter().map(|a| a * 1e6).collect(),
    });
    values
        .filter(|v| v.is_finite())
        .fold((false, false), |(below, above), v| {
            (below || v < range.0, above || v > range.1)
        })
}

/// The 98th percentile of `values` (the value at rank `⌊0.98·n⌋` of the sorted values;
/// 0 for none).
fn percentile_98(mut values: Vec<f64>) -> f64 {
    values.sort_by(f64::total_cmp);
    values
        .get((values.len() as f64 * 0.98) as usize)
        .or(values.last())
        .copied()
        .unwrap_or(0.0)
}

/// Frames of `n` states drawn every `stride`-th, the last added.
fn frame_count(n: usize, stride: usize) -> usize {
    frame_indices(n, stride).len()
}

/// Removes from `dir` the PNG frames `STEM_<number>.png` (at least 4 digits) that this
/// movie (`frames` frames of `digits` digits) did not write: an older, longer movie's
/// last frames, which an encoder reading `STEM_%04d.png` would show after this movie's.
/// Files of other names stay. Returns the frames removed, in order.
///
/// # Errors
/// [`Error::Io`] when `dir` cannot be read or a frame removed;
/// [`Error::NotARegularFile`] for a frame's name that is a link or not a regular file.
fn remove_stale_frames(
    dir: &Path,
    stem: &str,
    frames: usize,
    digits: usize,
) -> Result<Vec<PathBuf>> {
    const READING: &str = "reading the directory of the movie's PNG frames";
    let mut removed = Vec::new();
    for entry in std::fs::read_dir(dir).map_err(|e| Error::io(READING, dir, e))? {
        let entry = entry.map_err(|e| Error::io(READING, dir, e))?;
        let name = entry.file_name();
        let Some(number) = name
            .to_str()
            .and_then(|n| n.strip_prefix(stem))
            .and_then(|n| n.strip_prefix('_'))
            .and_then(|n| n.strip_suffix(".png"))
        else {
            continue;
        };
        let a_frame = number.len() >= 4 && number.bytes().all(|b| b.is_ascii_digit());
        let written = number.len() == digits && number.parse::<usize>().is_ok_and(|k| k < frames);
        if a_frame && !written {
            let path = entry.path();
            crate::files::remove_if_exists(&path, "removing a frame of an older movie")?;
            removed.push(path);
        }
    }
    removed.sort();
    Ok(removed)
}

fn frame_indices(n: usize, stride: usize) -> Vec<usize> {
    let mut indices: Vec<usize> = (0..n).step_by(stride.max(1)).collect();
    if n > 0 && indices.last() != Some(&(n - 1)) {
        indices.push(n - 1);
    }
    indices
}

/// The rows' edges (mm) of planes at heights `planes` (m, increasing, within the block
/// `0..=lz`): each plane owns the band of the heights nearer to it than to any other
/// plane, from the midpoint to its lower neighbour (the interface, z = 0, for the
/// lowest) to the midpoint to its upper one (the block's top face, z = Lz, for the
/// highest). The rows thus tile the slab, ending at the block's faces.
fn plane_edges(planes: &[f64], lz: f64) -> Vec<f64> {
    let z: Vec<f64> = planes.iter().map(|z| z * 1e3).collect();
    let mut edges = Vec::with_capacity(z.len() + 1);
    edges.push(0.0);
    edges.extend(z.windows(2).map(|w| (w[0] + w[1]) / 2.0));
    edges.push(lz * 1e3);
    edges
}

/// The boundary of the region `τ_C > 0` along the cells' edges: a segment between every
/// two neighbouring cells of opposite sign (`values`: rows of `nx` columns, the rows'
/// `edges`, the x range `0..lx`).
fn zero_contour(values: &[f64], nx: usize, edges: &[f64], lx: f64) -> Vec<Vec<(f64, f64)>> {
    let dx = lx / nx as f64;
    let positive = |r: usize, c: usize| values[r * nx + c] > 0.0;
    let rows = values.len() / nx;
    let mut lines = Vec::new();
    for r in 0..rows {
        for c in 0..nx {
            if c + 1 < nx && positive(r, c) != positive(r, c + 1) {
                let x = (c + 1) as f64 * dx;
                lines.push(vec![(x, edges[r]), (x, edges[r + 1])]);
            }
            if r + 1 < rows && positive(r, c) != positive(r + 1, c) {
                let z = edges[r + 1];
                lines.push(vec![(c as f64 * dx, z), ((c + 1) as f64 * dx, z)]);
            }
        }
    }
    lines
}

/// A map's RGB pixels at its size.
fn map_pixels(map: &Map, path: &Path) -> Result<Vec<u8>> {
    register_font()?;
    let x = axis_range(path, "x", Some(map.x_range), std::iter::empty())?;
    let y = axis_range(path, "y", Some(map.y_range), std::iter::empty())?;
    let c = axis_range(path, "colour", map.colour_range, map.values.iter().copied())?;
    let size = map.size;
    let mut pixels = vec![0u8; 3 * size.0 as usize * size.1 as usize];
    paint(
        BitMapBackend::with_buffer(&mut pixels, size).into_drawing_area(),
        &MapDrawing { map, x, y, c },
    )
    .map_err(|reason| PlotError::Figure {
        path: Some(path.to_path_buf()),
        reason,
    })?;
    Ok(pixels)
}

/// The indices a GIF has: 0..=254 colours, 255 transparent (a pixel as in the frame
/// before).
const TRANSPARENT: u8 = 255;
/// Colours of the GIF's palette taken along the colour map (the rest are greys).
const MAP_COLOURS: usize = 192;

/// A GIF's one palette for the frames of a colour map, with each pixel's nearest entry
/// (a table over all 2^24 colours, filled as colours are met: a frame has a few
/// thousand).
struct GifPalette {
    colours: Vec<[u8; 3]>,
    lookup: Vec<u8>,
}

impl GifPalette {
    /// [`MAP_COLOURS`] colours evenly along `palette` (its ends included: a step is about
    /// 2 units of a channel, below what the eye tells apart, so no band shows), the greys
    /// from black to white for the text's anti-aliased edges, the grey of cells without
    /// a value; 255 entries.
    fn new(palette: Palette) -> Self {
        let mut colours: Vec<[u8; 3]> = (0..MAP_COLOURS)
            .map(|k| {
                let c = palette.colour(k as f64 / (MAP_COLOURS - 1) as f64);
                [c.0, c.1, c.2]
            })
            .collect();
        colours.push([200, 200, 200]);
        let greys = usize::from(TRANSPARENT) - colours.len();
        colours.extend((0..greys).map(|k| {
            let v = (255.0 * k as f64 / (greys - 1) as f64).round() as u8;
            [v, v, v]
        }));
        Self {
            colours,
            lookup: vec![TRANSPARENT; 1 << 24],
        }
    }

    /// The entries as the GIF's global colour table (256 entries, the last unused).
    fn table(&self) -> Vec<u8> {
        let mut table: Vec<u8> = self.colours.iter().flatten().copied().collect();
        table.extend([255, 0, 255]);
        table
    }

    /// The index of the entry nearest to `rgb`.
    fn index(&mut self, rgb: &[u8]) -> u8 {
        let key = (usize::from(rgb[0]) << 16) | (usize::from(rgb[1]) << 8) | usize::from(rgb[2]);
        if self.lookup[key] == TRANSPARENT {
            let distance = |c: &[u8; 3]| -> i32 {
                (0..3)
                    .map(|i| (i32::from(c[i]) - i32::from(rgb[i])).pow(2))
                    .sum()
            };
            let nearest = (0..self.colours.len())
                .min_by_key(|&k| distance(&self.colours[k]))
                .unwrap_or(0);
            self.lookup[key] = nearest as u8;
        }
        self.lookup[key]
    }
}

/// An animated GIF encoded in memory: the first frame whole, each later one the
/// rectangle of the pixels that changed, the unchanged ones in it transparent (the
/// frame before shows through).
struct GifWriter<'a> {
    path: &'a Path,
    encoder: gif::Encoder<Vec<u8>>,
    palette: GifPalette,
    size: (u16, u16),
    delay: u16,
    /// The indices shown after the frames so far (none before the first).
    shown: Option<Vec<u8>>,
}

impl<'a> GifWriter<'a> {
    fn new(path: &'a Path, size: (u32, u32), delay: u16, palette: Palette) -> Result<Self> {
        let palette = GifPalette::new(palette);
        // The size was checked (at most 16384, within a GIF's 65535).
        let size = (size.0 as u16, size.1 as u16);
        let mut encoder = gif::Encoder::new(Vec::new(), size.0, size.1, &palette.table())
            .map_err(|e| gif_failed(path, e))?;
        encoder
            .set_repeat(gif::Repeat::Infinite)
            .map_err(|e| gif_failed(path, e))?;
        Ok(Self {
            path,
            encoder,
            palette,
            size,
            delay,
            shown: None,
        })
    }

    /// Adds the frame of RGB `pixels`.
    fn push(&mut self, pixels: &[u8]) -> Result<()> {
        let indices: Vec<u8> = pixels
            .chunks_exact(3)
            .map(|p| self.palette.index(p))
            .collect();
        let width = usize::from(self.size.0);
        let (left, top, w, h, buffer) = match &self.shown {
            None => (0, 0, self.size.0, self.size.1, indices.clone()),
            Some(shown) => changed(shown, &indices, width),
        };
        let frame = gif::Frame {
            left,
            top,
            width: w,
            height: h,
            buffer: buffer.into(),
            delay: self.delay,
            dispose: gif::DisposalMethod::Keep,
            transparent: self.shown.is_some().then_some(TRANSPARENT),
            ..gif::Frame::default()
        };
        self.encoder
            .write_frame(&frame)
            .map_err(|e| gif_failed(self.path, e))?;
        self.shown = Some(indices);
        Ok(())
    }

    /// The GIF's bytes.
    fn finish(self) -> Result<Vec<u8>> {
        self.encoder
            .into_inner()
            .map_err(|e| gif_failed(self.path, e))
    }
}

/// The rectangle of the pixels where `now` differs from `shown` (rows of `width`):
/// its left, top, width, height and indices, the unchanged pixels in it transparent;
/// one transparent pixel when none changed.
fn changed(shown: &[u8], now: &[u8], width: usize) -> (u16, u16, u16, u16, Vec<u8>) {
    let (mut x0, mut y0, mut x1, mut y1) = (usize::MAX, usize::MAX, 0, 0);
    for (k, (a, b)) in shown.iter().zip(now).enumerate() {
        if a != b {
            let (x, y) = (k % width, k / width);
            (x0, y0, x1, y1) = (x0.min(x), y0.min(y), x1.max(x), y1.max(y));
        }
    }
    if x0 == usize::MAX {
        return (0, 0, 1, 1, vec![TRANSPARENT]);
    }
    let mut buffer = Vec::with_capacity((x1 - x0 + 1) * (y1 - y0 + 1));
    for y in y0..=y1 {
        let row = y * width;
        buffer.extend((x0..=x1).map(|x| {
            if shown[row + x] == now[row + x] {
                TRANSPARENT
            } else {
                now[row + x]
            }
        }));
    }
    // Within the frame's size, itself within a GIF's 65535.
    (
        x0 as u16,
        y0 as u16,
        (x1 - x0 + 1) as u16,
        (y1 - y0 + 1) as u16,
        buffer,
    )
}

fn gif_failed(path: &Path, e: gif::EncodingError) -> PlotError {
    PlotError::Figure {
        path: Some(path.to_path_buf()),
        reason: format!("encoding the GIF: {e}"),
    }
}

/// The fields recorded in `dir`: its scene record gives the grid and the planes,
/// `fields.csv` the states.
fn read_recording(dir: &Path) -> Result<Recording> {
    let table = dir.join(FIELDS_FILE);
    let no_fields = |reason: String| PlotError::NoFields {
        dir: dir.to_path_buf(),
        reason,
    };
    if !table.is_file() {
        let partial = dir.join(format!("{FIELDS_FILE}{PARTIAL}"));
        return Err(no_fields(if partial.is_file() {
            format!(
                "its run has not reached global slip ({FIELDS_FILE}{PARTIAL}): resume it \
                 (`precursors resume`) to finish the table"
            )
        } else {
            format!("it holds no {FIELDS_FILE}")
        }));
    }
    let record = dir.join(RUN_SCENE);
    if !record.is_file() {
        return Err(no_fields(format!(
            "it holds {FIELDS_FILE} but no {RUN_SCENE}, the record of the run's scene"
        )));
    }
    let builder = crate::scene::SceneBuilder::from_json_file(&record)?;
    let grid = builder.grid()?;
    let (nx, ny) = (grid.nx(), grid.ny());
    let planes = builder.current_run().field_planes().to_vec();
    let text = crate::files::read_text(&table, "reading table")?;
    let corrupt = |reason: String| Error::CorruptTable {
        path: Some(table.clone()),
        reason,
    };
    let header = fields_header(nx);
    let mut lines = text.lines();
    if lines.next() != Some(header.as_str()) {
        return Err(corrupt(format!(
            "line 1 is not the header of {FIELDS_FILE} for the {nx} columns of the scene in \
             {RUN_SCENE}"
        ))
        .into());
    }
    // The run's tables, checked, for the states the recording must hold.
    let run = RunRecord::read(dir)?;
    let every = builder.current_run().fields_every().max(1);
    let states = read_states(lines, &table, &run, every, (nx, ny), &planes, &header)?;
    if states.is_empty() {
        return Err(no_fields(format!("its {FIELDS_FILE} holds no state")));
    }
    let block = grid.block();
    // The directory's name as written: its underscores are no subscripts.
    let mut scene = format!(
        "{}: {}",
        super::figures::name(dir).replace('_', "\\_"),
        super::figures::run_title(dir)
    );
    if !planes.is_empty() {
        scene.push_str(&format!(", {} planes", planes.len()));
    }
    Ok(Recording {
        nx,
        ny,
        lx: block.lx(),
        ly: block.ly(),
        lz: block.lz(),
        planes,
        scene,
        states,
    })
}

/// The states of `fields.csv` (`lines`: its rows after the header; `table` for the
/// messages), each row checked ([`fields_row`]) and the states against the run's
/// `curve.csv` (`run`): every `every`-th stable state from the first, in order, at its
/// load and ℓ, each whole. An empty table gives no state (the caller says so).
fn read_states<'a>(
    lines: impl Iterator<Item = &'a str>,
    table: &Path,
    run: &RunRecord,
    every: usize,
    (nx, ny): (usize, usize),
    planes: &[f64],
    header: &str,
) -> Result<Vec<State>> {
    let corrupt = |reason: String| Error::CorruptTable {
        path: Some(table.to_path_buf()),
        reason,
    };
    let expected: Vec<&crate::output::check::CurveRow> = run.curve.iter().step_by(every).collect();
    let header_cells: Vec<&str> = header.split(',').collect();
    let per_state = ny + planes.len();
    let mut states: Vec<State> = Vec::new();
    let mut texts: (&str, &str) = ("", "");
    for (n, row) in lines.enumerate() {
        let line = n + 2;
        let within = n % per_state;
        let r =
            fields_row(line, &header_cells, row, within, ny, planes).map_err(|b| b.at(table))?;
        if within == 0 {
            // The next state the scene records: the `every`-th stable state of curve.csv
            // from the first, at its load and ℓ.
            let Some(want) = expected.get(states.len()) else {
                return Err(corrupt(format!(
                    "line {line}: event {} is a state more than the {} the scene records \
                     (every {every}-th of the {} stable states of curve.csv)",
                    r.event,
                    expected.len(),
                    run.curve.len()
                ))
                .into());
            };
            if r.event != want.event
                || r.load_text != want.load_text
                || r.precursor_text != want.precursor_text
            {
                return Err(corrupt(format!(
                    "line {line}: event {} at F/(μF_N) = {}, ℓ/Lx = {}, but the state recorded \
                     there is event {} at {}, {} (curve.csv): states out of order, repeated, \
                     edited, or from another run",
                    r.event,
                    r.load_text,
                    r.precursor_text,
                    want.event,
                    want.load_text,
                    want.precursor_text
                ))
                .into());
            }
            texts = (r.load_text, r.precursor_text);
            states.push(State {
                event: r.event,
                load: r.load,
                ell: r.precursor_over_lx,
                area: Vec::with_capacity(nx * ny),
                coulomb: Vec::with_capacity(nx * planes.len()),
            });
        }
        let state = states.last_mut().expect("a state was started");
        if r.event != state.event || (r.load_text, r.precursor_text) != texts {
            return Err(corrupt(format!(
                "line {line}: event {} at F/(μF_N) = {}, ℓ/Lx = {} inside the rows of event {} \
                 at {}, {}",
                r.event, r.load_text, r.precursor_text, state.event, texts.0, texts.1
            ))
            .into());
        }
        if within < ny {
            state.area.extend(r.values);
        } else {
            state.coulomb.extend(r.values);
        }
    }
    let Some(last) = states.last() else {
        return Ok(states);
    };
    if last.area.len() + last.coulomb.len() != nx * per_state {
        return Err(corrupt(format!(
            "the last state (event {}) is cut: its rows are not all there",
            last.event
        ))
        .into());
    }
    if states.len() < expected.len() {
        return Err(corrupt(format!(
            "it holds {} states, the scene records {} (every {every}-th of the {} stable states \
             of curve.csv): the states from event {} on are missing",
            states.len(),
            expected.len(),
            run.curve.len(),
            expected[states.len()].event
        ))
        .into());
    }
    Ok(states)
}
