//! Expands a model of every URDF in a folder (`tests/robots/` by default,
//! the example-robot-data set `tests/robots/fetch_robots.py` copies) and
//! prints a markdown table: whether it derives, the expansion time, the
//! rhs's form and operation count, or the compile errors.
//!
//! Each robot is `#[appell(urdf("<path>", base = fixed), gravity(-9.81 *
//! N.z))] struct R;`, and again with `base = free` for the robots whose
//! usual Pinocchio model floats (`"base": "free"` in the folder's
//! `MANIFEST.json`). Each expansion runs in a child process of its own,
//! stopped after `--timeout` seconds (default 600), so one robot that takes
//! too long or too much memory does not stop the survey.
//!
//! ```sh
//! cargo run --release -p appell-codegen --example robot_survey -- [--timeout S] [--base fixed|free] [--jacobian off] [DIR_OR_URDF ...] [--only NAME ...]
//! ```
//!
//! `--jacobian off` expands each model with `jacobian(off)` (no
//! `rhs_jacobian`), to compare the expansion's time and size with and
//! without the derivatives.
//!
//! Build it with `--release`: the derive runs optimised in a build
//! (`[profile.*.build-override] opt-level = 3`), so only a release build
//! times it as users see it.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use appell_codegen::{derivation::Options, expand_with, FileRoots};
use proc_macro2::{TokenStream, TokenTree};

/// What one expansion gave.
struct Outcome {
    seconds: f64,
    code_kb: Option<f64>,
    errors: Vec<String>,
    form: Option<String>,
    ops: Option<usize>,
    coordinates: Option<usize>,
    peak_mb: Option<f64>,
}

/// Set by `--jacobian off` for the child processes.
const JACOBIAN_OFF: &str = "APPELL_SURVEY_JACOBIAN_OFF";

fn model_source(path: &Path, base: &str, extra: &str) -> String {
    let jacobian = if std::env::var_os(JACOBIAN_OFF).is_some() {
        ", jacobian(off)"
    } else {
        ""
    };
    format!(
        "#[appell(urdf({:?}, base = {base}{extra}), gravity(-9.81 * N.z){jacobian})] struct R;",
        path.display().to_string()
    )
}

/// Expands the model in this process and prints one line the parent reads.
fn expand_one(path: &Path, base: &str, extra: &str) {
    let input: syn::DeriveInput =
        syn::parse_str(&model_source(path, base, extra)).expect("valid Rust");
    let t = Instant::now();
    let tokens = expand_with(&input, &FileRoots::default(), &Options::default());
    let seconds = t.elapsed().as_secs_f64();
    let bytes = tokens.to_string().len();
    let errors = compile_errors(&tokens);
    let form = after(&tokens, "form").and_then(|t| string(&t));
    let ops = after(&tokens, "total").and_then(|t| t.to_string().parse().ok());
    let coordinates = after(&tokens, "coordinates").map(|t| match t {
        TokenTree::Group(g) => g
            .stream()
            .into_iter()
            .filter(|t| matches!(t, TokenTree::Literal(_)))
            .count(),
        _ => 0,
    });
    let peak = std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmHWM:"))
                .and_then(|l| l.split_whitespace().nth(1)?.parse::<f64>().ok())
        })
        .map(|kb| kb / 1024.0);
    // One line of tab-separated fields; newlines and tabs in messages
    // escaped.
    let esc = |s: &str| {
        s.replace('\\', "\\\\")
            .replace('\n', "\\n")
            .replace('\t', " ")
    };
    println!(
        "OUTCOME\t{seconds}\t{bytes}\t{}\t{}\t{}\t{}\t{}",
        form.as_deref().map(esc).unwrap_or_default(),
        ops.map(|o: usize| o.to_string()).unwrap_or_default(),
        coordinates.map(|c| c.to_string()).unwrap_or_default(),
        peak.map(|p| format!("{p:.0}")).unwrap_or_default(),
        errors.iter().map(|e| esc(e)).collect::<Vec<_>>().join("\t"),
    );
}

/// The messages of the `compile_error!`s in `tokens`.
fn compile_errors(tokens: &TokenStream) -> Vec<String> {
    let mut out = Vec::new();
    let all: Vec<TokenTree> = tokens.clone().into_iter().collect();
    for w in all.windows(3) {
        if let (TokenTree::Ident(i), TokenTree::Punct(p), TokenTree::Group(g)) =
            (&w[0], &w[1], &w[2])
        {
            if i == "compile_error" && p.as_char() == '!' {
                if let Some(s) = g.stream().into_iter().next().and_then(|t| string(&t)) {
                    out.push(s);
                }
            }
        }
    }
    out
}

