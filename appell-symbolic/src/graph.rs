//! The interned expression graph: a flat arena of unique nodes.
//!
//! Every node is stored once (hash-consing). A node's children are always
//! earlier entries of the arena, so the arena order is a topological order and
//! structural equality is identity of [`Id`]s. Nodes are built only through the
//! canonicalizing constructors (the `construct` module), so every stored node is
//! in canonical form.

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

use crate::deps::SymbolSet;
use crate::error::{Result, SymbolicError};
pub use crate::handles::{Id, Symbol};
use crate::number::Number;

/// What a symbol stands for. The kind decides how the total time derivative
/// treats it and which symbols may be hoisted out of a hot loop.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SymbolKind {
    /// A model parameter: constant in time, known before simulation.
    Parameter,
    /// A generalized coordinate q_r.
    Coordinate,
    /// The rate q̇ of the given coordinate.
    Rate(Symbol),
    /// The acceleration q̈ of the given coordinate.
    Acceleration(Symbol),
    /// A control input supplied at every call.
    Input,
    /// Time t.
    Time,
    /// Anything else the derivation needs (e.g. a quasi-velocity).
    Auxiliary,
}

/// A declared symbol.
#[derive(Clone, Debug)]
pub struct SymbolInfo {
    /// The name used in text and in emitted code.
    pub name: String,
    /// What it stands for.
    pub kind: SymbolKind,
}

/// A unary function known to the engine.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Func {
    /// Sine.
    Sin,
    /// Cosine.
    Cos,
    /// Tangent.
    Tan,
    /// Exponential.
    Exp,
    /// Natural logarithm.
    Ln,
    /// Absolute value.
    Abs,
    /// Square root.
    Sqrt,
    /// Hyperbolic sine.
    Sinh,
    /// Hyperbolic cosine.
    Cosh,
    /// Hyperbolic tangent.
    Tanh,
    /// Arcsine (principal value, in [−π/2, π/2]).
    Asin,
    /// Arccosine (principal value, in [0, π]).
    Acos,
    /// Arctangent (principal value, in (−π/2, π/2)).
    Atan,
    /// The sign: 1 above zero, −1 below, 0 at zero. Piecewise constant: its
    /// derivative is zero away from 0 (and taken as zero there).
    Sign,
    /// The identity, held: `hold(a + b)` is a sum the constructors treat as
    /// one factor, so a coefficient or a product is not distributed over
    /// it. A recursion over links holds each link's quantities, so that
    /// the next link multiplies them, computed once, instead of expanding
    /// their terms into its own (see `Graph::hold`). Lowered to its
    /// argument: it costs nothing.
    Hold,
}

impl Func {
    /// The name in text and in emitted method calls.
    pub fn name(self) -> &'static str {
        match self {
            Func::Sin => "sin",
            Func::Cos => "cos",
            Func::Tan => "tan",
            Func::Exp => "exp",
            Func::Ln => "ln",
            Func::Abs => "abs",
            Func::Sqrt => "sqrt",
            Func::Sinh => "sinh",
            Func::Cosh => "cosh",
            Func::Tanh => "tanh",
            Func::Asin => "asin",
            Func::Acos => "acos",
            Func::Atan => "atan",
            Func::Sign => "sign",
            Func::Hold => "hold",
        }
    }

    /// The function of that name.
    pub fn from_name(name: &str) -> Option<Func> {
        Some(match name {
            "sin" => Func::Sin,
            "cos" => Func::Cos,
            "tan" => Func::Tan,
            "exp" => Func::Exp,
            "ln" => Func::Ln,
            "abs" => Func::Abs,
            "sqrt" => Func::Sqrt,
            "sinh" => Func::Sinh,
            "cosh" => Func::Cosh,
            "tanh" => Func::Tanh,
            "asin" => Func::Asin,
            "acos" => Func::Acos,
            "atan" => Func::Atan,
            "sign" => Func::Sign,
            _ => return None,
        })
    }

    /// Applies the function to a float.
    pub fn apply(self, x: f64) -> f64 {
        match self {
            // The same functions as the generated code's (`appell-trig`), so
            // that the engine's values and the compiled code's agree.
            Func::Sin => appell_trig::sin(x),
            Func::Cos => appell_trig::cos(x),
            Func::Tan => x.tan(),
            Func::Exp => x.exp(),
            Func::Ln => x.ln(),
            Func::Abs => x.abs(),
            Func::Sqrt => x.sqrt(),
            Func::Sinh => x.sinh(),
            Func::Cosh => x.cosh(),
            Func::Tanh => x.tanh(),
            Func::Asin => x.asin(),
            Func::Acos => x.acos(),
            Func::Atan => x.atan(),
            Func::Sign => sign(x),
            Func::Hold => x,
        }
    }
}

