//! The entry points: the usage text, reading the arguments and dispatching
//! to the subcommand.

use super::animate::animate_dyn;
use super::bench::bench_dyn;
use super::error::CliError;
use super::eval::{eval_stream, Answer, EvalState};
use super::info::info_json_dyn;
use super::sweep::accuracy_dyn;
use appell_core::dynamic::DynModel;
use appell_core::{Model, ModelInfo};
use serde_json::json;
use std::error::Error;
use std::io::{BufRead, IsTerminal, Write};
use std::process::ExitCode;

/// The usage text for `program` running model `info`.
///
/// ```
/// # use appell_core::{ModelInfo, OpCounts};
/// # let info = ModelInfo {
/// #     name: "Pendulum", parameters: &[], coordinates: &[], speeds: &[], dependent: &[],
/// #     cyclic: &[], ignorable: &[], retained: &[], inputs: &[], effects: &[], outputs: &[], row_sources: &[], contacts: &[],
/// #     holonomic: 0, constraints: 0, bodies: &[], force_points: 0, torques: 0,
/// #     form: "closed form", symbolic_elimination: true, rhs_ops: OpCounts::default(), jacobian: None, equations: "",
/// # };
/// let text = appell_tools::cli::usage("pendulum", &info);
/// assert!(text.starts_with("usage: pendulum [eval|contacts|jacobian|info|equations|bench|accuracy|animate|help]"));
/// assert!(text.contains("Pendulum"));
/// ```
pub fn usage(program: &str, info: &ModelInfo) -> String {
    format!(
        "usage: {program} [eval|contacts|jacobian|info|equations|bench|accuracy|animate|help]\n\
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
         \x20 jacobian    the same input -> A = d(rates)/d(state), B = d(rates)/d(inputs)\n\
         \x20             as JSON; with \"step\": {{\"method\": \"rk4\" | \"semi_implicit_euler\",\n\
         \x20             \"h\": ..}} those of one step (`jacobian --scene NAME` too)\n\
         \x20 info        print the model's metadata as JSON\n\
         \x20 equations   print the derived equations\n\
         \x20 bench       time the generated rhs against the oracle, print JSON\n\
         \x20 accuracy    read one JSON problem from stdin (an `eval` state plus\n\
         \x20             \"t_end\", optional \"checkpoints\", \"levels\", \"repeats\") and\n\
         \x20             print the work-precision sweep of every integrator as JSON\n\
         \x20 animate     read one JSON problem from stdin (an `eval` state plus \"t_end\",\n\
         \x20             optional \"frames\", \"playback\", \"view\", ..) and print an\n\
         \x20             animated SVG of the simulated motion\n\
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
/// # use appell_core::{Model, ModelError, ModelInfo, OpCounts, Scalar};
/// # struct Free { m: f64 }
/// # static INFO: ModelInfo = ModelInfo {
/// #     name: "Free", parameters: &["m"], coordinates: &["x"], speeds: &["x"],
/// #     dependent: &[], cyclic: &[], ignorable: &["x"], retained: &[], inputs: &["f"],
/// #     effects: &["push"], outputs: &[], row_sources: &[], contacts: &[], holonomic: 0, constraints: 0, bodies: &[], force_points: 0,
/// #     torques: 0, form: "closed form", symbolic_elimination: true,
/// #     rhs_ops: OpCounts { add: 0, mul: 0, div: 1, calls: 0, total: 1 },
/// #     jacobian: None,
/// #     equations: "x'' = f/m",
/// # };
/// # fn unused() -> Result<(), ModelError> { Err(ModelError::NonFinite { what: "unused" }) }
/// # impl Model for Free {
/// #     type Prepared<T: Scalar> = T;
/// #     fn info() -> &'static ModelInfo { &INFO }
/// #     fn parameter_values(&self, out: &mut [f64]) -> Result<(), ModelError> {
/// #         appell_core::check_len("out", out, 1)?; out[0] = self.m; Ok(())
/// #     }
/// #     fn set_parameter(&mut self, name: &str, v: f64) -> bool {
/// #         if name == "m" { self.m = v; true } else { false }
/// #     }
/// #     fn prepare<T: Scalar>(&self) -> T { T::one() / T::from_f64(self.m) }
/// #     fn rhs<T: Scalar>(&self, p: &T, _t: T, s: &[T], i: &[T], ds: &mut [T]) -> Result<(), ModelError> {
/// #         appell_core::check_len("state", s, 1)?; appell_core::check_len("dstate", ds, 1)?;
/// #         appell_core::check_len("inputs", i, 1)?;
/// #         ds[0] = i[0] * *p; Ok(())
/// #     }
/// #     fn coordinate_rates<T: Scalar>(&self, _: T, q: &[T], u: &[T], qd: &mut [T]) -> Result<(), ModelError> {
/// #         appell_core::check_len("q", q, 1)?; appell_core::check_len("u", u, 1)?;
/// #         appell_core::check_len("qdot", qd, 1)?; qd[0] = u[0]; Ok(())
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
/// use appell_tools::cli::{run_with, CliError};
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
    mut model: M,
    args: &[String],
    stdin: &mut dyn BufRead,
    stdout: &mut dyn Write,
    default_action: impl FnOnce(&M) -> Result<(), Box<dyn Error>>,
) -> Result<(), CliError> {
    match dispatch(&mut model, args, stdin, stdout)? {
        Dispatched::Done => Ok(()),
        Dispatched::Default => default_action(&model).map_err(CliError::Action),
    }
}

/// What [`dispatch`] did.
enum Dispatched {
    /// Ran a subcommand.
    Done,
    /// There was no subcommand: the caller runs its default action.
    Default,
}

/// [`run_with`] but the default action, over a `dyn DynModel`: every
/// subcommand is compiled once here, not once per model.
fn dispatch(
    model: &mut dyn DynModel,
    args: &[String],
    stdin: &mut dyn BufRead,
    stdout: &mut dyn Write,
) -> Result<Dispatched, CliError> {
    let info = model.dyn_info();
    let program = args.first().map(String::as_str).unwrap_or(info.name);
    let rest = args.get(1..).unwrap_or(&[]);
    if let [command, flag, name] = rest {
        if let (Some(answer), "--scene") = (Answer::of_command(command), flag.as_str()) {
            let mut evaluator = EvalState::with_scene(model, name)?;
            evaluator.answer = answer;
            eval_stream(&evaluator, model, stdin, stdout)?;
            return Ok(Dispatched::Done);
        }
    }
    if let [command, flag] = rest {
        if Answer::of_command(command).is_some() && flag == "--scene" {
            return Err(EvalState::scene_name_missing(model, command));
        }
    }
    let command = match rest {
        [] => return Ok(Dispatched::Default),
        [command] => command.as_str(),
        [command, extra, ..] => {
            return Err(CliError::Usage(format!(
                "unexpected argument `{extra}` after `{command}`\n{}",
                usage(program, info)
            )))
        }
    };
    if let Some(answer) = Answer::of_command(command) {
        let mut evaluator = EvalState::new(model)?;
        evaluator.answer = answer;
        eval_stream(&evaluator, model, stdin, stdout)?;
        return Ok(Dispatched::Done);
    }
    match command {
        "info" => {
            writeln!(stdout, "{}", info_json_dyn(model)?)?;
            stdout.flush()?;
        }
        "equations" => {
            let eq = info.equations;
            if eq.ends_with('\n') {
                write!(stdout, "{eq}")?;
            } else {
                writeln!(stdout, "{eq}")?;
            }
            stdout.flush()?;
        }
        "bench" => match bench_dyn(model) {
            Ok(report) => {
                writeln!(stdout, "{}", report.to_json())?;
                stdout.flush()?;
            }
            Err(e) => {
                writeln!(stdout, "{}", json!({ "error": e.to_string() }))?;
                stdout.flush()?;
                return Err(e);
            }
        },
        "accuracy" => {
            let mut text = String::new();
            stdin.read_to_string(&mut text)?;
            match accuracy_dyn(model, &text) {
                Ok(report) => {
                    writeln!(stdout, "{report}")?;
                    stdout.flush()?;
                }
                Err(why) => {
                    writeln!(stdout, "{}", json!({ "error": why }))?;
                    stdout.flush()?;
                    return Err(CliError::Accuracy(why));
                }
            }
        }
        "animate" => {
            let mut text = String::new();
            stdin.read_to_string(&mut text)?;
            // The progress bar only on a terminal: a log file gets no `\r`s.
            let mut stderr = std::io::stderr();
            let terminal = stderr
                .is_terminal()
                .then_some(&mut stderr as &mut dyn Write);
            match animate_dyn(model, &text, terminal) {
                Ok(animated) => {
                    for note in &animated.notes {
                        eprintln!("animate: {note}");
                    }
                    write!(stdout, "{}", animated.svg)?;
                    stdout.flush()?;
                }
                Err(why) => return Err(CliError::Animate(why)),
            }
        }
        "help" | "-h" | "--help" => {
            write!(stdout, "{}", usage(program, info))?;
            stdout.flush()?;
        }
        other => {
            return Err(CliError::Usage(format!(
                "unknown command `{other}`\n{}",
                usage(program, info)
            )))
        }
    }
    Ok(Dispatched::Done)
}
