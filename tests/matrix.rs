//! Feature `nalgebra`: heights from and fields to `DMatrix`/`DVector`, orientation
//! explicit (row `iy`, column `ix`; vectors in the cell order `i = iy·Nx + ix`). The
//! references are literal: a non-square, non-symmetric map whose cell order is written
//! out by hand, so a map read y-fastest (nalgebra's storage order) or transposed fails.

use precursors::nalgebra::{DMatrix, DVector};
use precursors::{Block, Error, Grid, Heights, ProbeSpec, Scene};

/// Nx = 5 columns, Ny = 3 rows.
fn grid() -> Grid {
    Grid::new(Block::new(0.005, 0.003, 0.010).unwrap(), 5, 3).unwrap()
}

/// Height (µm) of cell (ix, iy): 1 + ix + 10 iy, row by row.
fn map() -> DMatrix<f64> {
    DMatrix::from_fn(3, 5, |iy, ix| 1e-6 * (1 + ix + 10 * iy) as f64)
}

/// The same heights in the crate's cell order, written out (x fastest).
const CELL_ORDER_UM: [f64; 15] = [
    1.0, 2.0, 3.0, 4.0, 5.0, // iy = 0
    11.0, 12.0, 13.0, 14.0, 15.0, // iy = 1
    21.0, 22.0, 23.0, 24.0, 25.0, // iy = 2
];

fn cell_order() -> Vec<f64> {
    CELL_ORDER_UM.iter().map(|h| h * 1e-6).collect()
}

#[test]
fn heights_from_a_map_keep_rows_as_rows() {
    let grid = grid();
    let heights = Heights::from_dmatrix(&grid, &map()).unwrap();
    assert_eq!(heights.values(), &cell_order()[..]);
    // nalgebra's own storage is y-fastest: exactly what must not be read as cell order.
    assert_ne!(map().as_slice(), &cell_order()[..]);
    // Cell (ix, iy) = (4, 1) is 15 µm.
    assert_eq!(heights.values()[grid.index(4, 1).unwrap()], 15.0 * 1e-6);
}

#[test]
fn a_transposed_map_is_refused() {
    let grid = grid();
    let transposed = map().transpose(); // 5 x 3: Nx rows
    assert!(matches!(
        Heights::from_dmatrix(&grid, &transposed),
        Err(Error::ShapeMismatch {
            rows: 5,
            columns: 3,
            expected_rows: 3,
            expected_columns: 5,
            ..
        })
    ));
    let message = grid
        .field_from_dmatrix(&transposed)
        .unwrap_err()
        .to_string();
    assert!(
        message.contains("5 x 3") && message.contains("3 x 5"),
        "{message}"
    );
}

#[test]
fn bad_map_values_are_typed_errors() {
    let grid = grid();
    let mut m = map();
    m[(2, 1)] = 0.0; // cell (ix, iy) = (1, 2): index 2·5 + 1
    assert!(matches!(
        Heights::from_dmatrix(&grid, &m),
        Err(Error::NonPositiveHeight { index: 11, .. })
    ));
    m[(2, 1)] = f64::NAN;
    assert!(matches!(
        Heights::from_dmatrix(&grid, &m),
        Err(Error::NonFinite { index: 11, .. })
    ));
}

#[test]
fn fields_to_matrices_and_vectors() {
    let grid = grid();
    let field = cell_order();
    let m = grid.field_to_dmatrix(&field).unwrap();
    assert_eq!(m.shape(), (3, 5));
    assert_eq!(m, map());
    assert_eq!(m[(0, 4)], 5.0 * 1e-6); // (ix, iy) = (4, 0)
    assert_eq!(m[(2, 0)], 21.0 * 1e-6); // (ix, iy) = (0, 2)
    assert_eq!(grid.field_from_dmatrix(&m).unwrap(), field);
    let v: DVector<f64> = grid.field_to_dvector(&field).unwrap();
    assert_eq!(v.len(), 15);
    assert_eq!(v[7], 13.0 * 1e-6); // i = 1·5 + 2
    assert_eq!(v.as_slice(), &field[..]);
    assert!(matches!(
        grid.field_to_dmatrix(&field[..14]),
        Err(Error::LengthMismatch {
            expected: 15,
            found: 14,
            ..
        })
    ));
    assert!(matches!(
        grid.field_to_dvector(&[f64::NAN; 15]),
        Err(Error::NonFinite { index: 0, .. })
    ));
}

#[test]
fn driver_fields_and_plane_stresses_as_matrices() {
    let grid = grid();
    let scene = Scene::builder()
        .block(0.005, 0.003, 0.010)
        .cells(5, 3)
        .normal_load(30.0)
        .heights(Heights::from_dmatrix(&grid, &map()).unwrap().into())
        .probes(ProbeSpec::default().with_plane(0.0))
        .build()
        .unwrap();
    let mut driver = scene.driver().unwrap();
    driver.step().unwrap();
    driver.step().unwrap(); // the first LoadRaised: shear acts
    let g = driver.grid();
    let normal = g
        .field_to_dmatrix(driver.normal_traction().unwrap())
        .unwrap();
    let shear = g
        .field_to_dmatrix(driver.shear_traction().unwrap())
        .unwrap();
    let area = g
        .field_to_dmatrix(&driver.cell_contact_area().unwrap())
        .unwrap();
    let stresses = driver.stresses().unwrap();
    let plane = &stresses.planes[0];
    let plane_shear = g.field_to_dmatrix(plane.shear()).unwrap();
    for iy in 0..3 {
        for ix in 0..5 {
            let i = 5 * iy + ix;
            assert_eq!(normal[(iy, ix)], driver.normal_traction().unwrap()[i]);
            assert_eq!(shear[(iy, ix)], driver.shear_traction().unwrap()[i]);
            assert_eq!(area[(iy, ix)], driver.cell_contact_area().unwrap()[i]);
            assert_eq!(plane_shear[(iy, ix)], plane.at(ix, iy).unwrap().shear);
        }
    }
    // The matrix's column sums are the column contact areas.
    let columns = driver.column_contact_area().unwrap();
    for (ix, column) in columns.iter().enumerate() {
        let sum: f64 = area.column(ix).iter().sum();
        assert!((sum - column).abs() <= 1e-15 * column.max(1e-30));
    }
}
