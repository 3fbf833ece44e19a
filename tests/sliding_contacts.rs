//! The rolling disc, pushed beyond its friction limit: it slides, its
//! normal force found from the momentum balances at every evaluation
//! (`appell::sliding`), and grips again where the slip dies out.

#[path = "../examples/models/sliding_disc.rs"]
mod sliding_disc;

mod common;
use common::XorShift;

use appell::hybrid::{Hybrid, HybridRun, Phase};
use appell::integrate::Dop853;
use appell::sliding::{sliding_normals, SlidingContact, SlidingError};
use appell::{Appell, DynModel, Model};
use sliding_disc::{
    friction_margin, phases, slip, PushedRollingDisc, PushedRollingDiscRolling,
    PushedRollingDiscSliding, SlidingDisc, DISC, GRIP_SPEED,
};

/// Rolling upright at 2.25 m/s (spin 15 rad/s), leaning 0.05 rad.
const Q0: [f64; 5] = [0.0, 0.05, 0.0, 0.0, 0.0];
const U0: [f64; 3] = [0.0, 0.0, 15.0];

fn contact(disc: &PushedRollingDisc) -> SlidingContact<'_> {
    SlidingContact::at_rolling_contact(disc, 0, 0, [0.0, 0.0, 1.0])
}

/// Sliding states: a time, coordinates and five speeds.
fn sliding_states(count: usize) -> Vec<(f64, [f64; 5], [f64; 5])> {
    let mut rng = XorShift(0x2545_f491_4f6c_dd1d);
    let mut next = move || rng.uniform(-1.0, 1.0);
    (0..count)
        .map(|_| {
            let t = 1.5 * next().abs();
            let q = [3.0 * next(), 0.6 * next(), 3.0 * next(), next(), next()];
            let u = [next(), next(), 20.0 * next(), 2.0 * next(), 2.0 * next()];
            (t, q, u)
        })
        .collect()
}

#[test]
fn the_sliding_scene_is_the_disc_written_with_sliding_alone() {
    let scene = PushedRollingDiscSliding::from_ref(&DISC);
    let alone = DISC.sliding_alone();
    // The same equations at the same cost.
    assert_eq!(
        PushedRollingDiscSliding::info().rhs_ops,
        SlidingDisc::info().rhs_ops
    );
    assert_eq!(
        PushedRollingDiscSliding::info().speeds,
        SlidingDisc::info().speeds
    );
    let (ps, pa) = (scene.dyn_prepare(), alone.dyn_prepare());
    let mut worst = 0.0f64;
    for (t, q, u) in sliding_states(50) {
        let state = [q[0], q[1], u[0], u[1], u[2], u[3], u[4]];
        let (mut a, mut b) = ([0.0; 7], [0.0; 7]);
        ps.rhs(t, &state, &[7.3], &mut a).unwrap();
        pa.rhs(t, &state, &[7.3], &mut b).unwrap();
        for (x, y) in a.iter().zip(&b) {
            worst = worst.max((x - y).abs() / (1.0 + y.abs()));
        }
    }
    println!("sliding scene against the model written alone: {worst:.1e}");
    assert!(worst < 1e-14, "{worst:e}");
}

