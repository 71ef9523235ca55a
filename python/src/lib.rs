//! The native part of the Python package `precursors` (`precursors._precursors`): the
//! crate's public API behind PyO3 classes. The pure-Python part (`python/precursors/`)
//! holds the exception classes, the keyword form of a scene, the table reader and the
//! stubs. Units are the crate's (SI); arrays are float64 numpy arrays of shape `(Ny, Nx)`
//! (row `iy`, column `ix`), always fresh copies of the driver's state.

use std::error::Error as StdError;
use std::ops::ControlFlow;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};

use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict, PyList};

use precursors::output::RunTables;
use precursors::solver::Parallelism;
use precursors::sweep::{Sweep, SweepError, SweepOptions};

// ---------------------------------------------------------------------------------------
// Errors: the crate's error, its Display text with its causes, as an instance of one of
// the package's classes (python/precursors/_errors.py).

/// Which Python class an error of the crate maps to.
#[derive(Clone, Copy)]
enum Class {
    /// Bad input (`ValueError` too).
    Value,
    /// A file or directory (`OSError` too).
    Os,
    /// A solve or a series that did not converge.
    NotConverged,
    /// The CUDA backend cannot run here (`RuntimeError` too).
    Cuda,
    /// Anything else: `PrecursorsError` itself.
    Base,
}

impl Class {
    fn name(self) -> &'static str {
        match self {
            Class::Value => "PrecursorsValueError",
            Class::Os => "PrecursorsOSError",
            Class::NotConverged => "NotConvergedError",
            Class::Cuda => "CudaUnavailableError",
            Class::Base => "PrecursorsError",
        }
    }
}

fn core_class(e: &precursors::Error) -> Class {
    use precursors::Error as E;
    match e {
        E::Io { .. }
        | E::NotARegularFile { .. }
        | E::RunDirectory { .. }
        | E::DirectoryLocked { .. } => Class::Os,
        E::SolverNotConverged { .. } | E::SeriesNotConverged { .. } | E::FitNotConverged { .. } => {
            Class::NotConverged
        }
        E::InvalidParameter { .. }
        | E::InvalidLength { .. }
        | E::InvalidCount { .. }
        | E::InvalidChoice { .. }
        | E::InvalidTolerance { .. }
        | E::OutOfRange { .. }
        | E::EmptyGrid { .. }
        | E::EmptyInput { .. }
        | E::EmptyContact { .. }
        | E::GridDoesNotDivide { .. }
        | E::GridTooLarge { .. }
        | E::LengthInMillimetres { .. }
        | E::LikelyMillimetres { .. }
        | E::OutputTooLarge { .. }
        | E::NonFinite { .. }
        | E::NonPositiveHeight { .. }
        | E::LengthMismatch { .. }
        | E::ShapeMismatch { .. }
        | E::OutsideBlock { .. }
        | E::RodBandOutsideFace { .. }
        | E::SingularPoint { .. }
        | E::SiteOutOfRange { .. }
        | E::DenseThreads { .. }
        | E::TooLargeForDense { .. }
        | E::NoProbes
        | E::SceneFile { .. }
        | E::HeightsFile { .. }
        | E::MapFile { .. }
        | E::MapValue { .. }
        | E::CheckpointFile { .. }
        | E::CheckpointSceneMismatch { .. }
        | E::InvalidCheckpoint { .. }
        | E::CorruptTable { .. }
        | E::NonFiniteCell { .. }
        | E::OutputCollision { .. }
        | E::LoadBeyondFriction { .. }
        | E::TooFewSamples { .. } => Class::Value,
        // (`DeviceOutOfMemory` and `Cuda`, of the crate's feature `cuda` only, are
        // `PrecursorsError` itself, as `OutOfMemory` and a failed computation are.)
        E::CudaUnavailable { .. } => Class::Cuda,
        _ => Class::Base,
    }
}

fn sweep_class(e: &SweepError) -> Class {
    match e {
        SweepError::Core(e) => core_class(e),
        SweepError::Directory { .. } => Class::Os,
        SweepError::File { .. } | SweepError::Axis { .. } | SweepError::TooLarge { .. } => {
            Class::Value
        }
        _ => Class::Base,
    }
}

fn plot_class(e: &precursors::plot::PlotError) -> Class {
    use precursors::plot::PlotError as P;
    match e {
        P::Core(e) => core_class(e),
        P::Sweep(e) => sweep_class(e),
        P::InvalidSize { .. } | P::InvalidDpi { .. } => Class::Value,
        _ => Class::Base,
    }
}

/// The variant's name (`OutOfRange`), from its `Debug` form; a nesting variant
/// (`Core(..)`, `Sweep(..)`) gives the name of what it holds.
fn kind(debug: &str) -> String {
    let mut rest = debug;
    loop {
        let end = rest
            .find(|c: char| !(c.is_alphanumeric() || c == '_'))
            .unwrap_or(rest.len());
        let name = &rest[..end];
        if (name == "Core" || name == "Sweep") && rest[end..].starts_with('(') {
            rest = &rest[end + 1..];
        } else {
            return name.to_string();
        }
    }
}