/// The token after `name :`, anywhere in `tokens` (the first such field).
fn after(tokens: &TokenStream, name: &str) -> Option<TokenTree> {
    let all: Vec<TokenTree> = tokens.clone().into_iter().collect();
    for (k, t) in all.iter().enumerate() {
        if let (TokenTree::Ident(i), Some(TokenTree::Punct(p))) = (t, all.get(k + 1)) {
            if i == name && p.as_char() == ':' {
                // `name: value` or `name: &[...]`.
                let value = match all.get(k + 2) {
                    Some(TokenTree::Punct(amp)) if amp.as_char() == '&' => all.get(k + 3),
                    Some(TokenTree::Punct(_)) => None,
                    other => other,
                };
                if let Some(v) = value {
                    return Some(v.clone());
                }
            }
        }
        if let TokenTree::Group(g) = t {
            if let Some(found) = after(&g.stream(), name) {
                return Some(found);
            }
        }
    }
    None
}

fn string(t: &TokenTree) -> Option<String> {
    syn::parse2::<syn::LitStr>(t.clone().into())
        .ok()
        .map(|l| l.value())
}

/// Runs `expand_one` in a child process, stopped after `timeout`.
fn survey_one(path: &Path, base: &str, extra: &str, timeout: Duration) -> Result<Outcome, String> {
    let mut child = Command::new(std::env::current_exe().expect("this program"))
        .arg("--one")
        .arg(path)
        .arg(base)
        .arg(extra)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| e.to_string())?;
    let t = Instant::now();
    loop {
        if child.try_wait().map_err(|e| e.to_string())?.is_some() {
            break;
        }
        if t.elapsed() > timeout {
            let _ = child.kill();
            let _ = child.wait();
            return Err(format!("stopped after {} s", timeout.as_secs()));
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    let out = child.wait_with_output().map_err(|e| e.to_string())?;
    let stdout = String::from_utf8_lossy(&out.stdout);
    let Some(line) = stdout.lines().find(|l| l.starts_with("OUTCOME\t")) else {
        let stderr = String::from_utf8_lossy(&out.stderr);
        let last = stderr.lines().rev().take(3).collect::<Vec<_>>().join(" | ");
        return Err(format!("crashed ({}): {last}", out.status));
    };
    let f: Vec<&str> = line.split('\t').collect();
    let unesc = |s: &str| s.replace("\\n", "\n").replace("\\\\", "\\");
    let opt = |s: &str| (!s.is_empty()).then(|| s.to_string());
    Ok(Outcome {
        seconds: f[1].parse().unwrap_or(f64::NAN),
        code_kb: f[2].parse::<f64>().map(|b| b / 1000.0).ok(),
        form: opt(f[3]).map(|s| unesc(&s)),
        ops: f[4].parse().ok(),
        coordinates: f[5].parse().ok(),
        peak_mb: f[6].parse().ok(),
        errors: f[7..]
            .iter()
            .filter(|s| !s.is_empty())
            .map(|s| unesc(s))
            .collect(),
    })
}

/// The URDFs to survey and the bases to try for each.
fn robots(args: &[String], bases: Option<&str>) -> Vec<(PathBuf, Vec<String>)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("workspace")
        .join("tests/robots");
    let dirs: Vec<PathBuf> = if args.is_empty() {
        vec![root]
    } else {
        args.iter().map(PathBuf::from).collect()
    };
    let mut out = Vec::new();
    for d in dirs {
        let d = d.canonicalize().unwrap_or(d);
        if d.is_file() {
            out.push((d.clone(), free_bases(d.parent().unwrap(), &d)));
            continue;
        }
        let mut files = Vec::new();
        walk(&d, &mut files);
        files.sort();
        for f in files {
            let b = free_bases(&d, &f);
            out.push((f, b));
        }
    }
    if let Some(only) = bases {
        for (_, b) in &mut out {
            b.retain(|x| x == only);
            if b.is_empty() && only == "fixed" {
                b.push("fixed".into());
            }
        }
        out.retain(|(_, b)| !b.is_empty());
    }
    out
}

fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let p = e.path();
        if p.is_dir() {
            walk(&p, out);
        } else if p.extension().is_some_and(|x| x == "urdf") {
            out.push(p);
        }
    }
}

/// `fixed`, and `free` too when a `MANIFEST.json` above the file says the
/// robot's usual base is free.
fn free_bases(dir: &Path, file: &Path) -> Vec<String> {
    let mut bases = vec!["fixed".to_string()];
    let mut at = Some(dir);
    while let Some(d) = at {
        if let Ok(text) = std::fs::read_to_string(d.join("MANIFEST.json")) {
            let rel = file.strip_prefix(d).unwrap_or(file).display().to_string();
            // A light reading of the manifest: the entry's `"urdf": "rel"`
            // line followed, within the entry, by `"base": "free"`.
            if let Some(k) = text.find(&format!("\"urdf\": {rel:?}")) {
                let entry = &text[k..];
                let end = entry.find('}').unwrap_or(entry.len());
                if entry[..end].contains("\"base\": \"free\"") {
                    bases.push("free".into());
                }
            }
            break;
        }
        at = d.parent();
    }
    bases
}

