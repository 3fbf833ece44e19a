//! [`Pass::ShareEqualValues`](super::Pass::ShareEqualValues): one
//! instruction for each value computed in several forms.

use crate::graph::{Func, FxHashMap, Graph, Symbol, SymbolKind};
use crate::number::Number;

use super::super::inst::{parameter_only_flags, Inst};
use super::modp::{add, int, inv, mul, neg, pow, P};
use super::rewrite;

/// Number of random points [`share_equal_values`] compares at.
const VALUE_POINTS: usize = 2;

/// One instruction for each value that several compute in different forms.
///
/// The graph's canonical forms leave some equal values apart (a sum kept
/// factored in one place and multiplied out in another); after lowering,
/// such a pair is two instructions. Every instruction is evaluated exactly,
/// modulo the prime 2⁶¹ − 1, at [`VALUE_POINTS`] pseudo-random points: each
/// symbol, each call other than sine, cosine and tangent (a square root,
/// say), each `atan2`, each non-integer constant and each rational constant
/// too large for the prime stands for an independent random residue, and
/// the sine and cosine of one argument for a random point of the unit
/// circle (rationally parametrized). Every kind of variable draws from its
/// own stream, so a sine's argument that is a small integer cannot tie it to
/// a symbol. Two instructions with the same residues (or opposite ones) at
/// every point are then the same rational function of those variables,
/// except with a probability of about (degree / 2⁶¹)² (Schwartz–Zippel), and
/// so the same value at every state; the later one is replaced by the
/// earlier (or its negation), which may be a symbol or a constant: `(a − b)
/// − a` becomes `−b`. Identities that need more of a function's meaning
/// than sin² + cos² = 1 (the double angle, √x² = |x|) are not found, which
/// only misses a merge.
///
/// The earlier form is used only where it reads no auxiliary symbol (the
/// unknowns of a solve, which a staged program computes between stages) or
/// acceleration the later one does not, and reads the state only if the
/// later one does: a value stays in its stage, and a parameter-only value
/// stays computed once per parameter set. Values change only by the
/// rounding of the form dropped.
pub(super) fn share_equal_values(
    graph: &Graph,
    insts: Vec<Inst>,
    outputs: Vec<u32>,
) -> (Vec<Inst>, Vec<u32>) {
    let n = insts.len();
    let reads = Reads::new(graph, &insts);
    let values = residues(&insts);
    // The instructions met so far, by value, earliest first; constants and
    // symbols are among them but are never replaced themselves.
    let mut earlier: FxHashMap<[u64; VALUE_POINTS], Vec<u32>> = FxHashMap::default();
    let mut replace: Vec<Option<(u32, bool)>> = vec![None; n];
    for (j, inst) in insts.iter().enumerate() {
        let Some(v) = values[j] else { continue };
        if v.iter().all(|&x| x == 0) {
            continue;
        }
        let leaf = matches!(inst, Inst::Const(_) | Inst::Symbol(_));
        if !leaf {
            let usable = |key: &[u64; VALUE_POINTS]| {
                earlier
                    .get(key)
                    .and_then(|c| c.iter().copied().find(|&i| reads.within(i as usize, j)))
            };
            replace[j] = usable(&v)
                .map(|i| (i, false))
                .or_else(|| usable(&v.map(neg)).map(|i| (i, true)));
        }
        if replace[j].is_none() {
            earlier.entry(v).or_default().push(j as u32);
        }
    }
    rewrite(insts, outputs, |j, _, out, map| {
        let (i, is_negated) = replace[j]?;
        let at = map[i as usize];
        Some(if is_negated { negated(out, at) } else { at })
    })
}

/// What each instruction reads, directly or not, that an equal earlier
/// form may not add: the state (`parameter_only_flags`), and the auxiliary
/// symbols and accelerations, a bit each, `words` words per instruction.
struct Reads {
    parameter: Vec<bool>,
    late: Vec<u64>,
    words: usize,
}

impl Reads {
    fn new(graph: &Graph, insts: &[Inst]) -> Reads {
        let n = insts.len();
        let parameter = parameter_only_flags(graph, insts);
        let mut late_bit: FxHashMap<Symbol, usize> = FxHashMap::default();
        for inst in insts {
            if let Inst::Symbol(s) = *inst {
                if matches!(
                    graph.symbol_kind(s),
                    SymbolKind::Auxiliary | SymbolKind::Acceleration(_)
                ) {
                    let next = late_bit.len();
                    late_bit.entry(s).or_insert(next);
                }
            }
        }
        let words = late_bit.len().div_ceil(64).max(1);
        let mut late = vec![0u64; n * words];
        for (i, inst) in insts.iter().enumerate() {
            if let Some(&bit) = match *inst {
                Inst::Symbol(s) => late_bit.get(&s),
                _ => None,
            } {
                late[i * words + bit / 64] |= 1 << (bit % 64);
            }
            for x in inst.operands() {
                for w in 0..words {
                    late[i * words + w] |= late[x as usize * words + w];
                }
            }
        }
        Reads {
            parameter,
            late,
            words,
        }
    }

