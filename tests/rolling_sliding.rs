//! A disc pushed back and forth on a line rolls, slides when the friction
//! rolling needs passes μ N, and rolls again when the slip dies out:
//! three scenes of one model and a hybrid run between them, against
//! closed forms.

#[path = "../examples/models/pushed_disc.rs"]
mod pushed_disc;

use appell::hybrid::{Hybrid, HybridRun};
use appell::integrate::Dop853;
use appell::{Appell, Model};
use pushed_disc::{
    phases, slip, PushedDisc, PushedDiscSlidingBackward, PushedDiscSlidingForward, DISC,
};

fn run(disc: &PushedDisc, t_end: f64, rtol: f64) -> HybridRun {
    Hybrid::new(phases(disc))
        .solver(Dop853::new().rtol(rtol).atol(rtol * 1e-2).event_tol(1e-13))
        .sample_every(1e-4)
        .run::<4>(0, 0.0, &[0.0, 0.0], &[0.0], t_end)
        .expect("the run completes")
}

/// The first root of `f` in (t0, t1) after a sign change, scanning every
/// 1e-3 s from t0 + 1e-3 (a slip that starts at zero is not a root) and
/// bisecting to 1e-15 s.
fn first_root(f: impl Fn(f64) -> f64, t0: f64, t1: f64) -> Option<f64> {
    let mut a = t0 + 1e-3;
    while a < t1 {
        let b = (a + 1e-3).min(t1);
        if f(a) > 0.0 && f(b) <= 0.0 {
            let (mut a, mut b) = (a, b);
            while b - a > 1e-15 {
                let mid = 0.5 * (a + b);
                if f(mid) > 0.0 {
                    a = mid
                } else {
                    b = mid
                }
            }
            return Some(0.5 * (a + b));
        }
        a = b;
    }
    None
}

/// The switches the closed forms give up to `t_end`: rolling needs the
/// friction f = −F/3 (I = m r²/2), so it holds while |F| ≤ 3 μ m g;
/// sliding forward from t_e the slip is v_s = F0/(m ω) (cos ω t_e −
/// cos ω t) − 3 μ g (t − t_e), backward the same with + 3 μ g (t − t_e).
/// Entering rolling with |F| > 3 μ m g slides on at once.
fn closed_form_switches(d: &PushedDisc, t_end: f64) -> Vec<(usize, usize, f64)> {
    let (w, limit) = (d.omega, 3.0 * d.mu * d.m * d.g);
    let force = |t: f64| d.push * (w * t).sin();
    let (mut phase, mut t, mut out) = (0usize, 0.0f64, Vec::new());
    while t < t_end && out.len() < 50 {
        let te = t;
        let next = match phase {
            0 if force(te) > limit => Some((1, te)),
            0 if force(te) < -limit => Some((2, te)),
            0 => {
                let fwd = first_root(|t| limit - force(t), te - 1e-3, t_end);
                let bwd = first_root(|t| force(t) + limit, te - 1e-3, t_end);
                match (fwd, bwd) {
                    (Some(a), Some(b)) => Some(if a < b { (1, a) } else { (2, b) }),
                    (Some(a), None) => Some((1, a)),
                    (None, Some(b)) => Some((2, b)),
                    (None, None) => None,
                }
            }
            k => {
                let sign = if k == 1 { 1.0 } else { -1.0 };
                let slip = |t: f64| {
                    d.push / (d.m * w) * ((w * te).cos() - (w * t).cos())
                        - sign * 3.0 * d.mu * d.g * (t - te)
                };
                first_root(|t| sign * slip(t), te, t_end).map(|t| (0, t))
            }
        };
        let Some((to, at)) = next else { break };
        out.push((phase, to, at));
        (phase, t) = (to, at);
    }
    out
}

#[test]
fn the_disc_slides_where_rolling_needs_more_than_mu_n_and_grips_when_the_slip_dies() {
    pushed(&DISC);
}

