//! The model command line every example gets: a stable, scriptable interface
//! to a [`Model`].
//!
//! ```text
//! <program>              run the example's own default action
//! <program> eval         JSON states on stdin (one per line) -> rates on stdout
//! <program> eval --scene NAME      the same for a scene, plus its outputs
//! <program> contacts     the same states -> multipliers and contact forces
//! <program> contacts --scene NAME  the same for a scene (its loads only)
//! <program> info         the model's metadata as JSON
//! <program> equations    the derived reduced equations, as text
//! <program> bench        time the generated rhs against the oracle, as JSON
//! <program> accuracy     a work-precision sweep of every integrator, as JSON
//! <program> help         usage (also -h, --help)
//! ```
//!
//! An example's `main` is just
//!
//! ```no_run
//! # use appell_runtime::Model;
//! # fn demo<M: Model>(model: M) -> std::process::ExitCode {
//! appell_runtime::cli::run(model, |model| {
//!     // what the example does without a subcommand
//!     Ok(())
//! })
//! # }
//! ```
//!
//! Exit status: 0 on success (also when `eval` answered some lines with
//! errors), 2 for a usage error (unknown subcommand or extra arguments), 1
//! for any other failure.
//!
//! # `eval`
//!
//! Every non-empty line of stdin is one JSON object
//!
//! ```text
//! {"t": 0.0, "params": {"a": 0.3}, "q": {"phi": 0.2, "x": 1.0}, "u": {"phi": 0.1}, "inputs": {"tau": 0.5}}
//! ```
//!
//! * `q`: coordinates by name. Every [retained](ModelInfo::retained)
//!   coordinate is required; the others default to 0 (their values do not
//!   enter the reduced equations but are passed to
//!   [`Model::coordinate_rates`]).
//! * `u`: the privileged speeds, keyed by their coordinate's name
//!   ([`ModelInfo::speeds`]); all are required.
//! * `params`: parameters by name; omitted ones keep the model's values (the
//!   values it had when the command started, for every line).
//! * `inputs`: inputs by name; omitted ones are 0.
//! * `t`: the time; 0 when omitted.
//!
//! Unknown fields or names, missing values, values that are not finite
//! numbers, malformed JSON and any [`ModelError`] (for example a singular
//! configuration) answer that line with `{"error": "..."}`; evaluation goes on
//! with the next line. A good line is answered with
//!
//! ```text
//! {"qdot": {<every coordinate>: rate}, "udot": {<every speed's coordinate>: acceleration}}
//! ```
//!
//! where `qdot` comes from [`Model::coordinate_rates`] and `udot` from
//! [`Model::rhs`] (after [`Model::prepare`]).
//!
//! With `--scene NAME` the scene's reduced equations answer, and the
//! outputs its `outputs(...)` asked for are added: `"energies"`
//! (`{"kinetic", "potential", "rate", "input_power"}`, see
//! [`crate::energy::energies`]) and `"contact_forces"` (as `contacts`
//! answers). The full model declares no outputs.
//!
//! # `contacts`
//!
//! The same input lines, answered by [`crate::constraint_forces`]:
//!
//! ```text
//! {"multipliers": [λ..], "rows": [{"source": "rolls at P, N.x", "multiplier": λ}, ..],
//!  "contacts": [{"point": "P", "body": "disc", "position": [..], "force": [..],
//!                "normal": {"force": N, "direction": [..], "source": "momentum balance"}
//!                          or {"unavailable": "NoDirection"},
//!                "friction": {"mu": μ} or {"lift_off": N} or {"unavailable": ".."}}]}
//! ```
//!
//! Forces are on the body, from the ground, in N components.
//!
//! # `info`
//!
//! One JSON object: `name`, `parameters` (a list of `{"name", "value"}` in
//! declaration order, with the model's current values), `coordinates`,
//! `speeds`, `dependent`, `cyclic`, `ignorable`, `retained`, `state` (the
//! retained names then the speeds' names suffixed `_dot`), `inputs`,
//! `effects`, `bodies` (a list of `{"name", "rigid"}`), `holonomic`,
//! `constraints`, `contacts` (a list of `{"point", "body", "along"}`),
//! `scenes` (a list of `{"name", "effects", "retained", "state_len",
//! "rhs_ops", "outputs"}`), `force_points`, `torques`, `symbolic_elimination` and
//! `rhs_ops` (`{"add", "mul", "div", "calls", "other", "total"}`, where
//! `other` counts negations, large integer powers and the numeric solves'
//! operations, which `total` includes). See [`info_json`].
//!
//! # `bench`
//!
//! Times [`Model::rhs`] (prepared once) and the oracle's
//! [`reduced_rhs`](crate::oracle::reduced_rhs) over 256 fixed pseudo-random
//! states and prints `{"rhs_ns": .., "oracle_ns": .., "ops": .., "states": ..}`
//! (nanoseconds per call, [`OpCounts::total`](crate::OpCounts::total) of the
//! rhs, number of states used). See [`bench()`].
//!
//! # `accuracy`
//!
//! Reads one JSON object from stdin: an `eval` state (`t` must be 0 or
//! omitted) plus `t_end` (the horizon, required), `checkpoints` (default
//! 10), `levels` (default 4) and `repeats` (default 3), for example
//!
//! ```text
//! {"q": {"phi": 0.3}, "u": {"phi": 0.2, "psi1": 1.0}, "inputs": {"tau": 0.4}, "t_end": 10}
//! ```
//!
//! and prints what accuracy costs on that problem: every integrator of
//! [`crate::accuracy::standard_methods`] against a DOP853 reference, as
//! `{"t_end", "checkpoints", "reference_error", "points": [{"method",
//! "setting", "error_final", "error_max", "seconds", "rhs_calls", "steps"}]}`.
//! A problem it cannot run is answered with `{"error": ".."}` and exit
//! status 1. States up to [`ACCURACY_MAX_STATE`] entries. See [`accuracy()`].