/// The disc's only support is the contact, so its normal force is the
/// vertical momentum balance m (g + z̈), with z = r cos(lean) the centre's
/// height: z̈ = −r (cos(lean) leaṅ² + sin(lean) lean̈), lean̈ from the
/// sliding equations at that normal force.
#[test]
fn the_normal_force_is_the_vertical_momentum_balance() {
    let scene = PushedRollingDiscSliding::from_ref(&DISC);
    let prepared = scene.dyn_prepare();
    let mut worst = 0.0f64;
    for (t, q, u) in sliding_states(50) {
        let found = sliding_normals(scene, t, &q, &u, &[0.0], &[contact(&DISC)]).unwrap();
        let n = found.forces[0];
        let state = [q[0], q[1], u[0], u[1], u[2], u[3], u[4]];
        let mut rates = [0.0; 7];
        prepared.rhs(t, &state, &[n], &mut rates).unwrap();
        let (lean, lean_rate, lean_accel) = (q[1], u[1], rates[3]);
        let zdd = -DISC.r * (lean.cos() * lean_rate * lean_rate + lean.sin() * lean_accel);
        let balance = DISC.m * (DISC.g + zdd);
        worst = worst.max((n - balance).abs() / balance.abs());
        assert!(found.residual < 1e-12, "{found:?}");
        assert!(found.rolling.is_empty());
    }
    println!("N against m (g + z̈): worst relative difference {worst:.1e}");
    assert!(worst < 1e-12, "{worst:e}");
    // At rest, upright, unpushed (sin 0 = 0): the weight.
    let rest = sliding_normals(scene, 0.0, &[0.0; 5], &[0.0; 5], &[0.0], &[contact(&DISC)]);
    let n = rest.unwrap().forces[0];
    assert!((n - DISC.m * DISC.g).abs() < 1e-13 * DISC.m * DISC.g, "{n}");
}

/// With μ = 2, a disc leaning 0.4 rad and slipping at 45° to its plane
/// has friction that feeds back into its own normal force by more than
/// one: no normal force is consistent (Painlevé). The feedback grows in
/// proportion to μ.
#[test]
fn friction_that_feeds_back_too_strongly_is_painleves_paradox() {
    let q = [0.0, 0.4, 0.0, 0.0, 0.0];
    let u = [
        0.0,
        0.0,
        0.0,
        (0.25 * std::f64::consts::PI).cos(),
        0.5f64.sqrt(),
    ];
    let with_mu = |mu: f64| PushedRollingDisc {
        mu,
        push: 0.0,
        ..DISC
    };
    let (low, high) = (with_mu(1.0), with_mu(2.0));
    let found = sliding_normals(
        PushedRollingDiscSliding::from_ref(&low),
        0.0,
        &q,
        &u,
        &[0.0],
        &[contact(&low)],
    )
    .unwrap();
    let kappa = found.feedback[0];
    assert!(kappa > 0.5 && kappa < 1.0, "{kappa}");
    let err = sliding_normals(
        PushedRollingDiscSliding::from_ref(&high),
        0.0,
        &q,
        &u,
        &[0.0],
        &[contact(&high)],
    )
    .unwrap_err();
    match err {
        SlidingError::Paradox { contacts, minor } => {
            assert_eq!(contacts, [0]);
            // 1 − κ at twice the friction coefficient.
            let expected = 1.0 - 2.0 * kappa;
            assert!((minor - expected).abs() < 1e-12, "{minor} {kappa}");
        }
        other => panic!("{other:?}"),
    }
    // In a hybrid run the paradox is a typed error of the phase's rates:
    // the run stops there and says why.
    let sliding = PushedRollingDiscSliding::from_ref(&high);
    let c = SlidingContact::named(&high, "P", sliding, "normal", [0.0, 0.0, 1.0]).unwrap();
    let phase = Phase::new("sliding", sliding)
        .state_inputs(appell::sliding::normal_inputs(sliding, vec![c]));
    let err = Hybrid::new(vec![phase])
        .run::<10>(0, 0.0, &q, &u, 0.1)
        .unwrap_err();
    let said = err.to_string();
    println!("{said}");
    assert!(said.contains("Painlev"), "{said}");
}

#[test]
fn a_sliding_contact_declared_wrongly_is_a_typed_error() {
    let scene = PushedRollingDiscSliding::from_ref(&DISC);
    let (q, u) = ([0.0; 5], [0.0; 5]);
    let call = |c: Vec<SlidingContact>, inputs: &[f64]| {
        sliding_normals(scene, 0.0, &q, &u, inputs, &c).unwrap_err()
    };
    let bad = |e: SlidingError| matches!(e, SlidingError::BadContact(_));
    let z = [0.0, 0.0, 1.0];
    assert!(bad(call(
        vec![SlidingContact::at_rolling_contact(&DISC, 0, 1, z)],
        &[0.0]
    )));
    assert!(bad(call(
        vec![SlidingContact::at_rolling_contact(
            &DISC,
            0,
            0,
            [0.0, 0.0, 2.0]
        )],
        &[0.0]
    )));
    assert!(bad(call(vec![contact(&DISC), contact(&DISC)], &[0.0])));
    assert!(bad(call(vec![contact(&DISC)], &[])));
    // A contact the model does not have.
    let err = call(
        vec![SlidingContact::at_rolling_contact(&DISC, 3, 0, z)],
        &[0.0],
    );
    assert!(
        matches!(
            err,
            SlidingError::Oracle(appell::oracle::OracleError::Model(
                appell::ModelError::Contact { .. }
            ))
        ),
        "{err:?}"
    );
}

