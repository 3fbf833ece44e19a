//! A hopping leg that alternates stance and flight: two scenes of one
//! model (the foot's ground constraint kept or left out), a hybrid run
//! that switches at lift-off (the ground's normal force, from the
//! constraint-force output, falls to zero) and at touchdown (a plastic
//! impact of the foot), the switch log, and an animation.
//!
//! `cargo run --release --example hopping` prints the log and writes
//! `docs/animations/hopping.svg`.

#[path = "models/hopper.rs"]
mod hopper;

use appell::animate::{svg, SvgOptions, View};
use appell::hybrid::{Hybrid, HybridError};
use appell::integrate::Dop853;
use hopper::HOPPER;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let phases = hopper::phases(&HOPPER);
    let names: Vec<&str> = phases.iter().map(|p| p.name).collect();
    let hybrid = Hybrid::new(phases)
        .solver(Dop853::new().rtol(1e-10).atol(1e-12))
        .sample_every(1.0 / 60.0)
        .max_switches(40);
    // The leg starts compressed, at rest, in stance.
    let (z0, t_end) = (0.2, 3.0);
    let run = match hybrid.run::<4>(0, 0.0, &[z0, 0.0], &[0.0], t_end) {
        Ok(run) => run,
        Err(HybridError::TooManySwitches(run)) => {
            println!("stopped after {} switches (Zeno?)", run.switches.len());
            *run
        }
        Err(e) => return Err(e.into()),
    };
    println!("Hopping leg: body {} kg, foot {} kg, leg {} N/m, rest length {} m, from z = {z0} m at rest", HOPPER.big_m, HOPPER.m, HOPPER.k, HOPPER.l0);
    println!(
        "{:>12}  {:<8} -> {:<8} {:<10} {:>12} {:>14}",
        "t [s]", "from", "to", "reason", "impulse [N s]", "energy lost [J]"
    );
    for s in &run.switches {
        let impulse = s
            .impulses
            .first()
            .map_or("-".to_string(), |i| format!("{i:.6}"));
        println!(
            "{:>12.6}  {:<8} -> {:<8} {:<10} {:>12} {:>14.6}",
            s.t, names[s.from], names[s.to], s.reason, impulse, s.energy_lost
        );
    }
    // The animation: every sample, once per instant.
    let frames = run.frames();
    let options = SvgOptions {
        title: "Hopping leg: stance and flight".into(),
        view: View::Along(0),
        connectors: vec![(Some(0), Some(1))],
        traces: vec![0],
        ..SvgOptions::default()
    };
    let picture = svg(&HOPPER, &frames, &options)?;
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/animations");
    std::fs::create_dir_all(&dir)?;
    std::fs::write(dir.join("hopping.svg"), picture)?;
    println!(
        "wrote docs/animations/hopping.svg ({} frames)",
        frames.len()
    );
    Ok(())
}