use crate::accuracy::{standard_methods, Problem};
use crate::constraint_forces::{contact_forces, Friction, Normal, NormalSource};
use crate::model::{Model, ModelError, ModelInfo, RowSource, SceneVisitor};
use serde_json::{json, Map, Value};
use std::error::Error;
use std::hint::black_box;
use std::io::{BufRead, Write};
use std::process::ExitCode;
use std::time::{Duration, Instant};

/// Why the command line failed.
#[derive(Debug)]
pub enum CliError {
    /// Unknown subcommand or unexpected arguments; holds the usage text.
    Usage(String),
    /// Reading stdin or writing stdout failed.
    Io(std::io::Error),
    /// The model could not report its parameters.
    Model(ModelError),
    /// `bench` found no state where both the rhs and the oracle succeed.
    Bench(String),
    /// `accuracy` could not read its problem or compute the reference.
    Accuracy(String),
    /// The example's default action failed.
    Action(Box<dyn Error>),
}

impl core::fmt::Display for CliError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            CliError::Usage(usage) => write!(f, "{usage}"),
            CliError::Io(e) => write!(f, "i/o error: {e}"),
            CliError::Model(e) => write!(f, "{e}"),
            CliError::Bench(why) => write!(f, "bench: {why}"),
            CliError::Accuracy(why) => write!(f, "accuracy: {why}"),
            CliError::Action(e) => write!(f, "{e}"),
        }
    }
}

impl Error for CliError {
    fn source(&self) -> Option<&(dyn Error + 'static)> {
        match self {
            CliError::Io(e) => Some(e),
            CliError::Model(e) => Some(e),
            CliError::Action(e) => Some(e.as_ref()),
            CliError::Usage(_) | CliError::Bench(_) | CliError::Accuracy(_) => None,
        }
    }
}

impl From<std::io::Error> for CliError {
    fn from(e: std::io::Error) -> Self {
        CliError::Io(e)
    }
}

impl From<ModelError> for CliError {
    fn from(e: ModelError) -> Self {
        CliError::Model(e)
    }
}

/// The usage text for `program` running model `info`.
///
/// ```
/// # use appell_runtime::{ModelInfo, OpCounts};
/// # let info = ModelInfo {
/// #     name: "Pendulum", parameters: &[], coordinates: &[], speeds: &[], dependent: &[],
/// #     cyclic: &[], ignorable: &[], retained: &[], inputs: &[], effects: &[], outputs: &[], row_sources: &[], contacts: &[],
/// #     holonomic: 0, constraints: 0, bodies: &[], force_points: 0, torques: 0,
/// #     symbolic_elimination: true, rhs_ops: OpCounts::default(), equations: "",
/// # };
/// let text = appell_runtime::cli::usage("pendulum", &info);
/// assert!(text.starts_with("usage: pendulum [eval|contacts|info|equations|bench|accuracy|help]"));
/// assert!(text.contains("Pendulum"));
/// ```
pub fn usage(program: &str, info: &ModelInfo) -> String {
    format!(
        "usage: {program} [eval|contacts|info|equations|bench|accuracy|help]\n\
         \n\
         Model `{name}`.\n\
         \n\
         Commands:\n\
         \x20 (none)      run this program's default action\n\
         \x20 eval        read JSON states from stdin, one per line, and print their rates:\n\
         \x20             {{\"t\": 0, \"params\": {{..}}, \"q\": {{coordinate: value}},\n\
         \x20              \"u\": {{speed coordinate: value}}, \"inputs\": {{..}}}}\n\
         \x20             -> {{\"qdot\": {{..}}, \"udot\": {{..}}}} or {{\"error\": \"..\"}}\n\
         \x20             (`eval --scene NAME`: a scene, plus the outputs it asks for)\n\
         \x20 contacts    the same input -> constraint multipliers, contact forces and\n\
         \x20             the friction rolling needs (`contacts --scene NAME` too)\n\
         \x20 info        print the model's metadata as JSON\n\
         \x20 equations   print the derived equations\n\
         \x20 bench       time the generated rhs against the oracle, print JSON\n\
         \x20 accuracy    read one JSON problem from stdin (an `eval` state plus\n\
         \x20             \"t_end\", optional \"checkpoints\", \"levels\", \"repeats\") and\n\
         \x20             print the work-precision sweep of every integrator as JSON\n\
         \x20 help        print this text (also -h, --help)\n",
        name = info.name
    )
}