fn run(t_end: f64) -> HybridRun {
    Hybrid::new(phases(&DISC))
        .solver(Dop853::new().rtol(1e-11).atol(1e-13).event_tol(1e-13))
        .run::<10>(0, 0.0, &Q0, &U0, t_end)
        .expect("the run completes")
}

/// The rolling scene alone from (t0, q0, u0) to t1.
fn roll(t0: f64, q0: &[f64], u0: &[f64], t1: f64) -> (Vec<f64>, Vec<f64>) {
    let rolling = PushedRollingDiscRolling::from_ref(&DISC);
    let end = Hybrid::new(vec![Phase::new("rolling", rolling)])
        .solver(Dop853::new().rtol(1e-13).atol(1e-15))
        .run::<10>(0, t0, q0, u0, t1)
        .expect("rolling")
        .end;
    (end.q, end.u)
}

#[test]
fn the_disc_slides_where_rolling_needs_mu_n_and_grips_where_the_slip_dies() {
    let run = run(3.0);
    for s in &run.switches {
        println!(
            "t = {:.9} s: {} -> {} ({}), impulses {:?}, energy lost {:.3e} J",
            s.t, s.from, s.to, s.reason, s.impulses, s.energy_lost
        );
    }
    let reasons: Vec<&str> = run.switches.iter().map(|s| s.reason).collect();
    assert_eq!(reasons, ["slips", "grips", "slips", "grips"]);

    // The first slip: where the friction rolling needs reaches μ N, by a
    // bisection of the constraint-force output along the rolling motion.
    let slip_at = run.switches[0].t;
    let (mut a, mut b) = (slip_at - 0.013, slip_at + 0.007);
    let (mut qa, mut ua) = roll(0.0, &Q0, &U0, a);
    while b - a > 1e-10 {
        let mid = 0.5 * (a + b);
        let (qm, um) = roll(a, &qa, &ua, mid);
        if friction_margin(&DISC, mid, &qm, &um).unwrap() > 0.0 {
            (a, qa, ua) = (mid, qm, um);
        } else {
            b = mid;
        }
    }
    println!(
        "the slip: {slip_at:.12} s, bisection {a:.12} s, {:.1e} s apart",
        (slip_at - a).abs()
    );
    assert!((slip_at - a).abs() < 1e-9, "{slip_at} against {a}");

    for s in &run.switches {
        let at = run
            .samples
            .iter()
            .rposition(|x| x.t == s.t && x.phase == s.from)
            .map(|k| run.samples[k].clone())
            .expect("the state before the switch is sampled");
        let after = run
            .samples
            .iter()
            .find(|x| x.t == s.t && x.phase == s.to)
            .expect("the state after the switch is sampled");
        if s.reason == "slips" {
            // Released: nothing jumps.
            assert!(
                s.impulses.is_empty() && s.energy_lost.abs() < 1e-13,
                "{s:?}"
            );
            assert_eq!(&after.u[..3], &at.u[..3]);
        } else {
            // Gripping at the slip speed GRIP_SPEED: a plastic impulse Λ
            // on the two rolling rows takes the slip v to zero and the
            // energy ½ |Λ · v| with it.
            let v = slip(&DISC, s.t, &at.q, &at.u).unwrap();
            let speed = v[0].hypot(v[1]);
            assert!((speed - GRIP_SPEED).abs() < 1e-9 * GRIP_SPEED, "{speed}");
            let rolling = PushedRollingDiscRolling::from_ref(&DISC);
            let mut qdot = [0.0; 5];
            rolling
                .dyn_coordinate_rates(s.t, &after.q, &after.u, &mut qdot)
                .unwrap();
            let left = slip(&DISC, s.t, &after.q, &qdot).unwrap();
            assert!(left[0].hypot(left[1]) < 1e-13, "{left:?}");
            let closed = -0.5 * (s.impulses[0] * v[0] + s.impulses[1] * v[1]);
            println!(
                "grip at {:.6} s: lost {:.6e} J, ½|Λ·v| = {closed:.6e} J, relative difference {:.1e}",
                s.t,
                s.energy_lost,
                (s.energy_lost - closed).abs() / closed
            );
            // The kinetic energy is about 60 J: the difference is its
            // round-off.
            assert!(
                (s.energy_lost - closed).abs() < 1e-13,
                "{} against {closed}",
                s.energy_lost
            );
        }
    }
}

