//! Prototype helper (issue 26; not built by cargo: copy it to examples/scratch_dump2.rs to
//! run it). A Lx x Ly x 75 mm block on 1 mm cells at PRESSURE (Pa, default 3.5e6), rod
//! drive, seed 1, run to its K-th rupture; writes to /tmp/proto, little-endian f64: the
//! plan's eigenvalues (TAG_eig.bin, row m, column p), the normal compliances
//! (TAG_K_d.bin) and the attached mask (TAG_K_att.bin); prints NX NY SCALE K ATTACHED.
//! `cargo run --release --example scratch_dump2 -- LX LY 0 TAG K [PRESSURE] > /tmp/proto/TAG.txt`
//! (N = 1e4 at 3.5 MPa: `0.2 0.05 0 n4 3000`; N = 1e5 at 1 MPa: `1.0 0.1 0 m5 1000 1e6`).
use precursors::{Event, Scene, SiteState};
use std::io::Write;
fn main() {
    let a: Vec<String> = std::env::args().skip(1).collect();
    let (lx, ly, k): (f64, f64, usize) = (a[0].parse().unwrap(), a[1].parse().unwrap(), a[2].parse().unwrap());
    let tag = &a[3];
    let scene = Scene::builder().block(lx, ly, 0.075).cell_size(1e-3, 1e-3).normal_load(a.get(5).map(|s| s.parse::<f64>().unwrap()).unwrap_or(3.5e6) * lx * ly).seed(1).build().unwrap();
    let plan = precursors::green::InfluencePlan::builder(*scene.grid()).plan_tolerance(1e-8).build().unwrap();
    let (nx, ny) = (scene.grid().nx(), scene.grid().ny());
    let mut eig = vec![0.0; nx * ny];
    for m in 0..ny { for p in 0..nx { eig[m * nx + p] = plan.eigenvalue(p, m).unwrap(); } }
    let mut d = scene.driver().unwrap();
    let mut r = 0;
    let w = |name: String, v: &[f64]| { let mut f = std::fs::File::create(format!("/tmp/proto/{name}")).unwrap(); for x in v { f.write_all(&x.to_le_bytes()).unwrap(); } };
    let m = d.material();
    let scale = scene.grid().cell_area() / (m.young_modulus() / (1.0 + m.poisson_ratio()));
    w(format!("{tag}_eig.bin"), &eig);
    let mut next = 0usize;
    let stops: Vec<usize> = a[4..5].iter().map(|s| s.parse().unwrap()).collect();
    loop {
        if r >= stops[next] {
            let comp = d.interface().normal_compliance();
            let att: Vec<f64> = d.site_states().iter().map(|s| if *s == SiteState::Attached {1.0} else {0.0}).collect();
            w(format!("{tag}_{}_d.bin", stops[next]), &comp); w(format!("{tag}_{}_att.bin", stops[next]), &att);
            println!("{nx} {ny} {scale} {} {}", stops[next], att.iter().sum::<f64>());
            next += 1;
            if next == stops.len() { break; }
        }
        match d.step().unwrap() { Some(Event::Rupture{..}) => r += 1, Some(_) => {}, None => break }
    }
    let _ = k;
}