fn main() {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    if args.first().map(String::as_str) == Some("--one") {
        expand_one(Path::new(&args[1]), &args[2], &args[3]);
        return;
    }
    let mut timeout = Duration::from_secs(600);
    let mut base = None;
    let mut only = Vec::new();
    let mut k = 0;
    while k < args.len() {
        match args[k].as_str() {
            "--timeout" => {
                timeout = Duration::from_secs(args[k + 1].parse().expect("seconds"));
                args.drain(k..k + 2);
            }
            "--base" => {
                base = Some(args[k + 1].clone());
                args.drain(k..k + 2);
            }
            "--jacobian" => {
                if args[k + 1] == "off" {
                    std::env::set_var(JACOBIAN_OFF, "1");
                }
                args.drain(k..k + 2);
            }
            "--only" => {
                only.push(args[k + 1].clone());
                args.drain(k..k + 2);
            }
            _ => k += 1,
        }
    }
    let mut list = robots(&args, base.as_deref());
    if !only.is_empty() {
        list.retain(|(p, _)| only.iter().any(|o| p.display().to_string().contains(o)));
    }
    println!("| robot | base | coordinates | derives | expansion (s) | code (kB) | peak memory (MB) | rhs ops | form, or the errors |");
    println!("| --- | --- | --- | --- | --- | --- | --- | --- | --- |");
    for (path, bases) in list {
        let name = path
            .parent()
            .and_then(|p| p.file_name())
            .map(|p| format!("{}/", p.to_string_lossy()))
            .unwrap_or_default()
            + &path.file_name().unwrap().to_string_lossy();
        for base in bases {
            let cell = |s: &str| s.replace('|', "\\|").replace('\n', " ");
            // A robot refused only for what an option fixes (unphysical
            // inertias, joints that move no mass): again with the options
            // the errors name, until it derives or an error names none.
            let mut outcome = survey_one(&path, &base, "", timeout);
            let (mut unchecked, mut welds) = (Vec::<String>::new(), Vec::<String>::new());
            let mut no_mimic = false;
            let mut extra = String::new();
            for _ in 0..3 {
                let Ok(o) = &outcome else { break };
                if o.errors.is_empty() {
                    break;
                }
                let named = |e: &str, option: &str| -> Option<String> {
                    Some(
                        e.split(&format!("`{option}("))
                            .nth(1)?
                            .split(')')
                            .next()?
                            .to_string(),
                    )
                };
                let mut all_named = true;
                for e in &o.errors {
                    match (named(e, "unchecked_inertia"), named(e, "weld")) {
                        (Some(n), _) => unchecked.push(n),
                        (None, Some(n)) => welds.push(n),
                        _ if e.contains("`mimic = false`") => no_mimic = true,
                        _ => all_named = false,
                    }
                }
                if !all_named {
                    break;
                }
                extra.clear();
                if !unchecked.is_empty() {
                    extra += &format!(", unchecked_inertia({})", unchecked.join(", "));
                }
                if !welds.is_empty() {
                    extra += &format!(", weld({})", welds.join(", "));
                }
                if no_mimic {
                    extra += ", mimic = false";
                }
                outcome = survey_one(&path, &base, &extra, timeout);
            }
            match outcome {
                Ok(o) => {
                    let derives = match (o.errors.is_empty(), extra.is_empty()) {
                        (false, _) => "no".to_string(),
                        (true, true) => "yes".to_string(),
                        (true, false) => format!("with `{}`", &extra[2..]),
                    };
                    let what = if o.errors.is_empty() {
                        o.form.clone().unwrap_or_default()
                    } else {
                        o.errors.join("; ")
                    };
                    let short: String = what.chars().take(400).collect();
                    println!(
                        "| {name} | {base} | {} | {derives} | {:.2} | {} | {} | {} | {} |",
                        o.coordinates.map(|c| c.to_string()).unwrap_or_default(),
                        o.seconds,
                        o.code_kb.map(|c| format!("{c:.0}")).unwrap_or_default(),
                        o.peak_mb.map(|p| format!("{p:.0}")).unwrap_or_default(),
                        o.ops.map(|c| c.to_string()).unwrap_or_default(),
                        cell(&short)
                    );
                }
                Err(e) => println!("| {name} | {base} | | no | | | | | {} |", cell(&e)),
            }
        }
    }
}