/// The sliding phase of the hybrid run is the motion of the disc written
/// with sliding alone, from the same start.
#[test]
fn the_sliding_phase_follows_the_disc_written_with_sliding_alone() {
    let run = run(1.5);
    let (start, end) = (&run.switches[0], &run.switches[1]);
    let first = |t: f64, phase: usize| {
        run.samples
            .iter()
            .find(|x| x.t == t && x.phase == phase)
            .expect("sampled")
            .clone()
    };
    let (s0, s1) = (first(start.t, 1), first(end.t, 1));
    let alone = DISC.sliding_alone();
    let c = SlidingContact::at_rolling_contact(&DISC, 0, 0, [0.0, 0.0, 1.0]);
    let phase = Phase::new("sliding alone", &alone)
        .state_inputs(appell::sliding::normal_inputs(&alone, vec![c]));
    let own = Hybrid::new(vec![phase])
        .solver(Dop853::new().rtol(1e-11).atol(1e-13))
        .run::<10>(0, s0.t, &s0.q, &s0.u, s1.t)
        .expect("sliding alone")
        .end;
    let worst = own
        .q
        .iter()
        .zip(&s1.q)
        .chain(own.u.iter().zip(&s1.u))
        .map(|(a, b)| (a - b).abs() / (1.0 + b.abs()))
        .fold(0.0f64, f64::max);
    println!(
        "sliding {:.6} s to {:.6} s: the scene and the model alone differ by {worst:.1e}",
        s0.t, s1.t
    );
    assert!(worst < 1e-12, "{worst:e}");
}

/// A wheelbarrow pushed along the ground: a wheel of radius `r` rolling at
/// its front, a frame (a particle `m_f` at `d` ahead of the axle and `h`
/// above the ground) resting on a skid `l` behind the axle, pushed at a
/// handle `l` behind the axle and `hy` high. The wheel's normal force is
/// held by the coordinates and the skid's drives the skid's friction: two
/// unknown normal forces, one of them fed back. (The lateral position `z`
/// gives the wheel's contact a second rolling row, so that its normal is
/// the one direction its rows leave out.)
#[derive(Appell, Clone, Debug, PartialEq)]
#[appell(coordinates(x, z, theta), speeds(x), positive(r, m_w, m_f))]
#[appell(frame(W = N.rotate_z(theta)))]
#[appell(point(C = O + x * N.x + r * N.y + z * N.z), point(P = C - r * N.y))]
#[appell(point(G = C + d * N.x + (h - r) * N.y), point(S = C - l * N.x - r * N.y),
         point(H = C - l * N.x + (hy - r) * N.y))]
#[appell(body(wheel, center = C, frame = W, mass = m_w,
              inertia = principal(m_w * r * r / 4, m_w * r * r / 4, m_w * r * r / 2)))]