/// The error's Display text followed by its causes' (`source()`), joined by ": ": the
/// crate's errors leave their cause out of their Display (`Error::Io` names the file, its
/// source the system's message). A cause the text already ends with (another library's
/// error that repeats its own) is skipped.
fn message(e: &(dyn StdError + 'static)) -> String {
    let mut text = e.to_string();
    let mut cause = e.source();
    while let Some(c) = cause {
        let s = c.to_string();
        if !text.ends_with(&s) {
            text.push_str(": ");
            text.push_str(&s);
        }
        cause = c.source();
    }
    text
}

/// A failure of the crate, ready to become a Python exception.
struct Failure {
    class: Class,
    kind: String,
    message: String,
}

impl From<precursors::Error> for Failure {
    fn from(e: precursors::Error) -> Self {
        let mut message = message(&e);
        if matches!(e, precursors::Error::CudaUnavailable { .. }) {
            message.push_str(WITHOUT_CUDA);
        }
        Failure {
            class: core_class(&e),
            kind: kind(&format!("{e:?}")),
            message,
        }
    }
}

/// What a user of the package can do about the CUDA backend: the crate's hint speaks of
/// cargo features, which a wheel's user does not choose.
#[cfg(not(feature = "cuda"))]
const WITHOUT_CUDA: &str = " (this Python package is built without the CUDA backend: run \
    scenes with backend \"cuda\" with the program `precursors` built with \
    `--features cli,cuda`, or build the package with its feature `cuda`; docs/gpu.md)";

/// Built with the CUDA backend: the crate's message says it all.
#[cfg(feature = "cuda")]
const WITHOUT_CUDA: &str = "";

impl From<SweepError> for Failure {
    fn from(e: SweepError) -> Self {
        Failure {
            class: sweep_class(&e),
            kind: kind(&format!("{e:?}")),
            message: message(&e),
        }
    }
}

impl From<precursors::plot::PlotError> for Failure {
    fn from(e: precursors::plot::PlotError) -> Self {
        Failure {
            class: plot_class(&e),
            kind: kind(&format!("{e:?}")),
            message: message(&e),
        }
    }
}

impl From<Failure> for PyErr {
    fn from(f: Failure) -> PyErr {
        Python::attach(|py| {
            let raised = (|| -> PyResult<PyErr> {
                let class = py.import("precursors._errors")?.getattr(f.class.name())?;
                let value = class.call1((f.message.as_str(),))?;
                value.setattr("kind", f.kind.as_str())?;
                Ok(PyErr::from_value(value))
            })();
            raised.unwrap_or_else(|e| e)
        })
    }
}

/// `result.or_raise()?`: the crate's error as the package's exception.
trait OrRaise<T> {
    fn or_raise(self) -> PyResult<T>;
}

impl<T, E: Into<Failure>> OrRaise<T> for Result<T, E> {
    fn or_raise(self) -> PyResult<T> {
        self.map_err(|e| PyErr::from(e.into()))
    }
}

/// A scene file error of the keyword form: the JSON text is the package's, not the
/// caller's, so its line and column are left out (`precursors._scene` checks the
/// keywords' types; what is left is a value the format refuses, named by its key).
fn keyword_error(e: precursors::Error) -> PyErr {
    match &e {
        precursors::Error::SceneFile { source, .. } => {
            let text = source.to_string();
            let text = match text.rfind(" at line ") {
                Some(at) => &text[..at],
                None => &text,
            };
            Failure {
                class: Class::Value,
                kind: "SceneFile".into(),
                message: format!("Scene(): a keyword's value is invalid: {text}"),
            }
            .into()
        }
        _ => Failure::from(e).into(),
    }
}

// ---------------------------------------------------------------------------------------
// Helpers.

/// A field of the grid, in the cell order `i = iy·Nx + ix`, as a `(Ny, Nx)` array.
fn field<'py>(
    py: Python<'py>,
    grid: &precursors::Grid,
    values: Vec<f64>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let array = Array2::from_shape_vec((grid.ny(), grid.nx()), values)
        .map_err(|e| pyo3::exceptions::PyValueError::new_err(e.to_string()))?;
    Ok(array.into_pyarray(py))
}

/// A dict in the scene-file format as JSON text, through `precursors._scene.dumps`
/// (numpy scalars and arrays become numbers and lists).
fn dumps(py: Python<'_>, value: &Bound<'_, PyAny>) -> PyResult<String> {
    py.import("precursors._scene")?
        .call_method1("dumps", (value,))?
        .extract()
}

fn build(py: Python<'_>, builder: precursors::SceneBuilder) -> PyResult<Scene> {
    // Planning the operator takes a while on large grids: without the GIL.
    let inner = py.detach(|| builder.build()).or_raise()?;
    Ok(Scene { inner })
}

// ---------------------------------------------------------------------------------------
// Scene.

/// A validated scene: the block, the grid, the material, the springs, the heights, the
/// normal load and the drive (the crate's `Scene`). Build one from a scene file
/// (`Scene.from_file`), a dict in the scene-file format (`Scene.from_dict`) or keywords
/// (`Scene(block=(0.14, 0.007, 0.075), cell_size=(0.001, 0.001), normal_load=3500.0)`).
///
/// Keywords (SI units; one left out takes the calibration scene's value):
/// block=(lx, ly, lz) lengths (m); cells=(nx, ny) counts, or cell_size=(dx, dy) (m);
/// normal_load (N); seed (int) of random heights, heights=array of shape (Ny, Nx) (m),
/// surface=SurfaceSpectrum, height_distribution=(mean, std_dev) (m);
/// young_modulus (Pa), poisson_ratio, friction_coefficient; c_x, c_z (springs);
/// friction_map, c_x_map, c_z_map: per-site values in their place, an array of shape
/// (Ny, Nx) or a dict in the scene-file form (`maps`: values, file, gaussian_surface,
/// self_affine_surface);
/// drive='rod' | 'top' | 'side' or a scene-file dict, rod=(height, half_width) (m);
/// backend='auto' | 'dense' | 'spectral', threads (int, 'all', 'current');
/// probe_planes=[z, ...], probe_points=[(x, y, z), ...] (m);
/// profile_loads=[F/(μF_N), ...], profile_planes=[z, ...] (m); confirm_metres=True for a
/// block of a metre or more under a mean pressure below 1e-6 E (refused otherwise as
/// millimetres typed as metres); max_output_bytes (B, default 1e10) bounds the estimated
/// size of the recorded profiles (refused above it, before the run);
/// contact_rule='paper' | 'anchored' | 'rejuvenation' (the site transitions, default the
/// paper's), with 'rejuvenation' delay_stable_states (int >= 1, default 1) and delay_load
/// (F/(μF_N) > 0, default 0.01) before a broken site re-forms. A custom rule (the crate's
/// `ContactLaw`) is Rust only.
#[pyclass(module = "precursors", frozen)]
struct Scene {
    inner: precursors::Scene,
}

