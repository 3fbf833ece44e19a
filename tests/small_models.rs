//! Small models with known answers: a planar double pendulum (holonomic-only
//! coordinates), a Chaplygin sleigh (nonholonomic, with a dependent-speed
//! pivot that can vanish, so it is solved numerically at run time), and a
//! pendulum in Cartesian coordinates (a holonomic constraint).

mod common;
#[path = "../examples/models/double_pendulum.rs"]
mod double_pendulum;
use appell::{Appell, Model, ModelError};
use common::{close, Rng};
use double_pendulum::DoublePendulum;

/// A rigid body on a knife edge at P = (x, y), heading θ, mass centre a
/// distance `b` ahead of the edge; the edge cannot slide sideways.
#[derive(Appell, Clone)]
#[appell(coordinates(x, y, theta), speeds(x, theta), positive(m, b))]
#[appell(frame(B = N.rotate_z(theta)))]
#[appell(point(P = O + x * N.x + y * N.y), point(C = P + b * B.x))]
#[appell(body(sleigh, center = C, frame = B, mass = m, inertia = principal(i0, i0, i0)))]
#[appell(nonholonomic(dt(y) * cos(theta) - dt(x) * sin(theta) == 0))]
pub struct Sleigh {
    pub m: f64,
    pub i0: f64,
    pub b: f64,
}

/// A simple pendulum in Cartesian coordinates: x² + y² = l².
#[derive(Appell, Clone)]
#[appell(coordinates(x, y), speeds(x))]
#[appell(point(P = O + x * N.x + y * N.y), particle(P, mass = m))]
#[appell(holonomic(x * x + y * y == l * l))]
#[appell(gravity(-g * N.y))]
pub struct CartesianPendulum {
    pub m: f64,
    pub l: f64,
    pub g: f64,
}

#[test]
fn double_pendulum_matches_the_textbook_formula() {
    let mut rng = Rng(3);
    for _ in 0..1000 {
        let p = DoublePendulum {
            m1: rng.uniform(0.5, 3.0),
            m2: rng.uniform(0.5, 3.0),
            l1: rng.uniform(0.5, 2.0),
            l2: rng.uniform(0.5, 2.0),
            g: 9.81,
        };
        let s = [
            rng.uniform(-3.0, 3.0),
            rng.uniform(-3.0, 3.0),
            rng.uniform(-3.0, 3.0),
            rng.uniform(-3.0, 3.0),
        ];
        let mut d = [0.0; 4];
        p.rhs(&p.prepare::<f64>(), 0.0, &s, &[], &mut d).unwrap();
        let (w1, w2) = (s[2], s[3]);
        let (a1, a2) = common::double_pendulum_accelerations(p.m1, p.m2, p.l1, p.l2, p.g, s);
        assert_eq!((d[0], d[1]), (w1, w2));
        assert!(close(d[2], a1, 1e-12), "{} vs {}", d[2], a1);
        assert!(close(d[3], a2, 1e-12), "{} vs {}", d[3], a2);
    }
    let info = DoublePendulum::info();
    assert_eq!(info.retained, &["q1", "q2"]);
    assert!(info.cyclic.is_empty());
}

#[test]
fn double_pendulum_small_oscillations() {
    // Equal links and masses: ω² = (2 ± √2) g / l, read off M⁻¹K at rest.
    let p = DoublePendulum {
        m1: 1.0,
        m2: 1.0,
        l1: 1.0,
        l2: 1.0,
        g: 9.81,
    };
    let prepared = p.prepare::<num_dual::Dual64>();
    let mut jac = [[0.0; 2]; 2];
    for j in 0..2 {
        let mut s = [num_dual::Dual64::from(0.0); 4];
        s[j] = num_dual::Dual64::new(0.0, 1.0);
        let mut d = [num_dual::Dual64::from(0.0); 4];
        p.rhs(&prepared, 0.0.into(), &s, &[], &mut d).unwrap();
        jac[0][j] = d[2].eps;
        jac[1][j] = d[3].eps;
    }
    // Eigenvalues of the 2×2 Jacobian block are −ω².
    let tr = jac[0][0] + jac[1][1];
    let det = jac[0][0] * jac[1][1] - jac[0][1] * jac[1][0];
    let disc = (tr * tr / 4.0 - det).sqrt();
    let mut w2 = [-(tr / 2.0 + disc), -(tr / 2.0 - disc)];
    w2.sort_by(f64::total_cmp);
    let expected = [(2.0 - 2f64.sqrt()) * 9.81, (2.0 + 2f64.sqrt()) * 9.81];
    assert!(
        close(w2[0], expected[0], 1e-12) && close(w2[1], expected[1], 1e-12),
        "{w2:?}"
    );
}

