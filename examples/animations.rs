//! Pictures of the motion, written to `docs/animations/` (or the directory
//! given as the first argument): `cargo run --release --example animations`.
//!
//! Each is a self-contained SVG that plays in a browser (SMIL, no script),
//! drawn by `appell::animate` from the model's own geometry: the benchmark
//! bicycle coasting at 4.6 m/s (stable: the weave dies out) and falling at
//! 2 m/s, the wheel-axle's track on its incline, a rolling disc, the
//! 8-link pendulum, the IFToMM four-bar through its dead centres (in full
//! coordinates, past the reduced equations' singular positions), the UR5
//! falling from a pose and the UR5 on its rolling base; and the bicycle's
//! eigenvalues against speed (Meijaard et al. 2007, Fig. 3).

#[path = "models/four_bar.rs"]
mod four_bar;
#[path = "models/mobile_manipulator.rs"]
mod mobile_manipulator;
#[allow(dead_code)] // the other lengths serve other programs
#[path = "models/n_link_pendulum.rs"]
mod n_link_pendulum;
#[path = "models/rolling_disc.rs"]
mod rolling_disc;
#[path = "models/ur5.rs"]
mod ur5;
#[path = "models/wheel_axle.rs"]
mod wheel_axle;
#[allow(dead_code)] // the critical speeds serve the bicycle's example
#[path = "models/whipple_bicycle.rs"]
mod whipple_bicycle;

use std::error::Error;
use std::path::{Path, PathBuf};

use appell::animate::{line_plot, simulate, simulate_watched, svg, Curve, Frame, SvgOptions, View};
use appell::augmented::{integrate, Settings};
use appell::contact_watch::ContactWatch;
use appell::Model;

fn main() -> Result<(), Box<dyn Error>> {
    let dir = std::env::args()
        .nth(1)
        .map_or_else(|| PathBuf::from("docs/animations"), PathBuf::from);
    std::fs::create_dir_all(&dir)?;
    bicycle(&dir)?;
    wheel_axle(&dir)?;
    rolling_disc(&dir)?;
    pendulum(&dir)?;
    four_bar(&dir)?;
    robots(&dir)?;
    println!("wrote the animations to {}", dir.display());
    Ok(())
}

/// Writes `name` and says so.
fn write(dir: &Path, name: &str, text: &str) -> Result<(), Box<dyn Error>> {
    let path = dir.join(name);
    std::fs::write(&path, text)?;
    println!("{} ({} kB)", path.display(), text.len() / 1000);
    Ok(())
}

/// `SvgOptions` with a title.
fn titled(title: &str) -> SvgOptions {
    SvgOptions {
        title: title.into(),
        ..SvgOptions::default()
    }
}

fn bicycle(dir: &Path) -> Result<(), Box<dyn Error>> {
    let p = whipple_bicycle::WhippleBicycle::default();
    let q = whipple_bicycle::operating_point(&p)?;
    // The frames: rear frame, rear wheel, front frame, front wheel; z down.
    let options = |title: &str| SvgOptions {
        up: [0.0, 0.0, -1.0],
        follow: true,
        view: View::Oblique,
        connectors: vec![(Some(1), Some(0)), (Some(0), Some(2)), (Some(2), Some(3))],
        ..titled(title)
    };
    // Nudged by a roll rate; the fall stops short of lying flat (1.1 rad).
    for (name, v, nudge, t_end, title) in [
        (
            "bicycle_coasting.svg",
            4.6,
            0.5,
            6.0,
            "Whipple bicycle at 4.6 m/s, nudged: the weave dies out",
        ),
        (
            "bicycle_falling.svg",
            2.0,
            0.1,
            1.75,
            "Whipple bicycle at 2 m/s, nudged: too slow, it falls",
        ),
    ] {
        let u = [nudge, -v / p.rr, 0.0];
        // Falling, the steer whips round and by 1.65 s the front wheel's
        // normal force turns negative: the two-sided contacts hold the wheel
        // down from there. The picture is drawn to the end, with a warning
        // watch that says so, instead of stopping there.
        let mut watch = ContactWatch::new(&p).inputs(&[0.0]).warn();
        let count = (t_end * 30.0) as usize;
        let frames = simulate_watched(&p, 0.0, &q, &u, &[0.0], t_end, count, &mut watch)?;
        for event in &watch.events {
            println!("{name}: {event}");
        }
        let lean = frames.iter().map(|f| f.q[3].abs()).fold(0.0, f64::max);
        println!("{name}: largest lean {lean:.3} rad");
        write(dir, name, &svg(&p, &frames, &options(title))?)?;
    }
    let speeds: Vec<f64> = (0..=100).map(|k| 0.1 * k as f64).collect();
    let (mut re, mut im) = (Vec::new(), Vec::new());
    for &v in &speeds {
        for (a, b) in whipple_bicycle::eigenvalues(&p, v)? {
            re.push((v, a));
            im.push((v, b.abs()));
        }
    }
    let plot = line_plot(
        "Whipple bicycle: lean and steer eigenvalues against speed",
        "forward speed v [m/s]",
        "eigenvalue [1/s]",
        &[
            Curve {
                label: "real part".into(),
                points: re,
            },
            Curve {
                label: "|imaginary part|".into(),
                points: im,
            },
        ],
    );
    write(dir, "bicycle_eigenvalues.svg", &plot)
}