#[pymethods]
impl Scene {
    /// The keyword form: see `precursors.Scene` (python/precursors/_scene.py maps the
    /// keywords onto the scene-file format; missing keys take the calibration scene's
    /// values).
    #[new]
    #[pyo3(
        signature = (**kwargs),
        text_signature = "(*, block=None, cells=None, cell_size=None, normal_load=None, \
                          seed=None, heights=None, surface=None, height_distribution=None, \
                          young_modulus=None, poisson_ratio=None, friction_coefficient=None, \
                          c_x=None, c_z=None, friction_map=None, c_x_map=None, \
                          c_z_map=None, drive=None, rod=None, backend=None, \
                          threads=None, probe_planes=None, probe_points=None, \
                          profile_loads=None, profile_planes=None, confirm_metres=None, \
                          max_output_bytes=None, contact_rule=None, \
                          delay_stable_states=None, delay_load=None)"
    )]
    fn new(py: Python<'_>, kwargs: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
        let dict = py
            .import("precursors._scene")?
            .getattr("scene_dict")?
            .call((), kwargs)?;
        let text = dumps(py, &dict)?;
        let builder = precursors::SceneBuilder::from_json_str(&text).map_err(keyword_error)?;
        for name in ["heights", "friction_map", "c_x_map", "c_z_map"] {
            let array = match kwargs {
                Some(k) => k
                    .get_item(name)?
                    .filter(|h| !h.is_none() && !h.is_instance_of::<PyDict>()),
                None => None,
            };
            let Some(array) = array else { continue };
            // The array's shape, which the scene file's flat values no longer carry: a
            // transposed or flat array is refused, not read row by row.
            let shape: Vec<usize> = py
                .import("numpy")?
                .call_method1("shape", (array,))?
                .extract()?;
            let grid = builder.grid().or_raise()?;
            if shape != [grid.ny(), grid.nx()] {
                let given: Vec<String> = shape.iter().map(usize::to_string).collect();
                let comma = if shape.len() == 1 { "," } else { "" };
                return Err(Failure {
                    class: Class::Value,
                    kind: "ShapeMismatch".into(),
                    message: format!(
                        "{name} has shape ({}{comma}), the grid needs (Ny, Nx) = ({}, {}): \
                         row iy, column ix",
                        given.join(", "),
                        grid.ny(),
                        grid.nx()
                    ),
                }
                .into());
            }
        }
        build(py, builder)
    }

    /// The scene of a JSON scene file (docs/scene-format.md).
    #[staticmethod]
    fn from_file(py: Python<'_>, path: PathBuf) -> PyResult<Self> {
        let builder = py
            .detach(|| precursors::SceneBuilder::from_json_file(&path))
            .or_raise()?;
        build(py, builder)
    }

    /// The scene of a dict in the scene-file format (the same keys and rules as a file).
    #[staticmethod]
    fn from_dict(py: Python<'_>, scene: &Bound<'_, PyAny>) -> PyResult<Self> {
        let text = dumps(py, scene)?;
        Self::from_json(py, &text)
    }

    /// The scene of a scene file's text.
    #[staticmethod]
    fn from_json(py: Python<'_>, text: &str) -> PyResult<Self> {
        let builder = precursors::SceneBuilder::from_json_str(text).or_raise()?;
        build(py, builder)
    }

    /// The scene file of this scene (every key, heights as values).
    fn to_json(&self) -> PyResult<String> {
        self.inner.to_builder().to_json().or_raise()
    }

    /// `to_json()` as a dict.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        py.import("json")?.call_method1("loads", (self.to_json()?,))
    }

    /// The grid and its estimated cost (the crate's `GridCost`): `nx`, `ny`, `cells`,
    /// `dx`, `dy` (m), `block` (m), `normal_load` (N), `backend`, `contact_rule` (the
    /// rule's name: `"paper"`, `"anchored"`, `"rejuvenation"`), `memory_bytes`,
    /// `plan_seconds` and `solve_seconds` (one cold normal + tangential solve, one
    /// thread; estimates).
    fn info<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let grid = self.inner.grid();
        let cost = precursors::GridCost::of(grid.nx(), grid.ny());
        let block = grid.block();
        let d = PyDict::new(py);
        d.set_item("nx", grid.nx())?;
        d.set_item("ny", grid.ny())?;
        d.set_item("cells", grid.len())?;
        d.set_item("dx", grid.dx())?;
        d.set_item("dy", grid.dy())?;
        d.set_item("block", (block.lx(), block.ly(), block.lz()))?;
        d.set_item("normal_load", self.inner.normal_load())?;
        d.set_item("backend", self.inner.solver_options().backend().to_string())?;
        d.set_item("contact_rule", self.inner.contact_rule().name())?;
        d.set_item("memory_bytes", cost.memory_bytes)?;
        d.set_item("plan_seconds", cost.plan_seconds)?;
        d.set_item("solve_seconds", cost.solve_seconds)?;
        Ok(d)
    }

    /// `(Ny, Nx)`: the shape of every field of the interface.
    #[getter]
    fn shape(&self) -> (usize, usize) {
        (self.inner.grid().ny(), self.inner.grid().nx())
    }

    /// `(Lx, Ly, Lz)` (m).
    #[getter]
    fn block(&self) -> (f64, f64, f64) {
        let b = self.inner.grid().block();
        (b.lx(), b.ly(), b.lz())
    }

    /// `(dx, dy)`: the cell size (m).
    #[getter]
    fn cell_size(&self) -> (f64, f64) {
        (self.inner.grid().dx(), self.inner.grid().dy())
    }

    /// `F_N` (N).
    #[getter]
    fn normal_load(&self) -> f64 {
        self.inner.normal_load()
    }

    /// A driver at zero shear. `threads`: 1 the calling thread, 0 every core, `n` a pool
    /// of `n` (the same events for every choice); `None` keeps the scene's
    /// `solver.threads`.
    #[pyo3(signature = (*, threads=None))]
    fn driver(&self, py: Python<'_>, threads: Option<usize>) -> PyResult<Driver> {
        let inner = py.detach(|| self.inner.driver()).or_raise()?;
        Driver::with_threads(inner, threads)
    }

    /// A driver continuing from `checkpoint` (taken on this scene, probes aside).
    #[pyo3(signature = (checkpoint, *, threads=None))]
    fn resume(
        &self,
        py: Python<'_>,
        checkpoint: &Checkpoint,
        threads: Option<usize>,
    ) -> PyResult<Driver> {
        let inner = py
            .detach(|| self.inner.resume(&checkpoint.inner))
            .or_raise()?;
        Driver::with_threads(inner, threads)
    }

    fn __repr__(&self) -> String {
        let g = self.inner.grid();
        let b = g.block();
        format!(
            "Scene({} x {} cells, block {} x {} x {} m, F_N = {} N)",
            g.nx(),
            g.ny(),
            b.lx(),
            b.ly(),
            b.lz(),
            self.inner.normal_load()
        )
    }
}

// ---------------------------------------------------------------------------------------
// Events.

/// One event of the quasi-static protocol (the crate's `Event`): `kind` is one of
/// `"load_raised"`, `"rupture"`, `"detach"`, `"attach"`, `"stable"`, `"global_slip"` (the
/// names of `events.csv`); `index` counts the driver's events (1 for the first).
/// Attributes a kind does not have are `None`.
#[pyclass(module = "precursors", frozen, eq)]
#[derive(PartialEq)]
struct Event {
    /// The event's kind.
    #[pyo3(get)]
    kind: &'static str,
    /// The driver's event count after this event (events.csv's `index`).
    #[pyo3(get)]
    index: usize,
    /// The site `i = iy·Nx + ix` (rupture, detach, attach).
    #[pyo3(get)]
    site: Option<usize>,
    /// The site's column (along x, from the trailing edge).
    #[pyo3(get)]
    ix: Option<usize>,
    /// The site's row (along y).
    #[pyo3(get)]
    iy: Option<usize>,
    /// The shear force `F` (N) (load_raised, rupture, stable, global_slip).
    #[pyo3(get)]
    force: Option<f64>,
    /// The drive displacement `U_S` (m) under displacement control.
    #[pyo3(get)]
    drive_displacement: Option<f64>,
    /// The energy released by a rupture (J).
    #[pyo3(get)]
    energy: Option<f64>,
    /// The ruptures of the avalanche that a stable state ends.
    #[pyo3(get)]
    ruptures: Option<usize>,
}

