//! Every model in the repository, expanded, against a committed snapshot.
//!
//! The derive's output is its contract with the compiled code: a
//! restructuring of the derivation must keep every expansion byte-identical,
//! and a change that means to alter generated code shows here as a diff.
//! The models are found, not listed: every struct deriving `Appell` in the
//! workspace's examples, tests (UI cases included, whose expansion is the
//! error) and benches. A struct written inside a `macro_rules!` body (the
//! gyroscopes of `tests/composite_bodies.rs`, Andrews' squeezer, declared
//! once for each privileged speed) is not seen.
//!
//! The expansion is compared as formatted Rust (see [`expansion_text`]),
//! with the workspace's directory written `$WORKSPACE` (a URDF model
//! includes its file by absolute path). Each model reads its files (URDF)
//! from the directory its crate is compiled in ([`manifest_dir`]), then
//! beside its source file ([`file_roots`]). Models
//! behind a cargo feature (`#[cfg(feature = ...)]`: the 32-link spatial
//! chain) are expanded only with `APPELL_LARGE_MODELS=1`.
//!
//! `APPELL_BLESS=1 cargo test -p appell-codegen --test snapshots` writes the
//! snapshots anew; review the diff before committing it.
//!
//! An expansion over [`FULL_TEXT_LIMIT`] bytes (a robot's, a long chain's)
//! is kept as a [`summary`]: its size, a hash of the whole text, and every
//! operation count and form it reports, so that a change of any byte fails
//! the test and a change of cost reads as a diff. When such a model
//! differs, the test writes its new text under cargo's temporary directory
//! and names the file; `APPELL_EXPAND=<snapshot name> cargo test -p
//! appell-codegen --test snapshots print_expansion -- --ignored
//! --nocapture` prints any model's full text.

use std::path::{Path, PathBuf};

use appell_codegen::{derivation::Options, FileRoots};
use quote::ToTokens;
use syn::visit::Visit;

/// Folders searched for models, relative to the workspace root.
const SOURCES: &[&str] = &["examples", "tests", "benches", "appell-nostd-check/src"];

fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("workspace root")
        .to_path_buf()
}

fn snapshot_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/snapshots")
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    let mut paths: Vec<PathBuf> = entries.map(|e| e.expect("entry").path()).collect();
    paths.sort();
    for p in paths {
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|e| e == "rs") {
            out.push(p);
        }
    }
}

/// Structs deriving `Appell`, wherever they sit in a file (modules and
/// function bodies included).
#[derive(Default)]
struct Models(Vec<syn::ItemStruct>);

impl<'ast> Visit<'ast> for Models {
    fn visit_item_struct(&mut self, item: &'ast syn::ItemStruct) {
        let derives_appell = item.attrs.iter().any(|a| {
            a.path().is_ident("derive")
                && a.parse_args_with(
                    syn::punctuated::Punctuated::<syn::Path, syn::Token![,]>::parse_terminated,
                )
                .is_ok_and(|paths| {
                    paths
                        .iter()
                        .any(|p| p.segments.last().is_some_and(|s| s.ident == "Appell"))
                })
        });
        if derives_appell {
            self.0.push(item.clone());
        }
        syn::visit::visit_item_struct(self, item);
    }
}

/// The expansion as formatted Rust: the syntax the compiler sees, one
/// statement a line so a change reads as a diff. Formatting the syntax tree
/// leaves out what only the token stream carries (spans, and whether two
/// punctuation marks were written together), which is no change of code.
fn expansion_text(item: &syn::ItemStruct, roots: &FileRoots) -> String {
    let input = syn::DeriveInput::from(item.clone());
    let tokens = appell_codegen::expand_with(&input, roots, &Options::default());
    // The workspace's path is replaced before formatting: its length would
    // otherwise decide where a long line breaks.
    let root = workspace_root().to_string_lossy().into_owned();
    let text = tokens.to_string().replace(&root, "$WORKSPACE");
    let file: syn::File = syn::parse_str(&text).expect("the expansion parses as Rust items");
    prettyplease::unparse(&file)
}

