//! Helpers for the tests of lowering and of the passes.

use super::inst::use_counts;
use super::{Inst, Program};
use crate::graph::{Graph, Id, Symbol};

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
    }
}