#[appell(particle(G, mass = m_f))]
#[appell(rolls(wheel, contact = P))]
#[appell(gravity(-g * N.y))]
#[appell(force(H, push * N.x, effect = push))]
#[appell(inputs(n_skid))]
#[appell(friction(S, mu = mu, normal = n_skid, plane = N.y, smoothing = eps, effect = skid))]
struct Wheelbarrow {
    r: f64,
    m_w: f64,
    m_f: f64,
    d: f64,
    h: f64,
    l: f64,
    hy: f64,
    g: f64,
    mu: f64,
    eps: f64,
    push: f64,
}

/// The wheelbarrow's closed forms, moving forward: with M = m_w + m_f +
/// I_w/r² and k = r m_w + I_w/r + h m_f, M a = F − μ N_s along the ground,
/// and the moments about the wheel's contact give
/// l N_s = −d m_f g − hy F + k a; the wheel carries the rest of the weight.
/// The skid's own feedback is ∂N_s/∂N_s through a: −μ k/(M l).
#[test]
fn a_rolling_wheel_and_a_sliding_skid_share_the_load_as_the_closed_form_says() {
    let b = Wheelbarrow {
        r: 0.2,
        m_w: 2.0,
        m_f: 10.0,
        d: -0.4,
        h: 0.5,
        l: 1.0,
        hy: 0.8,
        g: 9.81,
        mu: 0.4,
        eps: 1e-9,
        push: 30.0,
    };
    let i_w = b.m_w * b.r * b.r / 2.0;
    let big_m = b.m_w + b.m_f + i_w / (b.r * b.r);
    let k = b.r * b.m_w + i_w / b.r + b.h * b.m_f;
    let n_skid = (-b.d * b.m_f * b.g - b.hy * b.push + k * b.push / big_m)
        / (b.l * (1.0 + b.mu * k / (big_m * b.l)));
    let n_wheel = (b.m_w + b.m_f) * b.g - n_skid;
    let kappa = -b.mu * k / (big_m * b.l);
    let l = b.l;
    let skid = SlidingContact::new(0, [0.0, 1.0, 0.0], move |_, q: &[f64]| {
        [q[0] - l, 0.0, q[1]]
    });
    let found = sliding_normals(&b, 0.3, &[0.7, 0.1, -3.5], &[1.2], &[0.0], &[skid]).unwrap();
    println!("{found:?}: closed forms N_s = {n_skid}, N_w = {n_wheel}, κ = {kappa}");
    let rel = |a: f64, b: f64| (a - b).abs() / b.abs();
    assert!(rel(found.forces[0], n_skid) < 1e-12);
    assert!(rel(found.rolling[0], n_wheel) < 1e-12);
    assert!(rel(found.feedback[0], kappa) < 1e-12);
    assert!(found.residual < 1e-12);
}

#[path = "../examples/models/slipping_axle.rs"]
mod slipping_axle;

use slipping_axle::{
    margins, slip_at, SlippingAxleGripping, SlippingAxleSlipping, AXLE, WHEEL_2_MU,
};

/// Rolling straight downhill at 1.5 m/s.
const AXLE_Q0: [f64; 5] = [0.0; 5];
const AXLE_U0: [f64; 2] = [0.0, 5.0];

fn axle_run(t_end: f64) -> HybridRun {
    Hybrid::new(slipping_axle::phases(&AXLE))
        .solver(Dop853::new().rtol(1e-11).atol(1e-13).event_tol(1e-13))
        .sample_every(0.05)
        .run::<10>(0, 0.0, &AXLE_Q0, &AXLE_U0, t_end)
        .expect("the run completes")
}