#[test]
fn sleigh_solves_its_dependent_speed_numerically() {
    let info = Sleigh::info();
    assert!(!info.symbolic_elimination, "pivot cos(theta) may vanish");
    assert_eq!(info.dependent, &["y"]);
    assert_eq!(info.cyclic, &["y"]);
    assert_eq!(info.ignorable, &["x", "y"]);
    assert_eq!(info.retained, &["theta"]);
}

#[test]
fn sleigh_conserves_energy_and_respects_the_constraint() {
    // With no forces, dT/dt = 0: check ẏᵀ M ÿ + ½ ẏᵀ Ṁ ẏ = 0 through the
    // energy function and the accelerations, by a dual number along the path.
    use num_dual::Dual64;
    let p = Sleigh {
        m: 2.0,
        i0: 0.3,
        b: 0.4,
    };
    let mut rng = Rng(5);
    for _ in 0..200 {
        let theta = rng.uniform(-1.2, 1.2);
        let u = [rng.uniform(-2.0, 2.0), rng.uniform(-2.0, 2.0)];
        let mut d = [0.0; 3];
        p.rhs(&p.prepare::<f64>(), 0.0, &[theta, u[0], u[1]], &[], &mut d)
            .unwrap();
        // Along the motion: q̇ from the constraint, u̇ from the rhs.
        let q = [0.0, 0.0, theta];
        let mut qdot = [0.0; 3];
        p.coordinate_rates(0.0, &q, &u, &mut qdot).unwrap();
        let qd: Vec<Dual64> = q
            .iter()
            .zip(&qdot)
            .map(|(a, b)| Dual64::new(*a, *b))
            .collect();
        let ud = [Dual64::new(u[0], d[1]), Dual64::new(u[1], d[2])];
        let t = p.kinetic_energy(Dual64::from(0.0), &qd, &ud).unwrap();
        assert!(t.eps.abs() < 1e-12 * (1.0 + t.re), "dT/dt = {}", t.eps);
        let mut vel = [0.0];
        p.constraint_residuals(0.0, &q, &qdot, &mut [], &mut vel)
            .unwrap();
        assert!(vel[0].abs() < 1e-14);
    }
}

#[test]
fn sleigh_at_a_singular_heading_is_a_typed_error() {
    // θ = π/2: the chosen privileged speed ẋ is forced to zero and ẏ is not
    // determined by it; the numeric solve must report, not divide by zero.
    let p = Sleigh {
        m: 2.0,
        i0: 0.3,
        b: 0.4,
    };
    let mut d = [0.0; 3];
    let r = p.rhs(
        &p.prepare::<f64>(),
        0.0,
        &[std::f64::consts::FRAC_PI_2, 1.0, 0.5],
        &[],
        &mut d,
    );
    assert!(
        matches!(r, Err(ModelError::SingularConstraints { column: 0, .. })),
        "{r:?}"
    );
}

#[test]
fn cartesian_pendulum_matches_the_angle_form() {
    // θ from the downward vertical: x = l sin θ, y = −l cos θ, θ̈ = −(g/l) sin θ.
    let p = CartesianPendulum {
        m: 1.3,
        l: 0.8,
        g: 9.81,
    };
    let info = CartesianPendulum::info();
    assert_eq!(info.holonomic, 1);
    assert!(!info.symbolic_elimination);
    assert_eq!(info.retained, &["x", "y"]);
    let mut rng = Rng(9);
    for _ in 0..500 {
        let theta = rng.uniform(-1.4, 1.4);
        let w = rng.uniform(-3.0, 3.0);
        let (x, y) = (p.l * theta.sin(), -p.l * theta.cos());
        let xdot = p.l * theta.cos() * w;
        let mut d = [0.0; 3];
        p.rhs(&p.prepare::<f64>(), 0.0, &[x, y, xdot], &[], &mut d)
            .unwrap();
        let acc = -p.g / p.l * theta.sin();
        let xdd = p.l * (theta.cos() * acc - theta.sin() * w * w);
        assert!(close(d[2], xdd, 1e-11), "x'' {} vs {}", d[2], xdd);
        let ydot = p.l * theta.sin() * w;
        assert!(close(d[1], ydot, 1e-12), "y' {} vs {}", d[1], ydot);
        let mut hol = [0.0];
        p.constraint_residuals(0.0, &[x, y], &[xdot, ydot], &mut hol, &mut [0.0])
            .unwrap();
        assert!(hol[0].abs() < 1e-14);
    }
}

