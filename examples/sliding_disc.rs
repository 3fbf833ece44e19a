//! The rolling disc, pushed along its heading by F = F0 sin(ω t) beyond
//! what its friction can hold. It rolls while the friction rolling needs
//! stays within μ N. Past that it slides, and in the sliding scene its
//! normal force comes from the momentum balances at every evaluation
//! (`appell::sliding`). It grips again where the slip comes down to
//! 1 cm/s, and the plastic impulse that stops the slip is logged with the
//! energy it takes.
//!
//! `cargo run --release --example sliding_disc` prints the log and the
//! normal force along the run, and writes `docs/animations/sliding_disc.svg`.

#[path = "models/sliding_disc.rs"]
#[allow(dead_code)] // the model written with sliding alone is for the test
mod sliding_disc;

use appell::animate::{svg, SvgOptions, View};
use appell::hybrid::Hybrid;
use appell::integrate::Dop853;
use appell::sliding::{sliding_normals, SlidingContact};
use sliding_disc::{phases, PushedRollingDiscSliding, DISC};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let phases = phases(&DISC);
    let names: Vec<&str> = phases.iter().map(|p| p.name).collect();
    // Rolling at 2.25 m/s (spin 15 rad/s), leaning 0.05 rad.
    let (q0, u0) = ([0.0, 0.05, 0.0, 0.0, 0.0], [0.0, 0.0, 15.0]);
    let started = std::time::Instant::now();
    let run = Hybrid::new(phases)
        .solver(Dop853::new().rtol(1e-10).atol(1e-12))
        .sample_every(1.0 / 60.0)
        .run::<10>(0, 0.0, &q0, &u0, 4.0)?;
    let took = started.elapsed();
    println!(
        "Pushed rolling disc: r = {} m, m = {} kg, mu = {}, F = {:.3} N sin({} t) along its heading",
        DISC.r, DISC.m, DISC.mu, DISC.push, DISC.omega
    );
    println!(
        "{:>12}  {:<8} -> {:<8} {:<7} {:>15}  {:>24}",
        "t [s]", "from", "to", "reason", "energy lost [J]", "impulse [N s]"
    );
    for s in &run.switches {
        let impulse = match s.impulses.as_slice() {
            [a, b] => format!("({a:+.3e}, {b:+.3e})"),
            _ => "-".to_string(),
        };
        println!(
            "{:>12.6}  {:<8} -> {:<8} {:<7} {:>15.3e}  {:>24}",
            s.t, names[s.from], names[s.to], s.reason, s.energy_lost, impulse
        );
    }
    // The normal force while sliding, against the weight m g.
    let scene = PushedRollingDiscSliding::from_ref(&DISC);
    let contact = SlidingContact::at_rolling_contact(&DISC, 0, 0, [0.0, 0.0, 1.0]);
    let (mut low, mut high) = (f64::INFINITY, f64::NEG_INFINITY);
    for s in run.samples.iter().filter(|s| s.phase == 1) {
        let n = sliding_normals(
            scene,
            s.t,
            &s.q,
            &s.u,
            &[0.0],
            std::slice::from_ref(&contact),
        )?;
        low = low.min(n.forces[0]);
        high = high.max(n.forces[0]);
    }
    println!(
        "normal force while sliding: {low:.4} N to {high:.4} N (m g = {:.4} N)",
        DISC.m * DISC.g
    );
    println!(
        "{} switches in {:.1} ms",
        run.switches.len(),
        took.as_secs_f64() * 1e3
    );

    let frames = run.frames();
    let options = SvgOptions {
        title: "Pushed rolling disc: rolling and sliding".into(),
        view: View::Oblique,
        traces: vec![0],
        ..SvgOptions::default()
    };
    let picture = svg(&DISC, &frames, &options)?;
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/animations");
    std::fs::create_dir_all(&dir)?;
    std::fs::write(dir.join("sliding_disc.svg"), picture)?;
    println!(
        "wrote docs/animations/sliding_disc.svg ({} frames)",
        frames.len()
    );
    Ok(())
}
