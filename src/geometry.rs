//! The block `[0, Lx] x [0, Ly] x [0, Lz]` and the grid of cells on its bottom face.

use crate::error::{check_length, Error, Result};

/// The elastic block: lengths in metres, bottom face at `z = 0`.
///
/// ```
/// use precursors::{Block, Error};
/// let block = Block::new(0.14, 0.007, 0.075)?;       // the paper's PMMA block: 140 x 7 x 75 mm
/// assert_eq!(block.lengths(), [0.14, 0.007, 0.075]);
/// assert!((block.volume() / 7.35e-5 - 1.0).abs() < 1e-12);   // Lx Ly Lz (m³)
/// // A side must be finite and > 0.
/// let e = Block::new(-0.01, 0.007, 0.075).unwrap_err();
/// assert!(matches!(e, Error::InvalidLength { name: "Lx", value } if value == -0.01));
/// # Ok::<(), precursors::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(try_from = "BlockFields", into = "BlockFields")
)]
pub struct Block {
    lx: f64,
    ly: f64,
    lz: f64,
}

impl Block {
    /// A block of sides `lx`, `ly`, `lz` (m); each must be finite and > 0, and so must
    /// the volume `Lx Ly Lz` (the Green function divides by it).
    ///
    /// # Errors
    /// [`Error::InvalidLength`] for a side that is not finite and `> 0`;
    /// [`Error::InvalidParameter`] when the volume overflows or underflows.
    pub fn new(lx: f64, ly: f64, lz: f64) -> Result<Self> {
        let block = Self {
            lx: check_length("Lx", lx)?,
            ly: check_length("Ly", ly)?,
            lz: check_length("Lz", lz)?,
        };
        let volume = block.volume();
        if !(volume.is_finite() && volume > 0.0) {
            return Err(Error::InvalidParameter {
                name: "Lx Ly Lz",
                value: volume,
                reason: "the block's volume (m³) overflows or underflows f64",
            });
        }
        Ok(block)
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
///
/// The points at which [`GreenFunction`](crate::green::GreenFunction) is evaluated:
///
/// ```
/// use precursors::{green::GreenFunction, Block, Error, Point};
/// let green = GreenFunction::new(Block::new(0.010, 0.004, 0.005)?); // 10 x 4 x 5 mm
/// let target = Point::new(2e-3, 1e-3, 0.0);           // on the bottom face (m)
/// let source = Point { z: 3e-3, ..target };            // 3 mm above it
/// assert_eq!((source.x, source.y, source.z), (2e-3, 1e-3, 3e-3));
/// // G is symmetric in target and source (m⁻¹).
/// let (g, h) = (green.value(target, source, 1e-8)?, green.value(source, target, 1e-8)?);
/// assert!((g.value - h.value).abs() < 1e-7);
/// // A point beyond Lx = 10 mm lies outside the block.
/// let outside = Point::new(0.012, 1e-3, 0.0);
/// let e = green.value(outside, source, 1e-8).unwrap_err();
/// assert!(matches!(e, Error::OutsideBlock { name: "x", .. }));
/// # Ok::<(), precursors::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
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
///
/// ```
/// use precursors::{Block, Error, Grid};
/// let block = Block::new(0.010, 0.004, 0.005)?;          // 10 x 4 x 5 mm
/// let grid = Grid::from_cell_size(block, 1e-3, 1e-3)?;    // 1 mm cells
/// assert_eq!((grid.nx(), grid.ny(), grid.len()), (10, 4, 40));
/// assert!((grid.cell_area() / 1e-6 - 1.0).abs() < 1e-12); // ΔA = 1 mm² (m²)
/// assert_eq!(grid.index(3, 2), Some(2 * 10 + 3));         // i = iy·Nx + ix
/// let (x, y) = grid.centre(3, 2).unwrap();                // ((ix + ½)Δx, (iy + ½)Δy) (m)
/// assert!((x - 3.5e-3).abs() < 1e-15 && (y - 2.5e-3).abs() < 1e-15);
/// assert_eq!(grid.index(10, 0), None);                    // past the end of row 0
/// // 3 mm cells do not divide Lx = 10 mm.
/// let e = Grid::from_cell_size(block, 3e-3, 1e-3).unwrap_err();
/// assert!(matches!(e, Error::GridDoesNotDivide { axis: "x", .. }));
/// assert_eq!(Grid::new(block, 10, 4)?, grid);             // the same grid by counts
/// # Ok::<(), precursors::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(try_from = "GridFields", into = "GridFields")
)]
pub struct Grid {
    block: Block,
    nx: usize,
    ny: usize,
}

/// Most cells a grid may have: a vector of one `f64` per cell, the smallest thing the API
/// exchanges, must fit in the address space (`isize::MAX` bytes), so that `len()` and the
/// buffers sized by it cannot overflow.
const MAX_CELLS: usize = isize::MAX as usize / std::mem::size_of::<f64>();

