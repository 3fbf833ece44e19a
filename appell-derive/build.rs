//! Passes how Cargo builds this crate (its optimisation level and profile)
//! to the derive, which warns when an unoptimised derivation was slow.

fn main() {
    for var in ["OPT_LEVEL", "PROFILE"] {
        let value = std::env::var(var).unwrap_or_default();
        println!("cargo:rustc-env=APPELL_DERIVE_{var}={value}");
    }
    println!("cargo:rerun-if-changed=build.rs");
}