/// A disc on a gimbal with a particle on its rim: the disc's inertia and
/// the particle's mass are parameters, so only `validate` can check them.
#[derive(Appell, Clone)]
#[appell(coordinates(theta, phi), speeds(theta, phi), positive(m))]
#[appell(frame(A = N.rotate_z(theta)), frame(B = A.rotate_x(phi)))]
#[appell(point(P = O + r * B.y))]
#[appell(body(disc, center = O, frame = B, mass = m, inertia = principal(i1, i1, i3)))]
#[appell(particle(P, mass = mp))]
pub struct Gimbal {
    pub m: f64,
    pub i1: f64,
    pub i3: f64,
    pub mp: f64,
    pub r: f64,
}

#[test]
fn bodies_made_of_parameters_are_checked_before_a_simulation_starts() {
    use appell::integrate::{Dop853, IntegrateError, TrBdf2};
    let good = Gimbal {
        m: 2.0,
        i1: 0.25,
        i3: 0.5,
        mp: 0.1,
        r: 0.5,
    };
    assert_eq!(good.validate(), Ok(()));
    let impossible = |body, rule, parameters| {
        Err(ModelError::ImpossibleBody {
            body,
            rule,
            parameters,
        })
    };
    use appell::physical::BodyRule::*;
    let lopsided = Gimbal {
        i3: 0.6,
        ..good.clone()
    };
    assert_eq!(
        lopsided.validate(),
        impossible("disc", Triangle, &["i1", "i3"])
    );
    let negative = Gimbal {
        i1: -0.25,
        ..good.clone()
    };
    assert_eq!(
        negative.validate(),
        impossible("disc", NotSemidefinite, &["i1", "i3"])
    );
    let light = Gimbal {
        mp: -0.1,
        ..good.clone()
    };
    assert_eq!(light.validate(), impossible("P", NonPositiveMass, &["mp"]));
    assert_eq!(
        light.validate().unwrap_err().to_string(),
        "body `P` cannot be physical: its mass is not positive; check parameter `mp`"
    );
    assert_eq!(
        lopsided.validate().unwrap_err().to_string(),
        "body `disc` cannot be physical: its inertia violates the triangle inequality: a principal moment exceeds the sum of the other two; check parameters `i1`, `i3`"
    );
    // Declared positivity is checked first, as `rhs` does.
    let massless = Gimbal {
        m: 0.0,
        ..good.clone()
    };
    assert!(matches!(
        massless.validate(),
        Err(ModelError::NonPositiveParameter { name: "m", .. })
    ));
    // The entry points refuse before their first step: an explicit and an
    // implicit integrator, and the linearization.
    let x0 = [0.2, 0.3, 0.4];
    assert_eq!(
        Dop853::new()
            .solve_model(&lopsided, &[], 0.0, &x0, 1.0)
            .unwrap_err(),
        IntegrateError::Model(lopsided.validate().unwrap_err())
    );
    assert!(matches!(
        TrBdf2::new().solve_model(&light, &[], 0.0, &x0, 1.0),
        Err(IntegrateError::Model(ModelError::ImpossibleBody {
            body: "P",
            ..
        }))
    ));
    assert_eq!(
        appell::linearize::linearize(&negative, 0.0, &x0, &[]).unwrap_err(),
        negative.validate().unwrap_err()
    );
    assert!(Dop853::new().solve_model(&good, &[], 0.0, &x0, 0.1).is_ok());
}

/// A pendulum whose bob hangs at a length the model computes by dividing
/// by a parameter: `stretch = 0` makes the divisor zero.
#[derive(Appell, Clone)]
#[appell(coordinates(theta), speeds(theta))]
#[appell(point(P = O + (l / stretch) * (sin(theta) * N.x - cos(theta) * N.y)))]
#[appell(particle(P, mass = m), gravity(-g * N.y))]
pub struct StretchedPendulum {
    pub m: f64,
    pub l: f64,
    pub stretch: f64,
    pub g: f64,
}

