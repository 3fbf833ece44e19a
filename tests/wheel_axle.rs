//! The wheel-axle assemblage (Wang & Pao 2003, Sec. IV C) against the paper:
//! the closed form of eq. 64, C_rk of eq. 66, the cyclic coordinates, and
//! the generated code on f32 and dual numbers.

#[path = "../examples/models/wheel_axle.rs"]
mod model;

mod common;
use appell::Model;
use common::{close, Rng};
use model::WheelAxle;

fn random_model(rng: &mut Rng) -> WheelAxle {
    common::random_wheel_axle!(rng)
}

/// Eq. 64 with the drive torque: (64a) gains τ/a on its right side.
///   2a(M+m') ψ̈1 − l(M+m') φ̈ = 2Mg sinα cosφ + τ/a
///   al(M+m') ψ̈1 − (Ml² + m'l² + m'a²) φ̈ = Mgl sinα cosφ
/// solved by Cramer's rule: returns (φ̈, ψ̈1).
fn eq64(p: &WheelAxle, phi: f64, tau: f64) -> (f64, f64) {
    let (a, l, m, r) = (p.a, p.l, p.mass, p.rim);
    let s = p.g * p.alpha.sin() * phi.cos();
    let (a11, a12, b1) = (2.0 * a * (m + r), -l * (m + r), 2.0 * m * s + tau / a);
    let (a21, a22, b2) = (
        a * l * (m + r),
        -(m * l * l + r * l * l + r * a * a),
        m * l * s,
    );
    let det = a11 * a22 - a12 * a21;
    let psi = (b1 * a22 - a12 * b2) / det;
    let phi_dd = (a11 * b2 - b1 * a21) / det;
    (phi_dd, psi)
}

#[test]
fn reduced_state_and_cyclic_coordinates() {
    let info = WheelAxle::info();
    assert_eq!(info.cyclic, &["x1", "y1", "x2", "y2", "psi2"]);
    assert_eq!(info.ignorable, &["x1", "y1", "psi1", "x2", "y2", "psi2"]);
    assert_eq!(info.retained, &["phi"]);
    assert_eq!(info.speeds, &["phi", "psi1"]);
    assert_eq!(info.state_len(), 3);
    assert!(info.symbolic_elimination);
    assert_eq!(info.effects, &["gravity", "motor"]);
}

#[test]
fn gravity_alone_matches_eq_64_at_1000_states() {
    let mut rng = Rng(0x5eed_0001);
    for _ in 0..1000 {
        let p = random_model(&mut rng);
        let prepared = p.prepare::<f64>();
        let state = [
            rng.uniform(-3.0, 3.0),
            rng.uniform(-5.0, 5.0),
            rng.uniform(-5.0, 5.0),
        ];
        let mut d = [0.0; 3];
        p.rhs(&prepared, 0.0, &state, &[0.0], &mut d).unwrap();
        let (phi_dd, psi_dd) = eq64(&p, state[0], 0.0);
        assert_eq!(d[0], state[1], "phi' = phi_dot");
        assert!(
            d[1].abs() <= 1e-12 * (1.0 + psi_dd.abs()),
            "gravity alone: phi'' = 0, got {}",
            d[1]
        );
        assert!(close(d[1], phi_dd, 1e-12));
        assert!(
            close(d[2], psi_dd, 1e-12),
            "psi1'' {} vs eq. 64 {}",
            d[2],
            psi_dd
        );
        let expected = p.mass * p.g * p.alpha.sin() * state[0].cos() / (p.a * (p.mass + p.rim));
        assert!(close(d[2], expected, 1e-12));
    }
}

#[test]
fn drive_torque_on_level_ground_turns_the_axle() {
    // With α = 0 the torque on wheel 1 is the only asymmetric load: a sign
    // error in the φ coupling shows here and nowhere else.
    let mut rng = Rng(0x5eed_0002);
    for _ in 0..1000 {
        let mut p = random_model(&mut rng);
        p.alpha = 0.0;
        let tau = rng.uniform(-2.0, 2.0);
        let prepared = p.prepare::<f64>();
        let state = [
            rng.uniform(-3.0, 3.0),
            rng.uniform(-5.0, 5.0),
            rng.uniform(-5.0, 5.0),
        ];
        let mut d = [0.0; 3];
        p.rhs(&prepared, 0.0, &state, &[tau], &mut d).unwrap();
        let (phi_dd, psi_dd) = eq64(&p, state[0], tau);
        let (a, l, m, r) = (p.a, p.l, p.mass, p.rim);
        let closed = l * tau / (a * ((m + r) * l * l + 2.0 * r * a * a));
        assert!(close(phi_dd, closed, 1e-12));
        assert!(close(d[1], phi_dd, 1e-12), "phi'' {} vs {}", d[1], phi_dd);
        assert!(close(d[2], psi_dd, 1e-12), "psi1'' {} vs {}", d[2], psi_dd);
    }
}

