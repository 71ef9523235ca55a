//! The kernels of kernels.cu as Rust sees them: each one's parameter list declared once
//! ([`kernels!`] below), from which come its [`Kernel`] name, its typed launch function
//! on every [`Device`] (`device.scatter_rows(cfg, ..)`, [`Launch`]: the argument list
//! written by the macro, not by hand) and the declaration a test checks against
//! kernels.cu's `extern "C"` signature (names, count, types). Also: the threads per block
//! ([`THREADS`], passed to NVRTC and to the emulator's C++ compiler as `-DTHREADS`), the
//! launch shapes with their sizes checked against the 32-bit integers the kernels and the
//! driver take, and NVRTC ([`Kernels`], the GPU's compiled functions).
//!
//! What a typed launch does not check: that the buffers hold the values the kernel reads
//! and writes. That stays each caller's `unsafe` obligation.

use super::device::{guarded, Gpu};
use super::seam::{Device, Elem, KernelId, Value};
use crate::error::{Error, Result};
use cudarc::cufft::sys::double2;
use cudarc::driver::{CudaFunction, LaunchConfig};
use cudarc::nvrtc::{compile_ptx_with_opts, CompileOptions, Ptx};
use std::sync::OnceLock;

/// The kernels' source (NVRTC compiles it when a solver is built; it has no `THREADS` of
/// its own).
pub(super) const SOURCE: &str = include_str!("kernels.cu");

/// Threads per block: every launch's block size and kernels.cu's `THREADS` (its shared
/// memory trees and grid-stride loops), one value for both.
pub(super) const THREADS: u32 = 256;

/// The compiler option that gives kernels.cu its `THREADS` (NVRTC's and the emulator's
/// `c++` alike).
pub(super) fn threads_define(threads: u32) -> String {
    format!("-DTHREADS={threads}")
}

/// How a kernel parameter is passed.
#[cfg(test)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Pass {
    /// `const T*`: a buffer the kernel reads.
    In,
    /// `T*`: a buffer the kernel writes (and may read).
    Out,
    /// `T`: a value.
    Val,
}

/// An element or value type shared with kernels.cu, and its C name there.
#[cfg(test)]
pub(super) trait Scalar {
    /// The C type.
    const C: &'static str;
}

#[cfg(test)]
impl Scalar for f64 {
    const C: &'static str = "double";
}
#[cfg(test)]
impl Scalar for i32 {
    const C: &'static str = "int";
}
#[cfg(test)]
impl Scalar for u32 {
    const C: &'static str = "unsigned";
}
#[cfg(test)]
impl Scalar for i64 {
    const C: &'static str = "long long";
}
#[cfg(test)]
impl Scalar for double2 {
    const C: &'static str = "double2";
}

/// One parameter of a kernel as declared on the Rust side.
#[cfg(test)]
#[derive(Debug, Clone, Copy)]
pub(super) struct Param {
    pub(super) name: &'static str,
    pub(super) pass: Pass,
    /// The C name of its type ([`Scalar::C`]).
    pub(super) scalar: &'static str,
}

#[cfg(test)]
impl Param {
    /// The C type this parameter must have in kernels.cu.
    pub(super) fn c_type(&self) -> String {
        match self.pass {
            Pass::In => format!("const {}*", self.scalar),
            Pass::Out => format!("{}*", self.scalar),
            Pass::Val => self.scalar.to_string(),
        }
    }
}

/// One kernel as declared on the Rust side.
#[cfg(test)]
#[derive(Debug, Clone, Copy)]
pub(super) struct Declaration {
    pub(super) name: &'static str,
    pub(super) params: &'static [Param],
}

/// The Rust type of a launch argument on device `D`.
macro_rules! arg_type {
    ($d:ident, In, $t:ty) => { &$d::Buffer<$t> };
    ($d:ident, Out, $t:ty) => { &mut $d::Buffer<$t> };
    ($d:ident, Val, $t:ty) => { $t };
}

/// A launch argument as the seam's [`Arg`].
macro_rules! to_arg {
    ($d:ident, In, $t:ty, $v:ident) => {
        <$t as Elem>::arg::<$d>($v)
    };
    ($d:ident, Out, $t:ty, $v:ident) => {
        <$t as Elem>::arg_mut::<$d>($v)
    };
    ($d:ident, Val, $t:ty, $v:ident) => {
        <$t as Value>::arg::<$d>($v)
    };
}