/// The wheel-axle with wheel 1 on ice: it slips where the drive asks more
/// than μ N₁, grips again where its slip dies, and wheel 2 grips
/// throughout. Its normal forces always carry the weight's normal part
/// between them (nothing moves vertically), and the slip formula the
/// guard uses vanishes wherever both wheels grip.
#[test]
fn on_a_slope_the_wheel_on_ice_slips_while_the_other_rolls() {
    let run = axle_run(4.0);
    for s in &run.switches {
        println!(
            "t = {:.9} s: {} -> {} ({}), impulses {:?}, energy lost {:.3e} J",
            s.t, s.from, s.to, s.reason, s.impulses, s.energy_lost
        );
    }
    let reasons: Vec<&str> = run.switches.iter().map(|s| s.reason).collect();
    assert_eq!(reasons, ["wheel 1 slips", "wheel 1 grips"]);
    let weight = (2.0 * AXLE.m_w + AXLE.m_a) * AXLE.g * AXLE.alpha.cos();
    let support = |s: &appell::hybrid::Sample| {
        let tau = slipping_axle::torque(s.t);
        if s.phase == 0 {
            let scene = SlippingAxleGripping::from_ref(&AXLE);
            let c = SlidingContact::support_at_rolling_contact(&AXLE, 0, [0.0, 0.0, 1.0]);
            sliding_normals(scene, s.t, &s.q, &s.u, &[tau], &[c]).unwrap()
        } else {
            let scene = SlippingAxleSlipping::from_ref(&AXLE);
            let c = SlidingContact::at_rolling_contact(&AXLE, 0, 1, [0.0, 0.0, 1.0]);
            sliding_normals(scene, s.t, &s.q, &s.u, &[tau, 0.0], &[c]).unwrap()
        }
    };
    let (mut worst_sum, mut worst_slip, mut low_margin) = (0.0f64, 0.0f64, f64::INFINITY);
    let (mut n_low, mut n_high) = (f64::INFINITY, 0.0f64);
    for s in &run.samples {
        let found = support(s);
        let (n1, n2) = (found.forces[0], found.rolling[0]);
        worst_sum = worst_sum.max((n1 + n2 - weight).abs() / weight);
        (n_low, n_high) = (n_low.min(n1), n_high.max(n1));
        if s.phase == 0 {
            let scene = SlippingAxleGripping::from_ref(&AXLE);
            let mut qdot = [0.0; 5];
            scene
                .dyn_driven_coordinate_rates(
                    s.t,
                    &s.q,
                    &s.u,
                    &[slipping_axle::torque(s.t)],
                    &mut qdot,
                )
                .unwrap();
            let v = slip_at(&AXLE, &s.q, &qdot);
            worst_slip = worst_slip.max(v[0].hypot(v[1]));
            let m = margins(&AXLE, s.t, &s.q, &s.u, slipping_axle::torque(s.t)).unwrap();
            low_margin = low_margin.min(m[1]);
        }
    }
    println!(
        "N1 + N2 against the weight: {worst_sum:.1e}; N1 from {n_low:.3} N to {n_high:.3} N; \
         slip while gripping {worst_slip:.1e} m/s; wheel 2's smallest margin {low_margin:.3} N"
    );
    assert!(worst_sum < 1e-12, "{worst_sum:e}");
    assert!(worst_slip < 1e-12, "{worst_slip:e}");
    assert!(low_margin > 0.0, "wheel 2 would slip (μ = {WHEEL_2_MU})");
    // The gyroscopic moment of the spinning wheels moves load between them.
    assert!(n_high - n_low > 5.0, "{n_low} {n_high}");

    // The slip: where μ N₁ runs out, by a bisection of the same margin
    // along the gripping motion alone.
    let slip_at_t = run.switches[0].t;
    let gripping = |t0: f64, q0: &[f64], u0: &[f64], t1: f64| {
        let phase = Phase::new("gripping", SlippingAxleGripping::from_ref(&AXLE)).state_inputs(
            Box::new(|t, _, _, inputs: &mut [f64]| {
                inputs[0] = slipping_axle::torque(t);
                Ok(())
            }),
        );
        let end = Hybrid::new(vec![phase])
            .solver(Dop853::new().rtol(1e-13).atol(1e-15))
            .run::<10>(0, t0, q0, u0, t1)
            .expect("gripping")
            .end;
        (end.q, end.u)
    };
    let (mut a, mut b) = (slip_at_t - 0.013, slip_at_t + 0.007);
    let (mut qa, mut ua) = gripping(0.0, &AXLE_Q0, &AXLE_U0, a);
    while b - a > 1e-10 {
        let mid = 0.5 * (a + b);
        let (qm, um) = gripping(a, &qa, &ua, mid);
        if margins(&AXLE, mid, &qm, &um, slipping_axle::torque(mid)).unwrap()[0] > 0.0 {
            (a, qa, ua) = (mid, qm, um);
        } else {
            b = mid;
        }
    }
    println!("wheel 1 slips at {slip_at_t:.12} s, bisection {a:.12} s");
    assert!((slip_at_t - a).abs() < 1e-9, "{slip_at_t} against {a}");

    // The grip: a plastic impulse on wheel 1's rolling row takes its slip
    // (GRIP_SPEED along A.x) and ½ |Λ v| of energy.
    let grip = &run.switches[1];
    let before = run
        .samples
        .iter()
        .rev()
        .find(|x| x.t == grip.t && x.phase == 1)
        .expect("sampled");
    let v = slipping_axle::slip(&AXLE, grip.t, &before.q, &before.u).unwrap();
    let phi = before.q[0];
    let along = v[0] * phi.cos() + v[1] * phi.sin();
    let closed = 0.5 * (grip.impulses[0] * along).abs();
    println!(
        "grip: lost {:.6e} J, ½|Λ v| = {closed:.6e} J",
        grip.energy_lost
    );
    assert!(
        (grip.energy_lost - closed).abs() < 1e-13,
        "{} {closed}",
        grip.energy_lost
    );
    assert!(grip.impulses[1..].iter().all(|x| x.abs() < 1e-12));
}

