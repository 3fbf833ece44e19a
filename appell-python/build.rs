//! Embeds the source of the appell crates a compiled model needs (the
//! derive, the runtime, the engine and the glue) in the extension, so that a
//! package installed from a wheel or an sdist carries exactly the version it
//! was built from. The Python package writes them into its cache the first
//! time it compiles a model.
//!
//! Manifests are trimmed of what a dependency never builds (tests, benches,
//! dev-dependencies: their files are not carried), and the workspace's
//! member list is cut to the carried crates.

use std::fmt::Write as _;
use std::fs;
use std::path::{Path, PathBuf};

/// The carried crates, relative to the repository root.
const CRATES: &[&str] = &[
    "appell-trig",
    "appell-symbolic",
    "appell-core",
    "appell-dynamics",
    "appell-hybrid",
    "appell-integrate",
    "appell-linearize",
    "appell-tools",
    "appell-codegen",
    "appell-derive",
];

fn main() {
    let manifest = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").unwrap());
    let out = PathBuf::from(std::env::var("OUT_DIR").unwrap());
    let root = manifest.parent().unwrap().to_path_buf();
    let mut files: Vec<(String, PathBuf)> = Vec::new();

    let root_manifest =
        fs::read_to_string(root.join("Cargo.toml")).expect("the workspace manifest");
    let members = CRATES
        .iter()
        .map(|c| format!("\"{c}\""))
        .collect::<Vec<_>>()
        .join(", ");
    let root_manifest = trim_manifest(&root_manifest)
        .lines()
        .map(|line| {
            if line.starts_with("members = [") {
                format!("members = [{members}]")
            } else {
                line.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n")
        + "\n";
    files.push((
        "Cargo.toml".into(),
        written(&out, "root.Cargo.toml", &root_manifest),
    ));
    files.push(("README.md".into(), root.join("README.md")));
    collect(&root, &root.join("src"), &mut files);
    for krate in CRATES {
        let dir = root.join(krate);
        let text = fs::read_to_string(dir.join("Cargo.toml")).expect("a crate manifest");
        let name = format!("{krate}.Cargo.toml");
        files.push((
            format!("{krate}/Cargo.toml"),
            written(&out, &name, &trim_manifest(&text)),
        ));
        for extra in ["README.md", "build.rs"] {
            if dir.join(extra).exists() {
                files.push((format!("{krate}/{extra}"), dir.join(extra)));
            }
        }
        collect(&root, &dir.join("src"), &mut files);
    }
    let glue = manifest.join("glue");
    files.push((
        "appell-python/glue/Cargo.toml".into(),
        glue.join("Cargo.toml"),
    ));
    files.push((
        "appell-python/glue/model.Cargo.lock".into(),
        glue.join("model.Cargo.lock"),
    ));
    collect(&root, &glue.join("src"), &mut files);
    files.sort();

    // FNV-1a over paths and contents: the names of the cache's source
    // trees, one for the appell crates and one for the glue, so that a
    // change of the glue alone does not rebuild the appell crates.
    let mut hash: u64 = 0xcbf2_9ce4_8422_2325;
    let mut glue_hash: u64 = 0xcbf2_9ce4_8422_2325;
    let mut code = String::from(
        "/// (path, contents) of every carried file.\npub static SOURCES: &[(&str, &[u8])] = &[\n",
    );
    for (rel, path) in &files {
        let bytes = fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        // The READMEs are carried for the manifests' `readme` keys only:
        // an edit of the documentation leaves the compiled crates valid.
        if rel.ends_with("README.md") {
            writeln!(
                code,
                "    ({rel:?}, include_bytes!({:?})),",
                path.display().to_string()
            )
            .unwrap();
            println!("cargo:rerun-if-changed={}", path.display());
            continue;
        }
        let h = if rel.starts_with("appell-python/glue/") {
            &mut glue_hash
        } else {
            &mut hash
        };
        for b in rel.bytes().chain([0]).chain(bytes.iter().copied()) {
            *h ^= u64::from(b);
            *h = h.wrapping_mul(0x0100_0000_01b3);
        }
        writeln!(
            code,
            "    ({rel:?}, include_bytes!({:?})),",
            path.display().to_string()
        )
        .unwrap();
        println!("cargo:rerun-if-changed={}", path.display());
    }
    code.push_str("];\n");
    writeln!(code, "/// A hash of the appell crates in [`SOURCES`].\npub const APPELL_HASH: &str = \"{hash:016x}\";").unwrap();
    writeln!(
        code,
        "/// A hash of the glue in [`SOURCES`].\npub const GLUE_HASH: &str = \"{glue_hash:016x}\";"
    )
    .unwrap();
    fs::write(out.join("sources.rs"), code).unwrap();
    for dir in CRATES
        .iter()
        .map(|c| root.join(c).join("src"))
        .chain([root.join("src"), glue.join("src")])
    {
        println!("cargo:rerun-if-changed={}", dir.display());
    }
    println!(
        "cargo:rerun-if-changed={}",
        root.join("Cargo.toml").display()
    );
}

/// Writes `text` to `out/name` and returns the path.
fn written(out: &Path, name: &str, text: &str) -> PathBuf {
    let path = out.join(name);
    fs::write(&path, text).unwrap();
    path
}

/// Every file under `dir`, named relative to `root`.
fn collect(root: &Path, dir: &Path, files: &mut Vec<(String, PathBuf)>) {
    let mut entries: Vec<_> = fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .collect();
    entries.sort();
    for path in entries {
        if path.is_dir() {
            collect(root, &path, files);
        } else {
            let rel = path
                .strip_prefix(root)
                .unwrap()
                .to_string_lossy()
                .replace('\\', "/");
            files.push((rel, path));
        }
    }
}

/// The manifest without the sections a dependency never builds.
fn trim_manifest(text: &str) -> String {
    let dropped = ["[[bench]]", "[[test]]", "[[example]]", "[dev-dependencies]"];
    let mut keep = true;
    let mut out = String::new();
    for line in text.lines() {
        let trimmed = line.trim();
        if trimmed.starts_with('[') {
            keep = !dropped.contains(&trimmed);
        }
        if keep {
            out.push_str(line);
            out.push('\n');
        }
    }
    out
}