/// The sign of `x` as the engine and the generated code take it: 1, −1,
/// or 0 at zero (and NaN for NaN).
pub fn sign(x: f64) -> f64 {
    if x > 0.0 {
        1.0
    } else if x < 0.0 {
        -1.0
    } else {
        x * 0.0
    }
}

/// One canonical node.
///
/// Invariants (kept by the constructors):
/// - `Add`: at least two parts counting a non-zero constant; term bases are
///   neither numbers, sums nor products with a coefficient other than 1;
///   coefficients non-zero; sorted by id without repeats.
/// - `Mul`: non-zero coefficient; factor bases are neither numbers nor
///   products; exponents non-zero; sorted by id without repeats; never a bare
///   `1 * x^1`, never `c * (a + b)^1` (the coefficient is distributed).
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub enum Node {
    /// A constant.
    Num(Number),
    /// A symbol.
    Sym(Symbol),
    /// `constant + Σ coefficient · base`.
    Add {
        /// The constant part.
        constant: Number,
        /// `(base, coefficient)` pairs.
        terms: Box<[(Id, Number)]>,
    },
    /// `coefficient · Π base ^ exponent`.
    Mul {
        /// The numeric coefficient.
        coeff: Number,
        /// `(base, exponent)` pairs.
        factors: Box<[(Id, i32)]>,
    },
    /// A unary function.
    Fun(Func, Id),
    /// `atan2(y, x)`.
    Atan2(Id, Id),
    /// `powf(x, y)`: x to a power that is not an integer constant.
    Powf(Id, Id),
    /// `select(c, a, b)`: `a` where `c > 0`, else `b` (a conditional, and
    /// `min` and `max`).
    Select(Id, Id, Id),
}

impl Node {
    /// The children of this node, in order.
    pub fn children(&self) -> Vec<Id> {
        match self {
            Node::Num(_) | Node::Sym(_) => Vec::new(),
            Node::Add { terms, .. } => terms.iter().map(|t| t.0).collect(),
            Node::Mul { factors, .. } => factors.iter().map(|f| f.0).collect(),
            Node::Fun(_, a) => vec![*a],
            Node::Atan2(y, x) | Node::Powf(y, x) => vec![*y, *x],
            Node::Select(c, a, b) => vec![*c, *a, *b],
        }
    }

    pub(crate) fn for_each_child(&self, mut f: impl FnMut(Id)) {
        match self {
            Node::Num(_) | Node::Sym(_) => {}
            Node::Add { terms, .. } => terms.iter().for_each(|t| f(t.0)),
            Node::Mul { factors, .. } => factors.iter().for_each(|t| f(t.0)),
            Node::Fun(_, a) => f(*a),
            Node::Atan2(y, x) | Node::Powf(y, x) => {
                f(*y);
                f(*x)
            }
            Node::Select(c, a, b) => {
                f(*c);
                f(*a);
                f(*b)
            }
        }
    }
}

/// Bounds on all work the engine does, so a derivation inside a proc macro
/// always terminates in predictable time.
///
/// ```
/// use appell_symbolic::{Graph, Limits, SymbolicError};
/// let mut g = Graph::with_limits(Limits { max_nodes: 8, ..Limits::default() });
/// let r = g.parse("sin(x) + cos(y) * exp(z) + x * y * z");
/// assert!(matches!(r, Err(SymbolicError::NodeLimit { limit: 8 })));
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Limits {
    /// Most nodes the arena may hold.
    pub max_nodes: usize,
    /// Most terms in one sum, and in the result of [`Graph::expand`].
    pub max_terms: usize,
    /// Most rewrite passes of the trigonometric collapse within one sum.
    pub max_rewrite_passes: usize,
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            max_nodes: 4_000_000,
            max_terms: 20_000,
            max_rewrite_passes: 64,
        }
    }
}