#[test]
fn speed_transform_is_eq_66() {
    let p = WheelAxle::default();
    let mut rng = Rng(7);
    for _ in 0..100 {
        let q: Vec<f64> = (0..7).map(|_| rng.uniform(-3.0, 3.0)).collect();
        let phi = q[6];
        let mut c = [0.0; 14];
        let mut c0 = [0.0; 7];
        p.speed_transform(0.0, &q, &mut c, &mut c0).unwrap();
        let (a, l) = (p.a, p.l);
        // Columns φ̇ and ψ̇1 over (x1, y1, ψ1, x2, y2, ψ2, φ).
        let col_phi = [0.0, 0.0, 0.0, -l * phi.cos(), -l * phi.sin(), -l / a, 1.0];
        let col_psi = [
            a * phi.cos(),
            a * phi.sin(),
            1.0,
            a * phi.cos(),
            a * phi.sin(),
            1.0,
            0.0,
        ];
        for r in 0..7 {
            assert!(close(c[r * 2], col_phi[r], 1e-15), "C[{r}][phi]");
            assert!(close(c[r * 2 + 1], col_psi[r], 1e-15), "C[{r}][psi1]");
            assert_eq!(c0[r], 0.0);
        }
    }
}

#[test]
fn coordinate_rates_satisfy_the_constraints() {
    let p = WheelAxle::default();
    let mut rng = Rng(11);
    for _ in 0..100 {
        let q: Vec<f64> = (0..7).map(|_| rng.uniform(-3.0, 3.0)).collect();
        let u = [rng.uniform(-2.0, 2.0), rng.uniform(-2.0, 2.0)];
        let mut qdot = [0.0; 7];
        p.coordinate_rates(0.0, &q, &u, &mut qdot).unwrap();
        assert_eq!((qdot[6], qdot[2]), (u[0], u[1]));
        let mut vel = [0.0; 5];
        p.constraint_residuals(0.0, &q, &qdot, &mut [], &mut vel)
            .unwrap();
        assert!(vel.iter().all(|r| r.abs() < 1e-14), "{vel:?}");
    }
}

#[test]
fn kinetic_energy_matches_the_mass_matrix() {
    // T = ½ ẏᵀ M ẏ when the constraints are scleronomic (c = 0).
    let p = WheelAxle::default();
    let q = [0.1, -0.2, 0.3, 0.4, 0.5, 0.6, 0.7];
    let u = [0.8, -1.3];
    let t = p.kinetic_energy(0.0, &q, &u).unwrap();
    let mut m = [0.0; 4];
    let mut f = [0.0; 2];
    p.mass_matrix_and_forcing(0.0, &q, &u, &[0.0], &mut m, &mut f)
        .unwrap();
    let quad = 0.5 * (m[0] * u[0] * u[0] + 2.0 * m[1] * u[0] * u[1] + m[3] * u[1] * u[1]);
    assert!(close(t, quad, 1e-14), "{t} vs {quad}");
}

#[test]
fn f32_and_dual_numbers_run_the_same_code() {
    use num_dual::Dual64;
    let p = WheelAxle::default();
    let state = [0.4, 0.3, -1.2];
    let mut d64 = [0.0; 3];
    p.rhs(&p.prepare::<f64>(), 0.0, &state, &[0.5], &mut d64)
        .unwrap();
    let mut d32 = [0.0f32; 3];
    let s32 = state.map(|x| x as f32);
    p.rhs(&p.prepare::<f32>(), 0.0, &s32, &[0.5], &mut d32)
        .unwrap();
    for k in 0..3 {
        assert!((d32[k] as f64 - d64[k]).abs() < 1e-5);
    }
    // ∂(ψ̈1)/∂φ by a dual number equals the derivative of eq. 64.
    let sd = [Dual64::new(0.4, 1.0), Dual64::from(0.3), Dual64::from(-1.2)];
    let mut dd = [Dual64::from(0.0); 3];
    p.rhs(
        &p.prepare::<Dual64>(),
        Dual64::from(0.0),
        &sd,
        &[Dual64::from(0.5)],
        &mut dd,
    )
    .unwrap();
    let h = 1e-6;
    let fd = (eq64(&p, 0.4 + h, 0.5).1 - eq64(&p, 0.4 - h, 0.5).1) / (2.0 * h);
    assert!((dd[2].eps - fd).abs() < 1e-8, "{} vs {}", dd[2].eps, fd);
}

