//! One integration-test crate (one binary to link): each module tests one part of the
//! public API against references computed independently of the code under test.

mod api;
mod calibration;
mod checkpoint;
mod common;
mod contact_rules;
#[cfg(feature = "cli")]
mod damage;
mod driver;
#[cfg(feature = "serde")]
mod error_types;
mod errors;
mod green_point;
#[cfg(feature = "cli")]
mod hostile;
mod interface;
mod invariants;
mod laws;
mod loads;
mod maps;
#[cfg(feature = "nalgebra")]
mod matrix;
#[cfg(feature = "cli")]
mod messages;
#[cfg(feature = "plot")]
mod movie;
#[cfg(feature = "cli")]
mod observers;
mod operator;
#[cfg(feature = "cli")]
mod outputs;
#[cfg(feature = "serde")]
mod paper_sweeps;
#[cfg(feature = "plot")]
mod plot;
mod probe;
#[cfg(feature = "serde")]
mod profiles;
mod properties;
mod refinement;
mod robustness;
#[cfg(feature = "serde")]
mod runs;
#[cfg(feature = "serde")]
mod scene_file;
#[cfg(feature = "serde")]
mod serde_types;
mod solver;
mod stability;
#[cfg(feature = "serde")]
mod statistics;
mod surfaces;
#[cfg(feature = "serde")]
mod sweep;