/// The energy budget of the pushed disc over 3 s: the kinetic and
/// potential energy gained equal the push's work, less the sliding
/// friction's, less what the grips' impulses take. The powers are
/// integrated by trapezoids over samples every 0.25 ms.
#[test]
fn the_disc_s_energy_is_the_push_s_work_less_friction_and_grips() {
    let run = Hybrid::new(phases(&DISC))
        .solver(Dop853::new().rtol(1e-11).atol(1e-13).event_tol(1e-13))
        .sample_every(2.5e-4)
        .run::<10>(0, 0.0, &Q0, &U0, 3.0)
        .expect("the run completes");
    let rolling = PushedRollingDiscRolling::from_ref(&DISC);
    let sliding = PushedRollingDiscSliding::from_ref(&DISC);
    // (T + V, push power, friction power) at a sample.
    let state = |s: &appell::hybrid::Sample| -> (f64, f64, f64) {
        let (qdot, t_kin, friction) = if s.phase == 0 {
            let mut qdot = [0.0; 5];
            rolling
                .dyn_coordinate_rates(s.t, &s.q, &s.u, &mut qdot)
                .unwrap();
            (
                qdot.to_vec(),
                rolling.kinetic_energy(s.t, &s.q, &s.u).unwrap(),
                0.0,
            )
        } else {
            let n = sliding_normals(sliding, s.t, &s.q, &s.u, &[0.0], &[contact(&DISC)])
                .unwrap()
                .forces[0];
            let v = slip(&DISC, s.t, &s.q, &s.u).unwrap();
            let speed2 = v[0] * v[0] + v[1] * v[1];
            let power = -DISC.mu * n * speed2 / (speed2 + DISC.eps * DISC.eps).sqrt();
            (
                s.u.clone(),
                sliding.kinetic_energy(s.t, &s.q, &s.u).unwrap(),
                power,
            )
        };
        let potential = DISC.m * DISC.g * DISC.r * s.q[1].cos();
        let push = DISC.push * (DISC.omega * s.t).sin();
        let push_power = push * (qdot[3] * s.q[0].cos() + qdot[4] * s.q[0].sin());
        (t_kin + potential, push_power, friction)
    };
    let (mut work, mut friction) = (0.0, 0.0);
    let mut last: Option<(f64, usize, (f64, f64, f64))> = None;
    for s in &run.samples {
        let now = state(s);
        if let Some((t0, phase0, before)) = last {
            if s.t > t0 && s.phase == phase0 {
                let dt = s.t - t0;
                work += 0.5 * dt * (before.1 + now.1);
                friction += 0.5 * dt * (before.2 + now.2);
            }
        }
        last = Some((s.t, s.phase, now));
    }
    let lost: f64 = run.switches.iter().map(|s| s.energy_lost).sum();
    let (start, end) = (
        state(&run.samples[0]).0,
        state(run.samples.last().unwrap()).0,
    );
    let gained = end - start;
    let budget = work + friction - lost;
    println!(
        "gained {gained:.9} J; push {work:.9} J, friction {friction:.9} J, grips {lost:.3e} J: \
         off by {:.1e} J ({:.1e} of the push's work)",
        gained - budget,
        ((gained - budget) / work).abs()
    );
    assert!(friction < 0.0 && lost > 0.0);
    assert!(((gained - budget) / work).abs() < 1e-7);
}

