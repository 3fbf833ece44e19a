//! Writes random mechanisms (`mechanisms.rs`) through the real derive at
//! build time: each one's expansion goes into `models.rs` in `OUT_DIR`,
//! with a function that checks it; a model the derive refuses is recorded
//! with its message, and one that makes the derive panic is recorded as
//! such (the tests require none). The seed is fixed, or taken from
//! `APPELL_MECHANISM_SEED`; the count from `APPELL_MECHANISMS` (default
//! 320).

use std::fmt::Write as _;
use std::panic::{catch_unwind, AssertUnwindSafe};

#[path = "mechanisms.rs"]
mod mechanisms;

use mechanisms::{mechanism, Mechanism};

const DEFAULT_SEED: u64 = 0x00a9_9e11_2003;
const DEFAULT_COUNT: usize = 320;

/// What became of one mechanism at expansion.
enum Outcome {
    Derived(String),
    Refused(String),
    Panicked(String),
}

fn expand(m: &Mechanism) -> Outcome {
    let input: syn::DeriveInput = match syn::parse_str(&m.source()) {
        Ok(input) => input,
        Err(e) => return Outcome::Panicked(format!("the generator wrote invalid Rust: {e}")),
    };
    let roots = appell_codegen::FileRoots::default();
    let options = appell_codegen::derivation::Options::default();
    let result = catch_unwind(AssertUnwindSafe(|| {
        appell_codegen::expand_with(&input, &roots, &options).to_string()
    }));
    match result {
        Ok(text) if text.contains("compile_error") => Outcome::Refused(first_message(&text)),
        Ok(text) => Outcome::Derived(text),
        Err(payload) => Outcome::Panicked(
            payload
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| payload.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_else(|| "a panic without a message".into()),
        ),
    }
}

/// The first `compile_error!` message of an expansion.
fn first_message(text: &str) -> String {
    let start = text.find("compile_error").unwrap_or(0);
    let rest = &text[start..];
    let open = rest.find('"').map_or(0, |i| i + 1);
    let mut close = rest.len();
    let mut escaped = false;
    for (i, c) in rest[open..].char_indices() {
        match c {
            '\\' if !escaped => escaped = true,
            '"' if !escaped => {
                close = open + i;
                break;
            }
            _ => escaped = false,
        }
    }
    rest[open..close].replace("\\\"", "\"")
}

fn camel(s: &str) -> String {
    s.split('_')
        .map(|w| {
            let mut c = w.chars();
            c.next()
                .map(|f| f.to_uppercase().collect::<String>() + c.as_str())
                .unwrap_or_default()
        })
        .collect()
}

/// The struct, its expansion and its check function.
fn write_model(out: &mut String, m: &Mechanism, expansion: &str) {
    let name = &m.name;
    let fields: String = m
        .fields
        .iter()
        .map(|(f, _)| format!("pub {f}: f64, "))
        .collect();
    let values: String = m
        .fields
        .iter()
        .map(|(f, v)| format!("{f}: {v:?}, "))
        .collect();
    writeln!(
        out,
        "#[derive(Clone, Debug)] pub struct {name} {{ {fields} }}"
    )
    .unwrap();
    writeln!(out, "{expansion}").unwrap();
    let full_energy = m.conservative.as_deref() == Some("");
    let mut body = format!(
        "let model = {name} {{ {values} }}; let mut report = crate::check::model(&model, rng, {full_energy})?;"
    );
    for scene in &m.scenes {
        let energy = m.conservative.as_deref() == Some(scene.as_str());
        write!(
            body,
            " report.merge(crate::check::model({name}{}::from_ref(&model), rng, {energy})?);",
            camel(scene)
        )
        .unwrap();
    }
    writeln!(
        out,
        "fn check_{name}(rng: &mut crate::check::Rng) -> Result<crate::check::Report, String> {{ {body} Ok(report) }}"
    )
    .unwrap();
}

fn main() {
    println!("cargo:rerun-if-changed=build");
    println!("cargo:rerun-if-env-changed=APPELL_MECHANISM_SEED");
    println!("cargo:rerun-if-env-changed=APPELL_MECHANISMS");
    let seed = std::env::var("APPELL_MECHANISM_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(DEFAULT_SEED);
    let count = std::env::var("APPELL_MECHANISMS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(DEFAULT_COUNT);
    let mut models = String::new();
    let (mut cases, mut refused, mut panicked) = (String::new(), String::new(), String::new());
    let started = std::time::Instant::now();
    for k in 0..count {
        let m = mechanism(seed, k);
        let families = format!("{:?}", m.families);
        let entry = |message: &str| {
            format!(
                "Unchecked {{ name: {:?}, source: {:?}, families: &{families}, message: {:?} }},\n",
                m.name,
                m.source(),
                message
            )
        };
        match expand(&m) {
            Outcome::Derived(expansion) => {
                write_model(&mut models, &m, &expansion);
                writeln!(
                    cases,
                    "Case {{ name: {:?}, source: {:?}, families: &{families}, check: check_{} }},",
                    m.name,
                    m.source(),
                    m.name
                )
                .unwrap();
            }
            Outcome::Refused(message) => refused.push_str(&entry(&message)),
            Outcome::Panicked(message) => panicked.push_str(&entry(&message)),
        }
    }
    let seconds = started.elapsed().as_secs_f64();
    // Shown in the build's output, so every run states what it drew; the
    // test prints the agreement (`-- --nocapture`).
    println!(
        "cargo:warning=random mechanisms: seed {seed:#x}, {count} generated, {} derived, {} refused, {} panicked",
        cases.lines().count(),
        refused.lines().count(),
        panicked.lines().count()
    );
    let out = format!(
        "/// The seed the mechanisms were drawn with.\npub const SEED: u64 = {seed};\n\
         /// How many were generated.\npub const GENERATED: usize = {count};\n\
         /// Seconds the derive took for all of them (the build script's own, unoptimised unless the profile says otherwise).\npub const DERIVE_SECONDS: f64 = {seconds:?};\n\
         /// The derived ones, with their checks.\npub static CASES: &[Case] = &[\n{cases}];\n\
         /// Those the derive refused, with its first message.\npub static REFUSED: &[Unchecked] = &[\n{refused}];\n\
         /// Those whose expansion panicked (none may).\npub static PANICKED: &[Unchecked] = &[\n{panicked}];\n\
         {models}"
    );
    let path = std::path::Path::new(&std::env::var("OUT_DIR").unwrap()).join("models.rs");
    std::fs::write(path, out).unwrap();
}