impl Event {
    fn new(event: &precursors::Event, index: usize) -> Self {
        use precursors::Event as E;
        let kind = event.kind();
        let (site, load, energy, ruptures) = match *event {
            E::LoadRaised { load } | E::GlobalSlip { load } => (None, Some(load), None, None),
            E::Rupture { site, load, energy } => (Some(site), Some(load), Some(energy), None),
            E::Detach { site } | E::Attach { site } => (Some(site), None, None, None),
            E::Stable { load, ruptures } => (None, Some(load), None, Some(ruptures)),
            _ => (None, None, None, None),
        };
        Event {
            kind,
            index,
            site: site.map(|s| s.index),
            ix: site.map(|s| s.ix),
            iy: site.map(|s| s.iy),
            force: load.map(|l| l.force),
            drive_displacement: load.and_then(|l| l.drive_displacement),
            energy,
            ruptures,
        }
    }
}

#[pymethods]
impl Event {
    fn __repr__(&self) -> String {
        let mut text = format!("Event(index={}, kind='{}'", self.index, self.kind);
        if let (Some(ix), Some(iy)) = (self.ix, self.iy) {
            text += &format!(", ix={ix}, iy={iy}");
        }
        if let Some(f) = self.force {
            text += &format!(", force={f:?}");
        }
        if let Some(u) = self.drive_displacement {
            text += &format!(", drive_displacement={u:?}");
        }
        if let Some(e) = self.energy {
            text += &format!(", energy={e:?}");
        }
        if let Some(r) = self.ruptures {
            text += &format!(", ruptures={r}");
        }
        text + ")"
    }
}

// ---------------------------------------------------------------------------------------
// Driver.

/// The quasi-static protocol of a scene (the crate's `Driver`): iterate it for its
/// events (`for event in driver`), or `step()` / `run(until=...)`; read the state between
/// events. The solver runs without the GIL. Every array is a new float64 copy.
#[pyclass(module = "precursors")]
struct Driver {
    inner: precursors::Driver,
}

impl Driver {
    fn with_threads(mut inner: precursors::Driver, threads: Option<usize>) -> PyResult<Self> {
        if let Some(n) = threads {
            inner
                .set_parallelism(Parallelism::from_count(n))
                .or_raise()?;
        }
        Ok(Driver { inner })
    }

    /// The next event, solved without the GIL.
    fn next_event(&mut self, py: Python<'_>) -> PyResult<Option<Event>> {
        let driver = &mut self.inner;
        let event = py.detach(|| driver.step()).or_raise()?;
        Ok(event.map(|e| Event::new(&e, self.inner.event_count())))
    }
}

/// `until=` of `Driver.run`.
enum Until {
    Slip,
    Kind(String),
    Force(f64),
}

#[pymethods]
impl Driver {
    fn __iter__(slf: PyRef<'_, Self>) -> PyRef<'_, Self> {
        slf
    }

    fn __next__(&mut self, py: Python<'_>) -> PyResult<Option<Event>> {
        self.next_event(py)
    }

    /// The next event, or `None` after global slip.
    fn step(&mut self, py: Python<'_>) -> PyResult<Option<Event>> {
        self.next_event(py)
    }

    /// Runs events until `until` and returns the last one (`None` if the run had already
    /// ended): `None` runs to global slip, a kind (`"stable"`, `"rupture"`, ...) stops
    /// after the first event of that kind, a number stops after the first event whose
    /// force `F` reaches it (N). Ctrl-C stops between events with `KeyboardInterrupt`
    /// (the driver stays usable).
    #[pyo3(signature = (until=None))]
    fn run(&mut self, py: Python<'_>, until: Option<&Bound<'_, PyAny>>) -> PyResult<Option<Event>> {
        let until = match until {
            None => Until::Slip,
            Some(u) if u.is_instance_of::<pyo3::types::PyString>() => Until::Kind(u.extract()?),
            Some(u) => {
                let force: f64 = u.extract()?;
                if !force.is_finite() {
                    return Err(pyo3::exceptions::PyValueError::new_err(format!(
                        "until = {force} is not a finite force (N)"
                    )));
                }
                Until::Force(force)
            }
        };
        if let Until::Kind(kind) = &until {
            if !precursors::Event::KINDS.contains(&kind.as_str()) {
                return Err(pyo3::exceptions::PyValueError::new_err(format!(
                    "until = {kind:?} is not an event kind: one of {:?}",
                    precursors::Event::KINDS
                )));
            }
        }
        let mut last = None;
        while let Some(event) = self.next_event(py)? {
            let stop = match &until {
                Until::Slip => false,
                Until::Kind(kind) => event.kind == kind.as_str(),
                Until::Force(force) => event.force.is_some_and(|f| f >= *force),
            };
            last = Some(event);
            if stop {
                break;
            }
            // Ctrl-C between events.
            py.check_signals()?;
        }
        Ok(last)
    }

    /// A checkpoint of the state (resume it with `Scene.resume`, or the program's
    /// `precursors resume`).
    fn checkpoint(&self) -> Checkpoint {
        Checkpoint {
            inner: self.inner.checkpoint(),
        }
    }

    /// The driver's scene.
    #[getter]
    fn scene(&self) -> Scene {
        Scene {
            inner: self.inner.scene().clone(),
        }
    }

    /// Events so far.
    #[getter]
    fn event_count(&self) -> usize {
        self.inner.event_count()
    }

    /// Where the run stands: `"running"` (a new driver too), `"global_slip"` (the run is
    /// over: `step()` returns `None`) or `"failed"` (a step raised: later steps raise
    /// again, kind `DriverFailed`, with the first error's message).
    #[getter]
    fn state(&self) -> String {
        match self.inner.state() {
            precursors::RunState::Running => "running".into(),
            precursors::RunState::GlobalSlip => "global_slip".into(),
            precursors::RunState::Failed => "failed".into(),
            other => format!("{other:?}").to_lowercase(),
        }
    }

    /// The shear force `F` (N).
    #[getter]
    fn force(&self) -> f64 {
        self.inner.force()
    }

    /// The drive displacement `U_S` (m) under displacement control, else `None`.
    #[getter]
    fn drive_displacement(&self) -> Option<f64> {
        self.inner.load().drive_displacement
    }

    /// The driving spring's force (N), `None` under force control.
    #[getter]
    fn spring_force(&self) -> Option<f64> {
        self.inner.spring_force()
    }

    /// `F_N` (N).
    #[getter]
    fn normal_load(&self) -> f64 {
        self.inner.normal_load()
    }

    /// `μ`.
    #[getter]
    fn friction_coefficient(&self) -> f64 {
        self.inner.friction_coefficient()
    }

    /// The friction limit `μF_N` (N): the unit of the tables' loads `F/(μF_N)`, with `μ`
    /// the material's or, where larger, the friction map's largest value.
    #[getter]
    fn friction_limit(&self) -> f64 {
        self.inner.friction_limit()
    }

    /// `Lx·Ly` (m²).
    #[getter]
    fn nominal_area(&self) -> f64 {
        self.inner.nominal_area()
    }

    /// The real contact area `A_R` (m²). Not bounded by `nominal_area`: under the
    /// paper's area law it exceeds the face when asperities are pressed below the mean
    /// plane, a meaningless area; check `area_exceeds_nominal()`.
    #[getter]
    fn real_contact_area(&self) -> PyResult<f64> {
        self.inner.real_contact_area().or_raise()
    }

    /// Whether `real_contact_area` exceeds `nominal_area` (beyond rounding): a state the
    /// paper's unbounded area law reaches, whose area is not physical.
    fn area_exceeds_nominal(&self) -> PyResult<bool> {
        self.inner.area_exceeds_nominal().or_raise()
    }

    /// The precursor length `ℓ` (m).
    #[getter]
    fn precursor_length(&self) -> PyResult<f64> {
        self.inner.precursor_length().or_raise()
    }

    /// `ℓ` (m) with another threshold of the column contact area's drop.
    fn precursor_length_with_threshold(&self, drop: f64) -> PyResult<f64> {
        self.inner.precursor_length_with_threshold(drop).or_raise()
    }

    /// The mean shear displacement `⟨u_x⟩` (m).
    #[getter]
    fn mean_shear_displacement(&self) -> PyResult<f64> {
        self.inner.mean_shear_displacement().or_raise()
    }

    /// The threads a solve uses.
    #[getter]
    fn threads(&self) -> usize {
        self.inner.threads()
    }

    /// `(Ny, Nx)`.
    #[getter]
    fn shape(&self) -> (usize, usize) {
        (self.inner.grid().ny(), self.inner.grid().nx())
    }

    /// The normal traction `φ_z` of each cell (Pa), `(Ny, Nx)`.
    #[getter]
    fn normal_traction<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let v = self.inner.normal_traction().or_raise()?.to_vec();
        field(py, self.inner.grid(), v)
    }