/// Runs the command line on the process's arguments, stdin and stdout, and
/// returns the exit status (see the module documentation). Errors are
/// printed to stderr, except a closed stdout (broken pipe), which ends the
/// program quietly with status 1. Never panics on bad arguments or input; arguments that
/// are not valid Unicode are converted lossily.
pub fn run<M: Model>(
    model: M,
    default_action: impl FnOnce(&M) -> Result<(), Box<dyn Error>>,
) -> ExitCode {
    let args: Vec<String> = std::env::args_os()
        .map(|a| a.to_string_lossy().into_owned())
        .collect();
    let stdin = std::io::stdin();
    let mut input = stdin.lock();
    let stdout = std::io::stdout();
    let mut output = stdout.lock();
    match run_with(model, &args, &mut input, &mut output, default_action) {
        Ok(()) => ExitCode::SUCCESS,
        Err(CliError::Usage(text)) => {
            eprint!("{text}");
            ExitCode::from(2)
        }
        // The reader went away (`... | head`): stop quietly, like a tool
        // killed by SIGPIPE would.
        Err(CliError::Io(e)) if e.kind() == std::io::ErrorKind::BrokenPipe => ExitCode::FAILURE,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

/// The testable core of [`run`]: `args` is the whole argument list including
/// the program name (an empty list is allowed), `stdin` and `stdout` are the
/// streams the subcommands use.
///
/// `help` writes the usage to `stdout` and succeeds; an unknown subcommand
/// or an extra argument is [`CliError::Usage`]; without a subcommand
/// `default_action` is called.
///
/// ```
/// # use appell_runtime::{Model, ModelError, ModelInfo, OpCounts, Scalar};
/// # struct Free { m: f64 }
/// # static INFO: ModelInfo = ModelInfo {
/// #     name: "Free", parameters: &["m"], coordinates: &["x"], speeds: &["x"],
/// #     dependent: &[], cyclic: &[], ignorable: &["x"], retained: &[], inputs: &["f"],
/// #     effects: &["push"], outputs: &[], row_sources: &[], contacts: &[], holonomic: 0, constraints: 0, bodies: &[], force_points: 0,
/// #     torques: 0, symbolic_elimination: true,
/// #     rhs_ops: OpCounts { add: 0, mul: 0, div: 1, calls: 0, total: 1 },
/// #     equations: "x'' = f/m",
/// # };
/// # fn unused() -> Result<(), ModelError> { Err(ModelError::NonFinite { what: "unused" }) }
/// # impl Model for Free {
/// #     type Prepared<T: Scalar> = T;
/// #     fn info() -> &'static ModelInfo { &INFO }
/// #     fn parameter_values(&self, out: &mut [f64]) -> Result<(), ModelError> {
/// #         appell_runtime::check_len("out", out, 1)?; out[0] = self.m; Ok(())
/// #     }
/// #     fn set_parameter(&mut self, name: &str, v: f64) -> bool {
/// #         if name == "m" { self.m = v; true } else { false }
/// #     }
/// #     fn prepare<T: Scalar>(&self) -> T { T::one() / T::from_f64(self.m) }
/// #     fn rhs<T: Scalar>(&self, p: &T, _t: T, s: &[T], i: &[T], ds: &mut [T]) -> Result<(), ModelError> {
/// #         appell_runtime::check_len("state", s, 1)?; appell_runtime::check_len("dstate", ds, 1)?;
/// #         appell_runtime::check_len("inputs", i, 1)?;
/// #         ds[0] = i[0] * *p; Ok(())
/// #     }
/// #     fn coordinate_rates<T: Scalar>(&self, _: T, q: &[T], u: &[T], qd: &mut [T]) -> Result<(), ModelError> {
/// #         appell_runtime::check_len("q", q, 1)?; appell_runtime::check_len("u", u, 1)?;
/// #         appell_runtime::check_len("qdot", qd, 1)?; qd[0] = u[0]; Ok(())
/// #     }
/// #     fn mass_matrix_and_forcing<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn speed_transform<T: Scalar>(&self, _: T, _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn constraint_residuals<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn kinetic_energy<T: Scalar>(&self, _: T, _: &[T], _: &[T]) -> Result<T, ModelError> { unused().map(|_| T::zero()) }
/// #     fn mass_properties(&self, _: &mut [f64], _: &mut [[f64; 9]]) -> Result<(), ModelError> { unused() }
/// #     fn body_poses<T: Scalar>(&self, _: T, _: &[T], _: &mut [[T; 3]], _: &mut [[T; 9]]) -> Result<(), ModelError> { unused() }
/// #     fn constraint_rows<T: Scalar>(&self, _: T, _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn load_geometry<T: Scalar>(&self, _: T, _: &[T], _: &mut [[T; 3]], _: &mut [[T; 9]]) -> Result<(), ModelError> { unused() }
/// #     fn load_values<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &[T], _: &mut [[T; 3]], _: &mut [[T; 3]]) -> Result<(), ModelError> { unused() }
/// # }
/// use appell_runtime::cli::{run_with, CliError};
///
/// let args: Vec<String> = ["free", "eval"].iter().map(|s| s.to_string()).collect();
/// let mut stdin = &b"{\"q\": {}, \"u\": {\"x\": 1.5}, \"inputs\": {\"f\": 6.0}, \"params\": {\"m\": 2.0}}\n\
///                    {\"u\": {\"x\": 1.5}, \"inputs\": {\"g\": 1.0}}\n"[..];
/// let mut stdout = Vec::new();
/// run_with(Free { m: 1.0 }, &args, &mut stdin, &mut stdout, |_| Ok(())).unwrap();
/// let text = String::from_utf8(stdout).unwrap();
/// let lines: Vec<&str> = text.lines().collect();
/// assert_eq!(lines[0], r#"{"qdot":{"x":1.5},"udot":{"x":3.0}}"#);
/// assert!(lines[1].starts_with(r#"{"error":"#));
///
/// let bad: Vec<String> = ["free", "frobnicate"].iter().map(|s| s.to_string()).collect();
/// let err = run_with(Free { m: 1.0 }, &bad, &mut &b""[..], &mut Vec::new(), |_| Ok(()));
/// assert!(matches!(err, Err(CliError::Usage(_))));
/// ```
pub fn run_with<M: Model>(
    model: M,
    args: &[String],
    stdin: &mut dyn BufRead,
    stdout: &mut dyn Write,
    default_action: impl FnOnce(&M) -> Result<(), Box<dyn Error>>,
) -> Result<(), CliError> {
    let info = M::info();
    let program = args.first().map(String::as_str).unwrap_or(info.name);
    let rest = args.get(1..).unwrap_or(&[]);
    if let [command, flag, name] = rest {
        if (command == "eval" || command == "contacts") && flag == "--scene" {
            let mut evaluator = Evaluator::with_scene(model, name)?;
            evaluator.contacts = command == "contacts";
            return eval_stream(&mut evaluator, stdin, stdout);
        }
    }
    let command = match rest {
        [] => return default_action(&model).map_err(CliError::Action),
        [command] => command.as_str(),
        [command, extra, ..] => {
            return Err(CliError::Usage(format!(
                "unexpected argument `{extra}` after `{command}`\n{}",
                usage(program, info)
            )))
        }
    };
    match command {
        "eval" => {
            let mut evaluator = Evaluator::new(model)?;
            eval_stream(&mut evaluator, stdin, stdout)
        }
        "contacts" => {
            let mut evaluator = Evaluator::new(model)?;
            evaluator.contacts = true;
            eval_stream(&mut evaluator, stdin, stdout)
        }
        "info" => {
            writeln!(stdout, "{}", info_json(&model)?)?;
            Ok(stdout.flush()?)
        }
        "equations" => {
            let eq = info.equations;
            if eq.ends_with('\n') {
                write!(stdout, "{eq}")?;
            } else {
                writeln!(stdout, "{eq}")?;
            }
            Ok(stdout.flush()?)
        }
        "bench" => match bench(&model) {
            Ok(report) => {
                writeln!(stdout, "{}", report.to_json())?;
                Ok(stdout.flush()?)
            }
            Err(e) => {
                writeln!(stdout, "{}", json!({ "error": e.to_string() }))?;
                stdout.flush()?;
                Err(e)
            }
        },
        "accuracy" => {
            let mut text = String::new();
            stdin.read_to_string(&mut text)?;
            match accuracy(model, &text) {
                Ok(report) => {
                    writeln!(stdout, "{report}")?;
                    Ok(stdout.flush()?)
                }
                Err(why) => {
                    writeln!(stdout, "{}", json!({ "error": why }))?;
                    stdout.flush()?;
                    Err(CliError::Accuracy(why))
                }
            }
        }
        "help" | "-h" | "--help" => {
            write!(stdout, "{}", usage(program, info))?;
            Ok(stdout.flush()?)
        }
        other => Err(CliError::Usage(format!(
            "unknown command `{other}`\n{}",
            usage(program, info)
        ))),
    }
}

/// Answers every non-empty line of `stdin` on `stdout`.
fn eval_stream<M: Model>(
    evaluator: &mut Evaluator<M>,
    stdin: &mut dyn BufRead,
    stdout: &mut dyn Write,
) -> Result<(), CliError> {
    let mut buf = Vec::new();
    loop {
        buf.clear();
        if stdin.read_until(b'\n', &mut buf)? == 0 {
            break;
        }
        let answer = match std::str::from_utf8(&buf) {
            Ok(line) if line.trim().is_empty() => continue,
            Ok(line) => evaluator.eval_line(line),
            Err(_) => json!({ "error": "the line is not valid UTF-8" }),
        };
        writeln!(stdout, "{answer}")?;
        stdout.flush()?;
    }
    Ok(())
}

/// The metadata printed by `info` (layout in the module documentation).
///
/// ```
/// # use appell_runtime::{BodyInfo, Model, ModelError, ModelInfo, OpCounts, Scalar};
/// # struct Spin { i: f64 }
/// # static INFO: ModelInfo = ModelInfo {
/// #     name: "Spin", parameters: &["i"], coordinates: &["phi"], speeds: &["phi"],
/// #     dependent: &[], cyclic: &[], ignorable: &[], retained: &["phi"], inputs: &["tau"],
/// #     effects: &["motor"], outputs: &[], row_sources: &[], contacts: &[], holonomic: 0, constraints: 0,
/// #     bodies: &[BodyInfo { name: "B", rigid: true }], force_points: 0, torques: 1,
/// #     symbolic_elimination: true,
/// #     rhs_ops: OpCounts { add: 0, mul: 0, div: 1, calls: 0, total: 1 },
/// #     equations: "phi'' = tau/i",
/// # };
/// # fn unused() -> Result<(), ModelError> { Err(ModelError::NonFinite { what: "unused" }) }
/// # impl Model for Spin {
/// #     type Prepared<T: Scalar> = ();
/// #     fn info() -> &'static ModelInfo { &INFO }
/// #     fn parameter_values(&self, out: &mut [f64]) -> Result<(), ModelError> {
/// #         appell_runtime::check_len("out", out, 1)?; out[0] = self.i; Ok(())
/// #     }
/// #     fn set_parameter(&mut self, _: &str, _: f64) -> bool { false }
/// #     fn prepare<T: Scalar>(&self) {}
/// #     fn rhs<T: Scalar>(&self, _: &(), _: T, _: &[T], _: &[T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn coordinate_rates<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn mass_matrix_and_forcing<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn speed_transform<T: Scalar>(&self, _: T, _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn constraint_residuals<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn kinetic_energy<T: Scalar>(&self, _: T, _: &[T], _: &[T]) -> Result<T, ModelError> { unused().map(|_| T::zero()) }
/// #     fn mass_properties(&self, _: &mut [f64], _: &mut [[f64; 9]]) -> Result<(), ModelError> { unused() }
/// #     fn body_poses<T: Scalar>(&self, _: T, _: &[T], _: &mut [[T; 3]], _: &mut [[T; 9]]) -> Result<(), ModelError> { unused() }
/// #     fn constraint_rows<T: Scalar>(&self, _: T, _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn load_geometry<T: Scalar>(&self, _: T, _: &[T], _: &mut [[T; 3]], _: &mut [[T; 9]]) -> Result<(), ModelError> { unused() }
/// #     fn load_values<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &[T], _: &mut [[T; 3]], _: &mut [[T; 3]]) -> Result<(), ModelError> { unused() }
/// # }
/// let info = appell_runtime::cli::info_json(&Spin { i: 0.25 }).unwrap();
/// assert_eq!(info["name"], "Spin");
/// assert_eq!(info["parameters"][0]["value"], 0.25);
/// assert_eq!(info["state"], serde_json::json!(["phi", "phi_dot"]));
/// assert_eq!(info["rhs_ops"]["total"], 1);
/// assert_eq!(info["rhs_ops"]["other"], 0);
/// ```
pub fn info_json<M: Model>(model: &M) -> Result<Value, ModelError> {
    let info = M::info();
    let mut values = vec![0.0; info.parameters.len()];
    model.parameter_values(&mut values)?;
    let parameters: Vec<Value> = info
        .parameters
        .iter()
        .zip(&values)
        .map(|(name, value)| json!({ "name": name, "value": finite_or_null(*value) }))
        .collect();
    let state: Vec<String> = info
        .retained
        .iter()
        .map(|r| r.to_string())
        .chain(info.speeds.iter().map(|s| format!("{s}_dot")))
        .collect();
    let bodies: Vec<Value> = info
        .bodies
        .iter()
        .map(|b| json!({ "name": b.name, "rigid": b.rigid }))
        .collect();
    let ops = info.rhs_ops;
    let scenes: Vec<Value> = M::scene_infos()
        .iter()
        .map(|s| {
            json!({
                "name": s.name,
                "effects": s.effects,
                "retained": s.retained,
                "state_len": s.state_len(),
                "rhs_ops": s.rhs_ops.total,
                "outputs": s.outputs,
            })
        })
        .collect();
    Ok(json!({
        "name": info.name,
        "scenes": scenes,
        "parameters": parameters,
        "coordinates": info.coordinates,
        "speeds": info.speeds,
        "dependent": info.dependent,
        "cyclic": info.cyclic,
        "ignorable": info.ignorable,
        "retained": info.retained,
        "state": state,
        "inputs": info.inputs,
        "effects": info.effects,
        "bodies": bodies,
        "holonomic": info.holonomic,
        "constraints": info.constraints,
        "contacts": info
            .contacts
            .iter()
            .map(|c| json!({
                "point": c.point,
                "body": info.bodies.get(c.body).map(|b| b.name),
                "along": c.along,
            }))
            .collect::<Vec<_>>(),
        "force_points": info.force_points,
        "torques": info.torques,
        "symbolic_elimination": info.symbolic_elimination,
        "rhs_ops": {
            "add": ops.add,
            "mul": ops.mul,
            "div": ops.div,
            "calls": ops.calls,
            "other": ops.total.saturating_sub(ops.add + ops.mul + ops.div + ops.calls),
            "total": ops.total,
        },
    }))
}

/// A JSON number, or `null` for a value JSON cannot hold.
fn finite_or_null(x: f64) -> Value {
    serde_json::Number::from_f64(x).map_or(Value::Null, Value::Number)
}

/// Evaluates `eval` lines against a model (the state of the `eval`
/// subcommand, usable on its own).
///
/// Every line starts from the parameter values the model had when the
/// evaluator was created. The accepted format is described in the module
/// documentation; see [`run_with`] for an example through the command line.
pub struct Evaluator<M: Model> {
    model: M,
    defaults: Vec<f64>,
    scene: Option<usize>,
    /// Answer with the constraint forces instead of the rates (`contacts`).
    contacts: bool,
}

impl<M: Model> Evaluator<M> {
    /// Takes the model and records its current parameter values.
    pub fn new(model: M) -> Result<Self, ModelError> {
        let mut defaults = vec![0.0; M::info().parameters.len()];
        model.parameter_values(&mut defaults)?;
        Ok(Evaluator {
            model,
            defaults,
            scene: None,
            contacts: false,
        })
    }

    /// An evaluator of the scene named `name` (as in `info`'s `scenes`: the
    /// part after `::`, or the whole name).
    pub fn with_scene(model: M, name: &str) -> Result<Self, CliError> {
        let scenes = M::scene_infos();
        let index = scenes
            .iter()
            .position(|s| s.name == name || s.name.rsplit("::").next() == Some(name))
            .ok_or_else(|| {
                let names: Vec<&str> = scenes.iter().map(|s| s.name).collect();
                CliError::Usage(format!(
                    "unknown scene `{name}`; the model's scenes: {}\n",
                    if names.is_empty() {
                        "none".to_string()
                    } else {
                        names.join(", ")
                    }
                ))
            })?;
        let mut e = Evaluator::new(model)?;
        e.scene = Some(index);
        Ok(e)
    }

    /// The model (with the parameters of the last evaluated line).
    pub fn model(&self) -> &M {
        &self.model
    }

    /// Answers one line: `{"qdot": {..}, "udot": {..}}` or
    /// `{"error": ".."}`.
    pub fn eval_line(&mut self, line: &str) -> Value {
        match self.try_eval(line) {
            Ok(v) => v,
            Err(message) => json!({ "error": message }),
        }
    }

    /// The info of the model or of the selected scene (a scene has the
    /// model's coordinates, speeds and parameters but its own reduced state).
    fn info(&self) -> &'static ModelInfo {
        match self.scene {
            Some(i) => M::scene_infos()[i],
            None => M::info(),
        }
    }

    fn try_eval(&mut self, line: &str) -> Result<Value, String> {
        let info = self.info();
        let value: Value =
            serde_json::from_str(line).map_err(|e| format!("malformed JSON: {e}"))?;
        let Value::Object(obj) = value else {
            return Err("expected a JSON object".to_string());
        };
        let point = self.parse_point(&obj, &[])?;
        let (t, q, u, inputs, state) = (point.t, point.q, point.u, point.inputs, point.state);
        let outputs = |energies: bool, contacts: bool| {
            let visitor = Outputs {
                t,
                q: &q,
                u: &u,
                inputs: &inputs,
                energies,
                contacts,
            };
            match self.scene {
                Some(i) => self
                    .model
                    .visit_scene(i, visitor)
                    .map_err(|e| e.to_string())?,
                None => visitor.visit(&self.model),
            }
        };
        if self.contacts {
            let mut out = outputs(false, true)?;
            return Ok(out.remove("contact_forces").unwrap_or(Value::Null));
        }
        let mut dstate = vec![0.0; info.state_len()];
        match self.scene {
            Some(i) => self.model.scene_rhs(i, t, &state, &inputs, &mut dstate),
            None => {
                let prepared = self.model.prepare::<f64>();
                self.model.rhs(&prepared, t, &state, &inputs, &mut dstate)
            }
        }
        .map_err(|e| e.to_string())?;
        let mut qdot = vec![0.0; info.coordinates.len()];
        self.model
            .coordinate_rates(t, &q, &u, &mut qdot)
            .map_err(|e| e.to_string())?;

        let mut qdot_out = Map::new();
        for (name, v) in info.coordinates.iter().zip(&qdot) {
            qdot_out.insert(name.to_string(), result_number(*v, name)?);
        }
        let mut udot_out = Map::new();
        let udot = dstate.get(info.retained.len()..).unwrap_or(&[]);
        for (name, v) in info.speeds.iter().zip(udot) {
            udot_out.insert(name.to_string(), result_number(*v, name)?);
        }
        let mut answer = Map::new();
        answer.insert("qdot".into(), Value::Object(qdot_out));
        answer.insert("udot".into(), Value::Object(udot_out));
        let (energies, contacts) = (
            info.has_output("energies"),
            info.has_output("contact_forces"),
        );
        if energies || contacts {
            answer.extend(outputs(energies, contacts)?);
        }
        Ok(Value::Object(answer))
    }

    /// Reads `t`, `params`, `q`, `u` and `inputs` of a JSON object (fields
    /// in `extra` are allowed and left to the caller), sets the parameters
    /// and assembles the reduced state.
    fn parse_point(&mut self, obj: &Map<String, Value>, extra: &[&str]) -> Result<Point, String> {
        let info = self.info();
        for key in obj.keys() {
            if !["t", "params", "q", "u", "inputs"].contains(&key.as_str())
                && !extra.contains(&key.as_str())
            {
                let mut expected = String::from("t, params, q, u, inputs");
                for e in extra {
                    expected += ", ";
                    expected += e;
                }
                return Err(format!("unknown field `{key}` (expected {expected})"));
            }
        }
        let t = match obj.get("t") {
            None => 0.0,
            Some(v) => number(v, "`t`")?,
        };
        let params = named(obj.get("params"), "params", "parameter", info.parameters)?;
        let q_given = named(obj.get("q"), "q", "coordinate", info.coordinates)?;
        let u_given = named(obj.get("u"), "u", "privileged speed", info.speeds)?;
        let inputs_given = named(obj.get("inputs"), "inputs", "input", info.inputs)?;

        for (i, name) in info.parameters.iter().enumerate() {
            let value = params[i].unwrap_or(self.defaults[i]);
            if !self.model.set_parameter(name, value) {
                return Err(format!("the model does not accept parameter `{name}`"));
            }
        }
        for r in info.retained {
            if info
                .coordinate_index(r)
                .is_some_and(|i| q_given[i].is_none())
            {
                return Err(format!("missing coordinate `{r}` in `q`"));
            }
        }
        if let Some(k) = u_given.iter().position(Option::is_none) {
            return Err(format!(
                "missing privileged speed `{}` in `u`",
                info.speeds[k]
            ));
        }
        let q: Vec<f64> = q_given.iter().map(|v| v.unwrap_or(0.0)).collect();
        let u: Vec<f64> = u_given.iter().map(|v| v.unwrap_or(0.0)).collect();
        let inputs: Vec<f64> = inputs_given.iter().map(|v| v.unwrap_or(0.0)).collect();

        let mut state = Vec::with_capacity(info.state_len());
        for r in info.retained {
            let i = info
                .coordinate_index(r)
                .ok_or_else(|| format!("retained `{r}` is not a coordinate"))?;
            state.push(q[i]);
        }
        state.extend_from_slice(&u);
        Ok(Point {
            t,
            q,
            u,
            inputs,
            state,
        })
    }
}

/// The outputs a scene asks for (or the `contacts` answer), computed on
/// the scene's own type.
struct Outputs<'a> {
    t: f64,
    q: &'a [f64],
    u: &'a [f64],
    inputs: &'a [f64],
    energies: bool,
    contacts: bool,
}

