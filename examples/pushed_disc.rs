//! A disc pushed back and forth on a line, F = F0 sin(ω t): it rolls while
//! the friction rolling needs stays within μ N, slides where it does not,
//! and grips again when the slip dies out, or slides on the other way
//! when the push has already turned. Three scenes of one model, a hybrid
//! run between them, the switch log and an animation.
//!
//! `cargo run --release --example pushed_disc` prints the log and writes
//! `docs/animations/pushed_disc.svg`.

#[path = "models/pushed_disc.rs"]
mod pushed_disc;

use appell::animate::{svg, SvgOptions, View};
use appell::hybrid::Hybrid;
use appell::integrate::Dop853;
use pushed_disc::DISC;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let phases = pushed_disc::phases(&DISC);
    let names: Vec<&str> = phases.iter().map(|p| p.name).collect();
    let run = Hybrid::new(phases)
        .solver(Dop853::new().rtol(1e-10).atol(1e-12))
        .sample_every(1.0 / 60.0)
        .run::<4>(0, 0.0, &[0.0, 0.0], &[0.0], 6.0)?;
    println!(
        "Pushed disc: m = {} kg, r = {} m, mu = {}, F = {:.3} N sin({} t), from rest, rolling",
        DISC.m, DISC.r, DISC.mu, DISC.push, DISC.omega
    );
    println!(
        "{:>12}  {:<17} -> {:<17} {:<15} {:>15}",
        "t [s]", "from", "to", "reason", "energy lost [J]"
    );
    for s in &run.switches {
        println!(
            "{:>12.6}  {:<17} -> {:<17} {:<15} {:>15.2e}",
            s.t, names[s.from], names[s.to], s.reason, s.energy_lost
        );
    }
    let frames = run.frames();
    let options = SvgOptions {
        title: "Pushed disc: rolling and sliding".into(),
        view: View::Along(2),
        up: [0.0, 1.0, 0.0],
        ..SvgOptions::default()
    };
    let picture = svg(&DISC, &frames, &options)?;
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/animations");
    std::fs::create_dir_all(&dir)?;
    std::fs::write(dir.join("pushed_disc.svg"), picture)?;
    println!(
        "wrote docs/animations/pushed_disc.svg ({} frames)",
        frames.len()
    );
    Ok(())
}
