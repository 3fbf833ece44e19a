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


/// Each struct of a model file (up to the next blank line after its
/// derive), by name.
fn model_structs(src: &str) -> Vec<(String, String)> {
    let mut out = Vec::new();
    let mut rest = src;
    while let Some(start) = rest.find("#[derive(Appell") {
        let end = rest[start..].find("\n\n").map_or(rest.len(), |e| start + e);
        let item = &rest[start..end];
        let name = item.split("pub struct ").nth(1).unwrap().split([';', ' ', '{']).next().unwrap();
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
            println!("{name}: expansion {:.3} s, {} bytes", t.elapsed().as_secs_f64(), out.len());
            assert!(!out.contains("compile_error"), "{}", &out[..out.len().min(3000)]);
            if let Some(dir) = std::env::var_os("APPELL_WRITE_EXPANSIONS") {
                std::fs::write(Path::new(&dir).join(format!("{name}.rs")), &out).unwrap();
            }
        }
    }
}