impl SceneVisitor for Outputs<'_> {
    type Output = Result<Map<String, Value>, String>;

    fn visit<S: Model>(self, model: &S) -> Self::Output {
        let mut out = Map::new();
        if self.energies {
            let e = crate::energy::energies(model, self.t, self.q, self.u, self.inputs)
                .map_err(|e| e.to_string())?;
            out.insert(
                "energies".into(),
                json!({
                    "kinetic": finite_or_null(e.kinetic),
                    "potential": finite_or_null(e.potential),
                    "rate": finite_or_null(e.rate),
                    "input_power": finite_or_null(e.input_power),
                }),
            );
        }
        if self.contacts {
            out.insert(
                "contact_forces".into(),
                contact_forces_json(model, self.t, self.q, self.u, self.inputs)?,
            );
        }
        Ok(out)
    }
}

/// `{"multipliers": [..], "rows": [{"source", "multiplier"}], "contacts":
/// [{"point", "body", "position", "force", "normal", "friction"}]}`.
fn contact_forces_json<S: Model>(
    model: &S,
    t: f64,
    q: &[f64],
    u: &[f64],
    inputs: &[f64],
) -> Result<Value, String> {
    let info = S::info();
    let f = contact_forces(model, t, q, u, inputs).map_err(|e| e.to_string())?;
    let v3 = |v: [f64; 3]| {
        json!([
            finite_or_null(v[0]),
            finite_or_null(v[1]),
            finite_or_null(v[2])
        ])
    };
    let rows: Vec<Value> = f
        .rows
        .iter()
        .map(|r| {
            let source = match r.source {
                RowSource::Holonomic { index } => format!("holonomic {index}"),
                RowSource::Nonholonomic { index } => format!("nonholonomic {index}"),
                RowSource::Rolling { contact, direction } => {
                    let point = info.contacts.get(contact).map_or("?", |c| c.point);
                    match info.contacts.get(contact) {
                        Some(c) if !c.along => {
                            format!("rolls at {point}, N.{}", ["x", "y", "z"][direction.min(2)])
                        }
                        _ => format!("rolls at {point}, along {direction}"),
                    }
                }
            };
            json!({ "source": source, "multiplier": finite_or_null(r.multiplier) })
        })
        .collect();
    let contacts: Vec<Value> = f
        .contacts
        .iter()
        .map(|c| {
            let normal = match c.normal {
                Normal::Available {
                    direction,
                    force,
                    source,
                } => json!({
                    "force": finite_or_null(force),
                    "direction": v3(direction),
                    "source": match source {
                        NormalSource::HolonomicRow { index } => format!("holonomic {index}"),
                        NormalSource::MomentumBalance => "momentum balance".to_string(),
                    },
                }),
                Normal::Unavailable(why) => json!({ "unavailable": format!("{why:?}") }),
            };
            let friction = match c.friction() {
                Friction::Required { mu, .. } => json!({ "mu": finite_or_null(mu) }),
                Friction::LiftOff { normal } => json!({ "lift_off": finite_or_null(normal) }),
                Friction::NormalUnavailable(why) => {
                    json!({ "unavailable": format!("{why:?}") })
                }
            };
            json!({
                "point": c.point,
                "body": info.bodies.get(c.body).map(|b| b.name),
                "position": v3(c.position),
                "force": v3(c.force),
                "normal": normal,
                "friction": friction,
            })
        })
        .collect();
    Ok(json!({
        "multipliers": f.multipliers.iter().map(|x| finite_or_null(*x)).collect::<Vec<_>>(),
        "rows": rows,
        "contacts": contacts,
    }))
}