/// At rest with its axle pointing downhill, the wheel-axle stands still
/// (its rolling direction is level), and the weight's downhill part,
/// acting at the wheel centres' height a, moves load onto the lower wheel:
/// N₁ − N₂ = W a sin α / h, N₁ + N₂ = W cos α.
#[test]
fn across_the_slope_the_lower_wheel_carries_more_as_the_closed_form_says() {
    let scene = SlippingAxleGripping::from_ref(&AXLE);
    let support = SlidingContact::support_named(&AXLE, "P1", [0.0, 0.0, 1.0]).unwrap();
    let q = [0.5 * std::f64::consts::PI, 0.3, -0.2, 1.0, 2.0];
    let found = sliding_normals(scene, 0.0, &q, &[0.0, 0.0], &[0.0], &[support]).unwrap();
    let w = (2.0 * AXLE.m_w + AXLE.m_a) * AXLE.g;
    let (n1, n2) = (found.forces[0], found.rolling[0]);
    let (sum, difference) = (w * AXLE.alpha.cos(), w * AXLE.a * AXLE.alpha.sin() / AXLE.h);
    println!("N1 = {n1}, N2 = {n2}; closed forms: sum {sum}, difference {difference}");
    assert!(((n1 - n2) - difference).abs() < 1e-12 * w, "{n1} {n2}");
    assert!(((n1 + n2) - sum).abs() < 1e-12 * w, "{n1} {n2}");
}

#[test]
fn contacts_are_found_by_name_or_the_error_says_what_there_is() {
    let sliding = PushedRollingDiscSliding::from_ref(&DISC);
    let up = [0.0, 0.0, 1.0];
    let named = SlidingContact::named(&DISC, "P", sliding, "normal", up).unwrap();
    assert_eq!(named.input, Some(0));
    let bad = |r: Result<SlidingContact, SlidingError>| match r {
        Err(SlidingError::BadContact(why)) => why,
        Err(other) => panic!("{other:?}"),
        Ok(_) => panic!("accepted"),
    };
    let why = bad(SlidingContact::named(&DISC, "Q", sliding, "normal", up));
    assert!(why.contains("[\"P\"]"), "{why}");
    let rolling = PushedRollingDiscRolling::from_ref(&DISC);
    let why = bad(SlidingContact::named(&DISC, "P", rolling, "normal", up));
    assert!(why.contains("no input `normal`"), "{why}");
}

/// Radau5 reads the normal force through the phase's state inputs too
/// (its Jacobian holds them at the state it is taken at): its switch
/// times agree with DOP853's.
#[test]
fn radau5_runs_the_sliding_disc_to_the_same_switches() {
    let reference = run(3.0);
    let stiff = Hybrid::new(phases(&DISC))
        .stiff_solver(appell::integrate::Radau5::new().rtol(1e-10).atol(1e-12))
        .run::<10>(0, 0.0, &Q0, &U0, 3.0)
        .expect("the run completes");
    assert_eq!(stiff.switches.len(), reference.switches.len());
    let worst = stiff
        .switches
        .iter()
        .zip(&reference.switches)
        .map(|(a, b)| (a.t - b.t).abs())
        .fold(0.0f64, f64::max);
    println!("Radau5 against DOP853: switch times within {worst:.1e} s");
    assert!(worst < 1e-8, "{worst:e}");
}
