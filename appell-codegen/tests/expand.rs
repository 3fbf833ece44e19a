//! The codegen stages on token input, without compiling the output.

use appell_codegen::expand;

fn expand_str(src: &str) -> String {
    let input: syn::DeriveInput = syn::parse_str(src).expect("valid Rust");
    expand(&input).to_string()
}

const WHEEL_AXLE: &str = include_str!("../../examples/models/wheel_axle.rs");

/// A model file holds the struct and a Default impl; keep the struct.
fn wheel_axle_struct() -> String {
    model_struct(WHEEL_AXLE)
}

#[test]
fn wheel_axle_expands_without_errors() {
    let out = expand_str(&wheel_axle_struct());
    assert!(!out.contains("compile_error"), "{out}");
    assert!(out.contains("impl :: appell :: __private :: Model for WheelAxle"));
    if std::env::var_os("APPELL_SHOW_EXPANSION").is_some() {
        println!("{out}");
    }
}

#[test]
fn expansion_is_deterministic() {
    let s = wheel_axle_struct();
    assert_eq!(expand_str(&s), expand_str(&s));
}

#[test]
fn several_mistakes_are_reported_together() {
    let out = expand_str(
        r#"
        #[appell(coordinates(q, q), speeds(q))]
        #[appell(particle(P, mass = m))]
        struct Bad { m: f64 }
        "#,
    );
    assert!(out.contains("duplicate coordinate `q`"), "{out}");
    assert!(out.contains("unknown point `P`"), "{out}");
}

#[test]
fn whipple_bicycle_expands() {
    let src = model_struct(include_str!("../../examples/models/whipple_bicycle.rs"));
    let t = std::time::Instant::now();
    let out = expand_str(&src);
    println!(
        "whipple expansion: {:.3} s, {} bytes",
        t.elapsed().as_secs_f64(),
        out.len()
    );
    if let Some(i) = out.find("total :") {
        println!("{}", &out[i..i + 20]);
    }
    if let Some(path) = std::env::var_os("APPELL_WRITE_EXPANSION") {
        std::fs::write(path, &out).unwrap();
    }
    assert!(
        !out.contains("compile_error"),
        "{}",
        &out[..out.len().min(2000)]
    );
}

fn model_struct(src: &str) -> String {
    let start = src.find("#[derive(Appell").expect("derive");
    let end = src.find("impl Default").expect("impl");
    src[start..end].to_string()
}

#[test]
fn ldlt_keeps_a_pivots_reciprocal_where_it_saves_a_division_or_waits_for_f() {
    // No constraints: the first pivot divides l_10 and w_0 and is kept as
    // a reciprocal; the last divides w_1 only and stays a division.
    let out = expand_str(&model_struct(include_str!(
        "../../examples/models/double_pendulum.rs"
    )));
    assert!(out.contains("__l_1_0 = __e_1_0 * __r_0"), "{out}");
    assert!(out.contains("__w_0 = __z_0 * __r_0"), "{out}");
    assert!(out.contains("__w_1 = __z_1 / __d_1"), "{out}");
    assert!(!out.contains("__r_1"), "{out}");
    // A numeric elimination: M is complete before f, so the last pivot's
    // reciprocal is computed early and the solve that waits on f multiplies.
    let out = expand_str(&model_struct(include_str!(
        "../../examples/models/chaplygin_sleigh.rs"
    )));
    assert!(out.contains("__w_1 = __z_1 * __r_1"), "{out}");
    assert!(!out.contains("__z_1 / __d_1"), "{out}");
    // A constant M: the factors, the last pivot's reciprocal among them,
    // are computed in `prepare`, and the rhs divides by no pivot.
    let out = expand_str(&wheel_axle_struct());
    assert!(out.contains("let __r_1 = "), "{out}");
    assert!(out.contains("__w_1 = __z_1 * __r_1"), "{out}");
    assert!(!out.contains("__z_0 / __d_0"), "{out}");
    assert!(!out.contains("__z_1 / __d_1"), "{out}");
}