/// A parsed `eval` object.
struct Point {
    t: f64,
    q: Vec<f64>,
    u: Vec<f64>,
    inputs: Vec<f64>,
    state: Vec<f64>,
}

/// A finite JSON number from a value.
fn number(v: &Value, what: &str) -> Result<f64, String> {
    match v.as_f64() {
        Some(x) if x.is_finite() => Ok(x),
        Some(_) => Err(format!("{what} is not a finite number")),
        None => Err(format!("{what} must be a number, found {v}")),
    }
}

/// A finite result as a JSON number.
fn result_number(x: f64, name: &str) -> Result<Value, String> {
    serde_json::Number::from_f64(x)
        .map(Value::Number)
        .ok_or_else(|| format!("the result for `{name}` is not finite"))
}

/// Parses an optional object of named numbers; entry `i` of the result is the
/// value given for `names[i]`.
fn named(
    v: Option<&Value>,
    field: &str,
    kind: &str,
    names: &[&str],
) -> Result<Vec<Option<f64>>, String> {
    let mut out = vec![None; names.len()];
    let Some(v) = v else { return Ok(out) };
    let Value::Object(obj) = v else {
        return Err(format!("`{field}` must be an object of {kind} values"));
    };
    for (key, value) in obj {
        let i = names
            .iter()
            .position(|n| n == key)
            .ok_or_else(|| format!("unknown {kind} `{key}` in `{field}`"))?;
        out[i] = Some(number(value, &format!("`{field}.{key}`"))?);
    }
    Ok(out)
}

