//! Helpers for the tests of lowering and of the passes, and the tests of
//! the pass pipeline as a whole: every pass can be switched off, and the
//! report accounts for every pass that ran.

use super::inst::use_counts;
use super::passes::{LowerOptions, Pass, ProgramSize};
use super::{Inst, Program};
use crate::eval::Tape;
use crate::graph::{Graph, Id, Symbol};
use crate::workloads::spatial_chain;

/// Fixed values for the symbols the tests use.
pub(super) fn values(g: &Graph) -> impl Fn(Symbol) -> Option<f64> + '_ {
    |s| {
        Some(match g.symbol_name(s) {
            "x" => 0.7,
            "y" => -1.3,
            "z" => 2.1,
            "w" => 0.4,
            "d" => 1.9,
            "p" => 3.0,
            "q" => -0.5,
            name if name.len() == 2 && name.starts_with('v') => {
                0.1 + name.as_bytes()[1] as f64 / 50.0
            }
            _ => return None,
        })
    }
}

/// Lowers `texts` and checks the program against the graph's evaluation
/// at [`values`].
pub(super) fn check(g: &mut Graph, texts: &[&str]) -> Program {
    let roots: Vec<Id> = texts.iter().map(|t| g.parse(t).unwrap()).collect();
    let p = Program::lower(g, &roots);
    let got = p.eval(&values(g)).unwrap();
    let expected = crate::eval::Tape::new(g, &roots).eval(&values(g)).unwrap();
    for (a, b) in got.iter().zip(&expected) {
        assert!((a - b).abs() <= 1e-14 * b.abs().max(1.0), "{a} vs {b}");
    }
    p
}

/// A program made of `insts` directly, every instruction counted as
/// reading the state.
pub(super) fn program(insts: Vec<Inst>, outputs: Vec<u32>) -> Program {
    Program {
        parameter_only: vec![false; insts.len()],
        uses: use_counts(&insts, &outputs),
        insts,
        outputs,
        report: Vec::new(),
    }
}

/// A pseudo-random value in [0.5, 2) for each symbol, drawn from `seed`.
fn point(seed: u64) -> impl Fn(Symbol) -> Option<f64> {
    move |s| {
        let mut z = (seed << 32 | s.0 as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15);
        z ^= z >> 29;
        z = z.wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z ^= z >> 32;
        Some(0.5 + 1.5 * (z >> 11) as f64 / (1u64 << 53) as f64)
    }
}

/// Expressions on which every pass has work to do, as (graph, roots).
fn workloads() -> Vec<(Graph, Vec<Id>)> {
    let texts: &[&[&str]] = &[
        &[
            "x*y*z + x*y*w - sin(x)*cos(y)*p + p*q*x/d + q*x/d",
            "x*y*w*d - (x - y)*(y - x) + sin(x)*cos(y)*q",
        ],
        &[
            "(sin(x) + cos(y) + z)*(w - d) - w*sin(x) + d*sin(x)",
            "sin(x)^2 + cos(x)^2 + (x + y)*(x - y) - x^2",
            "w - sin(x) - cos(y) + x/d + y/d",
        ],
        &[
            "p*sin(x) + q*sin(x) + p*cos(y) + q*cos(y) - sqrt(x^2 + 1)*atan2(y, d)",
            "va*vb + vc*vd + ve*vf + vg*vh + vi*vj - p*q*va",
        ],
    ];
    let mut out = Vec::new();
    for set in texts {
        let mut g = Graph::new();
        g.parameter("p").unwrap();
        g.parameter("q").unwrap();
        let roots = set.iter().map(|t| g.parse(t).unwrap()).collect();
        out.push((g, roots));
    }
    // A multibody workload: the accelerations of a 3-link spatial chain.
    let mut g = Graph::new();
    let roots = spatial_chain(&mut g, 3).unwrap().acceleration_roots();
    out.push((g, roots));
    out
}

/// Checks `p` against the graph's evaluation at a few random points.
fn agrees(g: &Graph, roots: &[Id], p: &Program, what: &str) {
    let tape = Tape::new(g, roots);
    for seed in 1..=4 {
        let env = point(seed);
        let got = p.eval(&env).unwrap();
        let expected = tape.eval(&env).unwrap();
        for (a, b) in got.iter().zip(&expected) {
            assert!(
                (a - b).abs() <= 1e-11 * b.abs().max(1.0),
                "{what}, point {seed}: {a} vs {b}"
            );
        }
    }
}

