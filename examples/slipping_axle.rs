//! The paper's wheel-axle in three dimensions on a 0.2 rad slope, rolling
//! downhill, a torque τ0 sin(ω t) on each wheel, wheel 1 on ice (μ = 0.15)
//! and wheel 2 on dry ground. Where the drive asks more of the ice than
//! μ N₁, wheel 1 slides while wheel 2 keeps rolling, and the axle turns.
//! Wheel 1 grips again where its slip comes down to 1 cm/s. Both wheels'
//! normal forces come from the momentum balances (`appell::sliding`). The
//! spinning wheels' gyroscopic moment moves load between them as the
//! axle turns.
//!
//! `cargo run --release --example slipping_axle` prints the switch log
//! and the normal forces, and writes `docs/animations/slipping_axle.svg`.

#[path = "models/slipping_axle.rs"]
mod slipping_axle;

use appell::animate::{svg, SvgOptions, View};
use appell::hybrid::Hybrid;
use appell::integrate::Dop853;
use appell::sliding::{sliding_normals, SlidingContact};
use slipping_axle::{phases, torque, SlippingAxleGripping, SlippingAxleSlipping, AXLE};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let phases = phases(&AXLE);
    let names: Vec<&str> = phases.iter().map(|p| p.name).collect();
    let started = std::time::Instant::now();
    // Rolling straight downhill at 1.5 m/s.
    let run = Hybrid::new(phases)
        .solver(Dop853::new().rtol(1e-10).atol(1e-12))
        .sample_every(1.0 / 60.0)
        .run::<10>(0, 0.0, &[0.0; 5], &[0.0, 5.0], 4.0)?;
    let took = started.elapsed();
    println!(
        "Wheel-axle on a {} rad slope, wheel 1 on ice (mu = {}), torque {:.1} N m sin(2 t) on each wheel",
        AXLE.alpha,
        AXLE.mu,
        torque(std::f64::consts::FRAC_PI_4)
    );
    println!(
        "{:>12}  {:<9} -> {:<9} {:<14} {:>15}",
        "t [s]", "from", "to", "reason", "energy lost [J]"
    );
    for s in &run.switches {
        println!(
            "{:>12.6}  {:<9} -> {:<9} {:<14} {:>15.3e}",
            s.t, names[s.from], names[s.to], s.reason, s.energy_lost
        );
    }
    let up = [0.0, 0.0, 1.0];
    let (mut low, mut high) = (f64::INFINITY, f64::NEG_INFINITY);
    for s in &run.samples {
        let found = if s.phase == 0 {
            let c = SlidingContact::support_at_rolling_contact(&AXLE, 0, up);
            let scene = SlippingAxleGripping::from_ref(&AXLE);
            sliding_normals(scene, s.t, &s.q, &s.u, &[torque(s.t)], &[c])?
        } else {
            let c = SlidingContact::at_rolling_contact(&AXLE, 0, 1, up);
            let scene = SlippingAxleSlipping::from_ref(&AXLE);
            sliding_normals(scene, s.t, &s.q, &s.u, &[torque(s.t), 0.0], &[c])?
        };
        low = low.min(found.forces[0]);
        high = high.max(found.forces[0]);
    }
    println!("wheel 1's normal force: {low:.3} N to {high:.3} N");
    println!(
        "{} switches in {:.1} ms",
        run.switches.len(),
        took.as_secs_f64() * 1e3
    );

    let frames = run.frames();
    let options = SvgOptions {
        title: "Wheel-axle on a slope, wheel 1 on ice: gripping and slipping".into(),
        view: View::Oblique,
        traces: vec![1, 2],
        ..SvgOptions::default()
    };
    let picture = svg(&AXLE, &frames, &options)?;
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/animations");
    std::fs::create_dir_all(&dir)?;
    std::fs::write(dir.join("slipping_axle.svg"), picture)?;
    println!(
        "wrote docs/animations/slipping_axle.svg ({} frames)",
        frames.len()
    );
    Ok(())
}