/// Declares the kernels: each one's parameters as `name: Pass<type>`, in kernels.cu's
/// order. Generates [`DECLARATIONS`], the [`Kernel`] names and one typed, `unsafe`
/// launch function per kernel on every [`Device`] ([`Launch`]).
macro_rules! kernels {
    ($( $name:ident ( $( $p:ident : $pass:ident < $t:ty > ),* $(,)? ); )*) => {
        /// Every kernel of kernels.cu, as the launch functions pass their arguments (the
        /// tests' check against its signatures).
        #[cfg(test)]
        pub(super) const DECLARATIONS: &[Declaration] = &[$(
            Declaration {
                name: stringify!($name),
                params: &[$( Param {
                    name: stringify!($p),
                    pass: Pass::$pass,
                    scalar: <$t as Scalar>::C,
                } ),*],
            }
        ),*];

        /// A kernel of kernels.cu, by its name there.
        #[allow(non_camel_case_types)]
        #[derive(Debug, Clone, Copy, PartialEq, Eq)]
        pub(crate) enum Kernel {
            $( $name, )*
        }

        impl Kernel {
            /// Every kernel, in declaration order (`kernel as usize` is its index).
            pub(crate) const ALL: &[Kernel] = &[$( Kernel::$name, )*];

            /// Its name in kernels.cu.
            pub(crate) fn name(self) -> &'static str {
                match self {
                    $( Kernel::$name => stringify!($name), )*
                }
            }

            /// As a device finds it.
            pub(crate) fn id(self) -> KernelId {
                KernelId {
                    index: self as usize,
                    name: self.name(),
                }
            }
        }

        /// The typed launches: one function per kernel, on any [`Device`].
        pub(super) trait Launch: Device {
            $(
                #[doc = concat!("Launches kernels.cu's `", stringify!($name), "`.")]
                ///
                /// # Safety
                /// Every buffer holds the values the kernel reads or writes under `cfg`
                /// (kernels.cu says which). The argument types are the declaration's.
                #[allow(clippy::too_many_arguments)]
                unsafe fn $name(
                    &self,
                    cfg: LaunchConfig,
                    $( $p: arg_type!(Self, $pass, $t), )*
                ) -> Result<()> {
                    let mut args = [$( to_arg!(Self, $pass, $t, $p), )*];
                    // SAFETY: the argument list is the declaration's, which the tests
                    // check against kernels.cu; the buffers' sizes are the caller's.
                    unsafe { self.launch(Kernel::$name.id(), cfg, &mut args) }
                }
            )*
        }

        impl<D: Device + ?Sized> Launch for D {}
    };
}

