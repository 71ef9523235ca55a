//! Conversions between the crate's fields and `nalgebra` matrices and vectors (feature
//! `nalgebra`).
//!
//! A field on the grid is one value per cell in the paper's order `i = iy·Nx + ix` (x
//! fastest). As a matrix it is `Ny x Nx`: **row `iy`, column `ix`**, so `m[(iy, ix)]` is
//! cell `(ix, iy)` and a row of the matrix is a row of cells along x. nalgebra stores
//! matrices column-major (y fastest): its `as_slice()` is *not* the crate's cell order,
//! and these functions never read it as one. As a vector a field keeps the cell order.
//!
//! Every field works the same way: tractions and displacements of a
//! [`Driver`](crate::Driver), its real contact area, a [`PlaneStress`](crate::PlaneStress)'s
//! stresses, heights.
//!
//! ```
//! use nalgebra::DMatrix;
//! use precursors::{Block, Grid, Heights};
//! let grid = Grid::new(Block::new(0.003, 0.002, 0.010)?, 3, 2)?; // Nx = 3, Ny = 2
//! // Row iy = 0 then row iy = 1, each along x.
//! let map = DMatrix::from_row_slice(2, 3, &[1e-6, 2e-6, 3e-6, 4e-6, 5e-6, 6e-6]);
//! let heights = Heights::from_dmatrix(&grid, &map)?;
//! assert_eq!(heights.values()[grid.index(2, 0).unwrap()], 3e-6); // (ix, iy) = (2, 0)
//! assert_eq!(grid.field_to_dmatrix(heights.values())?, map);
//! # Ok::<(), precursors::Error>(())
//! ```

use crate::error::{check_slice, Error, Result};
use crate::geometry::Grid;
use crate::interface::Heights;
use nalgebra::{DMatrix, DVector};

impl Grid {
    /// A field (one value per cell in the order `i = iy·Nx + ix`, any unit) as an
    /// `Ny x Nx` matrix: row `iy`, column `ix` (`m[(iy, ix)]` is cell `(ix, iy)`), in the
    /// field's unit. Feature `nalgebra`.
    ///
    /// # Errors
    /// [`Error::LengthMismatch`] unless the field has `Nx·Ny` values,
    /// [`Error::NonFinite`] for a NaN or an infinity.
    pub fn field_to_dmatrix(&self, field: &[f64]) -> Result<DMatrix<f64>> {
        check_slice("field", field, self.len())?;
        Ok(DMatrix::from_row_slice(self.ny(), self.nx(), field))
    }

    /// A field (one value per cell, any unit) as a vector in the crate's cell order
    /// `i = iy·Nx + ix` (x fastest), in the field's unit. Feature `nalgebra`.
    ///
    /// # Errors
    /// As [`Grid::field_to_dmatrix`].
    pub fn field_to_dvector(&self, field: &[f64]) -> Result<DVector<f64>> {
        check_slice("field", field, self.len())?;
        Ok(DVector::from_column_slice(field))
    }

    /// The field (one value per cell in the order `i = iy·Nx + ix`, in the matrix's unit)
    /// of an `Ny x Nx` matrix read as row `iy`, column `ix`: the inverse of
    /// [`Grid::field_to_dmatrix`]. Feature `nalgebra`.
    ///
    /// # Errors
    /// [`Error::ShapeMismatch`] unless the matrix is `Ny x Nx` (a transposed `Nx x Ny`
    /// one is refused; on a square grid the shape cannot tell), [`Error::NonFinite`] for
    /// a NaN or an infinity.
    pub fn field_from_dmatrix(&self, matrix: &DMatrix<f64>) -> Result<Vec<f64>> {
        let (rows, columns) = matrix.shape();
        if (rows, columns) != (self.ny(), self.nx()) {
            return Err(Error::ShapeMismatch {
                name: "matrix",
                rows,
                columns,
                expected_rows: self.ny(),
                expected_columns: self.nx(),
            });
        }
        let mut field = Vec::with_capacity(self.len());
        for iy in 0..rows {
            field.extend(matrix.row(iy).iter().copied());
        }
        check_slice("matrix", &field, self.len())?;
        Ok(field)
    }
}

impl Heights {
    /// Heights (m) from an `Ny x Nx` map of `grid`: row `iy`, column `ix` (`m[(iy, ix)]`
    /// is the height of cell `(ix, iy)`), each finite and `> 0`. Feature `nalgebra`.
    ///
    /// # Errors
    /// As [`Grid::field_from_dmatrix`]; [`Error::NonPositiveHeight`] (with the cell index
    /// `iy·Nx + ix`) for a value `≤ 0`.
    pub fn from_dmatrix(grid: &Grid, matrix: &DMatrix<f64>) -> Result<Heights> {
        Heights::from_values(grid, grid.field_from_dmatrix(matrix)?)
    }
}
