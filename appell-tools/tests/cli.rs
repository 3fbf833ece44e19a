//! The model command line, driven through its testable core.

use appell_core::Model;
use appell_test_models::*;
use appell_tools::cli::{bench, info_json, run_with, CliError, Evaluator, BENCH_STATES};
use serde_json::{json, Value};

const PENDULUM: Pendulum = Pendulum {
    m: 1.7,
    l: 0.8,
    g: 9.81,
};

const KNIFE: KnifeEdge = KnifeEdge {
    m: 2.5,
    i: 0.35,
    gx: 1.2,
    c: 0.4,
};

fn args(list: &[&str]) -> Vec<String> {
    list.iter().map(|s| s.to_string()).collect()
}

/// Runs `program <command>` on `input`; returns the result and stdout.
fn run<M: Model>(model: M, command: &[&str], input: &[u8]) -> (Result<(), CliError>, String) {
    let mut full = vec!["model"];
    full.extend_from_slice(command);
    let mut stdin = input;
    let mut stdout = Vec::new();
    let r = run_with(model, &args(&full), &mut stdin, &mut stdout, |_| {
        Err("the default action should not run".into())
    });
    (r, String::from_utf8(stdout).expect("stdout is UTF-8"))
}

fn eval_lines<M: Model>(model: M, input: &str) -> Vec<Value> {
    let (r, out) = run(model, &["eval"], input.as_bytes());
    r.unwrap();
    out.lines()
        .map(|l| serde_json::from_str(l).expect("every output line is JSON"))
        .collect()
}

/// Asserts that a JSON number is `expected` to within 2 ulp: serde_json's
/// default float parsing (used here to read the output back) is not always
/// correctly rounded for 17-digit numbers.
fn assert_num(v: &Value, expected: f64) {
    let x = v
        .as_f64()
        .unwrap_or_else(|| panic!("expected a number, got {v}"));
    let tol = 2.0 * f64::EPSILON * expected.abs().max(f64::MIN_POSITIVE);
    assert!((x - expected).abs() <= tol, "{x} vs {expected}");
}

fn error_of(v: &Value) -> &str {
    v["error"]
        .as_str()
        .unwrap_or_else(|| panic!("expected an error, got {v}"))
}