kernels! {
    scatter_rows(x: In<f64>, pos: In<i32>, v: Out<f64>, nx: Val<i32>, ny: Val<i32>);
    rows_to_columns(spec: In<double2>, u: Out<f64>, nx: Val<i32>, ny: Val<i32>);
    filter_columns(
        spec: In<double2>, table: In<f64>, out: Out<double2>, nx: Val<i32>, ny: Val<i32>,
    );
    columns_to_rows(w: In<f64>, out: Out<double2>, nx: Val<i32>, ny: Val<i32>);
    gather_set(
        s: In<f64>, set: In<i32>, d: In<f64>, x: In<f64>, y: Out<f64>, with_d: Val<i32>,
        m: Val<i32>, nx: Val<i32>,
    );
    gather_grid(s: In<f64>, out: Out<f64>, nx: Val<i32>, ny: Val<i32>);
    residual_tail(r: Out<f64>, b: In<f64>, offset: Val<f64>, m: Val<i32>);
    jacobi(r: In<f64>, d: In<f64>, diag_c: Val<f64>, z: Out<f64>, m: Val<i32>);
    pre_updates(
        f: Out<f64>, r: Out<f64>, z: Out<f64>, p: Out<f64>, q: In<f64>, w: Out<f64>,
        best: Out<f64>, flags: Val<i32>, shift: Val<f64>, alpha: Val<f64>, u: Val<f64>,
        beta: Val<f64>, m: Val<i32>,
    );
    reduce_partial(
        mode: Val<i32>, a: In<f64>, b: In<f64>, c: In<f64>, m: Val<i32>, partials: Out<f64>,
    );
    reduce_final(mode: Val<i32>, partials: In<f64>, blocks: Val<i32>, out: Out<f64>);
    fsai_scatter(
        cells: In<i32>, weights: In<f64>, count: Val<i32>, planes: Out<f64>, stride: Val<i32>,
        n: Val<i32>,
    );
    fsai_g(
        planes: In<f64>, offsets: In<i32>, stride: Val<i32>, set: In<i32>, pos: In<i32>,
        r: In<f64>, y: Out<f64>, m: Val<i32>, n: Val<i32>,
    );
    fsai_gt(
        planes: In<f64>, offsets: In<i32>, stride: Val<i32>, set: In<i32>, pos: In<i32>,
        y: In<f64>, z: Out<f64>, m: Val<i32>, n: Val<i32>,
    );
    coarse_indicator(
        set: In<i32>, m: Val<i32>, nx: Val<i32>, block: Val<i32>, bx: Val<i32>, a: Val<i32>,
        x: Out<f64>,
    );
    coarse_restrict(
        v: In<f64>, t: In<f64>, subtract: Val<i32>, pos: In<i32>, nx: Val<i32>, ny: Val<i32>,
        block: Val<i32>, bx: Val<i32>, out: Out<f64>, column: Val<i32>, count: Val<i32>,
    );
    coarse_fix_empty(e: Out<f64>, c: In<f64>, count: Val<i32>);
    coarse_factor(l: Out<f64>, k: Val<i32>, info: Out<f64>);
    coarse_invert(l: In<f64>, k: Val<i32>, inv: Out<f64>);
    coarse_border(inv: In<f64>, c: In<f64>, k: Val<i32>, w: Out<f64>, info: Out<f64>);
    coarse_solve(
        inv: In<f64>, g: In<f64>, c: In<f64>, w: In<f64>, info: In<f64>, k: Val<i32>,
        sol: Out<f64>,
    );
    coarse_prolong(
        x: Out<f64>, sol: In<f64>, sign: Val<f64>, set: In<i32>, m: Val<i32>, nx: Val<i32>,
        block: Val<i32>, bx: Val<i32>,
    );
}

/// The kernels compiled and loaded on a GPU, one function per [`Kernel`] (by index).
pub(super) struct Kernels {
    functions: Vec<CudaFunction>,
}

impl Kernels {
    /// The loaded function of `kernel`.
    pub(super) fn function(&self, kernel: KernelId) -> &CudaFunction {
        &self.functions[kernel.index]
    }

    /// Compiles kernels.cu (once per process) and loads its functions on `gpu`.
    pub(super) fn compile(gpu: &Gpu) -> Result<Self> {
        let unavailable = |reason: String| Error::CudaUnavailable {
            reason,
            hint: "report it with the output of `precursors info` (docs/gpu.md); use backend \
                   \"spectral\" meanwhile"
                .into(),
        };
        // Compiled once per process (NVRTC took 1-2 s for sm_90 on the 2-core build
        // machine, scripts/nvrtc-check.py; the backend uses device 0 only, so one compute
        // capability), loaded per solver.
        static IMAGE: OnceLock<((u32, u32), std::result::Result<Ptx, String>)> = OnceLock::new();
        let capability = gpu.info.compute_capability;
        let (compiled_for, image) = IMAGE.get_or_init(|| (capability, compile(capability)));
        let ptx = if *compiled_for == capability {
            image.clone()
        } else {
            compile(capability)
        }
        .map_err(unavailable)?;
        let module = guarded("loading the kernels", || {
            gpu.ctx
                .load_module(ptx)
                .map_err(|e| format!("the driver does not load the compiled kernels: {e}"))
        })
        .map_err(unavailable)?;
        let functions = Kernel::ALL
            .iter()
            .map(|k| {
                module.load_function(k.name()).map_err(|e| {
                    unavailable(format!(
                        "kernel {} is missing from the module: {e}",
                        k.name()
                    ))
                })
            })
            .collect::<Result<_>>()?;
        Ok(Kernels { functions })
    }
}