/// Counters of what the graph did, for benchmarks and diagnostics.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Stats {
    /// Constructor calls that found their node already interned.
    pub intern_hits: u64,
    /// Trigonometric collapses applied (`sin² + cos² → 1` and relatives).
    pub trig_collapses: u64,
    /// Sums in which the rewrite-pass limit stopped the trigonometric collapse.
    pub rewrite_limit_stops: u64,
}

/// A fast, deterministic hasher (the Fx hash of rustc) for interning.
#[derive(Default, Clone, Copy)]
pub(crate) struct FxHasher {
    hash: u64,
}

const SEED: u64 = 0x51_7c_c1_b7_27_22_0a_95;

impl Hasher for FxHasher {
    fn write(&mut self, bytes: &[u8]) {
        for chunk in bytes.chunks(8) {
            let mut buf = [0u8; 8];
            buf[..chunk.len()].copy_from_slice(chunk);
            self.write_u64(u64::from_le_bytes(buf));
        }
    }
    fn write_u8(&mut self, i: u8) {
        self.write_u64(i as u64)
    }
    fn write_u32(&mut self, i: u32) {
        self.write_u64(i as u64)
    }
    fn write_u64(&mut self, i: u64) {
        self.hash = (self.hash.rotate_left(5) ^ i).wrapping_mul(SEED);
    }
    fn write_usize(&mut self, i: usize) {
        self.write_u64(i as u64)
    }
    fn finish(&self) -> u64 {
        self.hash
    }
}

pub(crate) type FxBuild = BuildHasherDefault<FxHasher>;
pub(crate) type FxHashMap<K, V> = HashMap<K, V, FxBuild>;

/// The expression arena. All expressions of one derivation live in one graph.
///
/// ```
/// use appell_symbolic::Graph;
/// let mut g = Graph::new();
/// let a = g.parse("x * (y + 1)").unwrap();
/// let b = g.parse("(1 + y) * x").unwrap();
/// assert_eq!(a, b); // hash-consed and canonical: same expression, same id
/// assert_eq!(g.display(a).to_string(), "x*(y + 1)");
/// ```
#[derive(Clone)]
pub struct Graph {
    pub(crate) nodes: Vec<Node>,
    pub(crate) deps: Vec<SymbolSet>,
    pub(crate) index: FxHashMap<Node, Id>,
    pub(crate) symbols: Vec<SymbolInfo>,
    pub(crate) symbol_names: FxHashMap<String, Symbol>,
    pub(crate) limits: Limits,
    pub(crate) stats: Stats,
    pub(crate) diff_memo: FxHashMap<(Id, Symbol), Id>,
    /// [`Graph::diff_held`]'s memo.
    pub(crate) held_diff_memo: FxHashMap<(Id, Symbol), Id>,
    /// Whether the derivative being taken holds held factors' derivatives.
    pub(crate) hold_derivatives: bool,
    pub(crate) derivative_symbol: FxHashMap<Symbol, Symbol>,
}

impl Default for Graph {
    fn default() -> Self {
        Self::new()
    }
}

impl Graph {
    /// An empty graph with default [`Limits`].
    pub fn new() -> Graph {
        Self::with_limits(Limits::default())
    }

    /// An empty graph with the given limits.
    pub fn with_limits(limits: Limits) -> Graph {
        Graph {
            nodes: Vec::new(),
            deps: Vec::new(),
            index: FxHashMap::default(),
            symbols: Vec::new(),
            symbol_names: FxHashMap::default(),
            limits,
            stats: Stats::default(),
            diff_memo: FxHashMap::default(),
            held_diff_memo: FxHashMap::default(),
            hold_derivatives: false,
            derivative_symbol: FxHashMap::default(),
        }
    }

    /// The limits in force.
    pub fn limits(&self) -> Limits {
        self.limits
    }

