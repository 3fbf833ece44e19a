//! The pictures of the motion: the SVG that `appell::animate` writes
//! moves (its frames differ), keeps every body's shape, and plays in a real
//! browser (headless Chromium, `--ignored`: it needs `/usr/bin/chromium`).

use std::path::{Path, PathBuf};
use std::process::Command;

use appell::animate::{simulate, svg, SvgOptions, View};
use appell::Appell;

/// A double pendulum: a rod from O and a disc at its end.
#[derive(Appell)]
#[appell(coordinates(a, b), speeds(a, b), positive(l))]
#[appell(frame(A = N.rotate_z(a)), frame(B = N.rotate_z(b)))]
#[appell(point(R = O + l / 2 * A.x), point(D = O + l * A.x))]
#[appell(body(rod, center = R, frame = A, mass = 1, inertia = principal(0, l * l / 12, l * l / 12)))]
#[appell(body(disc, center = D, frame = B, mass = 2, inertia = principal(0.01, 0.01, 0.02)))]
#[appell(gravity(-9.81 * N.y))]
struct Swing {
    l: f64,
}

/// The numbers of the `values` lists of the SVG's `animateTransform`
/// translations, one list per body.
fn translations(svg: &str) -> Vec<Vec<String>> {
    svg.split("type=\"translate\"")
        .skip(1)
        .map(|rest| {
            let start = rest.find("values=\"").expect("values") + 8;
            let end = start + rest[start..].find('"').expect("closing quote");
            rest[start..end].split(';').map(str::to_string).collect()
        })
        .collect()
}

#[test]
fn the_picture_moves_with_the_simulation() {
    let model = Swing { l: 1.0 };
    let frames = simulate(&model, 0.0, &[-1.0, -0.5], &[0.0, 0.0], &[], 2.0, 50).unwrap();
    assert_eq!(frames.len(), 51);
    // Released from rest, the pendulum swings.
    let swing = frames
        .iter()
        .map(|f| (f.q[0] - frames[0].q[0]).abs())
        .fold(0.0, f64::max);
    assert!(swing > 0.1, "{swing}");
    let options = SvgOptions {
        connectors: vec![(None, Some(0)), (Some(0), Some(1))],
        traces: vec![1],
        ..SvgOptions::default()
    };
    let picture = svg(&model, &frames, &options).unwrap();
    assert!(picture.starts_with("<svg") && picture.trim_end().ends_with("</svg>"));
    // A planar motion is seen along z.
    let moves = translations(&picture);
    assert_eq!(moves.len(), 2, "one moving group per body");
    for m in &moves {
        assert_eq!(m.len(), 51);
        assert_ne!(m[0], m[25], "the body moves");
    }
    assert_eq!(picture.matches("<ellipse").count(), 2);
    assert_eq!(
        picture.matches("t = ").count(),
        51,
        "a time readout per frame"
    );
    // Well formed: every element opened is closed.
    for tag in ["g", "ellipse", "line", "text"] {
        let opened = picture.matches(&format!("<{tag}")).count();
        let self_closed = picture
            .split(&format!("<{tag}"))
            .skip(1)
            .filter(|rest| {
                let end = rest.find('>').unwrap();
                rest[..end].ends_with('/')
            })
            .count();
        let closed = picture.matches(&format!("</{tag}>")).count();
        assert_eq!(opened, self_closed + closed, "<{tag}>");
    }
}

#[test]
fn bad_arguments_are_typed_errors() {
    let model = Swing { l: 1.0 };
    assert!(simulate(&model, 0.0, &[0.0], &[0.0, 0.0], &[], 1.0, 10).is_err());
    assert!(simulate(&model, 0.0, &[0.0, 0.0], &[0.0, 0.0], &[], -1.0, 10).is_err());
    assert!(simulate(&model, 0.0, &[f64::NAN, 0.0], &[0.0, 0.0], &[], 1.0, 10).is_err());
    let frames = simulate(&model, 0.0, &[0.5, 0.0], &[0.0, 0.0], &[], 1.0, 4).unwrap();
    assert!(svg(&model, &frames[..1], &SvgOptions::default()).is_err());
    let options = SvgOptions {
        connectors: vec![(Some(0), Some(5))],
        ..SvgOptions::default()
    };
    assert!(svg(&model, &frames, &options).is_err());
    let oblique = SvgOptions {
        view: View::Oblique,
        ..SvgOptions::default()
    };
    assert!(svg(&model, &frames, &oblique).is_ok());
}

