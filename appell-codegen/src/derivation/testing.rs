//! Small models and helpers for the stages' unit tests.
//!
//! Each stage is tested on mechanisms whose equations are short enough to
//! derive by hand: a planar pendulum (one particle, no constraint), a
//! pendulum in Cartesian coordinates (a holonomic constraint whose pivot is
//! not provably non-zero: a numeric elimination), the Chaplygin sleigh (a
//! knife edge: one nonholonomic row, a symbolic elimination) and the
//! paper's wheel-axle. Expressions are compared with hand-derived ones by
//! value at pseudo-random points, so a test does not depend on the form
//! the engine keeps.

use appell_symbolic::{Graph, Id, Symbol, Tape};

use super::elimination::SolvedRates;
use super::numeric::{Elimination, NumericInputs};
use super::partials::PartialVelocities;
use super::remainders::Remainders;
use super::rows::ConstraintRows;
use super::speed_map::{Rates, SpeedMap};
use super::speeds::SpeedDefinitions;
use super::{elimination, numeric, partials, remainders, rows, speed_map, speeds, Calculus};
use crate::ctxt::Ctxt;
use crate::model::{Kinematics, Model};
use crate::probe::pseudo_value;

/// A particle of mass m on a massless rod of length l, angle q from the
/// downward vertical, under gravity g.
pub const PENDULUM: &str = r#"
    #[appell(coordinates(q), speeds(q))]
    #[appell(point(P = O + l * sin(q) * N.x - l * cos(q) * N.y), particle(P, mass = m))]
    #[appell(gravity(-g * N.y))]
    struct Pendulum { m: f64, l: f64, g: f64 }
"#;

/// The same pendulum in Cartesian coordinates x, y with x² + y² = l², x
/// privileged.
pub const CARTESIAN: &str = r#"
    #[appell(coordinates(x, y), speeds(x))]
    #[appell(point(P = O + x * N.x + y * N.y), particle(P, mass = m))]
    #[appell(holonomic(x * x + y * y == l * l))]
    #[appell(gravity(-g * N.y))]
    struct CartesianPendulum { m: f64, l: f64, g: f64 }
"#;

/// The Chaplygin sleigh: a knife edge at P, mass centre C a distance b
/// ahead of it along the blade; ẏ cos θ − ẋ sin θ = 0.
pub const SLEIGH: &str = r#"
    #[appell(coordinates(x, y, theta), speeds(x, theta), positive(m, b))]
    #[appell(frame(B = N.rotate_z(theta)))]
    #[appell(point(P = O + x * N.x + y * N.y), point(C = P + b * B.x))]
    #[appell(body(sleigh, center = C, frame = B, mass = m, inertia = principal(i0, i0, i0)))]
    #[appell(nonholonomic(dt(y) * cos(theta) - dt(x) * sin(theta) == 0))]
    struct Sleigh { m: f64, b: f64, i0: f64 }
"#;

/// The kinematics of `src`, which must be free of errors.
pub fn kinematics(src: &str) -> Kinematics {
    let input: syn::DeriveInput = syn::parse_str(src).expect("valid Rust");
    let cx = Ctxt::new();
    let ast = crate::parse::parse(&cx, &input);
    let built = crate::model::build(&cx, &ast);
    cx.check().expect("a model without errors");
    built.expect("a model")
}

/// The model of `src` alone (its twin dropped).
pub fn model(src: &str) -> Model {
    kinematics(src).model
}

/// The model of `src` and the derivatives with its twin.
pub fn model_and_calculus(src: &str) -> (Model, Calculus) {
    let Kinematics { mut model, twin } = kinematics(src);
    let calculus = Calculus::new(&mut model, twin).expect("the rate rules");
    (model, calculus)
}

/// A symbol of the model's graph by name.
pub fn symbol(g: &Graph, name: &str) -> Symbol {
    g.symbol_named(name)
        .unwrap_or_else(|| panic!("no symbol `{name}`"))
}

/// Asserts that `e` equals the expression `expected` (in the graph's
/// names) at five pseudo-random points, to 1e-12 relative. `env` fixes
/// some symbols (X's in terms of the state, say) as expressions.
pub fn assert_agrees_with(g: &mut Graph, e: Id, expected: &str, env: &[(&str, &str)]) {
    let want = g.parse(expected).expect("expected expression parses");
    let fixed: Vec<(Symbol, Id)> = env
        .iter()
        .map(|(name, value)| (symbol(g, name), g.parse(value).expect("value parses")))
        .collect();
    let fixed_tape = Tape::new(g, &fixed.iter().map(|(_, v)| *v).collect::<Vec<_>>());
    let tape = Tape::new(g, &[e, want]);
    for trial in 0..5u64 {
        let base = |s: Symbol| Some(pseudo_value(g, s, trial));
        let values = fixed_tape.eval(&base).expect("values evaluate");
        let env = |s: Symbol| match fixed.iter().position(|(f, _)| *f == s) {
            Some(i) => Some(values[i]),
            None => Some(pseudo_value(g, s, trial)),
        };
        let v = tape.eval(&env).expect("evaluates");
        let scale = 1.0 + v[0].abs().max(v[1].abs());
        assert!(
            (v[0] - v[1]).abs() <= 1e-12 * scale,
            "trial {trial}: {} = {} but {expected} = {}",
            g.display(e),
            v[0],
            v[1]
        );
    }
}