/// The directory cargo compiles `file`'s crate in, which paths in its
/// models start from: the workspace's for the root crate, a member's own,
/// and for a UI case the project trybuild writes under the target
/// directory (`target/tests/trybuild/appell`, which need not exist: the
/// derive takes `..` out of a path by name).
fn manifest_dir(rel: &Path) -> PathBuf {
    let root = workspace_root();
    if rel.starts_with("tests/ui") {
        root.join("target/tests/trybuild/appell")
    } else if rel.starts_with("appell-nostd-check") {
        root.join("appell-nostd-check")
    } else {
        root
    }
}

/// Where `file`'s models look for the files they name: its crate's
/// directory, then beside the file itself, as the derive looks.
fn file_roots(rel: &Path) -> FileRoots {
    let source = workspace_root().join(rel);
    FileRoots::new(Some(&manifest_dir(rel)), source.parent())
}

/// Whether a model is compiled only with a cargo feature.
fn behind_a_feature(item: &syn::ItemStruct) -> bool {
    item.attrs.iter().any(|a| {
        a.path().is_ident("cfg") && a.meta.to_token_stream().to_string().contains("feature")
    })
}

/// Expansions longer than this many bytes are kept as a [`summary`].
const FULL_TEXT_LIMIT: usize = 100_000;

/// What the snapshot file holds for an expansion: the text itself, or its
/// summary when it is longer than [`FULL_TEXT_LIMIT`].
fn snapshot_of(text: &str) -> String {
    if text.len() <= FULL_TEXT_LIMIT {
        text.to_string()
    } else {
        summary(text)
    }
}

/// A long expansion's size, its FNV-1a hash, and the lines that report
/// its cost: each `form` and each operation count (one line a count).
fn summary(text: &str) -> String {
    let mut out = format!(
        "large expansion, kept as a summary (see the header of appell-codegen/tests/snapshots.rs)\nbytes: {}\nlines: {}\nfnv1a-64: {:016x}\n",
        text.len(),
        text.lines().count(),
        fnv1a(text.as_bytes())
    );
    let mut lines = text.lines().map(str::trim);
    while let Some(line) = lines.next() {
        if line.starts_with("form: ") {
            out.push_str(line);
            out.push('\n');
        } else if line.ends_with("OpCounts {") {
            let name = line.split(':').next().unwrap_or("").trim();
            let fields: Vec<&str> = lines.by_ref().take_while(|l| !l.starts_with('}')).collect();
            out.push_str(&format!("{name}: {}\n", fields.join(" ")));
        }
    }
    out
}

/// The 64-bit FNV-1a hash: stable across platforms and Rust versions.
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

/// Every model: (snapshot name, expansion).
fn expansions() -> Vec<(String, String)> {
    expansions_named(None)
}

/// Every model, or only the one whose snapshot is named `only` (with or
/// without `.txt`): (snapshot name, expansion).
fn expansions_named(only: Option<&str>) -> Vec<(String, String)> {
    let root = workspace_root();
    let mut files = Vec::new();
    for dir in SOURCES {
        rust_files(&root.join(dir), &mut files);
    }
    let mut out = Vec::new();
    for file in files {
        let src = std::fs::read_to_string(&file).expect("read");
        let Ok(parsed) = syn::parse_file(&src) else {
            continue;
        };
        let mut models = Models::default();
        models.visit_file(&parsed);
        let rel = file.strip_prefix(&root).expect("inside root");
        let stem = rel
            .with_extension("")
            .to_string_lossy()
            .replace(['/', '\\'], "__");
        let large = std::env::var_os("APPELL_LARGE_MODELS").is_some();
        for item in &models.0 {
            if behind_a_feature(item) && !large {
                continue;
            }
            let name = format!("{stem}__{}.txt", item.ident);
            if only.is_some_and(|o| o != name && format!("{o}.txt") != name) {
                continue;
            }
            let text = expansion_text(item, &file_roots(rel));
            out.push((name, text));
        }
    }
    out
}

