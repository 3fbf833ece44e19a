//! The model command line every example gets: a stable, scriptable interface
//! to a [`Model`].
//!
//! ```text
//! <program>              run the example's own default action
//! <program> eval         JSON states on stdin (one per line) -> rates on stdout
//! <program> eval --scene NAME      the same for a scene, plus its outputs
//! <program> contacts     the same states -> multipliers and contact forces
//! <program> contacts --scene NAME  the same for a scene (its loads only)
//! <program> jacobian     the same states -> A = ∂ẋ/∂x, B = ∂ẋ/∂u (or of one step)
//! <program> jacobian --scene NAME  the same for a scene
//! <program> info         the model's metadata as JSON
//! <program> equations    the derived reduced equations, as text
//! <program> bench        time the generated rhs against the oracle, as JSON
//! <program> accuracy     a work-precision sweep of every integrator, as JSON
//! <program> animate      one simulated motion as an animated SVG
//! <program> help         usage (also -h, --help)
//! ```
//!
//! An example's `main` is just
//!
//! ```no_run
//! # use appell_core::Model;
//! # fn demo<M: Model>(model: M) -> std::process::ExitCode {
//! appell_tools::cli::run(model, |model| {
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
//! * `q`: coordinates by name. A [dependent](ModelInfo::dependent)
//!   coordinate left out that a holonomic constraint involves (a bicycle's
//!   pitch) is solved from the constraints, the others held: Newton's
//!   method from 0 (from 0.3 when that fails), to a residual of at most
//!   1e-12 × (1 + max |q|); the answer then carries `"solved": {name:
//!   value}` and `"residual"` (the largest |residual| of the constraints
//!   solved), so that a wrong branch shows. Every other
//!   [retained](ModelInfo::retained) coordinate is required; the rest
//!   default to 0 (their values do not enter the reduced equations but are
//!   passed to [`Model::coordinate_rates`]).
//! * `u`: the privileged speeds, keyed by their coordinate's name
//!   ([`ModelInfo::speeds`]); all are required.
//! * `params`: parameters by name; omitted ones keep the model's values (the
//!   values it had when the command started, for every line).
//! * `inputs`: inputs by name; omitted ones are 0.
//! * `t`: the time; 0 when omitted.
//!
//! Unknown fields or names, a key given twice in one object (serde_json
//! would keep the last silently), missing values, values that are not
//! finite numbers, malformed JSON, constraints that cannot be solved for
//! the coordinates left out, and any [`ModelError`] (for example a singular
//! configuration) answer that line with `{"error": "..."}`; evaluation goes on
//! with the next line. A good line is answered with
//!
//! ```text
//! {"qdot": {<every coordinate>: rate}, "udot": {<every speed's coordinate>: acceleration}}
//! ```
//!
//! where `qdot` comes from [`Model::coordinate_rates`] and `udot` from
//! [`Model::rhs`] (after [`Model::prepare`]), plus `"solved"` and
//! `"residual"` when coordinates were solved. When `q` is off a holonomic
//! constraint by more than 1e-9 × (1 + max |q|), the answer also carries
//! `"warning": {"message": "...", "holonomic_residuals": [..]}`: the rates
//! are still computed, but for a state the mechanism cannot take. Every
//! action that reads a state (`eval`, `contacts`, `accuracy`, `animate`)
//! reads `q` this way and gives these notes.
//!
//! With `--scene NAME` the scene's reduced equations answer, and the
//! outputs its `outputs(...)` asked for are added: `"energies"`
//! (`{"kinetic", "potential", "rate", "input_power"}`, see
//! [`appell_dynamics::energy::energies`]) and `"contact_forces"` (as `contacts`
//! answers). The full model declares no outputs.
//!
//! # `contacts`
//!
//! The same input lines (coordinates solved and the warning as for
//! `eval`), answered by [`appell_dynamics::constraint_forces`]:
//!
//! ```text
//! {"multipliers": [λ..], "rows": [{"source": "rolls at P, N.x", "multiplier": λ}, ..],
//!  "contacts": [{"point": "P", "body": "disc", "position": [..], "force": [..],
//!                "normal": {"force": N, "direction": [..], "source": "momentum balance"}
//!                          or {"unavailable": "NoDirection"},
//!                "friction": {"mu": μ} or {"lift_off": N} or {"unavailable": ".."}}]}
//! ```
//!
//! Forces are on the body, from the ground, in N components. `"solved"`,
//! `"residual"` and `"warning"` are added as in `eval`.
//!
//! # `jacobian`
//!
//! The same input lines, and optionally `"step": {"method": "rk4" |
//! "semi_implicit_euler", "h": 0.01}`, answered with the Jacobians of the
//! reduced equations at that state (those of [`appell_linearize::linearize`])
//! or, with `step`, of one step of that method
//! ([`appell_linearize::step_jacobian`]):
//!
//! ```text
//! {"state": [names], "inputs": [names], "rates": [ẋ..], "a": [[∂ẋ_i/∂x_j..]..], "b": [[∂ẋ_i/∂u_k..]..]}
//! {"state": [..], "inputs": [..], "step": {"method": "rk4", "h": 0.01}, "next": [x⁺..], "a": [[∂x⁺_i/∂x_j..]..], "b": [..]}
//! ```
//!
//! A row per state component (the retained coordinates, then the speeds
//! suffixed `_dot`, as `info`'s `state`), exact to rounding (dual numbers
//! through the generated code, one pass per state component and input).
//! `"solved"`, `"residual"` and `"warning"` are added as in `eval`; a
//! Jacobian that is not finite answers the line with an error.
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
//! [`reduced_rhs`](appell_dynamics::oracle::reduced_rhs) over 256 fixed pseudo-random
//! states and prints `{"rhs_ns": .., "oracle_ns": .., "ops": .., "states": ..}`
//! (nanoseconds per call, [`OpCounts::total`](appell_core::OpCounts::total) of the
//! rhs, number of states used). See [`bench()`].
//!
//! # `accuracy`
//!
//! Reads one JSON object from stdin: an `eval` state (`t` must be 0 or
//! omitted) plus `t_end` (the horizon, required), `checkpoints` (default
//! 10, at most 1000), `levels` (default 4, at most 10) and `repeats`
//! (default 3, at most 100), for example
//!
//! ```text
//! {"q": {"phi": 0.3}, "u": {"phi": 0.2, "psi1": 1.0}, "inputs": {"tau": 0.4}, "t_end": 10}
//! ```
//!
//! and prints what accuracy costs on that problem: every integrator of
//! [`crate::accuracy::standard_methods`] against a DOP853 reference, as
//! `{"t_end", "checkpoints", "reference_error", "points": [{"method",
//! "setting", "error_final", "error_max", "seconds", "rhs_calls", "steps"}]}`,
//! plus `"solved"`, `"residual"` and `"warning"` as in `eval`. A problem it
//! cannot run is answered with `{"error": ".."}` on stdout and exit status
//! 1 (there is only the one problem to go on with). States up to
//! [`ACCURACY_MAX_STATE`] entries. See [`accuracy()`].
//!
//! # `animate`
//!
//! Reads one JSON object from stdin: an `eval` state plus `t_end` (when the
//! motion ends, required) and, optionally, `frames` (default 200, at most
//! 10000: the picture has `frames + 1` of them, the first at `t`),
//! `max_steps` (the step budget, default 2000000, see below), `playback`
//! (seconds of motion per second, default 1), `width` and `height`
//! (default 640 × 480, each at most 4096), `title` (default the model's
//! name), `view` (`"auto"`, the default, `"oblique"`, `"x"`, `"y"` or
//! `"z"`: looking along N's axis), `up` (three numbers, for the oblique
//! view, default `[0, 0, 1]`), `follow` (keep the bodies in the middle,
//! default `false`), `connectors` (pairs of body names, `"O"` for the
//! origin: lines drawn between them), `traces` and `dots` (body names: a
//! centre's path drawn; a body drawn as a dot; default none), for example
//!
//! ```text
//! {"q": {"phi": 0.3}, "u": {"phi": 0.2, "psi1": 1.0}, "inputs": {"tau": 0.4}, "t_end": 5, "view": "z"}
//! ```
//!
//! simulates it ([`crate::animate::simulate`]: RK4 on every coordinate) and
//! prints the SVG ([`crate::animate::svg`]). `q` is read as for `eval`:
//! the coordinates the holonomic constraints fix may be left out and are
//! solved; what was solved and the warning for a state off the constraints
//! go to stderr and into an XML comment at the top of the SVG.
//!
//! The simulation takes [`crate::animate::steps_needed`] steps (about
//! (t_end − t) / 1 ms); a problem that needs more than `max_steps` is
//! refused before it starts, with the number of steps it needs, so that a
//! huge `t_end` is not hours of silent computing. Runs of 100000 steps or
//! more draw a progress bar on stderr when stderr is a terminal.
//!
//! A problem it cannot run is reported on stderr with exit status 1 and
//! nothing on stdout (which is the picture).

// Items the documentation links to.
#[cfg(doc)]
use appell_core::{Model, ModelError, ModelInfo};

mod animate;
mod bench;
mod error;
mod eval;
mod holonomic;
mod info;
mod input;
mod jacobian;
mod json;
mod output;
mod progress;
mod run;
mod sweep;

pub use bench::{bench, BenchReport, BENCH_BATCHES, BENCH_SEED, BENCH_STATES};
pub use error::CliError;
pub use eval::Evaluator;
pub use info::info_json;
pub use run::{run, run_with, usage};
pub use sweep::{accuracy, ACCURACY_MAX_STATE};