/// `animate` on the command line, with `problem` on stdin.
fn animate(problem: &str) -> Result<String, appell::cli::CliError> {
    let args = ["swing".to_string(), "animate".to_string()];
    let mut out = Vec::new();
    appell::cli::run_with(
        Swing { l: 1.0 },
        &args,
        &mut problem.as_bytes(),
        &mut out,
        |_| Ok(()),
    )?;
    Ok(String::from_utf8(out).unwrap())
}

#[test]
fn the_command_line_animates_a_state() {
    let picture = animate(
        r#"{"q": {"a": -1.0, "b": -0.5}, "u": {"a": 0, "b": 0}, "t_end": 2, "frames": 20,
            "title": "swing", "view": "z", "connectors": [["O", "rod"], ["rod", "disc"]],
            "traces": ["disc"]}"#,
    )
    .unwrap();
    assert!(picture.starts_with("<svg") && picture.trim_end().ends_with("</svg>"));
    assert!(picture.contains(">swing<"), "the title");
    let moves = translations(&picture);
    assert_eq!(moves.len(), 2);
    assert_eq!(moves[1].len(), 21, "21 frames");
    assert_ne!(moves[1][0], moves[1][10], "the disc moves");
    // The same motion as the library draws.
    let frames = simulate(
        &Swing { l: 1.0 },
        0.0,
        &[-1.0, -0.5],
        &[0.0, 0.0],
        &[],
        2.0,
        20,
    )
    .unwrap();
    let options = SvgOptions {
        title: "swing".into(),
        view: View::Along(2),
        connectors: vec![(None, Some(0)), (Some(0), Some(1))],
        traces: vec![1],
        ..SvgOptions::default()
    };
    assert_eq!(picture, svg(&Swing { l: 1.0 }, &frames, &options).unwrap());
}

#[test]
fn the_command_line_names_what_is_wrong_with_a_problem() {
    let cases = [
        (
            r#"{"q": {"a": 0}, "u": {"a": 0, "b": 0}}"#,
            "missing field `t_end`",
        ),
        (
            r#"{"q": {"a": 0, "b": 0}, "u": {"a": 0, "b": 0}, "t_end": 0}"#,
            "must be after `t`",
        ),
        (
            r#"{"q": {"a": 0, "b": 0}, "u": {"a": 0, "b": 0}, "t_end": 1, "traces": ["wheel"]}"#,
            "unknown body `wheel` in `traces` (bodies: rod, disc",
        ),
        (
            r#"{"q": {"a": 0, "b": 0}, "u": {"a": 0, "b": 0}, "t_end": 1, "view": "top"}"#,
            "`view` must be",
        ),
        (
            r#"{"q": {"a": 0, "b": 0}, "u": {"a": 0, "b": 0}, "t_end": 1, "frames": 0}"#,
            "`frames` must be an integer from 1",
        ),
        (
            r#"{"q": {"a": 0, "b": 0}, "u": {"a": 0, "b": 0}, "t_end": 1, "colour": "red"}"#,
            "unknown field `colour`",
        ),
        (
            r#"{"q": {"a": 0, "b": 0}, "u": {"a": 0}, "t_end": 1}"#,
            "missing privileged speed `b`",
        ),
    ];
    for (problem, expected) in cases {
        match animate(problem) {
            Err(appell::cli::CliError::Animate(why)) => {
                assert!(why.contains(expected), "{problem}: {why}")
            }
            other => panic!("{problem}: {other:?}"),
        }
    }
}