#[test]
fn a_zero_divisor_names_its_parameter() {
    use appell::integrate::{Dop853, IntegrateError};
    let good = StretchedPendulum {
        m: 1.0,
        l: 1.0,
        stretch: 2.0,
        g: 9.81,
    };
    assert_eq!(good.validate(), Ok(()));
    let broken = StretchedPendulum {
        stretch: 0.0,
        ..good.clone()
    };
    let zero = ModelError::ZeroDivisor {
        place: "point `P`",
        parameters: &["stretch"],
    };
    assert_eq!(broken.validate(), Err(zero));
    assert_eq!(
        zero.to_string(),
        "division by zero in point `P`; check parameter `stretch`"
    );
    // The rhs, called directly, names it too instead of a non-finite result.
    let prepared = broken.prepare::<f64>();
    let mut d = [0.0; 2];
    assert_eq!(
        broken.rhs(&prepared, 0.0, &[0.3, 0.0], &[], &mut d),
        Err(zero)
    );
    assert_eq!(
        Dop853::new()
            .solve_model(&broken, &[], 0.0, &[0.3, 0.0], 1.0)
            .unwrap_err(),
        IntegrateError::Model(zero)
    );
}

#[test]
fn the_command_line_refuses_parameters_that_make_a_body_impossible() {
    let args: Vec<String> = ["gimbal", "eval"].iter().map(|s| s.to_string()).collect();
    let good = Gimbal {
        m: 2.0,
        i1: 0.25,
        i3: 0.5,
        mp: 0.1,
        r: 0.5,
    };
    let lines = b"{\"q\": {\"phi\": 0.2}, \"u\": {\"theta\": 0.3, \"phi\": 0.4}}\n\
                  {\"q\": {\"phi\": 0.2}, \"u\": {\"theta\": 0.3, \"phi\": 0.4}, \"params\": {\"i3\": 0.6}}\n";
    let mut out = Vec::new();
    appell::cli::run_with(good, &args, &mut &lines[..], &mut out, |_| Ok(())).unwrap();
    let text = String::from_utf8(out).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert!(lines[0].starts_with(r#"{"qdot":"#), "{}", lines[0]);
    assert!(
        lines[1].contains("body `disc` cannot be physical")
            && lines[1].contains("check parameters `i1`, `i3`"),
        "{}",
        lines[1]
    );
}

/// The command line's answer to `lines` (one JSON object per line) under
/// `command`, for the Cartesian pendulum (l = 0.8).
fn pendulum_cli(command: &str, lines: &str) -> Vec<serde_json::Value> {
    let p = CartesianPendulum {
        m: 1.3,
        l: 0.8,
        g: 9.81,
    };
    let args: Vec<String> = ["pendulum", command]
        .iter()
        .map(|s| s.to_string())
        .collect();
    let mut out = Vec::new();
    appell::cli::run_with(p, &args, &mut lines.as_bytes(), &mut out, |_| Ok(())).unwrap();
    String::from_utf8(out)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect()
}

#[test]
fn the_command_line_solves_a_coordinate_the_constraint_fixes() {
    // y is left out: x² + y² = l² fixes it (flat at y = 0, so Newton starts
    // from the second guess and finds the upper branch, which is reported).
    let answers = pendulum_cli(
        "eval",
        "{\"q\": {\"x\": 0.48}, \"u\": {\"x\": 0.1}}\n{\"u\": {\"x\": 0.1}}\n",
    );
    let solved = &answers[0];
    let y = solved["solved"]["y"].as_f64().expect("y solved");
    assert!((y.abs() - 0.64).abs() < 1e-12, "{solved}");
    let residual = solved["residual"].as_f64().unwrap();
    assert!(residual.abs() < 1e-12, "{solved}");
    assert!(solved.get("warning").is_none(), "{solved}");
    // On the circle, ẏ = −x ẋ / y.
    let ydot = solved["qdot"]["y"].as_f64().unwrap();
    assert!((ydot + 0.48 * 0.1 / y).abs() < 1e-12, "{solved}");
    // x is not fixed by the constraint (it is the independent coordinate).
    let missing = answers[1]["error"].as_str().unwrap();
    assert!(
        missing.contains("missing coordinate `x` in `q` (the holonomic constraints do not fix it)"),
        "{missing}"
    );
}

#[test]
fn contacts_warns_of_a_state_off_the_constraint_as_eval_does() {
    let off = "{\"q\": {\"x\": 0.48, \"y\": -0.7}, \"u\": {\"x\": 0.1}}\n";
    let on = "{\"q\": {\"x\": 0.48, \"y\": -0.64}, \"u\": {\"x\": 0.1}}\n";
    for command in ["eval", "contacts"] {
        let answers = pendulum_cli(command, &format!("{off}{on}"));
        let message = answers[0]["warning"]["message"].as_str().unwrap_or("");
        assert!(
            message.contains("violate holonomic constraint 0"),
            "{command}: {}",
            answers[0]
        );
        let residual = answers[0]["warning"]["holonomic_residuals"][0]
            .as_f64()
            .unwrap();
        assert!(
            (residual - (0.48f64.powi(2) + 0.49 - 0.64)).abs() < 1e-12,
            "{residual}"
        );
        assert!(
            answers[1].get("warning").is_none(),
            "{command}: {}",
            answers[1]
        );
        assert!(
            answers[1].get("error").is_none(),
            "{command}: {}",
            answers[1]
        );
    }
    // The contacts answer still carries the forces.
    let answers = pendulum_cli("contacts", off);
    assert!(answers[0]["multipliers"].is_array(), "{}", answers[0]);
}

#[test]
fn a_repeated_key_is_an_error_not_the_last_value() {
    let answers = pendulum_cli(
        "eval",
        "{\"q\": {\"x\": 0.48, \"x\": 0.2}, \"u\": {\"x\": 0.1}}\n",
    );
    let error = answers[0]["error"].as_str().unwrap();
    assert!(error.contains("duplicate key `x`"), "{error}");
}

/// `accuracy` or `animate` of one problem: stdout, or the error.
fn pendulum_problem(command: &str, problem: &str) -> Result<String, appell::cli::CliError> {
    let p = CartesianPendulum {
        m: 1.3,
        l: 0.8,
        g: 9.81,
    };
    let args: Vec<String> = ["pendulum", command]
        .iter()
        .map(|s| s.to_string())
        .collect();
    let mut out = Vec::new();
    appell::cli::run_with(p, &args, &mut problem.as_bytes(), &mut out, |_| Ok(()))?;
    Ok(String::from_utf8(out).unwrap())
}

#[test]
fn accuracy_reports_what_it_solved_and_warns_off_the_constraint() {
    let settings = "\"t_end\": 0.2, \"checkpoints\": 2, \"levels\": 1, \"repeats\": 1";
    let solved: serde_json::Value = serde_json::from_str(
        &pendulum_problem(
            "accuracy",
            &format!("{{\"q\": {{\"x\": 0.48}}, \"u\": {{\"x\": 0.1}}, {settings}}}"),
        )
        .unwrap(),
    )
    .unwrap();
    let y = solved["solved"]["y"].as_f64().expect("y solved");
    assert!((y.abs() - 0.64).abs() < 1e-12, "{solved}");
    assert!(solved.get("warning").is_none(), "{solved}");
    assert!(!solved["points"].as_array().unwrap().is_empty(), "{solved}");
    let off: serde_json::Value = serde_json::from_str(
        &pendulum_problem(
            "accuracy",
            &format!("{{\"q\": {{\"x\": 0.48, \"y\": -0.7}}, \"u\": {{\"x\": 0.1}}, {settings}}}"),
        )
        .unwrap(),
    )
    .unwrap();
    let message = off["warning"]["message"].as_str().unwrap_or("");
    assert!(message.contains("violate holonomic constraint 0"), "{off}");
}

#[test]
fn animate_records_what_it_solved_and_warns_off_the_constraint() {
    let picture = pendulum_problem(
        "animate",
        "{\"q\": {\"x\": 0.48}, \"u\": {\"x\": 0.1}, \"t_end\": 0.1, \"frames\": 4}",
    )
    .unwrap();
    assert!(picture.starts_with("<svg"), "{}", &picture[..200]);
    assert!(
        picture.contains("<!-- solved from the holonomic constraints: y = "),
        "{}",
        &picture[..400]
    );
    let off = pendulum_problem(
        "animate",
        "{\"q\": {\"x\": 0.48, \"y\": -0.7}, \"u\": {\"x\": 0.1}, \"t_end\": 0.1, \"frames\": 4}",
    )
    .unwrap();
    assert!(
        off.contains("warning: the coordinates violate holonomic constraint 0"),
        "{}",
        &off[..400]
    );
    // Given on the constraint, there is nothing to say.
    let on = pendulum_problem(
        "animate",
        "{\"q\": {\"x\": 0.48, \"y\": -0.64}, \"u\": {\"x\": 0.1}, \"t_end\": 0.1, \"frames\": 4}",
    )
    .unwrap();
    assert!(!on.contains("<!--"), "{}", &on[..400]);
}
