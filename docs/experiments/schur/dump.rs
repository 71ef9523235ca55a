//! Prototype helper (not built by cargo: copy it to examples/scratch_dump.rs to run it):
//! a scene of Lx x Ly x 75 mm on 1 mm cells at 3.5 MPa, rod drive, seed 1, run to its
//! K-th rupture; writes the dense Ĝ (plan tolerance 1e-8), the normal compliances and the
//! attached mask to /tmp/proto as little-endian f64, and prints NX NY SCALE ATTACHED.
//! `cargo run --release --example scratch_dump -- 0.2 0.05 3000` (N = 1e4, 800 MB).
use precursors::{Event, Scene, SiteState};
use std::io::Write;
fn main() {
    let a: Vec<String> = std::env::args().skip(1).collect();
    let (lx, ly, k): (f64, f64, usize) = (a[0].parse().unwrap(), a[1].parse().unwrap(), a[2].parse().unwrap());
    let scene = Scene::builder().block(lx, ly, 0.075).cell_size(1e-3, 1e-3).normal_load(3.5e6 * lx * ly).seed(1).build().unwrap();
    let plan = precursors::green::InfluencePlan::builder(*scene.grid()).plan_tolerance(1e-8).build().unwrap();
    let g = plan.dense().unwrap();
    let mut d = scene.driver().unwrap();
    let mut r = 0;
    while let Some(e) = d.step().unwrap() { if matches!(e, Event::Rupture{..}) { r += 1; if r >= k { break; } } }
    let m = d.material();
    let scale = scene.grid().cell_area() / (m.young_modulus() / (1.0 + m.poisson_ratio()));
    let comp = d.interface().normal_compliance();
    let att: Vec<f64> = d.site_states().iter().map(|s| if *s == SiteState::Attached {1.0} else {0.0}).collect();
    let w = |name: &str, v: &[f64]| { let mut f = std::fs::File::create(format!("/tmp/proto/{name}")).unwrap(); for x in v { f.write_all(&x.to_le_bytes()).unwrap(); } };
    w("g.bin", &g); w("d.bin", &comp); w("att.bin", &att);
    println!("{} {} {} {}", scene.grid().nx(), scene.grid().ny(), scale, att.iter().sum::<f64>());
}