fn wheel_axle(dir: &Path) -> Result<(), Box<dyn Error>> {
    let p = wheel_axle::WheelAxle::default();
    let info = wheel_axle::WheelAxle::info();
    let mut q = vec![0.0; info.coordinates.len()];
    // x1, y1, psi1, x2, y2, psi2, phi: wheel 2 at +l along the axle.
    q[4] = p.l;
    let u = [0.6, 4.0]; // phi', psi1'
    let frames = simulate(&p, 0.0, &q, &u, &[0.3], 6.0, 180)?;
    let options = SvgOptions {
        view: View::Along(2),
        connectors: vec![(Some(0), Some(1))],
        traces: vec![0, 1],
        ..titled("Wheel-axle on a 0.2 rad incline (downhill along +x), driven: the wheels' tracks")
    };
    write(dir, "wheel_axle.svg", &svg(&p, &frames, &options)?)
}

fn rolling_disc(dir: &Path) -> Result<(), Box<dyn Error>> {
    let p = rolling_disc::RollingDisc::default();
    // yaw, lean, spin, x, y; yaw rate, lean rate, spin rate.
    let q = [0.0, 0.25, 0.0, 0.0, 0.0];
    let u = [1.0, 0.0, 8.0];
    let frames = simulate(&p, 0.0, &q, &u, &[], 4.0, 120)?;
    let options = SvgOptions {
        view: View::Oblique,
        ..titled("Rolling disc, leaning and turning")
    };
    write(dir, "rolling_disc.svg", &svg(&p, &frames, &options)?)
}

fn pendulum(dir: &Path) -> Result<(), Box<dyn Error>> {
    let p = n_link_pendulum::Pendulum8::default();
    let q: Vec<f64> = (0..8).map(|k| 1.2 + 0.1 * k as f64).collect();
    let frames = simulate(&p, 0.0, &q, &[0.0; 8], &[], 6.0, 240)?;
    let mut connectors = vec![(None, Some(0))];
    connectors.extend((1..8).map(|k| (Some(k - 1), Some(k))));
    let options = SvgOptions {
        connectors,
        traces: vec![7],
        ..titled("8-link pendulum released from rest")
    };
    write(dir, "pendulum_8.svg", &svg(&p, &frames, &options)?)
}

/// The four-bar in full coordinates (the augmented Lagrangian
/// formulation with projections), so it passes the crossings where the
/// reduced equations' dependent block is singular.
fn four_bar(dir: &Path) -> Result<(), Box<dyn Error>> {
    let p = four_bar::FourBar2 {
        a: 1.0,
        m: 1.0,
        g: 9.81,
    };
    let half_pi = std::f64::consts::FRAC_PI_2;
    let mut q = vec![half_pi, half_pi, half_pi, 0.0, 0.0];
    let mut qdot = vec![-1.0, -1.0, -1.0, 0.0, 0.0];
    let h = 1e-3;
    let mut frames = vec![Frame {
        t: 0.0,
        q: q.clone(),
    }];
    let mut step = 0;
    integrate(
        &p,
        0.0,
        &mut q,
        &mut qdot,
        h,
        5000,
        &[],
        &Settings::default(),
        |t, q, _| {
            step += 1;
            if step % 25 == 0 {
                frames.push(Frame { t, q: q.to_vec() });
            }
        },
    )?;
    let options = titled("IFToMM four-bar (N = 2) through its singular positions");
    write(dir, "four_bar.svg", &svg(&p, &frames, &options)?)
}

fn robots(dir: &Path) -> Result<(), Box<dyn Error>> {
    let arm = ur5::Ur5;
    let q = [0.0, -1.2, 1.0, 0.3, 0.2, 0.0];
    let frames = simulate(&arm, 0.0, &q, &[0.0; 6], &[0.0; 6], 2.5, 75)?;
    // A stick figure: the URDF's inertias (a 1.2 kg wrist with the moments
    // of a 1.3 m disc) make poor shapes.
    let links = ur5::Ur5::info().bodies.len();
    let options = SvgOptions {
        view: View::Oblique,
        connectors: (1..links).map(|k| (Some(k - 1), Some(k))).collect(),
        dots: (0..links).collect(),
        ..titled("UR5 falling from a pose, no torques")
    };
    write(dir, "ur5.svg", &svg(&arm, &frames, &options)?)?;

    let base = mobile_manipulator::MobileManipulator::default();
    let info = mobile_manipulator::MobileManipulator::info();
    let mut q = vec![0.0; info.coordinates.len()];
    for (name, value) in [("shoulder_lift_joint", -1.0), ("elbow_joint", 1.2)] {
        q[info.coordinate_index(name).ok_or("a UR5 joint")?] = value;
    }
    let mut u = vec![0.0; info.speeds.len()];
    u[0] = 6.0; // left wheel
    u[1] = 4.0; // right wheel
    let inputs = vec![0.0; info.inputs.len()];
    let frames = simulate(&base, 0.0, &q, &u, &inputs, 3.0, 90)?;
    // Chassis, wheels, then the UR5's links base to tip.
    let mut connectors = vec![(Some(0), Some(1)), (Some(0), Some(2)), (Some(0), Some(3))];
    connectors.extend((4..info.bodies.len()).map(|k| (Some(k - 1), Some(k))));
    let options = SvgOptions {
        view: View::Oblique,
        connectors,
        dots: (3..info.bodies.len()).collect(),
        ..titled("UR5 on a differential-drive base, the arm falling as the base turns")
    };
    write(
        dir,
        "mobile_manipulator.svg",
        &svg(&base, &frames, &options)?,
    )
}