    /// The shear traction `φ_x` of each cell (Pa), `(Ny, Nx)`.
    #[getter]
    fn shear_traction<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let v = self.inner.shear_traction().or_raise()?.to_vec();
        field(py, self.inner.grid(), v)
    }

    /// The normal displacement `u_z` of each cell (m), `(Ny, Nx)`.
    #[getter]
    fn normal_displacement<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let v = self.inner.normal_displacement().or_raise()?.to_vec();
        field(py, self.inner.grid(), v)
    }

    /// The shear displacement `u_x` of each cell (m), `(Ny, Nx)`.
    #[getter]
    fn shear_displacement<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let v = self.inner.shear_displacement().or_raise()?.to_vec();
        field(py, self.inner.grid(), v)
    }

    /// The real contact area of each cell (m²), `(Ny, Nx)`.
    #[getter]
    fn cell_contact_area<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let v = self.inner.cell_contact_area().or_raise()?;
        field(py, self.inner.grid(), v)
    }

    /// The real contact area of each column `ix` (m²), `(Nx,)`.
    #[getter]
    fn column_contact_area<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        Ok(PyArray1::from_vec(
            py,
            self.inner.column_contact_area().or_raise()?,
        ))
    }

    /// The shear force `F` (N) at which each site breaks under the Coulomb rule,
    /// `(Ny, Nx)`.
    #[getter]
    fn breaking_loads<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        field(py, self.inner.grid(), self.inner.breaking_loads().to_vec())
    }

    /// The state of each site, `(Ny, Nx)` uint8: `ATTACHED` (0), `DETACHED` (1), `BROKEN`
    /// (2).
    #[getter]
    fn site_states<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<u8>>> {
        let grid = self.inner.grid();
        let codes: Vec<u8> = self
            .inner
            .site_states()
            .iter()
            .map(|s| match s {
                precursors::SiteState::Attached => 0,
                precursors::SiteState::Detached => 1,
                _ => 2,
            })
            .collect();
        let array = Array2::from_shape_vec((grid.ny(), grid.nx()), codes)
            .map_err(|e| pyo3::exceptions::PyValueError::new_err(e.to_string()))?;
        Ok(array.into_pyarray(py))
    }

    /// Adds stress probes: planes at heights `z` (m) and points `(x, y, z)` (m) inside
    /// the block, read by `stresses()` from now on.
    #[pyo3(signature = (*, planes=Vec::new(), points=Vec::new(), tolerance=None))]
    fn add_probes(
        &mut self,
        py: Python<'_>,
        planes: Vec<f64>,
        points: Vec<(f64, f64, f64)>,
        tolerance: Option<f64>,
    ) -> PyResult<()> {
        let mut spec = precursors::ProbeSpec::default();
        for z in planes {
            spec = spec.with_plane(z);
        }
        for (x, y, z) in points {
            spec = spec.with_point(precursors::Point::new(x, y, z));
        }
        if let Some(t) = tolerance {
            spec = spec.with_tolerance(t).or_raise()?;
        }
        let driver = &mut self.inner;
        py.detach(|| driver.add_probes(&spec)).or_raise()
    }

    /// The stresses at the probes (the scene's and those added): a dict with `planes`
    /// (a list of `PlaneStress`) and `points` (a list of `PointStress`).
    fn stresses<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let driver = &self.inner;
        let stresses = match py.detach(|| driver.stresses()) {
            // The crate's message names SceneBuilder::probes: say it in Python's terms.
            Err(precursors::Error::NoProbes) => {
                return Err(Failure {
                    class: Class::Value,
                    kind: "NoProbes".into(),
                    message: "no stress probes: give them to the scene \
                              (Scene(probe_planes=[z, ...], probe_points=[(x, y, z), ...])) \
                              or to the driver (driver.add_probes(planes=..., points=...))"
                        .into(),
                }
                .into())
            }
            other => other.or_raise()?,
        };
        let planes = PyList::empty(py);
        for plane in stresses.planes {
            planes.append(PlaneStress::new(py, plane)?)?;
        }
        let points = PyList::empty(py);
        for p in stresses.points {
            points.append(PointStress {
                point: (p.point.x, p.point.y, p.point.z),
                shear: p.shear,
                normal: p.normal,
                coulomb: p.coulomb,
            })?;
        }
        let d = PyDict::new(py);
        d.set_item("planes", planes)?;
        d.set_item("points", points)?;
        Ok(d)
    }

    fn __repr__(&self) -> String {
        let g = self.inner.grid();
        format!(
            "Driver({} x {} cells, {} events, F = {} N, {} backend, {} thread(s))",
            g.nx(),
            g.ny(),
            self.inner.event_count(),
            self.inner.force(),
            self.inner.backend(),
            self.inner.threads()
        )
    }
}