#[test]
fn pushed_harder_the_disc_slides_the_other_way_where_its_slip_dies() {
    // F0 = 6 μ m g: when the forward slip dies the push has turned past
    // −3 μ m g, so the rolling phase is left at once, backward.
    let harder = PushedDisc {
        push: 6.0 * DISC.mu * DISC.m * DISC.g,
        ..DISC
    };
    let switches = pushed(&harder);
    assert!(switches
        .windows(2)
        .any(|w| w[0].t == w[1].t && w[0].to == 0 && w[1].to == 2));
}

/// The hybrid run of `d` for 3.5 s against the closed forms: the switch
/// times and the energy balance.
fn pushed(d: &PushedDisc) -> Vec<appell::hybrid::SwitchRecord> {
    let run = run(d, 3.5, 1e-12);
    for s in &run.switches {
        println!(
            "t = {:.9} s: {} -> {} ({}), impulses {:?}, energy lost {:.1e}",
            s.t, s.from, s.to, s.reason, s.impulses, s.energy_lost
        );
    }
    let expected = closed_form_switches(d, 3.5);
    assert_eq!(run.switches.len(), expected.len(), "{expected:?}");
    for (s, &(from, to, t)) in run.switches.iter().zip(&expected) {
        assert_eq!((s.from, s.to), (from, to), "{s:?}");
        println!(
            "{} -> {}: {:.1e} s from the closed form",
            s.from,
            s.to,
            (s.t - t).abs()
        );
        assert!(
            (s.t - t).abs() < 1e-9,
            "{} -> {} at {} against {t}",
            s.from,
            s.to,
            s.t
        );
        // The slip is zero at every switch: nothing jumps.
        assert!(s.impulses.iter().all(|i| i.abs() < 1e-9) && s.energy_lost.abs() < 1e-9);
    }
    // Energy: the kinetic energy at the end is the push's work less the
    // friction's, both integrated over the samples (every 0.1 ms, trapezoids).
    let mut work = 0.0;
    let mut power = Vec::new();
    for s in &run.samples {
        let (xdot, thdot) = if s.phase == 0 {
            (-d.r * s.u[0], s.u[0])
        } else {
            (s.u[0], s.u[1])
        };
        let push = d.push * (d.omega * s.t).sin();
        let friction = if s.phase == 0 {
            0.0
        } else {
            d.mu * d.m * d.g * slip(d, &[xdot, thdot]).abs()
        };
        power.push((s.t, push * xdot - friction));
    }
    for pair in power.windows(2) {
        let ((t0, p0), (t1, p1)) = (pair[0], pair[1]);
        work += 0.5 * (t1 - t0) * (p0 + p1);
    }
    let end = &run.end;
    let (xdot, thdot) = if end.phase == 0 {
        (-d.r * end.u[0], end.u[0])
    } else {
        (end.u[0], end.u[1])
    };
    let kinetic = 0.5 * d.m * xdot * xdot + 0.5 * (d.m * d.r * d.r / 2.0) * thdot * thdot;
    let gap = (kinetic - work).abs() / kinetic.max(work.abs());
    println!("kinetic energy {kinetic:.6} J against the push's work less the friction's {work:.6} J ({gap:.1e})");
    assert!(gap < 1e-6, "energy {gap:e}");
    run.switches
}

/// The disc sliding forward, written on its own.
#[derive(Appell, Clone, Debug, PartialEq)]
#[appell(coordinates(x, theta), speeds(x, theta), positive(m, r))]
#[appell(frame(B = N.rotate_z(theta)))]
#[appell(point(C = O + x * N.x + r * N.y))]
#[appell(body(disc, center = C, frame = B, mass = m,
              inertia = principal(m * r * r / 4, m * r * r / 4, m * r * r / 2)))]
#[appell(force(C, push * sin(omega * t) * N.x, effect = push))]
#[appell(force(C, -mu * m * g * N.x, effect = friction),
         torque(B, -r * mu * m * g * N.z, effect = friction))]
struct SlidingDisc {
    m: f64,
    r: f64,
    g: f64,
    mu: f64,
    push: f64,
    omega: f64,
}