/// The result of [`bench()`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BenchReport {
    /// Median nanoseconds per call of the generated [`Model::rhs`].
    pub rhs_ns: f64,
    /// Median nanoseconds per call of [`crate::oracle::reduced_rhs`].
    pub oracle_ns: f64,
    /// [`OpCounts::total`](crate::OpCounts::total) of the generated rhs.
    pub ops: usize,
    /// Number of states timed (those where both succeeded).
    pub states: usize,
}

impl BenchReport {
    /// `{"rhs_ns": .., "oracle_ns": .., "ops": .., "states": ..}`.
    ///
    /// ```
    /// use appell_runtime::cli::BenchReport;
    /// let r = BenchReport { rhs_ns: 12.5, oracle_ns: 4000.0, ops: 40, states: 256 };
    /// assert_eq!(r.to_json()["oracle_ns"], 4000.0);
    /// ```
    pub fn to_json(&self) -> Value {
        json!({
            "rhs_ns": finite_or_null(self.rhs_ns),
            "oracle_ns": finite_or_null(self.oracle_ns),
            "ops": self.ops,
            "states": self.states,
        })
    }
}

/// Number of benchmark states.
pub const BENCH_STATES: usize = 256;
/// Number of timed batches (the median is reported).
pub const BENCH_BATCHES: usize = 15;
/// Seed of the benchmark states.
pub const BENCH_SEED: u64 = 0x00A9_9E11_5EED_2003;
/// The shortest duration of one timed batch.
const MIN_BATCH: Duration = Duration::from_millis(2);

