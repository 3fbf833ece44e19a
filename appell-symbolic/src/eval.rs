//! Numeric evaluation of node sets: the reference against which simplification,
//! differentiation and emitted code are tested, and a quick way to look at a
//! derived expression.
//!
//! A [`Tape`] is compiled once from the roots (the reachable nodes in arena
//! order) and evaluated at many points. It is generic over [`Value`], so the
//! same tape runs on `f64` and, in tests, on dual numbers.

use std::ops::{Add, Div, Mul, Neg, Sub};

use crate::error::{Result, SymbolicError};
use crate::graph::{Func, Graph, Id, Node, Symbol};

/// A number type a [`Tape`] can evaluate in.
pub trait Value:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    /// The constant `x`.
    fn from_f64(x: f64) -> Self;
    /// The real part, for finiteness checks.
    fn real(self) -> f64;
    /// `self ^ n`.
    fn powi(self, n: i32) -> Self;
    /// A unary function.
    fn apply(self, f: Func) -> Self;
    /// `atan2(self, x)`.
    fn atan2(self, x: Self) -> Self;
    /// `self ^ y` for a real exponent.
    fn powf(self, y: Self) -> Self;
}

impl Value for f64 {
    fn from_f64(x: f64) -> f64 {
        x
    }
    fn real(self) -> f64 {
        self
    }
    fn powi(self, n: i32) -> f64 {
        f64::powi(self, n)
    }
    fn apply(self, f: Func) -> f64 {
        f.apply(self)
    }
    fn atan2(self, x: f64) -> f64 {
        f64::atan2(self, x)
    }
    fn powf(self, y: f64) -> f64 {
        f64::powf(self, y)
    }
}

#[derive(Clone, Debug)]
enum Step {
    Const(f64),
    Symbol(Symbol),
    Add(f64, Vec<(u32, f64)>),
    Mul(f64, Vec<(u32, i32)>),
    Fun(Func, u32),
    Atan2(u32, u32),
    Powf(u32, u32),
    Select(u32, u32, u32),
}

/// The nodes reachable from some roots, ready to evaluate repeatedly.
///
/// ```
/// use appell_symbolic::{Graph, Tape};
/// let mut g = Graph::new();
/// let e = g.parse("x^2 + sin(y)").unwrap();
/// let x = g.symbol_named("x").unwrap();
/// let y = g.symbol_named("y").unwrap();
/// let tape = Tape::new(&g, &[e]);
/// let v = tape.eval(&|s| if s == x { Some(3.0) } else if s == y { Some(0.0) } else { None }).unwrap();
/// assert_eq!(v, vec![9.0]);
/// ```
#[derive(Clone, Debug)]
pub struct Tape {
    steps: Vec<Step>,
    ids: Vec<Id>,
    outputs: Vec<u32>,
    text: Vec<String>,
}

impl Tape {
    /// Compiles the tape of `roots`.
    pub fn new(g: &Graph, roots: &[Id]) -> Tape {
        let ids = g.reachable(roots);
        let mut slot = vec![u32::MAX; g.len()];
        for (i, id) in ids.iter().enumerate() {
            slot[id.index()] = i as u32;
        }
        let steps = ids
            .iter()
            .map(|&id| match g.node(id) {
                Node::Num(n) => Step::Const(n.to_f64()),
                Node::Sym(s) => Step::Symbol(*s),
                Node::Add { constant, terms } => Step::Add(
                    constant.to_f64(),
                    terms
                        .iter()
                        .map(|&(b, k)| (slot[b.index()], k.to_f64()))
                        .collect(),
                ),
                Node::Mul { coeff, factors } => Step::Mul(
                    coeff.to_f64(),
                    factors.iter().map(|&(b, e)| (slot[b.index()], e)).collect(),
                ),
                Node::Fun(f, a) => Step::Fun(*f, slot[a.index()]),
                Node::Atan2(y, x) => Step::Atan2(slot[y.index()], slot[x.index()]),
                Node::Powf(x, y) => Step::Powf(slot[x.index()], slot[y.index()]),
                Node::Select(c, a, b) => {
                    Step::Select(slot[c.index()], slot[a.index()], slot[b.index()])
                }
            })
            .collect();
        let outputs = roots.iter().map(|r| slot[r.index()]).collect();
        // Names of symbols for error messages; other nodes are named by id
        // (rendering every node would cost more than the evaluation).
        let text = ids
            .iter()
            .map(|&id| match g.node(id) {
                Node::Sym(s) => g.symbol_name(*s).to_string(),
                _ => format!("node #{}", id.index()),
            })
            .collect();
        Tape {
            steps,
            ids,
            outputs,
            text,
        }
    }