#[test]
fn every_models_expansion_matches_its_snapshot() {
    let dir = snapshot_dir();
    let bless = std::env::var_os("APPELL_BLESS").is_some();
    let all = expansions();
    assert!(all.len() >= 40, "found only {} models", all.len());
    let mut failures = Vec::new();
    for (name, full) in &all {
        let path = dir.join(name);
        let text = &snapshot_of(full);
        if bless {
            std::fs::create_dir_all(&dir).expect("snapshot dir");
            std::fs::write(&path, text).expect("write snapshot");
            continue;
        }
        match std::fs::read_to_string(&path) {
            Ok(old) if old == *text => {}
            Ok(old) => {
                let line = old
                    .lines()
                    .zip(text.lines())
                    .position(|(a, b)| a != b)
                    .unwrap_or(old.lines().count().min(text.lines().count()));
                let mut failure = format!("{name}: differs from line {}", line + 1);
                if text != full {
                    let new = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
                    std::fs::write(&new, full).expect("write the new expansion");
                    failure.push_str(&format!(" (its new full text: {})", new.display()));
                }
                failures.push(failure);
            }
            Err(_) => failures.push(format!("{name}: no snapshot (run with APPELL_BLESS=1)")),
        }
    }
    if !bless {
        let known: std::collections::BTreeSet<&str> = all.iter().map(|(n, _)| n.as_str()).collect();
        for entry in std::fs::read_dir(&dir).expect("snapshot dir") {
            let name = entry.expect("entry").file_name();
            let name = name.to_string_lossy();
            if !known.contains(name.as_ref()) {
                failures.push(format!("{name}: snapshot of a model that no longer exists"));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The full expansion of the model whose snapshot is named by
/// `APPELL_EXPAND` (e.g. `tests__standing__Solo12`), on standard output.
#[test]
#[ignore]
fn print_expansion() {
    let name = std::env::var("APPELL_EXPAND").expect("APPELL_EXPAND names a snapshot");
    let found = expansions_named(Some(&name));
    assert!(!found.is_empty(), "no model has the snapshot name `{name}`");
    for (_, text) in found {
        print!("{text}");
    }
}

#[test]
fn a_long_expansions_summary_keeps_its_size_hash_forms_and_counts() {
    let mut text = String::from("    form: \"structured: 12 operations\",\n");
    text.push_str("    rhs_ops: ::appell::__private::OpCounts {\n        add: 5,\n        total: 12,\n    },\n");
    let s = summary(&text);
    assert!(
        s.contains(&format!("bytes: {}\nlines: 5\n", text.len())),
        "{s}"
    );
    assert!(s.contains("form: \"structured: 12 operations\",\n"), "{s}");
    assert!(s.contains("rhs_ops: add: 5, total: 12,\n"), "{s}");
    // One byte more changes the hash.
    assert_ne!(summary(&text), summary(&format!("{text} ")));
    assert_eq!(fnv1a(b"a"), 0xaf63_dc4c_8601_ec8c);
    assert_eq!(snapshot_of("short"), "short");
}

/// Expansion time (median of five), emitted size and rhs operation count of
/// every example model: `cargo test --release -p appell-codegen --test
/// snapshots -- --ignored --nocapture`. Figures, not a check: the machine
/// is shared.
#[test]
#[ignore]
fn expansion_costs() {
    let root = workspace_root();
    let mut files = Vec::new();
    rust_files(&root.join("examples"), &mut files);
    println!("| model | expansion | emitted | rhs ops |\n| --- | ---: | ---: | ---: |");
    for file in files {
        let src = std::fs::read_to_string(&file).expect("read");
        let Ok(parsed) = syn::parse_file(&src) else {
            continue;
        };
        let mut models = Models::default();
        models.visit_file(&parsed);
        let dir = manifest_dir(file.strip_prefix(&root).expect("inside root"));
        for item in &models.0 {
            let input = syn::DeriveInput::from(item.clone());
            let mut times = Vec::new();
            let mut text = String::new();
            for _ in 0..5 {
                let t = std::time::Instant::now();
                text = appell_codegen::expand_in(&input, Some(&dir)).to_string();
                times.push(t.elapsed().as_secs_f64());
            }
            times.sort_by(f64::total_cmp);
            let ops = text
                .find("total :")
                .map(|i| {
                    text[i + 7..]
                        .split(['}', ','])
                        .next()
                        .unwrap_or("")
                        .trim()
                        .to_string()
                })
                .unwrap_or_default();
            println!(
                "| {} | {:.1} ms | {:.1} kB | {ops} |",
                item.ident,
                times[2] * 1e3,
                text.len() as f64 / 1e3
            );
        }
    }
}