/// The stresses on a plane `z = const` (Pa, cell averages), each `(Ny, Nx)`; `profile()`
/// their y-averages along x.
#[pyclass(module = "precursors", frozen)]
struct PlaneStress {
    /// The plane's height (m).
    #[pyo3(get)]
    z: f64,
    /// `τ = σ_xz` (Pa), `(Ny, Nx)`.
    #[pyo3(get)]
    shear: Py<PyArray2<f64>>,
    /// `σ = σ_zz` (Pa), `(Ny, Nx)`.
    #[pyo3(get)]
    normal: Py<PyArray2<f64>>,
    /// `|τ| - μ|σ|` (Pa), `(Ny, Nx)`.
    #[pyo3(get)]
    coulomb: Py<PyArray2<f64>>,
    profile: precursors::Profile,
}

impl PlaneStress {
    fn new(py: Python<'_>, plane: precursors::PlaneStress) -> PyResult<Self> {
        let profile = plane.profile();
        let shape = (plane.ny(), plane.nx());
        let array = |v: Vec<f64>| -> PyResult<Py<PyArray2<f64>>> {
            let a = Array2::from_shape_vec(shape, v)
                .map_err(|e| pyo3::exceptions::PyValueError::new_err(e.to_string()))?;
            Ok(a.into_pyarray(py).unbind())
        };
        Ok(PlaneStress {
            z: plane.z(),
            shear: array(plane.shear().to_vec())?,
            normal: array(plane.normal().to_vec())?,
            coulomb: array(plane.coulomb().to_vec())?,
            profile,
        })
    }
}

#[pymethods]
impl PlaneStress {
    /// The y-averaged profiles along x, each `(Nx,)`: `x` (the columns' centres, m),
    /// `shear`, `normal` (Pa), `coulomb_of_means` (`|⟨τ⟩_y| - μ|⟨σ⟩_y|`, the paper's
    /// `τ_C(x, z)`, Pa) and `mean_coulomb` (`⟨|τ| - μ|σ|⟩_y`, Pa).
    fn profile<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        let p = &self.profile;
        d.set_item("x", PyArray1::from_slice(py, p.x()))?;
        d.set_item("shear", PyArray1::from_slice(py, p.shear()))?;
        d.set_item("normal", PyArray1::from_slice(py, p.normal()))?;
        d.set_item(
            "coulomb_of_means",
            PyArray1::from_slice(py, p.coulomb_of_means()),
        )?;
        d.set_item("mean_coulomb", PyArray1::from_slice(py, p.mean_coulomb()))?;
        Ok(d)
    }

    fn __repr__(&self, py: Python<'_>) -> String {
        let shape = self.shear.bind(py).shape().to_vec();
        format!("PlaneStress(z={:?} m, shape={shape:?})", self.z)
    }
}

/// The stresses at a point (Pa).
#[pyclass(module = "precursors", frozen)]
struct PointStress {
    /// `(x, y, z)` (m).
    #[pyo3(get)]
    point: (f64, f64, f64),
    /// `τ = σ_xz` (Pa).
    #[pyo3(get)]
    shear: f64,
    /// `σ = σ_zz` (Pa).
    #[pyo3(get)]
    normal: f64,
    /// `|τ| - μ|σ|` (Pa).
    #[pyo3(get)]
    coulomb: f64,
}

#[pymethods]
impl PointStress {
    fn __repr__(&self) -> String {
        format!(
            "PointStress(point={:?} m, shear={:?} Pa, normal={:?} Pa, coulomb={:?} Pa)",
            self.point, self.shear, self.normal, self.coulomb
        )
    }
}

// ---------------------------------------------------------------------------------------
// Checkpoints.

/// A driver's state after an event (the crate's `Checkpoint`): to and from files and
/// bytes (the checkpoint file's JSON, which the program's `precursors resume` reads).
#[pyclass(module = "precursors", frozen)]
struct Checkpoint {
    inner: precursors::Checkpoint,
}

#[pymethods]
impl Checkpoint {
    /// The checkpoint of a file (written by `write_to` or `precursors run --checkpoint`).
    #[staticmethod]
    fn read_from(path: PathBuf) -> PyResult<Self> {
        let inner = precursors::Checkpoint::read_from(path).or_raise()?;
        Ok(Checkpoint { inner })
    }

    /// Writes the checkpoint to `path` atomically.
    fn write_to(&self, path: PathBuf) -> PyResult<()> {
        self.inner.write_to(path).or_raise()
    }

    /// The checkpoint file's bytes (UTF-8 JSON).
    fn to_bytes<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyBytes>> {
        Ok(PyBytes::new(
            py,
            self.inner.to_json().or_raise()?.as_bytes(),
        ))
    }

    /// The checkpoint of `to_bytes()`'s bytes.
    #[staticmethod]
    fn from_bytes(data: &[u8]) -> PyResult<Self> {
        let text = std::str::from_utf8(data).map_err(|e| {
            PyErr::from(Failure::from(precursors::Error::InvalidCheckpoint {
                reason: format!("the bytes are not UTF-8 text: {e}"),
            }))
        })?;
        let inner = precursors::Checkpoint::from_json_str(text).or_raise()?;
        Ok(Checkpoint { inner })
    }

    /// The events before the checkpoint.
    #[getter]
    fn event_count(&self) -> usize {
        self.inner.event_count()
    }

    /// The scene the checkpoint was taken on (built: resume with `scene.resume(cp)`).
    fn scene(&self, py: Python<'_>) -> PyResult<Scene> {
        build(py, self.inner.scene().clone())
    }

    fn __repr__(&self) -> String {
        format!("Checkpoint(event_count={})", self.inner.event_count())
    }
}

// ---------------------------------------------------------------------------------------
// Runs, sweeps, merges, figures.

