//! URDF robots: their expansion, the errors, and what they lower to.

use std::path::{Path, PathBuf};

use appell_codegen::expand_in;

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().expect("workspace").to_path_buf()
}

fn expand_str(src: &str) -> String {
    let input: syn::DeriveInput = syn::parse_str(src).expect("valid Rust");
    expand_in(&input, Some(&workspace())).to_string()
}

#[test]
fn the_ur5_expands() {
    let t = std::time::Instant::now();
    let out = expand_str(
        r#"
        #[appell(urdf("examples/robots/ur5/ur5_robot.urdf"), gravity(-9.81 * N.z))]
        struct Ur5;
        "#,
    );
    println!("ur5: {:.3} s, {} bytes", t.elapsed().as_secs_f64(), out.len());
    assert!(!out.contains("compile_error"), "{}", &out[..out.len().min(3000)]);
}
