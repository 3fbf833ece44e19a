//! Composite bodies and rotors change how M and f are computed, not what
//! they are: the derivation with folding forced agrees with the one
//! without, at pseudo-random points, on models where folding would not
//! otherwise be chosen (a particle bolted to a rigid arm; a gyroscope).

use appell_codegen::ctxt::Ctxt;
use appell_codegen::derivation::{derive_with, Options};
use appell_codegen::probe::pseudo_value;
use appell_codegen::{model, parse};
use appell_symbolic::Tape;

/// M and f (and the equations text) of `src`, folding forced or not.
fn equations(src: &str, fold_always: bool) -> (Vec<Vec<f64>>, String) {
    equations_with(src, fold_always, None)
}

/// The same, with the rotors' form forced (whole or split) when given.
fn equations_with(
    src: &str,
    fold_always: bool,
    rotor_form: Option<bool>,
) -> (Vec<Vec<f64>>, String) {
    let input: syn::DeriveInput = syn::parse_str(src).expect("valid Rust");
    let cx = Ctxt::new();
    let ast = parse::parse(&cx, &input);
    let kinematics = model::build(&cx, &ast).expect("model");
    let options = Options {
        fold_always,
        rotor_form,
        ..Options::default()
    };
    let derived = derive_with(&cx, kinematics, &options).expect("derivation");
    let (d, g) = (&derived.full, &derived.model.g);
    cx.check().expect("no errors");
    let mut roots = d.equations.mass.clone();
    roots.extend(&d.equations.forcing);
    let tape = Tape::new(g, &roots);
    let values = (0..5u64)
        .map(|trial| {
            tape.eval(&|s| Some(pseudo_value(g, s, trial)))
                .expect("finite")
        })
        .collect();
    (values, d.text.clone())
}

fn assert_same(a: &[Vec<f64>], b: &[Vec<f64>]) {
    for (x, y) in a.iter().flatten().zip(b.iter().flatten()) {
        assert!(
            (x - y).abs() <= 1e-12 * (1.0 + x.abs().max(y.abs())),
            "{x} vs {y}"
        );
    }
}

const ARM_WITH_TIP: &str = r#"
#[appell(coordinates(yaw, pitch, roll), speeds(yaw, pitch, roll))]
#[appell(positive(m1, m2))]
#[appell(frame(A = N.rotate_z(yaw)), frame(B = A.rotate_y(pitch)), frame(C = B.rotate_x(roll)))]
#[appell(point(G1 = O + a * C.x + b * C.z), point(Tip = O + l * C.x + h * C.y))]
#[appell(body(arm, center = G1, frame = C, mass = m1, inertia = matrix(i11, i22, i33, 0, 0, i31)))]
#[appell(particle(Tip, mass = m2))]
#[appell(gravity(-g * N.z))]
struct ArmWithTip { a: f64, b: f64, l: f64, h: f64, m1: f64, m2: f64, i11: f64, i22: f64, i33: f64, i31: f64, g: f64 }
"#;

const GYROSCOPE: &str = r#"
#[appell(coordinates(yaw, pitch, spin), speeds(yaw, pitch, spin))]
#[appell(positive(mb, md))]
#[appell(frame(A = N.rotate_z(yaw)), frame(B = A.rotate_x(pitch)), frame(D = B.rotate_y(spin)))]
#[appell(point(Bo = O + a * B.z + c * B.x), point(Do = O + h * B.z))]
#[appell(body(gimbal, center = Bo, frame = B, mass = mb, inertia = matrix(i11, i22, i33, 0, 0, i31)))]
#[appell(body(rotor, center = Do, frame = D, mass = md, inertia = principal(j1, j2, j1)))]
#[appell(gravity(-g * N.z))]
struct Gyroscope { a: f64, c: f64, h: f64, mb: f64, md: f64, i11: f64, i22: f64, i33: f64, i31: f64, j1: f64, j2: f64, g: f64 }
"#;

#[test]
fn a_particle_on_a_rigid_arm_folds_into_a_composite() {
    let (plain, text) = equations(ARM_WITH_TIP, false);
    assert!(!text.contains("composite:"), "{text}");
    let (folded, text) = equations(ARM_WITH_TIP, true);
    assert!(text.contains("composite: `arm` with `Tip`"), "{text}");
    assert_same(&plain, &folded);
}

#[test]
fn a_spinning_rotor_folds_into_its_gimbal() {
    let (plain, _) = equations(GYROSCOPE, false);
    for form in [None, Some(true), Some(false)] {
        let (folded, text) = equations_with(GYROSCOPE, true, form);
        assert!(text.contains("composite: `gimbal` with `rotor`"), "{text}");
        assert!(
            text.contains("rotor: `rotor` spins about axis y of `gimbal`"),
            "{text}"
        );
        assert_same(&plain, &folded);
    }
}