    /// Replaces the limits (a stage that may grow the graph past what it
    /// can use lowers `max_nodes` while it runs, and stops at the typed
    /// error). Nodes already built stay.
    ///
    /// ```
    /// use appell_symbolic::{Graph, Limits, SymbolicError};
    /// let mut g = Graph::new();
    /// let x = g.parse("x").unwrap();
    /// g.set_limits(Limits { max_nodes: g.len(), ..g.limits() });
    /// assert!(matches!(g.parse("x^2 + 1"), Err(SymbolicError::NodeLimit { .. })));
    /// assert_eq!(g.parse("x").unwrap(), x);
    /// ```
    pub fn set_limits(&mut self, limits: Limits) {
        self.limits = limits;
    }

    /// Counters of the work done so far.
    pub fn stats(&self) -> Stats {
        self.stats
    }

    /// Number of nodes in the arena.
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// Whether the arena is empty.
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// The node behind an id.
    pub fn node(&self, id: Id) -> &Node {
        &self.nodes[id.index()]
    }

    /// Interns a canonical node. Only the constructors call this.
    pub(crate) fn intern(&mut self, node: Node) -> Result<Id> {
        if let Some(&id) = self.index.get(&node) {
            self.stats.intern_hits += 1;
            return Ok(id);
        }
        if self.nodes.len() >= self.limits.max_nodes {
            return Err(SymbolicError::NodeLimit {
                limit: self.limits.max_nodes,
            });
        }
        let deps = match &node {
            Node::Num(_) => SymbolSet::new(),
            Node::Sym(s) => SymbolSet::single(*s),
            _ => {
                let mut set = SymbolSet::new();
                node.for_each_child(|c| set.union_with(&self.deps[c.index()]));
                set
            }
        };
        let id = Id(self.nodes.len() as u32);
        self.nodes.push(node.clone());
        self.deps.push(deps);
        self.index.insert(node, id);
        Ok(id)
    }

    /// The id of an already interned node, without creating it.
    pub fn lookup(&self, node: &Node) -> Option<Id> {
        self.index.get(node).copied()
    }

    // ----- symbols -------------------------------------------------------

    /// Declares a symbol (or returns the existing one of that name and kind).
    pub fn declare(&mut self, name: &str, kind: SymbolKind) -> Result<Symbol> {
        if let Some(&s) = self.symbol_names.get(name) {
            if self.symbols[s.index()].kind == kind {
                return Ok(s);
            }
            return Err(SymbolicError::SymbolKindConflict {
                name: name.to_string(),
            });
        }
        let s = Symbol(self.symbols.len() as u32);
        self.symbols.push(SymbolInfo {
            name: name.to_string(),
            kind,
        });
        self.symbol_names.insert(name.to_string(), s);
        Ok(s)
    }

    /// Declares a model parameter.
    pub fn parameter(&mut self, name: &str) -> Result<Symbol> {
        self.declare(name, SymbolKind::Parameter)
    }

    /// Declares an input.
    pub fn input(&mut self, name: &str) -> Result<Symbol> {
        self.declare(name, SymbolKind::Input)
    }

    /// Declares (or returns) time `t`.
    pub fn time(&mut self) -> Result<Symbol> {
        self.declare("t", SymbolKind::Time)
    }

    /// Declares a generalized coordinate `q` with its rate `q_dot` and
    /// acceleration `q_ddot`.
    ///
    /// ```
    /// use appell_symbolic::{Graph, SymbolKind};
    /// let mut g = Graph::new();
    /// let phi = g.coordinate("phi").unwrap();
    /// assert_eq!(g.symbol_name(phi.rate), "phi_dot");
    /// assert_eq!(g.symbol_kind(phi.accel), SymbolKind::Acceleration(phi.q));
    /// ```
    pub fn coordinate(&mut self, name: &str) -> Result<Coordinate> {
        let q = self.declare(name, SymbolKind::Coordinate)?;
        let rate = self.declare(&format!("{name}_dot"), SymbolKind::Rate(q))?;
        let accel = self.declare(&format!("{name}_ddot"), SymbolKind::Acceleration(q))?;
        self.derivative_symbol.insert(q, rate);
        self.derivative_symbol.insert(rate, accel);
        Ok(Coordinate { q, rate, accel })
    }

    /// The symbol whose value is the time derivative of `s`: q̇ for a
    /// coordinate q, q̈ for q̇.
    pub fn derivative_symbol(&self, s: Symbol) -> Option<Symbol> {
        self.derivative_symbol.get(&s).copied()
    }