    /// Number of nodes on the tape.
    pub fn len(&self) -> usize {
        self.steps.len()
    }

    /// Whether the tape is empty.
    pub fn is_empty(&self) -> bool {
        self.steps.is_empty()
    }

    /// The node ids on the tape, in evaluation order.
    pub fn ids(&self) -> &[Id] {
        &self.ids
    }

    /// Evaluates in `f64`; `env` gives each symbol's value. An unbound symbol
    /// or a non-finite intermediate is an error naming it.
    pub fn eval(&self, env: &dyn Fn(Symbol) -> Option<f64>) -> Result<Vec<f64>> {
        self.eval_as::<f64>(&|s| env(s))
    }

    /// Evaluates in any [`Value`] type.
    pub fn eval_as<T: Value>(&self, env: &dyn Fn(Symbol) -> Option<T>) -> Result<Vec<T>> {
        let mut vals: Vec<T> = Vec::with_capacity(self.steps.len());
        for (i, step) in self.steps.iter().enumerate() {
            let v = match step {
                Step::Const(c) => T::from_f64(*c),
                Step::Symbol(s) => env(*s).ok_or_else(|| SymbolicError::UnboundSymbol {
                    symbol: self.text[i].clone(),
                })?,
                Step::Add(c, terms) => {
                    let mut acc = T::from_f64(*c);
                    for &(b, k) in terms {
                        acc = acc + T::from_f64(k) * vals[b as usize];
                    }
                    acc
                }
                Step::Mul(c, factors) => {
                    let mut acc = T::from_f64(*c);
                    for &(b, e) in factors {
                        let x = vals[b as usize];
                        acc = acc * if e == 1 { x } else { x.powi(e) };
                    }
                    acc
                }
                Step::Fun(f, a) => vals[*a as usize].apply(*f),
                Step::Atan2(y, x) => vals[*y as usize].atan2(vals[*x as usize]),
                Step::Powf(x, y) => vals[*x as usize].powf(vals[*y as usize]),
                Step::Select(c, a, b) => {
                    if vals[*c as usize].real() > 0.0 {
                        vals[*a as usize]
                    } else {
                        vals[*b as usize]
                    }
                }
            };
            if !v.real().is_finite() {
                return Err(SymbolicError::NonFiniteValue {
                    expr: self.text[i].clone(),
                });
            }
            vals.push(v);
        }
        Ok(self.outputs.iter().map(|&o| vals[o as usize]).collect())
    }
}

impl Graph {
    /// Evaluates one expression in `f64` with values given by name.
    ///
    /// ```
    /// use appell_symbolic::Graph;
    /// let mut g = Graph::new();
    /// let e = g.parse("a*cos(phi)").unwrap();
    /// let v = g.eval_named(e, &[("a", 2.0), ("phi", 0.0)]).unwrap();
    /// assert_eq!(v, 2.0);
    /// ```
    pub fn eval_named(&self, e: Id, values: &[(&str, f64)]) -> Result<f64> {
        let bound: Vec<(Symbol, f64)> = values
            .iter()
            .filter_map(|(n, v)| self.symbol_named(n).map(|s| (s, *v)))
            .collect();
        let tape = Tape::new(self, &[e]);
        Ok(tape.eval(&|s| bound.iter().find(|(t, _)| *t == s).map(|(_, v)| *v))?[0])
    }
}