/// kernels.cu compiled for the GPU's architecture (`sm_XY`, a binary the driver loads as
/// it is), else as PTX for the driver to compile. Why a binary first: PTX carries the
/// ISA version of the NVRTC that wrote it, which a driver older than that NVRTC refuses
/// (`CUDA_ERROR_UNSUPPORTED_PTX_VERSION`); a binary of the same major version loads.
fn compile((major, minor): (u32, u32)) -> std::result::Result<Ptx, String> {
    guarded("compiling the kernels (NVRTC)", || {
        let binary = compile_binary(major, minor);
        binary.map(Ptx::from_binary).or_else(|binary_error| {
            let options = CompileOptions {
                name: Some("precursors_kernels.cu".into()),
                options: vec![threads_define(THREADS)],
                ..Default::default()
            };
            compile_ptx_with_opts(SOURCE, options).map_err(|e| {
                format!(
                    "the kernels do not compile with NVRTC (for sm_{major}{minor}: \
                     {binary_error}; as PTX: {e:?})"
                )
            })
        })
    })
}

/// kernels.cu as a binary for `sm_{major}{minor}` (NVRTC's `nvrtcGetCUBIN`, which the
/// bindings' safe API does not wrap).
fn compile_binary(major: u32, minor: u32) -> std::result::Result<Vec<u8>, String> {
    use cudarc::nvrtc::{result, sys};
    use std::ffi::{CStr, CString};
    let source = CString::new(SOURCE).map_err(|e| e.to_string())?;
    let name = CString::new("precursors_kernels.cu").map_err(|e| e.to_string())?;
    let program = result::create_program(&source, Some(&name)).map_err(|e| e.to_string())?;
    let options = [
        format!("--gpu-architecture=sm_{major}{minor}"),
        threads_define(THREADS),
    ];
    // SAFETY: `program` is a live NVRTC program until destroyed below; the log and the
    // binary are read into buffers of the sizes NVRTC reports.
    let outcome = unsafe {
        match result::compile_program(program, &options) {
            Err(e) => {
                let log = result::get_program_log(program)
                    .map(|log| CStr::from_ptr(log.as_ptr()).to_string_lossy().into_owned())
                    .unwrap_or_default();
                Err(format!("{e:?}: {log}"))
            }
            Ok(()) => {
                let mut size = 0usize;
                sys::nvrtcGetCUBINSize(program, &mut size)
                    .result()
                    .and_then(|()| {
                        let mut binary = vec![0u8; size];
                        sys::nvrtcGetCUBIN(program, binary.as_mut_ptr().cast())
                            .result()
                            .map(|()| binary)
                    })
                    .map_err(|e| format!("{e:?}"))
            }
        }
    };
    // SAFETY: destroyed once, after its last use.
    let _ = unsafe { result::destroy_program(program) };
    outcome
}

/// The `extern "C"` kernels of a CUDA source: each one's name and its parameters as
/// `(C type, name)`, the type's spacing normalised (`const double*`). Comments are not
/// parsed: kernels.cu keeps none inside a signature.
#[cfg(test)]
pub(super) fn signatures(source: &str) -> Vec<(String, Vec<(String, String)>)> {
    const START: &str = "extern \"C\" __global__ void ";
    let mut out = Vec::new();
    let mut rest = source;
    while let Some(at) = rest.find(START) {
        rest = &rest[at + START.len()..];
        let open = rest.find('(').expect("a kernel's parameter list");
        let close = rest.find(')').expect("a kernel's parameter list closed");
        let name = rest[..open].trim().to_string();
        let params = rest[open + 1..close]
            .split(',')
            .filter(|p| !p.trim().is_empty())
            .map(|p| {
                let spaced = p.replace('*', " * ");
                let mut tokens: Vec<&str> = spaced.split_whitespace().collect();
                let name = tokens.pop().unwrap_or_default().to_string();
                let c_type = tokens.join(" ").replace(" *", "*");
                (c_type, name)
            })
            .collect();
        out.push((name, params));
        rest = &rest[close..];
    }
    out
}