    /// The symbol of that name, if declared.
    pub fn symbol_named(&self, name: &str) -> Option<Symbol> {
        self.symbol_names.get(name).copied()
    }

    /// A symbol's name.
    pub fn symbol_name(&self, s: Symbol) -> &str {
        &self.symbols[s.index()].name
    }

    /// A symbol's kind.
    pub fn symbol_kind(&self, s: Symbol) -> SymbolKind {
        self.symbols[s.index()].kind
    }

    /// All declared symbols, in declaration order.
    pub fn symbols(&self) -> impl Iterator<Item = (Symbol, &SymbolInfo)> {
        self.symbols
            .iter()
            .enumerate()
            .map(|(i, s)| (Symbol(i as u32), s))
    }

    /// Number of declared symbols.
    pub fn symbol_count(&self) -> usize {
        self.symbols.len()
    }

    // ----- dependency queries ---------------------------------------------

    /// The set of symbols an expression depends on.
    ///
    /// ```
    /// use appell_symbolic::Graph;
    /// let mut g = Graph::new();
    /// let e = g.parse("a * sin(q) + b").unwrap();
    /// let q = g.symbol_named("q").unwrap();
    /// let z = g.symbol_named("b").unwrap();
    /// assert!(g.depends_on(e, q));
    /// let s = g.parse("sin(q)").unwrap();
    /// assert!(!g.depends_on(s, z));
    /// ```
    pub fn dependencies(&self, id: Id) -> &SymbolSet {
        &self.deps[id.index()]
    }

    /// Whether `id` depends on symbol `s`.
    pub fn depends_on(&self, id: Id, s: Symbol) -> bool {
        self.deps[id.index()].contains(s)
    }

    /// Whether `id` depends on any symbol of `set`.
    pub fn depends_on_any(&self, id: Id, set: &SymbolSet) -> bool {
        self.deps[id.index()].intersects(set)
    }

    /// The set of all symbols of the given kinds.
    pub fn symbols_where(&self, mut pred: impl FnMut(SymbolKind) -> bool) -> SymbolSet {
        let mut set = SymbolSet::new();
        for (s, info) in self.symbols() {
            if pred(info.kind) {
                set.insert(s);
            }
        }
        set
    }

    /// Whether `id` depends on parameters (and constants) only, so that it can
    /// be computed once per parameter set.
    pub fn is_parameter_only(&self, id: Id) -> bool {
        self.deps[id.index()]
            .iter()
            .all(|s| self.symbol_kind(s) == SymbolKind::Parameter)
    }

    /// The constant value of a node, if it is a number.
    pub fn as_number(&self, id: Id) -> Option<Number> {
        match self.node(id) {
            Node::Num(n) => Some(*n),
            _ => None,
        }
    }

    /// Whether the node is exactly zero.
    pub fn is_zero(&self, id: Id) -> bool {
        self.as_number(id).is_some_and(|n| n.is_zero())
    }

    /// The ids reachable from `roots`, in arena (topological) order.
    pub fn reachable(&self, roots: &[Id]) -> Vec<Id> {
        let mut seen = vec![false; self.nodes.len()];
        let mut stack: Vec<Id> = roots.to_vec();
        while let Some(id) = stack.pop() {
            if seen[id.index()] {
                continue;
            }
            seen[id.index()] = true;
            self.nodes[id.index()].for_each_child(|c| {
                if !seen[c.index()] {
                    stack.push(c)
                }
            });
        }
        seen.iter()
            .enumerate()
            .filter(|(_, &s)| s)
            .map(|(i, _)| Id(i as u32))
            .collect()
    }

    /// Number of distinct nodes reachable from `roots` (the DAG size),
    /// not counting [`Func::Hold`], which the emitted code does not see.
    pub fn dag_size(&self, roots: &[Id]) -> usize {
        let reachable = self.reachable(roots);
        let held = reachable
            .iter()
            .filter(|&&id| matches!(self.node(id), Node::Fun(Func::Hold, _)))
            .count();
        reachable.len() - held
    }
}

/// A generalized coordinate with its rate and acceleration symbols.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Coordinate {
    /// q.
    pub q: Symbol,
    /// q̇.
    pub rate: Symbol,
    /// q̈.
    pub accel: Symbol,
}