    /// Whether instruction `i` reads nothing of the state, nor auxiliary
    /// symbol or acceleration, that instruction `j` does not.
    fn within(&self, i: usize, j: usize) -> bool {
        let (late, words) = (&self.late, self.words);
        (self.parameter[i] || !self.parameter[j])
            && (0..words).all(|w| late[i * words + w] & !late[j * words + w] == 0)
    }
}

/// A residue per instruction and point; None where a division by zero
/// (a probability of about 2⁻⁶¹) leaves it undefined.
fn residues(insts: &[Inst]) -> Vec<Option<[u64; VALUE_POINTS]>> {
    let n = insts.len();
    let mix = |mut z: u64| {
        z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        (z ^ (z >> 31)) % P
    };
    // The streams the kinds of variable draw from.
    const FLOAT: u64 = 0xF10A_7000_0000_0001;
    const RATIONAL: u64 = 0x4A71_0000_0000_0002;
    const SYMBOL: u64 = 0x5E4B_0000_0000_0003;
    const CIRCLE: u64 = 0xC14C_1E00_0000_0004;
    const CALL: u64 = 0xCA11_0000_0000_0005;
    let mut values: Vec<Option<[u64; VALUE_POINTS]>> = Vec::with_capacity(n);
    for (i, inst) in insts.iter().enumerate() {
        let mut out = [0u64; VALUE_POINTS];
        let mut defined = true;
        for (k, slot) in out.iter_mut().enumerate() {
            let v = |x: u32| values[x as usize].map(|v| v[k]);
            let fresh = |kind: u64, x: u64| mix(mix(x ^ kind).wrapping_add(k as u64 + 1));
            let r = match *inst {
                Inst::Const(c) => match c {
                    Number::Rational { num, den }
                        if num.unsigned_abs() < P as u128 && den.unsigned_abs() < P as u128 =>
                    {
                        inv(int(den)).map(|d| mul(int(num), d))
                    }
                    // Too large for the prime: two such constants could
                    // share a residue, so each is a variable of its own.
                    Number::Rational { num, den } => {
                        let fold = |x: i128| mix(x as u64) ^ ((x >> 64) as u64);
                        Some(fresh(RATIONAL, fold(num) ^ mix(fold(den))))
                    }
                    Number::Float(_) => Some(fresh(FLOAT, c.to_f64().to_bits())),
                },
                Inst::Symbol(s) => Some(fresh(SYMBOL, s.0 as u64)),
                Inst::Add(a, b) => v(a).zip(v(b)).map(|(a, b)| add(a, b)),
                Inst::Sub(a, b) => v(a).zip(v(b)).map(|(a, b)| add(a, neg(b))),
                Inst::Mul(a, b) => v(a).zip(v(b)).map(|(a, b)| mul(a, b)),
                Inst::Div(a, b) => v(a).zip(v(b).and_then(inv)).map(|(a, b)| mul(a, b)),
                Inst::Neg(a) => v(a).map(neg),
                Inst::Powi(a, e) => v(a).and_then(|a| {
                    let base = if e < 0 { inv(a)? } else { a };
                    Some(pow(base, e.unsigned_abs() as u64))
                }),
                // The sine and cosine of one argument are a point of the
                // unit circle, (2t, 1 − t²)/(1 + t²) for a t drawn from the
                // argument's residue, so sin² + cos² = 1 holds exactly.
                Inst::Call(f @ (Func::Sin | Func::Cos | Func::Tan), a) => v(a).and_then(|a| {
                    let t = fresh(CIRCLE, a);
                    let d = inv(add(1, mul(t, t)))?;
                    let sin = mul(add(t, t), d);
                    let cos = mul(add(1, neg(mul(t, t))), d);
                    Some(match f {
                        Func::Sin => sin,
                        Func::Cos => cos,
                        _ => mul(sin, inv(cos)?),
                    })
                }),
                // Other calls and atan2 are variables of their own.
                Inst::Call(..) | Inst::Atan2(..) | Inst::Powf(..) | Inst::Select(..) => {
                    Some(fresh(CALL, i as u64))
                }
            };
            match r {
                Some(r) => *slot = r,
                None => defined = false,
            }
        }
        values.push(defined.then_some(out));
    }
    values
}