#[test]
fn eval_pendulum_good_line() {
    let out = eval_lines(
        PENDULUM,
        r#"{"t": 0.5, "q": {"theta": 0.3}, "u": {"theta": -1.25}}"#,
    );
    assert_eq!(out.len(), 1);
    let mut d = [0.0; 2];
    PENDULUM
        .rhs(&PENDULUM.prepare::<f64>(), 0.5, &[0.3, -1.25], &[], &mut d)
        .unwrap();
    assert_num(&out[0]["qdot"]["theta"], -1.25);
    assert_num(&out[0]["udot"]["theta"], d[1]);
    // The printed text is the exact value (shortest round-trip form).
    let (_, text) = run(
        PENDULUM,
        &["eval"],
        br#"{"t": 0.5, "q": {"theta": 0.3}, "u": {"theta": -1.25}}"#,
    );
    let printed = text
        .split(r#""udot":{"theta":"#)
        .nth(1)
        .and_then(|rest| rest.split('}').next())
        .expect("udot in the output");
    assert_eq!(printed.parse::<f64>(), Ok(d[1]));
    assert_eq!(out[0].as_object().map(|o| o.len()), Some(2));
}

#[test]
fn eval_knife_edge_defaults_ignorable_coordinates_and_inputs() {
    let input = concat!(
        r#"{"q": {"phi": 0.4}, "u": {"x": 1.5, "phi": -0.5}, "inputs": {"tau": 0.7}}"#,
        "\n",
        r#"{"q": {"phi": 0.4, "x": 10.0, "y": -3.0}, "u": {"x": 1.5, "phi": -0.5}}"#,
        "\n",
    );
    let out = eval_lines(KNIFE, input);
    assert_eq!(out.len(), 2);
    let (xdd, phidd) = KNIFE.accelerations(0.4, 1.5, -0.5, 0.7);
    assert_num(&out[0]["udot"]["x"], xdd);
    assert_num(&out[0]["udot"]["phi"], phidd);
    assert_num(&out[0]["qdot"]["x"], 1.5);
    assert_num(&out[0]["qdot"]["y"], 1.5 * 0.4_f64.tan());
    assert_num(&out[0]["qdot"]["phi"], -0.5);
    // The input defaults to 0; the ignorable coordinates change nothing.
    assert_num(&out[1]["udot"]["phi"], 0.0);
    assert_eq!(out[1]["udot"]["x"], out[0]["udot"]["x"]);
}

#[test]
fn eval_params_apply_to_their_line_only() {
    let input = concat!(
        r#"{"params": {"g": 1.0, "l": 2.0}, "q": {"theta": 0.5}, "u": {"theta": 0.0}}"#,
        "\n",
        r#"{"q": {"theta": 0.5}, "u": {"theta": 0.0}}"#,
        "\n",
    );
    let out = eval_lines(PENDULUM, input);
    assert_num(&out[0]["udot"]["theta"], -(1.0 / 2.0) * 0.5_f64.sin());
    assert_num(
        &out[1]["udot"]["theta"],
        -(PENDULUM.g / PENDULUM.l) * 0.5_f64.sin(),
    );
}

#[test]
fn eval_bad_lines_answer_with_errors_and_go_on() {
    let good = r#"{"q": {"phi": 0.1}, "u": {"x": 1.0, "phi": 0.0}}"#;
    let cases: &[(&str, &str)] = &[
        (
            r#"{"q": {"phi": 0.1, "z": 1.0}, "u": {"x": 1.0, "phi": 0.0}}"#,
            "`z`",
        ),
        (
            r#"{"q": {}, "u": {"x": 1.0, "phi": 0.0}}"#,
            "missing coordinate `phi`",
        ),
        (
            r#"{"q": {"phi": 0.1}, "u": {"x": 1.0}}"#,
            "missing privileged speed `phi`",
        ),
        (
            r#"{"q": {"phi": 0.1}, "u": {"x": 1.0, "phi": 0.0, "y": 2.0}}"#,
            "`y`",
        ),
        (
            r#"{"q": {"phi": "NaN"}, "u": {"x": 1.0, "phi": 0.0}}"#,
            "`q.phi`",
        ),
        (
            r#"{"q": {"phi": 0.1}, "u": {"x": 1e400, "phi": 0.0}}"#,
            "out of range",
        ),
        (
            r#"{"q": {"phi": 0.1}, "u": {"x": 1.0, "phi": 0.0}"#,
            "malformed JSON",
        ),
        (
            r#"{"q": {"phi": 0.1}, "u": {"x": 1.0, "phi": 0.0}, "v": 1}"#,
            "unknown field `v`",
        ),
        (
            r#"{"params": {"mass": 1.0}, "q": {"phi": 0.1}, "u": {"x": 1.0, "phi": 0.0}}"#,
            "`mass`",
        ),
        (
            r#"{"inputs": {"force": 1.0}, "q": {"phi": 0.1}, "u": {"x": 1.0, "phi": 0.0}}"#,
            "`force`",
        ),
        (
            r#"{"t": "now", "q": {"phi": 0.1}, "u": {"x": 1.0, "phi": 0.0}}"#,
            "`t`",
        ),
        (
            r#"{"q": [0.1], "u": {"x": 1.0, "phi": 0.0}}"#,
            "`q` must be an object",
        ),
        ("[1, 2, 3]", "expected a JSON object"),
        ("nonsense", "malformed JSON"),
        // A singular configuration of the model itself (cos φ = 0).
        (
            r#"{"q": {"phi": 1.5707963267948966}, "u": {"x": 1.0, "phi": 0.0}}"#,
            "singular",
        ),
        // A parameter the model rejects.
        (
            r#"{"params": {"m": -1.0}, "q": {"phi": 0.1}, "u": {"x": 1.0, "phi": 0.0}}"#,
            "`m`",
        ),
    ];
    let mut input = String::new();
    for (line, _) in cases {
        input.push_str(line);
        input.push('\n');
        input.push_str(good);
        input.push_str("\n\n   \n");
    }
    let out = eval_lines(KNIFE, &input);
    assert_eq!(out.len(), 2 * cases.len(), "one answer per non-empty line");
    for (k, (line, expected)) in cases.iter().enumerate() {
        let message = error_of(&out[2 * k]);
        assert!(
            message.contains(expected),
            "line {line}: message {message:?} lacks {expected:?}"
        );
        assert!(
            out[2 * k + 1]["udot"]["x"].is_number(),
            "good line after {line}"
        );
    }
}

#[test]
fn eval_rejects_invalid_utf8_and_survives_crlf() {
    let mut input = b"\xff\xfe{}\n".to_vec();
    input.extend_from_slice(b"{\"q\": {\"theta\": 0.2}, \"u\": {\"theta\": 0.1}}\r\n");
    let (r, out) = run(PENDULUM, &["eval"], &input);
    r.unwrap();
    let lines: Vec<Value> = out
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert!(error_of(&lines[0]).contains("UTF-8"));
    assert_eq!(lines[1]["qdot"]["theta"].as_f64(), Some(0.1));
}

#[test]
fn evaluator_can_be_used_directly() {
    let mut ev = Evaluator::new(PENDULUM).unwrap();
    let v = ev.eval_line(r#"{"params": {"m": 3.0}, "q": {"theta": 0.0}, "u": {"theta": 2.0}}"#);
    assert_eq!(v, json!({"qdot": {"theta": 2.0}, "udot": {"theta": -0.0}}));
    assert_eq!(ev.model().m, 3.0);
}

#[test]
fn info_lists_the_metadata() {
    let (r, out) = run(KNIFE, &["info"], b"");
    r.unwrap();
    let info: Value = serde_json::from_str(out.trim()).unwrap();
    assert_eq!(info, info_json(&KNIFE).unwrap());
    assert_eq!(info["name"], "KnifeEdge");
    assert_eq!(
        info["parameters"],
        json!([
            {"name": "m", "value": 2.5},
            {"name": "i", "value": 0.35},
            {"name": "gx", "value": 1.2},
            {"name": "c", "value": 0.4}
        ])
    );
    assert_eq!(info["coordinates"], json!(["x", "y", "phi"]));
    assert_eq!(info["speeds"], json!(["x", "phi"]));
    assert_eq!(info["dependent"], json!(["y"]));
    assert_eq!(info["cyclic"], json!(["y"]));
    assert_eq!(info["ignorable"], json!(["x", "y"]));
    assert_eq!(info["retained"], json!(["phi"]));
    assert_eq!(info["state"], json!(["phi", "x_dot", "phi_dot"]));
    assert_eq!(info["inputs"], json!(["tau"]));
    assert_eq!(info["effects"], json!(["field", "drag", "motor"]));
    assert_eq!(info["bodies"], json!([{"name": "B", "rigid": true}]));
    assert_eq!(info["holonomic"], 0);
    assert_eq!(info["constraints"], 1);
    assert_eq!(info["force_points"], 1);
    assert_eq!(info["torques"], 1);
    assert_eq!(info["symbolic_elimination"], true);
    assert_eq!(
        info["rhs_ops"],
        json!({"add": 2, "mul": 7, "div": 2, "calls": 3, "other": 0, "total": 14})
    );
}

#[test]
fn equations_prints_the_text() {
    let (r, out) = run(KNIFE, &["equations"], b"");
    r.unwrap();
    assert_eq!(out, format!("{}\n", KNIFE_INFO.equations));
}

#[test]
fn help_default_action_and_usage_errors() {
    for flag in ["help", "--help", "-h"] {
        let (r, out) = run(PENDULUM, &[flag], b"");
        r.unwrap();
        assert!(out.starts_with("usage: model "), "{out}");
        for command in ["eval", "info", "equations", "bench"] {
            assert!(out.contains(command));
        }
    }
    let (r, out) = run(PENDULUM, &["simulate"], b"");
    match r {
        Err(CliError::Usage(text)) => assert!(text.contains("unknown command `simulate`")),
        other => panic!("expected a usage error, got {other:?}"),
    }
    assert!(out.is_empty());
    let (r, _) = run(PENDULUM, &["info", "extra"], b"");
    assert!(matches!(r, Err(CliError::Usage(t)) if t.contains("`extra`")));

    // No subcommand: the default action runs, with the model.
    let mut ran = None;
    let r = run_with(
        PENDULUM,
        &args(&["model"]),
        &mut &b""[..],
        &mut Vec::new(),
        |m| {
            ran = Some(m.l);
            Ok(())
        },
    );
    r.unwrap();
    assert_eq!(ran, Some(PENDULUM.l));
    // Also with an empty argument list.
    let r = run_with(PENDULUM, &[], &mut &b""[..], &mut Vec::new(), |_| {
        Err("failed on purpose".into())
    });
    match r {
        Err(e @ CliError::Action(_)) => assert_eq!(e.to_string(), "failed on purpose"),
        other => panic!("expected the action's error, got {other:?}"),
    }
}

#[test]
fn bench_reports_times_and_ops() {
    let (r, out) = run(KNIFE, &["bench"], b"");
    r.unwrap();
    let v: Value = serde_json::from_str(out.trim()).unwrap();
    assert!(v["rhs_ns"].as_f64().is_some_and(|x| x > 0.0), "{v}");
    assert!(v["oracle_ns"].as_f64().is_some_and(|x| x > 0.0), "{v}");
    assert_eq!(v["ops"], 14);
    // Every random state has |φ| ≤ 1 < π/2, so none is skipped.
    assert_eq!(v["states"].as_u64(), Some(BENCH_STATES as u64));
}

#[test]
fn bench_with_no_valid_state_fails() {
    let broken = Pendulum {
        m: -1.0,
        ..PENDULUM
    };
    let (r, out) = run(broken, &["bench"], b"");
    assert!(matches!(r, Err(CliError::Bench(_))), "{r:?}");
    let v: Value = serde_json::from_str(out.trim()).unwrap();
    assert!(error_of(&v).contains("`m`"), "{v}");
    assert!(bench(&broken).is_err());
}

#[test]
fn accuracy_sweeps_every_integrator() {
    let (r, out) = run(
        PENDULUM,
        &["accuracy"],
        br#"{"q": {"theta": 0.3}, "u": {"theta": 0.0}, "t_end": 2, "checkpoints": 4, "levels": 2, "repeats": 1}"#,
    );
    r.unwrap();
    assert_eq!(out.lines().count(), 1);
    let v: Value = serde_json::from_str(out.trim()).unwrap();
    assert!(
        v["reference_error"].as_f64().is_some_and(|e| e < 1e-11),
        "{v}"
    );
    assert_eq!(v["checkpoints"], 4);
    let points = v["points"].as_array().unwrap();
    // levels = 2: RK4, Heun, midpoint at 2 step counts; both Dormand–Prince
    // pairs at 4 tolerances; TR-BDF2 at 2; Radau5 at 4.
    assert_eq!(points.len(), 3 * 2 + 2 * 4 + 2 + 4, "{v}");
    let error = |method: &str, setting: f64| {
        points
            .iter()
            .find(|p| p["method"] == method && p["setting"].as_f64() == Some(setting))
            .and_then(|p| p["error_max"].as_f64())
            .unwrap_or_else(|| panic!("no {method} at {setting} in {v}"))
    };
    // Halving the RK4 step divides the error by about 16.
    let ratio = error("rk4", 100.0) / error("rk4", 200.0);
    assert!((10.0..24.0).contains(&ratio), "RK4 ratio {ratio}");
    assert!(error("dop853", 1e-6) < error("dop853", 1e-3));
    assert!(error("radau5", 1e-6) < error("radau5", 1e-3));
    for p in points {
        assert!(p["seconds"].as_f64().is_some_and(|s| s > 0.0), "{p}");
        assert!(p["rhs_calls"].as_u64().is_some_and(|n| n > 0), "{p}");
        assert!(p["steps"].as_u64().is_some_and(|n| n > 0), "{p}");
    }
}

#[test]
fn accuracy_rejects_bad_problems_with_json_errors() {
    for (input, needle) in [
        (
            &br#"{"q": {"theta": 0.3}, "u": {"theta": 0.0}}"#[..],
            "t_end",
        ),
        (
            br#"{"q": {"theta": 0.3}, "u": {"theta": 0.0}, "t_end": -1}"#,
            "positive",
        ),
        (
            br#"{"q": {"theta": 0.3}, "u": {"theta": 0.0}, "t_end": 1, "t": 2}"#,
            "`t`",
        ),
        (
            br#"{"q": {"theta": 0.3}, "u": {"theta": 0.0}, "t_end": 1, "levels": 0}"#,
            "levels",
        ),
        (br#"{"q": {"theta": 0.3}, "t_end": 1}"#, "theta"),
        (
            br#"{"q": {"theta": 0.3}, "u": {"theta": 0.0}, "t_end": 1, "speed": 3}"#,
            "unknown field",
        ),
        (b"not json", "malformed"),
    ] {
        let (r, out) = run(PENDULUM, &["accuracy"], input);
        assert!(matches!(r, Err(CliError::Accuracy(_))), "{r:?}");
        let v: Value = serde_json::from_str(out.trim()).unwrap();
        assert!(error_of(&v).contains(needle), "{needle}: {v}");
    }
    // A model that fails everywhere: the reference cannot be computed.
    let broken = Pendulum { l: 0.0, ..PENDULUM };
    let (r, out) = run(
        broken,
        &["accuracy"],
        br#"{"q": {"theta": 0.3}, "u": {"theta": 0.0}, "t_end": 1}"#,
    );
    assert!(matches!(r, Err(CliError::Accuracy(_))), "{r:?}");
    assert!(out.contains("error"), "{out}");
}