/// Every declaration against `source`'s signatures, and every kernel of `source`
/// declared: the first difference, if any.
#[cfg(test)]
pub(super) fn check_declarations(
    source: &str,
    declarations: &[Declaration],
) -> std::result::Result<(), String> {
    let found = signatures(source);
    for (name, _) in &found {
        if !declarations.iter().any(|d| d.name == name) {
            return Err(format!(
                "kernel {name} of kernels.cu has no Rust declaration"
            ));
        }
    }
    for d in declarations {
        let Some((_, params)) = found.iter().find(|(name, _)| name == d.name) else {
            return Err(format!("{} is declared but not in kernels.cu", d.name));
        };
        if params.len() != d.params.len() {
            return Err(format!(
                "{}: {} parameters in kernels.cu, {} declared",
                d.name,
                params.len(),
                d.params.len()
            ));
        }
        for (k, ((c_type, c_name), p)) in params.iter().zip(d.params).enumerate() {
            if *c_type != p.c_type() || c_name != p.name {
                return Err(format!(
                    "{} parameter {k}: `{c_type} {c_name}` in kernels.cu, `{} {}` declared",
                    d.name,
                    p.c_type(),
                    p.name
                ));
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_kernel_is_declared_as_kernels_cu_signs_it() {
        assert_eq!(signatures(SOURCE).len(), DECLARATIONS.len());
        assert_eq!(DECLARATIONS.len(), 22);
        check_declarations(SOURCE, DECLARATIONS).unwrap();
    }

    /// Planted differences, one of each kind, each caught.
    #[test]
    fn a_planted_mismatch_fails_the_check() {
        let plant = |from: &str, to: &str| {
            assert!(SOURCE.contains(from), "{from}");
            let planted = SOURCE.replacen(from, to, 1);
            check_declarations(&planted, DECLARATIONS).unwrap_err()
        };
        // A size as a 64-bit integer.
        let e = plant(
            "scatter_rows(const double* x, const int* pos, double* v, int nx, int ny)",
            "scatter_rows(const double* x, const int* pos, double* v, long long nx, int ny)",
        );
        assert!(e.contains("scatter_rows parameter 3"), "{e}");
        // A written buffer made const, a const one written.
        let e = plant("jacobi(const double* r", "jacobi(double* r");
        assert!(e.contains("jacobi parameter 0"), "{e}");
        let e = plant("residual_tail(double* r", "residual_tail(const double* r");
        assert!(e.contains("residual_tail parameter 0"), "{e}");
        // double for double2, unsigned for int.
        let e = plant(
            "rows_to_columns(const double2* spec",
            "rows_to_columns(const double* spec",
        );
        assert!(e.contains("rows_to_columns parameter 0"), "{e}");
        let e = plant(
            "coarse_factor(double* l, int k",
            "coarse_factor(double* l, unsigned k",
        );
        assert!(e.contains("coarse_factor parameter 1"), "{e}");
        // A value for a pointer.
        let e = plant("double offset, int m", "double* offset, int m");
        assert!(e.contains("residual_tail parameter 2"), "{e}");
        // Two parameters swapped (same types: only the names tell).
        let e = plant(
            "columns_to_rows(const double* w, double2* out, int nx, int ny)",
            "columns_to_rows(const double* w, double2* out, int ny, int nx)",
        );
        assert!(e.contains("columns_to_rows parameter 2"), "{e}");
        // One parameter more, one kernel renamed, one kernel added.
        let e = plant(
            "int with_d, int m, int nx)",
            "int with_d, int m, int nx, int ny)",
        );
        assert!(
            e.contains("gather_set: 9 parameters in kernels.cu, 8 declared"),
            "{e}"
        );
        let e = plant("void fsai_gt(", "void fsai_g_transposed(");
        assert!(e.contains("fsai_g_transposed"), "{e}");
        let e = check_declarations(
            &format!("{SOURCE}\nextern \"C\" __global__ void extra(int m) {{}}\n"),
            DECLARATIONS,
        )
        .unwrap_err();
        assert!(
            e.contains("kernel extra of kernels.cu has no Rust declaration"),
            "{e}"
        );
        // A declaration with a parameter of the wrong type, against the true source.
        let mut wrong = DECLARATIONS.to_vec();
        let params: &'static [Param] = Box::leak(
            wrong[0]
                .params
                .iter()
                .map(|p| Param {
                    scalar: if p.name == "ny" { u32::C } else { p.scalar },
                    ..*p
                })
                .collect(),
        );
        wrong[0].params = params;
        let e = check_declarations(SOURCE, &wrong).unwrap_err();
        assert!(
            e.contains("`int ny` in kernels.cu, `unsigned ny` declared"),
            "{e}"
        );
    }

    /// kernels.cu has no block size of its own: without the define it does not compile
    /// (the guard), so the Rust constant is the only one.
    #[test]
    fn threads_come_from_the_rust_constant_only() {
        assert!(SOURCE.contains("#ifndef THREADS\n#error"));
        assert!(!SOURCE.contains("#define THREADS"));
        assert_eq!(threads_define(THREADS), "-DTHREADS=256");
    }
}