/// `−v` appended to `out`, folded into a constant or into a negation it
/// undoes; returns its index.
fn negated(out: &mut Vec<Inst>, v: u32) -> u32 {
    match out[v as usize] {
        Inst::Const(c) => out.push(Inst::Const(-c)),
        Inst::Neg(y) => return y,
        _ => out.push(Inst::Neg(v)),
    }
    (out.len() - 1) as u32
}

#[cfg(test)]
mod tests {
    use crate::emit::passes::Pass;
    use crate::emit::tests::{program, values};
    use crate::emit::Inst;
    use crate::graph::{Func, Graph, SymbolKind};
    use crate::number::Number;

    #[test]
    fn terms_added_and_subtracted_cancel_between_instructions() {
        let mut g = Graph::new();
        let [x, y, z] = ["x", "y", "z"].map(|n| g.declare(n, SymbolKind::Auxiliary).unwrap());
        use Inst::*;
        // t = x·x − 1 shared; z·(t − x·x) is −z and y·(x·x − t) is y.
        let insts = vec![
            Symbol(x),
            Symbol(y),
            Symbol(z),
            Const(Number::ONE),
            Mul(0, 0),
            Sub(4, 3),
            Sub(5, 4),
            Mul(2, 6),
            Sub(4, 5),
            Mul(1, 8),
            // (x + y) − x is y, and (y − z) + z is y.
            Add(0, 1),
            Sub(10, 0),
            Sub(1, 2),
            Add(12, 2),
            Mul(11, 13),
        ];
        let outputs = vec![7, 9, 14];
        let (after, outs) = Pass::ShareEqualValues.run(&g, insts, outputs);
        let program = program(after, outs);
        let got = program.eval(&values(&g)).unwrap();
        assert_eq!(got, vec![-2.1, -1.3, 1.3 * 1.3]);
        let ops = program.op_count();
        // −z, y as is, and y·y: one negation and one product.
        assert_eq!(
            (ops.neg, ops.mul, ops.add, ops.total()),
            (1, 1, 0, 2),
            "{ops}"
        );
    }

    #[test]
    fn a_value_computed_in_two_forms_is_computed_once() {
        let mut g = Graph::new();
        let [x, y] = ["x", "y"].map(|n| g.declare(n, SymbolKind::Auxiliary).unwrap());
        use Inst::*;
        let insts = vec![
            Symbol(x),
            Symbol(y),
            // (x + y)(x − y), x·x − y·y and y·y − x·x.
            Add(0, 1),
            Sub(0, 1),
            Mul(2, 3),
            Mul(0, 0),
            Mul(1, 1),
            Sub(5, 6),
            Sub(6, 5),
            // √(x·x)·√(x·x) equals x·x but reads a square root: kept.
            Call(Func::Sqrt, 5),
            Mul(9, 9),
        ];
        let outputs = vec![4, 7, 8, 10, 5];
        let (after, outs) = Pass::ShareEqualValues.run(&g, insts, outputs);
        assert_eq!(outs[1], outs[0], "{after:?}");
        assert_eq!(after[outs[2] as usize], Neg(outs[0]), "{after:?}");
        assert_ne!(outs[3], outs[4], "{after:?}");
        assert!(matches!(after[outs[3] as usize], Mul(..)), "{after:?}");
    }

    #[test]
    fn an_equal_earlier_form_that_reads_more_is_not_used() {
        let mut g = Graph::new();
        let p = g.parameter("p").unwrap();
        let x = g.declare("x", SymbolKind::Coordinate).unwrap();
        let a = g.declare("a", SymbolKind::Auxiliary).unwrap();
        use Inst::*;
        let insts = vec![
            Symbol(p),
            Symbol(x),
            Symbol(a),
            // (p + x)·p − x·p reads the state; p·p, later, is computed once
            // per parameter set and stays so.
            Add(0, 1),
            Mul(3, 0),
            Mul(1, 0),
            Sub(4, 5),
            Mul(0, 0),
            // (x + a)·x − a·x reads the unknown a of a later stage; x·x,
            // later, must not wait for it.
            Add(1, 2),
            Mul(8, 1),
            Mul(2, 1),
            Sub(9, 10),
            Mul(1, 1),
            // (x·x + a) − a reads x and a, like both forms of x·x before
            // it: either may stand for it.
            Add(12, 2),
            Sub(13, 2),
        ];
        let outputs = vec![6, 7, 11, 12, 14];
        let (after, outs) = Pass::ShareEqualValues.run(&g, insts, outputs);
        assert_ne!(outs[1], outs[0], "{after:?}");
        assert_eq!(after[outs[1] as usize], Mul(0, 0), "{after:?}");
        assert_ne!(outs[3], outs[2], "{after:?}");
        assert!([outs[2], outs[3]].contains(&outs[4]), "{after:?}");
        assert_eq!(after.len(), 13, "{after:?}");
    }
}
