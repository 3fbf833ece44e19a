//! The codegen stages on token input, without compiling the output.

use appell_codegen::expand;

fn expand_str(src: &str) -> String {
    let input: syn::DeriveInput = syn::parse_str(src).expect("valid Rust");
    expand(&input).to_string()
}

const WHEEL_AXLE: &str = include_str!("../../examples/models/wheel_axle.rs");

fn wheel_axle_struct() -> String {
    // The model file holds the struct and a Default impl; keep the struct.
    let start = WHEEL_AXLE.find("#[derive(Appell").expect("derive");
    let end = WHEEL_AXLE.find("impl Default").expect("impl");
    WHEEL_AXLE[start..end].to_string()
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
    let src = include_str!("../../examples/models/whipple_bicycle.rs");
    let start = src.find("#[derive(Appell").expect("derive");
    let end = src.find("impl Default").expect("impl");
    let t = std::time::Instant::now();
    let out = expand_str(&src[start..end]);
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
