//! The generated code names everything by absolute path: a model compiles in
//! a module that shadows the prelude's names and the runtime's.

#![allow(dead_code, non_camel_case_types)]

mod shadowed {
    // Shadow what generated code might otherwise pick up by name.
    struct Result;
    struct Ok;
    struct Err;
    struct Option;
    struct Some;
    struct None;
    struct Vec;
    struct String;
    struct Box;
    struct Scalar;
    struct Model;
    struct ModelError;
    struct ModelInfo;
    trait Copy {}
    trait Clone {}
    fn check_len() {}
    fn lu_solve() {}
    fn ldlt_solve() {}
    mod core {}
    mod appell_core {}
    mod appell_integrate {}

    /// A sleigh (run-time elimination path) and a constant mass matrix
    /// (hoisted factorization path) in one shadowed module.
    #[derive(::appell::Appell)]
    #[appell(coordinates(x, y, theta), speeds(x, theta))]
    #[appell(frame(B = N.rotate_z(theta)))]
    #[appell(point(P = O + x * N.x + y * N.y), point(C = P + b * B.x))]
    #[appell(body(sleigh, center = C, frame = B, mass = m, inertia = principal(i0, i0, i0)))]
    #[appell(nonholonomic(dt(y) * cos(theta) - dt(x) * sin(theta) == 0))]
    pub struct Sleigh {
        pub m: f64,
        pub i0: f64,
        pub b: f64,
    }

    #[derive(::appell::Appell)]
    #[appell(coordinates(s), speeds(s), inputs(f))]
    #[appell(point(P = O + s * N.x), particle(P, mass = m))]
    #[appell(force(P, f * N.x, effect = push))]
    pub struct Block {
        pub m: f64,
    }
}

#[test]
fn shadowed_models_compile_and_run() {
    use appell::Model;
    let s = shadowed::Sleigh {
        m: 1.0,
        i0: 0.2,
        b: 0.3,
    };
    let mut d = [0.0; 3];
    s.rhs(&s.prepare::<f64>(), 0.0, &[0.1, 1.0, 0.5], &[], &mut d)
        .unwrap();
    let b = shadowed::Block { m: 2.0 };
    let mut d = [0.0; 1];
    b.rhs(&b.prepare::<f64>(), 0.0, &[0.0], &[3.0], &mut d)
        .unwrap();
    assert_eq!(d[0], 1.5);
}