/// Runs `scene` to global slip writing its tables into `out` (created if missing), as
/// `precursors run` does: `events.csv`, `curve.csv`, `contact_map.csv` keep their
/// `.partial` names until global slip. Returns their paths. With `checkpoint=PATH`, a
/// checkpoint is written over PATH every `every` stable states (`precursors resume PATH
/// DIR` continues the run). Ctrl-C stops at the next event with `KeyboardInterrupt`, the
/// rows so far on disk, the tables left `.partial`.
#[pyfunction]
#[pyo3(signature = (scene, out, *, threads=None, checkpoint=None, every=100))]
fn run(
    py: Python<'_>,
    scene: &Scene,
    out: PathBuf,
    threads: Option<usize>,
    checkpoint: Option<PathBuf>,
    every: u64,
) -> PyResult<Vec<PathBuf>> {
    let every = std::num::NonZeroU64::new(every).ok_or_else(|| {
        pyo3::exceptions::PyValueError::new_err(
            "every= is the number of stable states between checkpoints: at least 1, not 0",
        )
    })?;
    std::fs::create_dir_all(&out)
        .map_err(|source| precursors::Error::Io {
            operation: "creating the output directory",
            path: out.clone(),
            source,
        })
        .or_raise()?;
    let mut driver =
        Driver::with_threads(py.detach(|| scene.inner.driver()).or_raise()?, threads)?.inner;
    let mut tables = RunTables::create(&out, &driver).or_raise()?;
    let checkpoint = checkpoint.as_deref().map(|path| (path, every));
    // The crate's one run loop; Python's signals are checked after each event.
    let stopped = py
        .detach(|| {
            tables.run_until(&mut driver, checkpoint, |_, _| {
                match Python::attach(|py| py.check_signals()) {
                    Ok(()) => ControlFlow::Continue(()),
                    Err(interrupt) => ControlFlow::Break(interrupt),
                }
            })
        })
        .or_raise()?;
    if let Some(interrupt) = stopped {
        return Err(interrupt);
    }
    Ok(py.detach(|| tables.finish()).or_raise()?.to_vec())
}

/// Runs the sweep file `file` into `out` on `jobs` parallel runs (`precursors sweep`);
/// returns the summary (`runs`, `completed`, `skipped`, `held_elsewhere`, `stopped`,
/// `seconds`). Ctrl-C stops it with `KeyboardInterrupt`: no new run starts and the runs
/// under way stop at their next event, unmarked, so that only complete runs are marked
/// done; called again, the sweep redoes the stopped runs.
#[pyfunction]
#[pyo3(signature = (file, out, *, jobs=1))]
fn sweep<'py>(
    py: Python<'py>,
    file: PathBuf,
    out: PathBuf,
    jobs: usize,
) -> PyResult<Bound<'py, PyDict>> {
    let sweep = py.detach(|| Sweep::from_json_file(&file)).or_raise()?;
    let options = SweepOptions::new().with_jobs(jobs).or_raise()?;
    let stop = AtomicBool::new(false);
    let summary = std::thread::scope(|scope| -> PyResult<_> {
        let handle = scope.spawn(|| sweep.execute_until(&out, &options, |_| {}, &stop));
        // The sweep on its own thread; this one, Python's, watches for signals.
        while !py.detach(|| wait_for(&handle)) {
            if let Err(interrupt) = py.check_signals() {
                stop.store(true, Ordering::SeqCst);
                let _ = py.detach(|| handle.join());
                return Err(interrupt);
            }
        }
        match handle.join() {
            Ok(summary) => summary.or_raise(),
            Err(_) => Err(pyo3::exceptions::PyRuntimeError::new_err(
                "the sweep's thread panicked",
            )),
        }
    })?;
    let d = PyDict::new(py);
    d.set_item("runs", summary.runs)?;
    d.set_item("completed", summary.completed)?;
    d.set_item("skipped", summary.skipped)?;
    d.set_item("held_elsewhere", summary.held_elsewhere)?;
    d.set_item("stopped", summary.stopped)?;
    d.set_item("seconds", summary.seconds)?;
    Ok(d)
}

/// Waits up to 0.1 s for the thread of `handle` to end; whether it has.
fn wait_for<T>(handle: &std::thread::ScopedJoinHandle<'_, T>) -> bool {
    let start = std::time::Instant::now();
    while !handle.is_finished() && start.elapsed() < std::time::Duration::from_millis(100) {
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    handle.is_finished()
}

/// Merges the runs of the sweep directory `dir` (`precursors merge`); returns the paths
/// of the merged tables (`precursors.merge` reads them into arrays).
#[pyfunction]
fn merge_files(py: Python<'_>, dir: PathBuf) -> PyResult<Vec<PathBuf>> {
    let summary = py.detach(|| precursors::sweep::merge(&dir)).or_raise()?;
    Ok(summary.files)
}

/// The options of the power-law fits, checked as the program checks its options.
fn power_law_options(
    bootstrap: usize,
    goodness: usize,
    confidence: f64,
    min_tail: usize,
    seed: u64,
) -> precursors::statistics::PowerLawOptions {
    precursors::statistics::PowerLawOptions::default()
        .bootstrap(bootstrap)
        .goodness_samples(goodness)
        .confidence(confidence)
        .min_tail(min_tail)
        .seed(seed)
}

/// The statistics of a run or sweep directory (`precursors stats`): pooled per point,
/// fitted and log-binned into `power_laws.csv` and `distributions.csv` there; returns
/// their paths (`precursors.stats` reads them into arrays).
#[pyfunction]
#[pyo3(signature = (dir, *, bootstrap=200, goodness=200, confidence=0.95, min_tail=10,
                    bins_per_decade=5, seed=0, include_spanning=false))]
#[allow(clippy::too_many_arguments)]
fn stats_files(
    py: Python<'_>,
    dir: PathBuf,
    bootstrap: usize,
    goodness: usize,
    confidence: f64,
    min_tail: usize,
    bins_per_decade: usize,
    seed: u64,
    include_spanning: bool,
) -> PyResult<Vec<PathBuf>> {
    let options = precursors::sweep::StatsOptions::default()
        .fit(power_law_options(
            bootstrap, goodness, confidence, min_tail, seed,
        ))
        .bins_per_decade(bins_per_decade)
        .include_spanning(include_spanning);
    let summary = py
        .detach(|| precursors::sweep::statistics(&dir, &options))
        .or_raise()?;
    Ok(summary.files)
}

/// The maximum-likelihood power-law fit of `samples` (Clauset, Shalizi and Newman 2009):
/// `discrete` for counts; returns a dict of the fit's values (`x_min`, `alpha`, its
/// bootstrap interval `alpha_low`/`alpha_high` at `confidence`, `ks_distance`, `p_value`
/// (None when `goodness` is 0), `samples`, `tail`, ...).
#[pyfunction]
#[pyo3(signature = (samples, *, discrete, bootstrap=200, goodness=200, confidence=0.95,
                    min_tail=10, seed=0))]