/// A screenshot of `file` after `millis` of virtual time.
fn screenshot(file: &Path, millis: u32, out: &Path) -> Vec<u8> {
    let profile =
        std::env::temp_dir().join(format!("appell-chromium-{}-{millis}", std::process::id()));
    let status = Command::new("/usr/bin/chromium")
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--hide-scrollbars",
            "--window-size=640,480",
        ])
        .arg(format!("--user-data-dir={}", profile.display()))
        .arg(format!("--virtual-time-budget={millis}"))
        .arg(format!("--screenshot={}", out.display()))
        .arg(format!("file://{}", file.display()))
        .output()
        .expect("chromium runs");
    assert!(
        status.status.success(),
        "{}",
        String::from_utf8_lossy(&status.stderr)
    );
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(out).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut pixels = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut pixels).unwrap();
    pixels.truncate(info.buffer_size());
    pixels
}

#[test]
#[ignore = "needs /usr/bin/chromium (Debian's chromium package) and the pictures of `cargo run --release --example animations`"]
fn every_animation_plays_in_chromium() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("docs/animations");
    let shots = std::env::temp_dir().join("appell-screenshots");
    std::fs::create_dir_all(&shots).unwrap();
    let mut checked = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_stem().unwrap().to_string_lossy().to_string();
        if path.extension().is_none_or(|e| e != "svg") || name.contains("eigenvalues") {
            continue;
        }
        let early = screenshot(&path, 1500, &shots.join(format!("{name}_early.png")));
        let late = screenshot(&path, 3000, &shots.join(format!("{name}_late.png")));
        let inked = |p: &[u8]| {
            p.chunks(4)
                .filter(|px| px[..3].iter().any(|&c| c < 200))
                .count()
        };
        let total = early.len() / 4;
        assert!(inked(&early) * 200 > total, "{name}: blank");
        let changed = early
            .chunks(4)
            .zip(late.chunks(4))
            .filter(|(a, b)| a != b)
            .count();
        assert!(
            changed * 1000 > total,
            "{name}: the two instants look the same"
        );
        println!(
            "{name}: {} of {total} pixels inked, {changed} changed",
            inked(&early)
        );
        checked += 1;
    }
    assert!(
        checked >= 8,
        "only {checked} animations in {}",
        dir.display()
    );
}

#[test]
fn a_long_animation_is_refused_before_it_starts_unless_its_budget_is_raised() {
    // A billion seconds would be 10¹² steps: refused at once, saying how
    // many steps it needs and what to change.
    let huge = r#"{"q": {"a": 0, "b": 0}, "u": {"a": 0, "b": 0}, "t_end": 1e9}"#;
    match animate(huge) {
        Err(appell::cli::CliError::Animate(why)) => {
            assert!(
                why.contains("needs 1000000000000 RK4 steps")
                    && why.contains("the budget of 2000000 (the default)")
                    && why.contains("shorten `t_end`")
                    && why.contains("raise `max_steps`"),
                "{why}"
            );
        }
        other => panic!("{other:?}"),
    }
    // 2 s in 20 frames is 2000 steps: over a budget of 1999, within 2000.
    let problem = |max_steps: &str| {
        format!(
            r#"{{"q": {{"a": -1, "b": 0}}, "u": {{"a": 0, "b": 0}}, "t_end": 2, "frames": 20, "max_steps": {max_steps}}}"#
        )
    };
    match animate(&problem("1999")) {
        Err(appell::cli::CliError::Animate(why)) => {
            assert!(
                why.contains("needs 2000 RK4 steps") && why.contains("(`max_steps`)"),
                "{why}"
            )
        }
        other => panic!("{other:?}"),
    }
    assert!(animate(&problem("2000")).unwrap().starts_with("<svg"));
    for bad in ["0", "-3", "1.5", "\"many\""] {
        match animate(&problem(bad)) {
            Err(appell::cli::CliError::Animate(why)) => {
                assert!(
                    why.contains("`max_steps` must be a positive integer"),
                    "{why}"
                )
            }
            other => panic!("{bad}: {other:?}"),
        }
    }
    assert_eq!(appell::animate::steps_needed(0.0, 2.0, 20), 2000.0);
}

#[test]
fn a_repeated_key_in_an_animation_is_an_error() {
    let problem = r#"{"q": {"a": 0, "b": 0}, "u": {"a": 0, "b": 0}, "t_end": 1, "t_end": 2}"#;
    match animate(problem) {
        Err(appell::cli::CliError::Animate(why)) => {
            assert!(why.contains("duplicate key `t_end`"), "{why}")
        }
        other => panic!("{other:?}"),
    }
}
