//! The block `[0, Lx] x [0, Ly] x [0, Lz]` and the grid of cells on its bottom face.

use crate::error::{check_length, Error, Result};

/// The elastic block: lengths in metres, bottom face at `z = 0`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Block {
    lx: f64,
    ly: f64,
    lz: f64,
}

impl Block {
    /// A block of sides `lx`, `ly`, `lz` (m); each must be finite and > 0.
    pub fn new(lx: f64, ly: f64, lz: f64) -> Result<Self> {
        Ok(Self {
            lx: check_length("Lx", lx)?,
            ly: check_length("Ly", ly)?,
            lz: check_length("Lz", lz)?,
        })
    }

    /// Length along x, the shear direction (m).
    pub fn lx(&self) -> f64 {
        self.lx
    }
    /// Width along y (m).
    pub fn ly(&self) -> f64 {
        self.ly
    }
    /// Height along z (m).
    pub fn lz(&self) -> f64 {
        self.lz
    }
    /// Volume `Lx Ly Lz` (m³).
    pub fn volume(&self) -> f64 {
        self.lx * self.ly * self.lz
    }
    /// Side lengths as `[Lx, Ly, Lz]` (m).
    pub fn lengths(&self) -> [f64; 3] {
        [self.lx, self.ly, self.lz]
    }

    /// Checks that a point lies in the closed block; `names` label the coordinates in errors.
    pub(crate) fn check_point(&self, p: Point, names: [&'static str; 3]) -> Result<()> {
        for ((&value, max), name) in [p.x, p.y, p.z].iter().zip(self.lengths()).zip(names) {
            if !(value.is_finite() && (0.0..=max).contains(&value)) {
                return Err(Error::OutsideBlock { name, value, max });
            }
        }
        Ok(())
    }

    /// Checks a height `z` in `[0, Lz]`.
    pub(crate) fn check_height(&self, z: f64) -> Result<f64> {
        if z.is_finite() && (0.0..=self.lz).contains(&z) {
            Ok(z)
        } else {
            Err(Error::OutsideBlock {
                name: "z",
                value: z,
                max: self.lz,
            })
        }
    }
}

/// A point `(x, y, z)` of the block (m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Point {
    /// x (m).
    pub x: f64,
    /// y (m).
    pub y: f64,
    /// z (m).
    pub z: f64,
}

impl Point {
    /// The point `(x, y, z)` (m).
    pub fn new(x: f64, y: f64, z: f64) -> Self {
        Self { x, y, z }
    }
    pub(crate) fn coords(&self) -> [f64; 3] {
        [self.x, self.y, self.z]
    }
}

/// The grid of `Nx x Ny` equal cells on the bottom face of a [`Block`].
///
/// Cell `(ix, iy)` has centre `((ix + 1/2) Δx, (iy + 1/2) Δy)` and flat index
/// `i = iy * Nx + ix` (the paper's order, Eq. `ij`, counted from 0).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Grid {
    block: Block,
    nx: usize,
    ny: usize,
}

impl Grid {
    /// `nx x ny` cells on the bottom face of `block`; both counts must be >= 1.
    pub fn new(block: Block, nx: usize, ny: usize) -> Result<Self> {
        if nx == 0 {
            return Err(Error::EmptyGrid { axis: "x" });
        }
        if ny == 0 {
            return Err(Error::EmptyGrid { axis: "y" });
        }
        Ok(Self { block, nx, ny })
    }

    /// Cells of size `dx x dy` (m), which must divide `Lx` and `Ly` into whole numbers
    /// (to 1e-9 relative).
    pub fn from_cell_size(block: Block, dx: f64, dy: f64) -> Result<Self> {
        let count = |axis, length: f64, cell: f64| -> Result<usize> {
            check_length(if axis == "x" { "dx" } else { "dy" }, cell)?;
            let ratio = length / cell;
            let n = ratio.round();
            if n < 1.0 || (ratio - n).abs() > 1e-9 * ratio.max(1.0) {
                return Err(Error::GridDoesNotDivide {
                    axis,
                    length,
                    cell,
                    ratio,
                });
            }
            Ok(n as usize)
        };
        let nx = count("x", block.lx, dx)?;
        let ny = count("y", block.ly, dy)?;
        Self::new(block, nx, ny)
    }

    /// The block the grid lies on.
    pub fn block(&self) -> &Block {
        &self.block
    }
    /// Cells along x.
    pub fn nx(&self) -> usize {
        self.nx
    }
    /// Cells along y.
    pub fn ny(&self) -> usize {
        self.ny
    }
    /// Number of cells `Nx Ny`.
    pub fn len(&self) -> usize {
        self.nx * self.ny
    }
    /// Always false: a grid has at least one cell.
    pub fn is_empty(&self) -> bool {
        false
    }
    /// Cell size along x, `Δx = Lx / Nx` (m).
    pub fn dx(&self) -> f64 {
        self.block.lx / self.nx as f64
    }
    /// Cell size along y, `Δy = Ly / Ny` (m).
    pub fn dy(&self) -> f64 {
        self.block.ly / self.ny as f64
    }
    /// Cell area `ΔA = Δx Δy` (m²).
    pub fn cell_area(&self) -> f64 {
        self.dx() * self.dy()
    }
    /// Flat index of cell `(ix, iy)`: `iy * Nx + ix`.
    pub fn index(&self, ix: usize, iy: usize) -> usize {
        iy * self.nx + ix
    }
    /// Centre `(x, y)` of cell `(ix, iy)` (m).
    pub fn centre(&self, ix: usize, iy: usize) -> (f64, f64) {
        ((ix as f64 + 0.5) * self.dx(), (iy as f64 + 0.5) * self.dy())
    }
}
