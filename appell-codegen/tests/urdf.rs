//! URDF robots: their expansion, the errors, and what they lower to.

use std::path::{Path, PathBuf};

use appell_codegen::expand_in;

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("workspace")
        .to_path_buf()
}

fn expand_str(src: &str) -> String {
    let input: syn::DeriveInput = syn::parse_str(src).expect("valid Rust");
    expand_in(&input, Some(&workspace())).to_string()
}

/// Each struct of a model file (from the blank line before its derive to
/// the next, so with its attributes), by name.
fn model_structs(src: &str) -> Vec<(String, String)> {
    let mut out = Vec::new();
    let mut rest = src;
    while let Some(derive) = rest.find("#[derive(Appell") {
        let start = rest[..derive].rfind("\n\n").map_or(0, |b| b + 2);
        let end = rest[derive..]
            .find("\n\n")
            .map_or(rest.len(), |e| derive + e);
        let item = &rest[start..end];
        let name = item
            .split("pub struct ")
            .nth(1)
            .unwrap()
            .split([';', ' ', '{'])
            .next()
            .unwrap();
        out.push((name.to_string(), item.to_string()));
        rest = &rest[end..];
    }
    out
}

/// Expansion time and size of each robot model, printed (`--nocapture`).
#[test]
fn robots_expand_and_their_time_and_size() {
    let files = [
        include_str!("../../examples/models/ur5.rs"),
        include_str!("../../examples/models/panda.rs"),
        include_str!("../../examples/models/spatial_chain.rs"),
    ];
    let large = std::env::var_os("APPELL_LARGE_MODELS").is_some();
    for file in files {
        for (name, src) in model_structs(file) {
            if src.contains("large-models") && !large {
                continue;
            }
            let t = std::time::Instant::now();
            let out = expand_str(&src);
            println!(
                "{name}: expansion {:.3} s, {} bytes",
                t.elapsed().as_secs_f64(),
                out.len()
            );
            assert!(
                !out.contains("compile_error"),
                "{}",
                &out[..out.len().min(3000)]
            );
            if let Some(dir) = std::env::var_os("APPELL_WRITE_EXPANSIONS") {
                std::fs::write(Path::new(&dir).join(format!("{name}.rs")), &out).unwrap();
            }
        }
    }
}

#[test]
fn the_output_includes_the_file_so_cargo_rebuilds_on_change() {
    let out = expand_str(
        r#"
        #[appell(urdf = "examples/robots/spatial_chain/spatial_chain_2.urdf")]
        struct Chain;
        "#,
    );
    let path = workspace().join("examples/robots/spatial_chain/spatial_chain_2.urdf");
    let include = format!(
        "const _ : & [u8] = :: core :: include_bytes ! ({:?})",
        path.to_str().unwrap()
    );
    assert!(out.contains(&include), "{}", &out[..out.len().min(2000)]);
}

#[test]
fn a_robot_on_a_moving_base() {
    // The UR5's root link fixed to a cart that slides along N.x.
    let out = expand_str(
        r#"
        #[appell(joint(slide, prismatic(x), parent = N, child = cart))]
        #[appell(body(cart_body, center = cart_origin, frame = cart, mass = 20.0, inertia = principal(1, 1, 1)))]
        #[appell(urdf("examples/robots/ur5/ur5_robot.urdf", parent = cart), gravity(-9.81 * N.z))]
        struct Mobile;
        "#,
    );
    assert!(
        !out.contains("compile_error"),
        "{}",
        &out[..out.len().min(3000)]
    );
    assert!(
        out.contains(r#"coordinates : & ["slide" , "shoulder_pan_joint""#),
        "{}",
        &out[..3000]
    );
    // A frame not made by a joint has no origin: `at` is needed.
    let out = expand_str(
        r#"
        #[appell(coordinates(a), frame(turntable = N.rotate_z(a)))]
        #[appell(urdf("examples/robots/ur5/ur5_robot.urdf", parent = turntable))]
        struct Turning;
        "#,
    );
    assert!(out.contains("give `at = P`"), "{out}");
    let out = expand_str(
        r#"
        #[appell(coordinates(a), speeds(a), frame(turntable = N.rotate_z(a)), point(top = O + 0.5 * N.z))]
        #[appell(urdf("examples/robots/ur5/ur5_robot.urdf", parent = turntable, at = top))]
        #[appell(gravity(-9.81 * N.z))]
        struct Turning;
        "#,
    );
    assert!(
        !out.contains("compile_error"),
        "{}",
        &out[..out.len().min(3000)]
    );
}

#[test]
fn without_a_manifest_directory_a_urdf_is_an_error() {
    let input: syn::DeriveInput =
        syn::parse_str(r#"#[appell(urdf("robot.urdf"))] struct R;"#).unwrap();
    let out = expand_in(&input, None).to_string();
    assert!(out.contains("CARGO_MANIFEST_DIR"), "{out}");
}