/// [`assert_agrees_with`] with no symbol fixed.
pub fn assert_agrees(g: &mut Graph, e: Id, expected: &str) {
    assert_agrees_with(g, e, expected, &[]);
}

/// A model taken through stages 1 to 5.
pub struct Run {
    /// The model; its graph holds every expression.
    pub model: Model,
    /// The derivatives and the twin.
    pub calculus: Calculus,
    /// Stage 2.
    pub speeds: SpeedDefinitions,
    /// Stage 4.
    pub map: SpeedMap,
    /// Stage 4's rate rules, with X's rates from stage 5.
    pub rates: Rates,
    /// Stage 5.
    pub elimination: Elimination,
}

/// Stages 1 to 3 of `src`.
pub fn solve(
    src: &str,
) -> (
    Model,
    Calculus,
    ConstraintRows,
    SpeedDefinitions,
    SolvedRates,
) {
    let (mut model, calculus) = model_and_calculus(src);
    let cx = Ctxt::new();
    let set = model.constraints.clone();
    let rows = rows::constraint_rows(&cx, &mut model, &set, &calculus)
        .expect("rows")
        .expect("no errors");
    let speeds = speeds::speed_definitions(&cx, &mut model, &set, &rows)
        .expect("speeds")
        .expect("no errors");
    let solved = elimination::eliminate(&cx, &mut model, &set, &rows.d, &rows.d0, &speeds)
        .expect("elimination")
        .expect("no errors");
    cx.check().expect("no errors");
    (model, calculus, rows, speeds, solved)
}

/// Stages 1 to 5 of `src`.
pub fn run(src: &str) -> Run {
    let (mut model, mut calculus, rows, speeds, solved) = solve(src);
    let set = model.constraints.clone();
    let (map, mut rates) =
        speed_map::speed_map(&mut model, &set, &speeds, &solved, &calculus).expect("speed map");
    let elimination = match solved.schur {
        Some(schur) => Elimination::Numeric(
            numeric::numeric_elimination(
                &mut model,
                schur,
                NumericInputs {
                    set: &set,
                    rows: &rows,
                    dependent: &speeds.dependent,
                    map: &map,
                    vanishing: &solved.vanishing,
                },
                &mut rates,
                &mut calculus.uncut,
            )
            .expect("numeric elimination"),
        ),
        None => Elimination::Symbolic,
    };
    Run {
        model,
        calculus,
        speeds,
        map,
        rates,
        elimination,
    }
}

/// Stages 6 to 11 of a [`Run`].
pub struct Later {
    /// Stage 9 (with stage 8).
    pub folded_lines: Vec<String>,
    /// Stage 10.
    pub equations: super::loads::Equations,
    /// Stage 11.
    pub energies: super::energies::Energies,
}

impl Run {
    /// Stages 6 to 11, with folding chosen by `options`.
    pub fn later(&mut self, options: &super::Options) -> Later {
        let (partials, mut remainders) = self.remainders();
        let folded = super::assemble_and_fold(
            &mut self.model,
            &partials,
            &mut remainders,
            &self.map,
            &mut self.rates,
            &mut self.calculus,
            options,
        )
        .expect("folding");
        let model = &mut self.model;
        let equations = super::loads::equations(
            model,
            folded.assembled,
            &folded.composites,
            &partials,
            &self.map,
            &self.calculus.rules,
            &mut self.rates.fixed,
        )
        .expect("equations");
        let energies =
            super::energies::energies(model, &partials, &self.map, &mut self.rates.fixed)
                .expect("energies");
        Later {
            folded_lines: folded.lines,
            equations,
            energies,
        }
    }

    /// Stage 6.
    pub fn partials(&mut self) -> PartialVelocities {
        partials::partial_velocities(
            &mut self.model,
            &self.map,
            &self.calculus.rules,
            &self.rates.fixed,
        )
        .expect("partial velocities")
    }

    /// Stages 6 and 7.
    pub fn remainders(&mut self) -> (PartialVelocities, Remainders) {
        let p = self.partials();
        let r = remainders::remainders(
            &mut self.model,
            &self.speeds.dependent,
            &self.map,
            &p,
            &mut self.rates,
            &mut self.calculus,
        )
        .expect("remainders");
        (p, r)
    }
}

/// A disc of radius r rolling on a line: ẋ + r φ̇ = 0, a symbolic
/// elimination (the pivot is 1).
pub const DISC_ON_A_LINE: &str = r#"
    #[appell(coordinates(x, phi), speeds(phi))]
    #[appell(frame(B = N.rotate_z(phi)))]
    #[appell(point(D = O + x * N.x + r * N.y), point(P = D - r * N.y))]
    #[appell(body(disc, center = D, frame = B, mass = m, inertia = principal(i, i, j)))]
    #[appell(rolls(disc, contact = P))]
    #[appell(force(D, f * N.x, effect = push), inputs(f))]
    struct Disc { m: f64, r: f64, i: f64, j: f64 }
"#;

#[test]
#[should_panic(expected = "but")]
fn assert_agrees_sees_a_difference() {
    let mut m = model(PENDULUM);
    let e = m.g.parse("l*sin(q)").unwrap();
    assert_agrees(&mut m.g, e, "l*cos(q)");
}
