//! The bicycle's Jacobians timed side by side: the generated
//! `rhs_jacobian`, `linearize` (which calls it), the same Jacobians by dual
//! numbers through the rhs (`dual_linearize`, what `linearize` did before
//! there was a generated one), and the lean and steer linearization with
//! its eigenvalues at 5 m/s (`whipple_bicycle::eigenvalues`). Each is
//! timed in 31 alternating passes; the medians, and the ratios within each
//! pass, are printed.
//!
//! ```sh
//! cargo run --release --example bicycle_jacobian
//! ```

#[path = "models/whipple_bicycle.rs"]
#[allow(dead_code)] // the example uses the model and its operating point
mod whipple_bicycle;

use std::hint::black_box;
use std::time::Instant;

use appell::linearize::{dual_linearize, linearize};
use appell::Model;
use whipple_bicycle::WhippleBicycle;

/// Microseconds per call of `f`, over `n` calls.
fn per_call(n: usize, mut f: impl FnMut()) -> f64 {
    let t = Instant::now();
    for _ in 0..n {
        f();
    }
    t.elapsed().as_secs_f64() * 1e6 / n as f64
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let bike = WhippleBicycle::default();
    let info = WhippleBicycle::info();
    let (s, ni) = (info.state_len(), info.inputs.len());
    // The upright operating point at 5 m/s, as `lean_steer` takes it.
    let q = whipple_bicycle::operating_point(&bike).unwrap();
    let mut x: Vec<f64> = info
        .retained
        .iter()
        .map(|r| q[info.coordinate_index(r).unwrap()])
        .collect();
    x.extend([0.0, -5.0 / bike.rr, 0.0]);
    let w = vec![0.0; ni];
    let (mut v, mut a, mut b) = (vec![0.0; s], vec![0.0; s * s], vec![0.0; s * ni]);
    println!(
        "{}",
        info.jacobian.map_or("no generated Jacobian", |j| j.form)
    );
    let (mut generated, mut lin, mut dual, mut eig) = (vec![], vec![], vec![], vec![]);
    let mut ratios = vec![];
    for _ in 0..31 {
        let g = per_call(2000, || {
            bike.rhs_jacobian(0.0, black_box(&x), &w, &mut v, &mut a, &mut b)
                .unwrap();
            black_box(&a);
        });
        let l = per_call(2000, || {
            black_box(linearize(&bike, 0.0, black_box(&x), &w).unwrap());
        });
        let d = per_call(200, || {
            black_box(dual_linearize(&bike, 0.0, black_box(&x), &w).unwrap());
        });
        let e = per_call(200, || {
            black_box(whipple_bicycle::eigenvalues(&bike, black_box(5.0)).unwrap());
        });
        ratios.push(d / l);
        generated.push(g);
        lin.push(l);
        dual.push(d);
        eig.push(e);
    }
    println!("rhs_jacobian                 {:8.2} µs", median(generated));
    println!("linearize (generated)        {:8.2} µs", median(lin));
    println!("dual_linearize               {:8.2} µs", median(dual));
    println!("lean/steer + eigenvalues     {:8.2} µs", median(eig));
    let (lo, hi) = (
        ratios.iter().copied().fold(f64::INFINITY, f64::min),
        ratios.iter().copied().fold(0.0, f64::max),
    );
    println!(
        "dual / generated linearize   {:8.2} ({lo:.2}–{hi:.2})",
        median(ratios.clone())
    );
}