#[test]
fn the_sliding_scene_is_the_disc_written_sliding() {
    let d = &DISC;
    let alone = SlidingDisc {
        m: d.m,
        r: d.r,
        g: d.g,
        mu: d.mu,
        push: d.push,
        omega: d.omega,
    };
    let scene = PushedDiscSlidingForward::from_ref(&DISC);
    assert_eq!(
        PushedDiscSlidingForward::info().state_len(),
        SlidingDisc::info().state_len()
    );
    let (ps, pa) = (scene.prepare::<f64>(), alone.prepare::<f64>());
    for k in 0..20 {
        let t = 0.17 * k as f64;
        let x = [0.3 * k as f64 - 2.0, 1.0 - 0.1 * k as f64];
        let x: Vec<f64> = PushedDiscSlidingForward::info()
            .retained
            .iter()
            .map(|_| 0.4)
            .chain(x)
            .collect();
        let (mut a, mut b) = (vec![0.0; x.len()], vec![0.0; x.len()]);
        scene.rhs(&ps, t, &x, &[], &mut a).unwrap();
        alone.rhs(&pa, t, &x, &[], &mut b).unwrap();
        for (p, q) in a.iter().zip(&b) {
            assert!(
                (p - q).abs() <= 1e-14 * (1.0 + q.abs()),
                "{a:?} against {b:?}"
            );
        }
    }
    // It costs what the disc written sliding costs (the same equations,
    // lowered from a graph that holds the other scenes' too).
    let (a, b) = (
        PushedDiscSlidingForward::info().rhs_ops.total,
        SlidingDisc::info().rhs_ops.total,
    );
    println!("sliding scene {a} ops, the disc written sliding {b} ops");
    assert!(a.abs_diff(b) as f64 <= 0.05 * b as f64, "{a} against {b}");
    for info in PushedDisc::scene_infos() {
        println!(
            "{}: state {:?} + {:?}, {} ops",
            info.name, info.retained, info.speeds, info.rhs_ops.total
        );
    }
    assert_eq!(PushedDiscSlidingBackward::info().speeds, ["x", "theta"]);
}

/// A disc sliding on a line against the friction element on its contact
/// point (`frame`/`center`: the slip of the disc's material point there,
/// the force on the disc there).
#[derive(Appell, Clone, Debug, PartialEq)]
#[appell(coordinates(x, theta), speeds(x, theta), positive(m, r))]
#[appell(frame(B = N.rotate_z(theta)))]
#[appell(point(C = O + x * N.x + r * N.y), point(P = O + x * N.x))]
#[appell(body(disc, center = C, frame = B, mass = m,
              inertia = principal(m * r * r / 4, m * r * r / 4, m * r * r / 2)))]
#[appell(friction(P, mu = mu, normal = m * g, plane = N.y, smoothing = eps, frame = B, center = C))]
struct SkiddingDisc {
    m: f64,
    r: f64,
    g: f64,
    mu: f64,
    eps: f64,
}

#[test]
fn the_friction_of_a_contact_on_a_body_acts_on_its_material_point() {
    // The slip is v_s = ẋ + r θ̇ (the material point at the contact), the
    // friction F = −μ m g v_s/√(v_s² + ε²) on the disc there: ẍ = F/m and
    // θ̈ = r F / I, I = m r²/2 (the moment of F about the centre).
    let disc = SkiddingDisc {
        m: 1.3,
        r: 0.2,
        g: 9.81,
        mu: 0.4,
        eps: 1e-2,
    };
    let p = disc.prepare::<f64>();
    let info = SkiddingDisc::info();
    let mut worst = 0.0f64;
    for k in 0..12 {
        let (xdot, thdot) = (0.7 - 0.13 * k as f64, 2.0 - 0.45 * k as f64);
        let x: Vec<f64> = info
            .retained
            .iter()
            .map(|_| 0.3)
            .chain([xdot, thdot])
            .collect();
        let mut dx = vec![0.0; x.len()];
        disc.rhs(&p, 0.0, &x, &[], &mut dx).unwrap();
        let vs = xdot + disc.r * thdot;
        let f = -disc.mu * disc.m * disc.g * vs / (vs * vs + disc.eps * disc.eps).sqrt();
        let inertia = disc.m * disc.r * disc.r / 2.0;
        let l = dx.len();
        worst = worst
            .max((dx[l - 2] - f / disc.m).abs())
            .max((dx[l - 1] - disc.r * f / inertia).abs());
    }
    assert!(worst < 1e-12, "{worst:e}");
}