#[test]
fn bad_calls_are_typed_errors() {
    let p = WheelAxle::default();
    let prepared = p.prepare::<f64>();
    let mut d = [0.0; 3];
    assert!(matches!(
        p.rhs(&prepared, 0.0, &[0.0; 2], &[0.0], &mut d),
        Err(appell::ModelError::Length { .. })
    ));
    let bad = WheelAxle {
        a: 0.0,
        ..WheelAxle::default()
    };
    assert!(matches!(
        bad.rhs(&bad.prepare::<f64>(), 0.0, &[0.0; 3], &[0.0], &mut d),
        Err(appell::ModelError::NonPositiveParameter { name: "a", .. })
    ));
    // A NaN in the state is named, not just its effect on the result.
    assert_eq!(
        p.rhs(&prepared, 0.0, &[f64::NAN, 0.0, 0.0], &[0.0], &mut d),
        Err(appell::ModelError::NonFinite {
            what: "state component `phi`"
        })
    );
}

#[test]
fn controller_functions_agree_with_the_equations() {
    let mut rng = Rng(41);
    let worst = common::controller_agrees(&WheelAxle::default(), &mut rng, 50, 3.0);
    assert!(worst < 1e-12, "{worst:.2e}");
}

#[test]
fn every_coordinate_acceleration_is_the_rate_of_its_rate() {
    // q̈ of all seven coordinates, the five dependent ones included, against
    // a central difference of q̇ along the motion: q̇(q ± h q̇, u ± h u̇).
    use appell::motion::rates;
    let mut rng = Rng(0x9a11);
    let mut worst: f64 = 0.0;
    for _ in 0..200 {
        let p = random_model(&mut rng);
        let q: Vec<f64> = (0..7).map(|_| rng.uniform(-2.0, 2.0)).collect();
        let u = [rng.uniform(-2.0, 2.0), rng.uniform(-5.0, 5.0)];
        let inputs = [rng.uniform(-1.0, 1.0)];
        let r = rates(&p, 0.0, &q, &u, &inputs).unwrap();
        let h = 1e-5;
        let rate_at = |s: f64| {
            let qs: Vec<f64> = q.iter().zip(&r.qdot).map(|(q, v)| q + s * v).collect();
            let us: Vec<f64> = u.iter().zip(&r.udot).map(|(u, a)| u + s * a).collect();
            let mut out = [0.0; 7];
            p.coordinate_rates(0.0, &qs, &us, &mut out).unwrap();
            out
        };
        let (ahead, behind) = (rate_at(h), rate_at(-h));
        for k in 0..7 {
            let fd = (ahead[k] - behind[k]) / (2.0 * h);
            worst = worst.max((r.qddot[k] - fd).abs() / (1.0 + fd.abs()));
        }
        // The privileged speeds' coordinates: q̈ is u̇ itself.
        assert_eq!(r.qddot[6], r.udot[0]);
        assert_eq!(r.qddot[2], r.udot[1]);
    }
    println!("wheel-axle: q̈ against central differences of q̇: {worst:.1e}");
    assert!(worst < 1e-8, "{worst:e}");
}

#[test]
fn the_contact_watch_has_nothing_to_watch() {
    // The wheels' rolling is written as nonholonomic constraints, not
    // `rolls` contacts: no contact watch runs, and a solve is the same with
    // the switch either way.
    use appell::integrate::Dop853;
    assert!(WheelAxle::info().contacts.is_empty());
    let p = random_model(&mut Rng(0x5eed_0003));
    let solver = Dop853::new().rtol(1e-9).atol(1e-12);
    let x0 = [0.3, 1.0, -2.0];
    let on = solver.solve_model(&p, &[0.5], 0.0, &x0, 2.0).unwrap();
    let off = solver
        .contact_watch(false)
        .solve_model(&p, &[0.5], 0.0, &x0, 2.0)
        .unwrap();
    assert_eq!(on.x, off.x);
    assert_eq!(on.stats, off.stats);
}