#[test]
fn every_pass_switched_off_still_computes_the_same_values() {
    let mut choices = vec![
        ("all passes".to_string(), LowerOptions::default()),
        ("no pass".to_string(), LowerOptions::none()),
    ];
    for pass in Pass::ALL {
        let options = LowerOptions::default().without(pass);
        choices.push((format!("without {pass}"), options));
        choices.push((format!("only {pass}"), LowerOptions::none().with(pass)));
    }
    for (g, roots) in workloads() {
        for (what, options) in &choices {
            let p = Program::lower_with(&g, &roots, options);
            agrees(&g, &roots, &p, what);
            // After the first prune, every pass keeps every instruction live.
            if options.runs(Pass::Prune) {
                let live = |(i, &u): (usize, &u32)| u > 0 || p.outputs.contains(&(i as u32));
                assert!(p.uses.iter().enumerate().all(live), "{what}");
            }
        }
    }
}

#[test]
fn the_default_options_are_program_lower() {
    for (g, roots) in workloads() {
        let a = Program::lower(&g, &roots);
        let b = Program::lower_with(&g, &roots, &LowerOptions::default());
        assert_eq!(a.insts(), b.insts());
        assert_eq!(a.outputs(), b.outputs());
        assert_eq!(a.pass_report(), b.pass_report());
    }
}

/// The passes of `p`'s report, and a check that each pass was given the
/// program the one before returned, the first the lowering's, and that
/// the last returned `p`.
fn chained_passes(g: &Graph, roots: &[Id], p: &Program) -> Vec<Pass> {
    let report = p.pass_report();
    let (lowered, _) = super::lower::lower(g, roots);
    let mut size = ProgramSize {
        insts: lowered.len(),
        ops: super::OpCount::of(&lowered),
    };
    for r in report {
        assert_eq!(r.before, size, "{r}");
        size = r.after;
    }
    assert_eq!(size.insts, p.insts().len());
    assert_eq!(size.ops, p.op_count());
    report.iter().map(|r| r.pass).collect()
}

#[test]
fn the_report_lists_every_pass_in_order_and_its_counts_chain() {
    for (g, roots) in workloads() {
        let p = Program::lower(&g, &roots);
        assert_eq!(chained_passes(&g, &roots, &p), Pass::ALL);
        // The sharing passes did something on these workloads.
        let first = p.pass_report()[0].before;
        assert!(p.op_count().total() < first.ops.total(), "{first}");
        for off in Pass::ALL {
            let options = LowerOptions::default().without(off);
            let p = Program::lower_with(&g, &roots, &options);
            let want: Vec<Pass> = Pass::ALL.into_iter().filter(|&q| q != off).collect();
            assert_eq!(chained_passes(&g, &roots, &p), want, "without {off}");
        }
        let p = Program::lower_with(&g, &roots, &LowerOptions::none());
        assert!(chained_passes(&g, &roots, &p).is_empty());
    }
}

#[test]
fn without_share_equal_values_a_value_in_two_forms_costs_more() {
    let mut g = Graph::new();
    // (x + y)·(x − y) and x² − y² are one value in two forms; only
    // share_equal_values finds it.
    let roots = [
        g.parse("(x + y)*(x - y)*sin(z)").unwrap(),
        g.parse("(x^2 - y^2)*sin(z)").unwrap(),
    ];
    let with = Program::lower(&g, &roots);
    let options = LowerOptions::default().without(Pass::ShareEqualValues);
    let without = Program::lower_with(&g, &roots, &options);
    agrees(&g, &roots, &with, "with");
    agrees(&g, &roots, &without, "without");
    assert_eq!(with.outputs()[0], with.outputs()[1]);
    assert!(
        with.op_count().total() < without.op_count().total(),
        "{} vs {}",
        with.op_count(),
        without.op_count()
    );
    let merged = with
        .pass_report()
        .iter()
        .find(|r| r.pass == Pass::ShareEqualValues)
        .unwrap();
    assert!(
        merged.after.ops.total() < merged.before.ops.total(),
        "{merged}"
    );
}