/// SplitMix64: a small deterministic generator.
struct SplitMix(u64);

impl SplitMix {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [-1, 1).
    fn symmetric(&mut self) -> f64 {
        let unit = (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
        2.0 * unit - 1.0
    }
}

struct BenchState {
    q_full: Vec<f64>,
    state: Vec<f64>,
    u: Vec<f64>,
    inputs: Vec<f64>,
}

/// Median nanoseconds per call of `pass` (which makes `calls` calls), after
/// one warm-up pass, over [`BENCH_BATCHES`] batches of at least 2 ms each.
fn time_per_call(calls: usize, mut pass: impl FnMut()) -> f64 {
    let start = Instant::now();
    pass();
    let once = start.elapsed().max(Duration::from_nanos(1));
    let reps = (MIN_BATCH.as_nanos() / once.as_nanos()).max(1) as usize + 1;
    let mut samples: Vec<f64> = (0..BENCH_BATCHES)
        .map(|_| {
            let start = Instant::now();
            for _ in 0..reps {
                pass();
            }
            start.elapsed().as_nanos() as f64 / (reps * calls) as f64
        })
        .collect();
    samples.sort_by(f64::total_cmp);
    samples[samples.len() / 2]
}

/// Times the generated [`Model::rhs`] (with [`Model::prepare`] done once)
/// and the oracle's [`reduced_rhs`](crate::oracle::reduced_rhs) over
/// [`BENCH_STATES`] pseudo-random states from [`BENCH_SEED`]: every
/// coordinate (ignorable ones included, for the oracle), every privileged
/// speed and every input uniform in [-1, 1], t = 0. States where either
/// fails are skipped; [`CliError::Bench`] when all fail.
///
/// The reported times are medians over [`BENCH_BATCHES`] batches, each
/// repeating the whole set of states for at least 2 ms, after a warm-up.
/// This takes a noticeable time (about 16 passes of the oracle over the
/// states at least); a runnable example would be slow, so see the module
/// documentation and the crate's tests.
pub fn bench<M: Model>(model: &M) -> Result<BenchReport, CliError> {
    let info = M::info();
    let n = info.coordinates.len();
    let mut retained = Vec::with_capacity(info.retained.len());
    for r in info.retained {
        retained.push(
            info.coordinate_index(r)
                .ok_or_else(|| CliError::Bench(format!("retained `{r}` is not a coordinate")))?,
        );
    }
    let prepared = model.prepare::<f64>();
    let mut rng = SplitMix(BENCH_SEED);
    let mut states = Vec::with_capacity(BENCH_STATES);
    let mut dstate = vec![0.0; info.state_len()];
    let mut last_error = String::from("no states");
    for _ in 0..BENCH_STATES {
        let q_full: Vec<f64> = (0..n).map(|_| rng.symmetric()).collect();
        let u: Vec<f64> = info.speeds.iter().map(|_| rng.symmetric()).collect();
        let inputs: Vec<f64> = info.inputs.iter().map(|_| rng.symmetric()).collect();
        let mut state: Vec<f64> = retained.iter().map(|&i| q_full[i]).collect();
        state.extend_from_slice(&u);
        let rhs = model.rhs(&prepared, 0.0, &state, &inputs, &mut dstate);
        let oracle = crate::oracle::reduced_rhs(model, 0.0, &q_full, &u, &inputs);
        match (rhs, oracle) {
            (Ok(()), Ok(_)) if dstate.iter().all(|x| x.is_finite()) => states.push(BenchState {
                q_full,
                state,
                u,
                inputs,
            }),
            (Err(e), _) => last_error = format!("rhs: {e}"),
            (_, Err(e)) => last_error = format!("oracle: {e}"),
            (Ok(()), Ok(_)) => last_error = "rhs: the result is not finite".to_string(),
        }
    }
    if states.is_empty() {
        return Err(CliError::Bench(format!(
            "no state where both the rhs and the oracle succeed (last error: {last_error})"
        )));
    }

    let rhs_ns = time_per_call(states.len(), || {
        for s in &states {
            let r = model.rhs(
                black_box(&prepared),
                black_box(0.0),
                black_box(&s.state),
                black_box(&s.inputs),
                black_box(&mut dstate),
            );
            let _ = black_box((r, &dstate));
        }
    });
    let oracle_ns = time_per_call(states.len(), || {
        for s in &states {
            let r = crate::oracle::reduced_rhs(
                model,
                black_box(0.0),
                black_box(&s.q_full),
                black_box(&s.u),
                black_box(&s.inputs),
            );
            let _ = black_box(r);
        }
    });
    Ok(BenchReport {
        rhs_ns,
        oracle_ns,
        ops: info.rhs_ops.total,
        states: states.len(),
    })
}

/// The largest reduced state `accuracy` handles (the integrators work on
/// fixed-size arrays; the sweep is compiled for every size up to this).
pub const ACCURACY_MAX_STATE: usize = 16;

/// The `accuracy` subcommand: parses one problem (an `eval` object plus
/// `t_end`, and optionally `checkpoints` (default 10), `levels` (default 4)
/// and `repeats` (default 3)), computes the reference and runs
/// [`standard_methods`]`(100, levels)` over it ([`Problem::sweep`]). Returns
/// the report as one JSON object, or why it could not.
///
/// The report: `{"t_end", "checkpoints", "reference_error", "points": [{"method",
/// "setting", "error_final", "error_max", "seconds", "rhs_calls", "steps"}, ..]}`
/// with the fields of [`crate::accuracy::Point`]; methods that fail (a
/// step-size underflow, say) are left out.
pub fn accuracy<M: Model>(model: M, text: &str) -> Result<Value, String> {
    let value: Value = serde_json::from_str(text).map_err(|e| format!("malformed JSON: {e}"))?;
    let Value::Object(obj) = value else {
        return Err("expected a JSON object".to_string());
    };
    let mut evaluator = Evaluator::new(model).map_err(|e| e.to_string())?;
    let extra = ["t_end", "checkpoints", "levels", "repeats"];
    let point = evaluator.parse_point(&obj, &extra)?;
    if point.t != 0.0 {
        return Err("`t` must be 0 (or omitted): a sweep starts at t = 0".to_string());
    }
    let t_end = match obj.get("t_end") {
        Some(v) => number(v, "`t_end`")?,
        None => return Err("missing field `t_end` (the horizon)".to_string()),
    };
    if t_end <= 0.0 {
        return Err(format!("`t_end` must be positive, not {t_end}"));
    }
    let count = |key: &str, default: usize, max: usize| -> Result<usize, String> {
        match obj.get(key) {
            None => Ok(default),
            Some(v) => match v.as_u64() {
                Some(n) if (1..=max as u64).contains(&n) => Ok(n as usize),
                _ => Err(format!(
                    "`{key}` must be an integer from 1 to {max}, found {v}"
                )),
            },
        }
    };
    let checkpoints = count("checkpoints", 10, 1000)?;
    let levels = count("levels", 4, 10)?;
    let repeats = count("repeats", 3, 100)?;
    let model = evaluator.model();
    macro_rules! sizes {
        ($($n:literal)*) => {
            match point.state.len() {
                $($n => sweep_report::<M, $n>(model, &point, t_end, checkpoints, levels, repeats),)*
                n => Err(format!(
                    "the reduced state has {n} entries; `accuracy` handles up to {ACCURACY_MAX_STATE}"
                )),
            }
        };
    }
    sizes!(1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16)
}

fn sweep_report<M: Model, const S: usize>(
    model: &M,
    point: &Point,
    t_end: f64,
    checkpoints: usize,
    levels: usize,
    repeats: usize,
) -> Result<Value, String> {
    let mut x0 = [0.0; S];
    x0.copy_from_slice(&point.state);
    let problem = Problem {
        model,
        x0,
        t_end,
        inputs: &point.inputs,
        checkpoints,
    };
    let (reference, estimate) = problem
        .reference()
        .map_err(|e| format!("the reference integration failed: {e}"))?;
    let points = problem.sweep(
        &reference,
        &standard_methods(100, levels),
        repeats,
        |_, _| {},
    );
    let points: Vec<Value> = points
        .iter()
        .map(|p| {
            json!({
                "method": p.method.name(),
                "setting": p.method.setting(),
                "error_final": finite_or_null(p.error_final),
                "error_max": finite_or_null(p.error_max),
                "seconds": p.seconds,
                "rhs_calls": p.rhs_calls,
                "steps": p.steps,
            })
        })
        .collect();
    Ok(json!({
        "t_end": t_end,
        "checkpoints": checkpoints,
        "reference_error": finite_or_null(estimate),
        "points": points,
    }))
}