#[allow(clippy::too_many_arguments)]
fn fit_power_law<'py>(
    py: Python<'py>,
    samples: Vec<f64>,
    discrete: bool,
    bootstrap: usize,
    goodness: usize,
    confidence: f64,
    min_tail: usize,
    seed: u64,
) -> PyResult<Bound<'py, PyDict>> {
    use precursors::statistics::Support;
    let support = if discrete {
        Support::Discrete
    } else {
        Support::Continuous
    };
    let options = power_law_options(bootstrap, goodness, confidence, min_tail, seed);
    let fit = py
        .detach(|| precursors::statistics::fit_power_law(&samples, support, &options))
        .or_raise()?;
    let d = PyDict::new(py);
    d.set_item("discrete", discrete)?;
    d.set_item("samples", fit.samples)?;
    d.set_item("tail", fit.tail)?;
    d.set_item("x_min", fit.x_min)?;
    d.set_item("alpha", fit.alpha)?;
    d.set_item("alpha_std_error", fit.alpha_std_error)?;
    d.set_item("alpha_low", fit.alpha_low)?;
    d.set_item("alpha_high", fit.alpha_high)?;
    d.set_item("x_min_low", fit.x_min_low)?;
    d.set_item("x_min_high", fit.x_min_high)?;
    d.set_item("ks_distance", fit.ks_distance)?;
    d.set_item("p_value", fit.p_value)?;
    d.set_item("confidence", confidence)?;
    Ok(d)
}

/// Draws the figures of a run or sweep directory into it (`precursors plot`); `formats`
/// of `"png"`, `"svg"`; `width` x `height` pixels (200 to 16384 each, as `--width` and
/// `--height`, in 1/150 inch); `figures` the names of the figures to draw (as `--figure`;
/// `None`: every figure the directory allows); `dpi` the PNGs' resolution (50 to 1200, as
/// `--dpi`: a PNG has `width·dpi/150` x `height·dpi/150` pixels). Returns the paths of the
/// figures.
#[pyfunction]
#[pyo3(signature = (dir, *, formats=vec!["png".to_string()], width=800, height=560, figures=None, dpi=150))]
fn plot(
    py: Python<'_>,
    dir: PathBuf,
    formats: Vec<String>,
    width: u32,
    height: u32,
    figures: Option<Vec<String>>,
    dpi: u32,
) -> PyResult<Vec<PathBuf>> {
    let formats = formats
        .iter()
        .map(|f| match f.as_str() {
            "png" => Ok(precursors::plot::Format::Png),
            "svg" => Ok(precursors::plot::Format::Svg),
            other => Err(pyo3::exceptions::PyValueError::new_err(format!(
                "format {other:?} is not one of \"png\", \"svg\""
            ))),
        })
        .collect::<PyResult<Vec<_>>>()?;
    let options = precursors::plot::DrawOptions::default()
        .formats(&formats)
        .size(width, height)
        .dpi(dpi)
        .figures(figures.unwrap_or_default());
    let drawn = py
        .detach(|| precursors::plot::draw_with_options(&dir, &options))
        .or_raise()?;
    Ok(drawn.files)
}

/// The paper's movies of a run directory with recorded fields (`precursors movie`):
/// `field` `"contact-area"` (Movie S1, `DIR/contact_area.gif`), `"coulomb-stress"`
/// (Movie S2, `DIR/coulomb_stress.gif`) or `"all"` (both; S2 left out, without an error,
/// when no planes were recorded); every `every`-th recorded state and the last, at most
/// `max_frames` frames, `width` x `height` pixels, `frame_duration` seconds per frame;
/// `out` names the file of a single movie; `png_frames` a directory that also gets every
/// frame as a numbered PNG (`contact_area_0000.png`, ...; `precursors movie
/// --png-frames`). Returns the paths of the movies written.
#[pyfunction]
#[pyo3(signature = (dir, *, field="all", every=1, max_frames=200, width=900, height=560,
                    frame_duration=0.1, out=None, png_frames=None))]
#[allow(clippy::too_many_arguments)]
fn movie(
    py: Python<'_>,
    dir: PathBuf,
    field: &str,
    every: usize,
    max_frames: usize,
    width: u32,
    height: u32,
    frame_duration: f64,
    out: Option<PathBuf>,
    png_frames: Option<PathBuf>,
) -> PyResult<Vec<PathBuf>> {
    use precursors::plot::{Movie, MovieKind, PlotError};
    let all = [
        (MovieKind::ContactArea, "contact_area.gif"),
        (MovieKind::CoulombStress, "coulomb_stress.gif"),
    ];
    let kinds = match field {
        "contact-area" => &all[..1],
        "coulomb-stress" => &all[1..],
        "all" => &all[..],
        other => {
            return Err(pyo3::exceptions::PyValueError::new_err(format!(
                "field {other:?} is not one of \"contact-area\", \"coulomb-stress\", \"all\""
            )))
        }
    };
    if out.is_some() && kinds.len() > 1 {
        return Err(pyo3::exceptions::PyValueError::new_err(
            "out names one movie: give field=\"contact-area\" or field=\"coulomb-stress\"",
        ));
    }
    let mut written = Vec::new();
    for &(kind, name) in kinds {
        let path = out.clone().unwrap_or_else(|| dir.join(name));
        let mut interrupt = None;
        let outcome = py.detach(|| {
            let mut movie = Movie::new(&dir, kind)
                .every(every)?
                .max_frames(max_frames)?
                .size(width, height)
                .frame_duration(frame_duration)?;
            if let Some(frames) = &png_frames {
                movie = movie.png_frames(frames);
            }
            // Ctrl-C between frames: nothing written.
            movie.save_until(&path, |_, _| {
                match Python::attach(|py| py.check_signals()) {
                    Ok(()) => ControlFlow::Continue(()),
                    Err(e) => {
                        interrupt = Some(e);
                        ControlFlow::Break(())
                    }
                }
            })
        });
        if let Some(interrupt) = interrupt {
            return Err(interrupt);
        }
        match outcome {
            Ok(_) => written.push(path),
            // As the program: "all" skips Movie S2 of a run that recorded no planes.
            Err(PlotError::NoFields { .. })
                if field == "all" && kind == MovieKind::CoulombStress => {}
            Err(e) => return Err::<Vec<PathBuf>, _>(e).or_raise(),
        }
    }
    Ok(written)
}

/// The native module; `precursors/__init__.py` re-exports it.
#[pymodule]
fn _precursors(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Scene>()?;
    m.add_class::<Driver>()?;
    m.add_class::<Event>()?;
    m.add_class::<Checkpoint>()?;
    m.add_class::<PlaneStress>()?;
    m.add_class::<PointStress>()?;
    m.add_function(wrap_pyfunction!(run, m)?)?;
    m.add_function(wrap_pyfunction!(sweep, m)?)?;
    m.add_function(wrap_pyfunction!(merge_files, m)?)?;
    m.add_function(wrap_pyfunction!(stats_files, m)?)?;
    m.add_function(wrap_pyfunction!(fit_power_law, m)?)?;
    m.add_function(wrap_pyfunction!(plot, m)?)?;
    m.add_function(wrap_pyfunction!(movie, m)?)?;
    m.add("ATTACHED", 0u8)?;
    m.add("DETACHED", 1u8)?;
    m.add("BROKEN", 2u8)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