/// Largest count along one axis: above `2^53` a count is not exactly an `f64`, and
/// [`Grid::from_cell_size`] could not tell whether the cell divides the face.
const MAX_AXIS_CELLS: f64 = 9_007_199_254_740_992.0;

impl Grid {
    /// `nx x ny` cells on the bottom face of `block`; both counts must be >= 1, the cell
    /// area `ΔA` must not underflow to zero, and `Nx Ny` f64 values must fit in memory.
    ///
    /// # Errors
    /// [`Error::EmptyGrid`] for a zero count; [`Error::GridTooLarge`] when `Nx Ny`
    /// overflows the address space; [`Error::InvalidLength`] when `Δx` or `Δy` rounds to
    /// zero; [`Error::InvalidParameter`] when `ΔA` underflows.
    pub fn new(block: Block, nx: usize, ny: usize) -> Result<Self> {
        if nx == 0 {
            return Err(Error::EmptyGrid { axis: "x" });
        }
        if ny == 0 {
            return Err(Error::EmptyGrid { axis: "y" });
        }
        // More cells than a vector of one f64 per cell can hold.
        crate::cost::check_cells(nx, ny, MAX_CELLS)?;
        let grid = Self { block, nx, ny };
        // lx / nx rounds to zero when nx is huge against a tiny block.
        check_length("dx", grid.dx())?;
        check_length("dy", grid.dy())?;
        let area = grid.cell_area();
        if area <= 0.0 {
            return Err(Error::InvalidParameter {
                name: "ΔA",
                value: area,
                reason: "the cell area (m²) underflows to zero",
            });
        }
        Ok(grid)
    }

    /// Cells of size `dx x dy` (m), which must divide `Lx` and `Ly` into whole numbers
    /// (to 1e-9 relative) of at most `2^53` cells each, then as [`Grid::new`].
    ///
    /// # Errors
    /// [`Error::InvalidLength`] for a size that is not finite and `> 0`;
    /// [`Error::InvalidParameter`] when `L / cell` exceeds `2^53`;
    /// [`Error::GridDoesNotDivide`]; those of [`Grid::new`].
    pub fn from_cell_size(block: Block, dx: f64, dy: f64) -> Result<Self> {
        let count = |axis, length: f64, cell: f64| -> Result<usize> {
            check_length(if axis == "x" { "dx" } else { "dy" }, cell)?;
            let ratio = length / cell;
            if ratio > MAX_AXIS_CELLS {
                // Any cell this small "divides" the face in f64 (the ratio is an integer),
                // and the count would saturate `usize`: refuse it before rounding.
                return Err(Error::InvalidParameter {
                    name: if axis == "x" { "dx" } else { "dy" },
                    value: cell,
                    reason: "the cell is so small that L / cell exceeds 2^53 cells",
                });
            }
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
    /// Flat index `iy * Nx + ix` of cell `(ix, iy)`; `None` unless `ix < Nx` and
    /// `iy < Ny` (an `ix` past the row would otherwise name a cell of the next row).
    pub fn index(&self, ix: usize, iy: usize) -> Option<usize> {
        (ix < self.nx && iy < self.ny).then(|| iy * self.nx + ix)
    }
    /// Centre `(x, y)` of cell `(ix, iy)` (m); `None` unless `ix < Nx` and `iy < Ny`.
    pub fn centre(&self, ix: usize, iy: usize) -> Option<(f64, f64)> {
        (ix < self.nx && iy < self.ny)
            .then(|| ((ix as f64 + 0.5) * self.dx(), (iy as f64 + 0.5) * self.dy()))
    }
}

/// A [`Block`] as serde sees it (feature `serde`): the scene file's `block` keys, read
/// back through [`Block::new`].
#[cfg(feature = "serde")]
#[derive(serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct BlockFields {
    lx: f64,
    ly: f64,
    lz: f64,
}

#[cfg(feature = "serde")]
impl From<Block> for BlockFields {
    fn from(Block { lx, ly, lz }: Block) -> Self {
        Self { lx, ly, lz }
    }
}

#[cfg(feature = "serde")]
impl TryFrom<BlockFields> for Block {
    type Error = Error;
    fn try_from(BlockFields { lx, ly, lz }: BlockFields) -> Result<Self> {
        Block::new(lx, ly, lz)
    }
}

/// A [`Grid`] as serde sees it (feature `serde`): its block and the cell counts (the
/// scene file's `cells` of kind `count`), read back through [`Grid::new`].
#[cfg(feature = "serde")]
#[derive(serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct GridFields {
    block: Block,
    nx: usize,
    ny: usize,
}

#[cfg(feature = "serde")]
impl From<Grid> for GridFields {
    fn from(Grid { block, nx, ny }: Grid) -> Self {
        Self { block, nx, ny }
    }
}

#[cfg(feature = "serde")]
impl TryFrom<GridFields> for Grid {
    type Error = Error;
    fn try_from(GridFields { block, nx, ny }: GridFields) -> Result<Self> {
        Grid::new(block, nx, ny)
    }
}
