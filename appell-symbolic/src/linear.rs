//! Linear structure: coefficients of expressions that must be linear in some
//! symbols (velocity constraints → D(q,t) and d(q,t), eq. 25; accelerations
//! split off the Appell function), and a small symbolic solve for the
//! dependent-speed block D' (eq. 27) that pivots only on entries it can prove
//! non-zero.

use std::collections::{BTreeSet, HashMap};

use crate::deps::SymbolSet;
use crate::error::{Result, SymbolicError};
use crate::graph::{Func, Graph, Id, Node, Symbol};

/// `e = Σ coefficients[i] · symbols[i] + remainder`, with no coefficient and
/// no remainder depending on any of the symbols.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LinearForm {
    /// One coefficient per requested symbol.
    pub coefficients: Vec<Id>,
    /// The part free of the symbols.
    pub remainder: Id,
}

/// A dense matrix of expressions, row-major.
///
/// ```
/// use appell_symbolic::{Graph, SymMatrix};
/// let mut g = Graph::new();
/// let m = SymMatrix::parse(&mut g, &[&["a", "0"], &["1", "b"]]).unwrap();
/// assert_eq!((m.rows(), m.cols()), (2, 2));
/// assert!(g.is_zero(m[(0, 1)]));
/// ```
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SymMatrix {
    rows: usize,
    cols: usize,
    entries: Vec<Id>,
}

impl SymMatrix {
    /// A matrix from row-major entries.
    pub fn from_rows(rows: usize, cols: usize, entries: Vec<Id>) -> Result<SymMatrix> {
        if entries.len() != rows * cols {
            return Err(SymbolicError::DimensionMismatch {
                expected: format!("{rows}×{cols} = {} entries", rows * cols),
                found: format!("{} entries", entries.len()),
            });
        }
        Ok(SymMatrix {
            rows,
            cols,
            entries,
        })
    }

    /// A matrix of parsed entries (for tests and docs).
    pub fn parse(g: &mut Graph, rows: &[&[&str]]) -> Result<SymMatrix> {
        let cols = rows.first().map_or(0, |r| r.len());
        let mut entries = Vec::new();
        for r in rows {
            if r.len() != cols {
                return Err(SymbolicError::DimensionMismatch {
                    expected: format!("{cols} columns"),
                    found: format!("{} columns", r.len()),
                });
            }
            for s in r.iter() {
                entries.push(g.parse(s)?);
            }
        }
        SymMatrix::from_rows(rows.len(), cols, entries)
    }

    /// Number of rows.
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// Number of columns.
    pub fn cols(&self) -> usize {
        self.cols
    }

    /// The entries, row-major.
    pub fn entries(&self) -> &[Id] {
        &self.entries
    }
}

impl std::ops::Index<(usize, usize)> for SymMatrix {
    type Output = Id;
    fn index(&self, (r, c): (usize, usize)) -> &Id {
        &self.entries[r * self.cols + c]
    }
}

impl std::ops::IndexMut<(usize, usize)> for SymMatrix {
    fn index_mut(&mut self, (r, c): (usize, usize)) -> &mut Id {
        &mut self.entries[r * self.cols + c]
    }
}

/// What the caller knows about symbols and expressions: which never vanish
/// and which are positive. Everything else may be zero.
#[derive(Clone, Debug, Default)]
pub struct Assumptions {
    nonzero_symbols: SymbolSet,
    positive_symbols: SymbolSet,
    nonzero_exprs: BTreeSet<Id>,
}

impl Assumptions {
    /// Nothing assumed.
    pub fn new() -> Assumptions {
        Assumptions::default()
    }

    /// Declares a symbol positive (e.g. a radius or a mass).
    pub fn positive(mut self, s: Symbol) -> Assumptions {
        self.positive_symbols.insert(s);
        self.nonzero_symbols.insert(s);
        self
    }

    /// Declares a symbol non-zero.
    pub fn nonzero(mut self, s: Symbol) -> Assumptions {
        self.nonzero_symbols.insert(s);
        self
    }

    /// Declares an expression non-vanishing.
    pub fn nonzero_expr(mut self, e: Id) -> Assumptions {
        self.nonzero_exprs.insert(e);
        self
    }
}

/// The sign of an expression as far as it can be proven.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sign {
    /// Provably > 0.
    Positive,
    /// Provably < 0.
    Negative,
    /// Provably ≠ 0, sign unknown.
    NonZero,
    /// Nothing proven (may vanish).
    Unknown,
}

impl Sign {
    fn nonzero(self) -> bool {
        self != Sign::Unknown
    }
    fn flip(self) -> Sign {
        match self {
            Sign::Positive => Sign::Negative,
            Sign::Negative => Sign::Positive,
            s => s,
        }
    }
}

/// The result of [`Graph::solve_linear`].
#[derive(Clone, Debug)]
pub struct LinearSolution {
    /// `X` with `A X = B`.
    pub x: SymMatrix,
    /// `det A`, the signed product of the pivots.
    pub determinant: Id,
    /// The pivot row chosen for each unknown, in elimination order.
    pub pivot_rows: Vec<usize>,
}

/// The result of [`Graph::eliminate`]: the unknowns with provably safe
/// pivots solved symbolically in terms of the rest, and the remaining square
/// system (the Schur complement) left for a numeric solve.
///
/// With `x_f` the free unknowns (solved numerically from `s x_f = s_rhs`),
/// every pivoted unknown `pivot_cols[i]` is `pivot_rhs[i] − Σ_j pivot_free[i][j] x_f[j]`.
#[derive(Clone, Debug)]
pub struct PartialSolution {
    /// Unknowns solved symbolically, in elimination order.
    pub pivot_cols: Vec<usize>,
    /// Their right-hand sides (one row per pivoted unknown, one column per
    /// right-hand side of the system).
    pub pivot_rhs: SymMatrix,
    /// Their coefficients on the free unknowns.
    pub pivot_free: SymMatrix,
    /// The unknowns left for the numeric solve.
    pub free_cols: Vec<usize>,
    /// The remaining square system's matrix (free × free).
    pub s: SymMatrix,
    /// Its right-hand sides.
    pub s_rhs: SymMatrix,
}

impl Graph {
    /// Gauss–Jordan elimination that pivots only where it is provably safe and
    /// leaves the rest for a numeric solve: scalar pivots that are provably
    /// non-zero first (the smallest), then 2×2 block pivots whose determinant
    /// is provably non-zero after expansion (a rotation block such as
    /// `[[cos q, sin q], [−sin q, cos q]]` has determinant 1 although no entry
    /// is safe). Unknowns without a safe pivot, and the rows left over, form
    /// the square system of [`PartialSolution::s`]. A structurally zero
    /// column is [`SymbolicError::StructurallySingular`].
    ///
    /// ```
    /// use appell_symbolic::{Assumptions, Graph, SymMatrix};
    /// let mut g = Graph::new();
    /// // Two unknowns rotated by q, a third with a pivot that may vanish.
    /// let a = SymMatrix::parse(&mut g, &[
    ///     &["cos(q)", "sin(q)", "0"],
    ///     &["-sin(q)", "cos(q)", "0"],
    ///     &["x", "0", "p"],
    /// ]).unwrap();
    /// let b = SymMatrix::parse(&mut g, &[&["u"], &["v"], &["w"]]).unwrap();
    /// let sol = g.eliminate(&a, &b, &Assumptions::new()).unwrap();
    /// assert_eq!(sol.pivot_cols, vec![0, 1]); // by the rotation block
    /// assert_eq!(sol.free_cols, vec![2]);     // p may vanish: numeric
    /// assert_eq!(g.display(sol.s[(0, 0)]).to_string(), "p");
    /// ```
    pub fn eliminate(
        &mut self,
        a: &SymMatrix,
        b: &SymMatrix,
        assumptions: &Assumptions,
    ) -> Result<PartialSolution> {
        let n = a.rows;
        if a.cols != n || b.rows != n {
            return Err(SymbolicError::DimensionMismatch {
                expected: format!("a square A and B with {n} rows"),
                found: format!("A {}×{}, B {}×{}", a.rows, a.cols, b.rows, b.cols),
            });
        }
        let m = b.cols;
        let mut rows: Vec<Vec<Id>> = (0..n)
            .map(|r| {
                let mut v: Vec<Id> = (0..n).map(|c| a[(r, c)]).collect();
                v.extend((0..m).map(|c| b[(r, c)]));
                v
            })
            .collect();
        let mut open_rows: Vec<usize> = (0..n).collect();
        let mut open_cols: Vec<usize> = (0..n).collect();
        // The pivots as (row, col).
        let mut pivots: Vec<(usize, usize)> = Vec::new();
        // The blocks' determinants, expanded once (rows a pivot leaves
        // alone keep their entries, so the next search meets them again).
        let mut dets = HashMap::new();
        loop {
            for &c in &open_cols {
                if open_rows.iter().all(|&r| self.is_zero(rows[r][c])) {
                    return Err(SymbolicError::StructurallySingular { column: c });
                }
            }
            // Pivot choice, cheapest first: a constant entry; a 2×2 block with
            // a constant determinant (a rotation); a provably non-zero entry
            // (the smallest); a 2×2 block with a provably non-zero determinant.
            let scalar = self.best_scalar_pivot(&rows, &open_rows, &open_cols, assumptions);
            let constant_scalar = scalar.filter(|&(r, c)| self.as_number(rows[r][c]).is_some());
            let mut block = None;
            if constant_scalar.is_none() {
                block = self.block_pivot(
                    &rows,
                    (&open_rows, &open_cols),
                    assumptions,
                    true,
                    &mut dets,
                )?;
                if block.is_none() && scalar.is_none() {
                    block = self.block_pivot(
                        &rows,
                        (&open_rows, &open_cols),
                        assumptions,
                        false,
                        &mut dets,
                    )?;
                }
            }
            if block.is_none() {
                if let Some((r, c)) = scalar {
                    // An expansion past the term limit leaves this unknown,
                    // and the rest, to the numeric solve.
                    match give_up_on_term_limit(self.scalar_pivot(&rows, r, c))? {
                        Some(next) => rows = next,
                        None => break,
                    }
                    open_rows.retain(|&x| x != r);
                    open_cols.retain(|&x| x != c);
                    pivots.push((r, c));
                    continue;
                }
            }
            let Some((r1, r2, c1, c2, det)) = block else {
                break;
            };
            match give_up_on_term_limit(self.two_by_two_pivot(&rows, (r1, r2, c1, c2, det)))? {
                Some(next) => rows = next,
                None => break,
            }
            open_rows.retain(|&x| x != r1 && x != r2);
            open_cols.retain(|&x| x != c1 && x != c2);
            pivots.push((r1, c1));
            pivots.push((r2, c2));
        }
        let k = open_cols.len();
        let np = pivots.len();
        let mut pivot_rhs = Vec::with_capacity(np * m);
        let mut pivot_free = Vec::with_capacity(np * k);
        for &(r, _) in &pivots {
            pivot_rhs.extend((0..m).map(|j| rows[r][n + j]));
            pivot_free.extend(open_cols.iter().map(|&c| rows[r][c]));
        }
        let mut s = Vec::with_capacity(k * k);
        let mut s_rhs = Vec::with_capacity(k * m);
        for &r in &open_rows {
            s.extend(open_cols.iter().map(|&c| rows[r][c]));
            s_rhs.extend((0..m).map(|j| rows[r][n + j]));
        }
        Ok(PartialSolution {
            pivot_cols: pivots.iter().map(|p| p.1).collect(),
            pivot_rhs: SymMatrix::from_rows(np, m, pivot_rhs)?,
            pivot_free: SymMatrix::from_rows(np, k, pivot_free)?,
            free_cols: open_cols,
            s: SymMatrix::from_rows(k, k, s)?,
            s_rhs: SymMatrix::from_rows(k, m, s_rhs)?,
        })
    }

    /// The rows after pivoting on entry (`r`, `c`): row `r` divided by it,
    /// column `c` cleared from the others.
    fn scalar_pivot(&mut self, rows: &[Vec<Id>], r: usize, c: usize) -> Result<Vec<Vec<Id>>> {
        let mut rows = rows.to_vec();
        let inv = self.recip(rows[r][c])?;
        for x in rows[r].iter_mut() {
            let t = self.mul(*x, inv)?;
            *x = self.expand_outside_functions(t, self.limits.max_terms)?;
        }
        self.clear_column(&mut rows, r, &[c])?;
        Ok(rows)
    }

    /// The rows after pivoting on the 2×2 block (`r1`, `r2`) × (`c1`, `c2`)
    /// of determinant `det`: the two rows multiplied by the block's inverse,
    /// its columns cleared from the others.
    fn two_by_two_pivot(
        &mut self,
        rows: &[Vec<Id>],
        (r1, r2, c1, c2, det): (usize, usize, usize, usize, Id),
    ) -> Result<Vec<Vec<Id>>> {
        let mut rows = rows.to_vec();
        let (a11, a12, a21, a22) = (rows[r1][c1], rows[r1][c2], rows[r2][c1], rows[r2][c2]);
        let inv_det = self.recip(det)?;
        // [row1; row2] ← adj(B)/det · [row1; row2]
        let width = rows[r1].len();
        let (old1, old2) = (rows[r1].clone(), rows[r2].clone());
        for k in 0..width {
            let x = self.mul(a22, old1[k])?;
            let y = self.mul(a12, old2[k])?;
            let n1 = self.sub(x, y)?;
            let n1 = self.mul(n1, inv_det)?;
            rows[r1][k] = self.expand_outside_functions(n1, self.limits.max_terms)?;
            let x = self.mul(a11, old2[k])?;
            let y = self.mul(a21, old1[k])?;
            let n2 = self.sub(x, y)?;
            let n2 = self.mul(n2, inv_det)?;
            rows[r2][k] = self.expand_outside_functions(n2, self.limits.max_terms)?;
        }
        self.clear_column(&mut rows, r1, &[c1])?;
        self.clear_column(&mut rows, r2, &[c2])?;
        Ok(rows)
    }

    /// The smallest provably non-zero entry among the open rows and columns
    /// (constants first).
    fn best_scalar_pivot(
        &self,
        rows: &[Vec<Id>],
        open_rows: &[usize],
        open_cols: &[usize],
        assumptions: &Assumptions,
    ) -> Option<(usize, usize)> {
        let mut best: Option<(bool, usize, usize, usize)> = None;
        for &c in open_cols {
            for &r in open_rows {
                let e = rows[r][c];
                if !self.is_zero(e) && self.is_provably_nonzero(e, assumptions) {
                    let key = (self.as_number(e).is_none(), self.dag_size(&[e]), c, r);
                    if best.is_none_or(|b| key < b) {
                        best = Some(key);
                    }
                }
            }
        }
        best.map(|(_, _, c, r)| (r, c))
    }

    /// A 2×2 block of the open rows and columns whose determinant is a
    /// non-zero constant (`constant_only`) or provably non-zero. `dets`
    /// holds the expanded determinants of blocks met before (`None`: too
    /// large to expand).
    #[allow(clippy::type_complexity)] // (r1, r2, c1, c2, determinant)
    fn block_pivot(
        &mut self,
        rows: &[Vec<Id>],
        (open_rows, open_cols): (&[usize], &[usize]),
        assumptions: &Assumptions,
        constant_only: bool,
        dets: &mut HashMap<[Id; 4], Option<Id>>,
    ) -> Result<Option<(usize, usize, usize, usize, Id)>> {
        for (i, &c1) in open_cols.iter().enumerate() {
            for &c2 in &open_cols[i + 1..] {
                for (j, &r1) in open_rows.iter().enumerate() {
                    for &r2 in &open_rows[j + 1..] {
                        let (a11, a12, a21, a22) =
                            (rows[r1][c1], rows[r1][c2], rows[r2][c1], rows[r2][c2]);
                        if (self.is_zero(a11) || self.is_zero(a22))
                            && (self.is_zero(a12) || self.is_zero(a21))
                        {
                            continue;
                        }
                        let det = match dets.get(&[a11, a12, a21, a22]) {
                            Some(&det) => det,
                            None => {
                                let det = self.block_determinant(a11, a12, a21, a22)?;
                                dets.insert([a11, a12, a21, a22], det);
                                det
                            }
                        };
                        // A determinant too large to expand is no pivot.
                        let Some(det) = det else {
                            continue;
                        };
                        let ok = if constant_only {
                            self.as_number(det).is_some_and(|n| !n.is_zero())
                        } else {
                            self.is_provably_nonzero(det, assumptions)
                        };
                        if ok {
                            return Ok(Some((r1, r2, c1, c2, det)));
                        }
                    }
                }
            }
        }
        Ok(None)
    }

    /// `a11 a22 − a12 a21` expanded, or `None` when that takes more than
    /// [`BLOCK_DETERMINANT_TERMS`] terms.
    fn block_determinant(&mut self, a11: Id, a12: Id, a21: Id, a22: Id) -> Result<Option<Id>> {
        let p = self.mul(a11, a22)?;
        let q = self.mul(a12, a21)?;
        let d = self.sub(p, q)?;
        let budget = self.limits.max_terms.min(BLOCK_DETERMINANT_TERMS);
        give_up_on_term_limit(self.expand_outside_functions(d, budget))
    }

    /// Subtracts multiples of the (normalized) pivot row `p` from every other
    /// row so the columns `cols` vanish there.
    fn clear_column(&mut self, rows: &mut [Vec<Id>], p: usize, cols: &[usize]) -> Result<()> {
        let pivot_row = rows[p].clone();
        for (r, row) in rows.iter_mut().enumerate() {
            if r == p {
                continue;
            }
            for &c in cols {
                let f = row[c];
                if self.is_zero(f) {
                    continue;
                }
                for (x, &pk) in row.iter_mut().zip(&pivot_row) {
                    let t = self.mul(f, pk)?;
                    let d = self.sub(*x, t)?;
                    *x = self.expand_outside_functions(d, self.limits.max_terms)?;
                }
            }
        }
        Ok(())
    }

    /// Splits `e` into coefficients of `symbols` and a remainder; an error
    /// names the first symbol in which `e` is not linear.
    ///
    /// ```
    /// use appell_symbolic::{Graph, SymbolicError};
    /// let mut g = Graph::new();
    /// let e = g.parse("x_dot - a*psi_dot*cos(phi) + 3").unwrap();
    /// let xd = g.symbol_named("x_dot").unwrap();
    /// let pd = g.symbol_named("psi_dot").unwrap();
    /// let form = g.linear_coefficients(e, &[xd, pd]).unwrap();
    /// assert_eq!(g.display(form.coefficients[1]).to_string(), "-a*cos(phi)");
    /// assert_eq!(g.display(form.remainder).to_string(), "3");
    ///
    /// let bad = g.parse("x_dot*psi_dot").unwrap();
    /// assert!(matches!(g.linear_coefficients(bad, &[xd, pd]),
    ///                  Err(SymbolicError::NonLinear { .. })));
    /// ```
    pub fn linear_coefficients(&mut self, e: Id, symbols: &[Symbol]) -> Result<LinearForm> {
        let set = SymbolSet::from_symbols(symbols.iter().copied());
        let mut coefficients = Vec::with_capacity(symbols.len());
        for &s in symbols {
            let c = self.diff(e, s)?;
            if self.depends_on_any(c, &set) {
                return Err(SymbolicError::NonLinear {
                    symbol: self.symbol_name(s).to_string(),
                    expr: self.display(e).to_string(),
                });
            }
            coefficients.push(c);
        }
        let zero = self.int(0)?;
        let pairs: Vec<(Symbol, Id)> = symbols.iter().map(|&s| (s, zero)).collect();
        let remainder = self.substitute(e, &pairs)?;
        Ok(LinearForm {
            coefficients,
            remainder,
        })
    }

    /// What can be proven about the sign of `e` under `assumptions`.
    ///
    /// ```
    /// use appell_symbolic::{Assumptions, Graph, Sign};
    /// let mut g = Graph::new();
    /// let m = g.parameter("m").unwrap();
    /// let a = g.parameter("a").unwrap();
    /// let assume = Assumptions::new().positive(m).positive(a);
    /// let e = g.parse("2*a^2*(m + 1)").unwrap();
    /// assert_eq!(g.sign(e, &assume), Sign::Positive);
    /// let c = g.parse("a*cos(q)").unwrap();
    /// assert_eq!(g.sign(c, &assume), Sign::Unknown);
    /// ```
    pub fn sign(&self, e: Id, assumptions: &Assumptions) -> Sign {
        if assumptions.nonzero_exprs.contains(&e) {
            return Sign::NonZero;
        }
        match self.node(e) {
            Node::Num(n) => {
                if n.is_zero() {
                    Sign::Unknown
                } else if n.is_negative() {
                    Sign::Negative
                } else {
                    Sign::Positive
                }
            }
            Node::Sym(s) => {
                if assumptions.positive_symbols.contains(*s) {
                    Sign::Positive
                } else if assumptions.nonzero_symbols.contains(*s) {
                    Sign::NonZero
                } else {
                    Sign::Unknown
                }
            }
            Node::Mul { coeff, factors } => {
                let mut sign = if coeff.is_negative() {
                    Sign::Negative
                } else {
                    Sign::Positive
                };
                for &(b, p) in factors.iter() {
                    let s = self.sign(b, assumptions);
                    let s = match s {
                        Sign::Unknown => return Sign::Unknown,
                        _ if p % 2 == 0 => Sign::Positive,
                        s => s,
                    };
                    sign = match (sign, s) {
                        (Sign::NonZero, _) | (_, Sign::NonZero) => Sign::NonZero,
                        (a, Sign::Negative) => a.flip(),
                        (a, _) => a,
                    };
                }
                sign
            }
            Node::Add { constant, terms } => {
                let mut all_pos = !constant.is_negative();
                let mut all_neg = constant.is_zero() || constant.is_negative();
                let mut strict = !constant.is_zero();
                for &(b, k) in terms.iter() {
                    let s = self.sign(b, assumptions);
                    let s = if k.is_negative() { s.flip() } else { s };
                    match s {
                        Sign::Positive => {
                            all_neg = false;
                            strict = true;
                        }
                        Sign::Negative => {
                            all_pos = false;
                            strict = true;
                        }
                        _ => {
                            // Even powers are non-negative: they keep a sum
                            // positive if something else makes it strict.
                            if self.is_even_power(b) {
                                if k.is_negative() {
                                    all_pos = false;
                                } else {
                                    all_neg = false;
                                }
                            } else {
                                return Sign::Unknown;
                            }
                        }
                    }
                }
                match (all_pos, all_neg, strict) {
                    (true, _, true) => Sign::Positive,
                    (_, true, true) => Sign::Negative,
                    _ => Sign::Unknown,
                }
            }
            Node::Fun(Func::Exp | Func::Cosh, _) => Sign::Positive,
            Node::Select(_, a, b) => match (self.sign(*a, assumptions), self.sign(*b, assumptions))
            {
                (Sign::Positive, Sign::Positive) => Sign::Positive,
                (Sign::Negative, Sign::Negative) => Sign::Negative,
                _ => Sign::Unknown,
            },
            Node::Fun(Func::Sqrt, a) => match self.sign(*a, assumptions) {
                Sign::Positive => Sign::Positive,
                _ => Sign::Unknown,
            },
            Node::Fun(Func::Abs, a) => match self.sign(*a, assumptions) {
                Sign::Unknown => Sign::Unknown,
                _ => Sign::Positive,
            },
            _ => Sign::Unknown,
        }
    }

    fn is_even_power(&self, e: Id) -> bool {
        match self.node(e) {
            Node::Mul { coeff, factors } => {
                !coeff.is_negative() && factors.iter().all(|(_, p)| p % 2 == 0)
            }
            _ => false,
        }
    }

    /// Whether `e` is provably non-zero under `assumptions`.
    pub fn is_provably_nonzero(&self, e: Id, assumptions: &Assumptions) -> bool {
        self.sign(e, assumptions).nonzero()
    }

    /// Solves `A X = B` by Gauss–Jordan elimination, choosing for each unknown
    /// a pivot that is provably non-zero (the smallest such entry). Never
    /// divides by an expression that may vanish: when no entry of a column can
    /// be proven non-zero it returns [`SymbolicError::NoProvablyNonzeroPivot`]
    /// so the caller can fall back to a pivoted numeric solve at run time, and
    /// [`SymbolicError::StructurallySingular`] when every entry is zero.
    ///
    /// ```
    /// use appell_symbolic::{Assumptions, Graph, SymMatrix};
    /// let mut g = Graph::new();
    /// let a = g.parameter("a").unwrap();
    /// let m = SymMatrix::parse(&mut g, &[&["a", "0"], &["1", "1"]]).unwrap();
    /// let b = SymMatrix::parse(&mut g, &[&["a*u"], &["v"]]).unwrap();
    /// let sol = g.solve_linear(&m, &b, &Assumptions::new().positive(a)).unwrap();
    /// assert_eq!(g.display(sol.x[(0, 0)]).to_string(), "u");
    /// assert_eq!(g.display(sol.x[(1, 0)]).to_string(), "v - u");
    /// assert_eq!(g.display(sol.determinant).to_string(), "a");
    /// ```
    pub fn solve_linear(
        &mut self,
        a: &SymMatrix,
        b: &SymMatrix,
        assumptions: &Assumptions,
    ) -> Result<LinearSolution> {
        let n = a.rows;
        if a.cols != n || b.rows != n {
            return Err(SymbolicError::DimensionMismatch {
                expected: format!("a square A and B with {n} rows"),
                found: format!("A {}×{}, B {}×{}", a.rows, a.cols, b.rows, b.cols),
            });
        }
        let m = b.cols;
        let mut a = a.clone();
        let mut b = b.clone();
        let mut rows: Vec<usize> = (0..n).collect();
        let mut det = self.int(1)?;
        let mut pivot_rows = Vec::with_capacity(n);
        for col in 0..n {
            let candidates: Vec<usize> = (col..n).filter(|&r| !self.is_zero(a[(r, col)])).collect();
            if candidates.is_empty() {
                return Err(SymbolicError::StructurallySingular { column: col });
            }
            let best = candidates
                .iter()
                .copied()
                .filter(|&r| self.is_provably_nonzero(a[(r, col)], assumptions))
                .min_by_key(|&r| {
                    let e = a[(r, col)];
                    (self.as_number(e).is_none(), self.dag_size(&[e]), r)
                });
            let Some(p) = best else {
                return Err(SymbolicError::NoProvablyNonzeroPivot {
                    column: col,
                    candidates: candidates
                        .iter()
                        .map(|&r| self.display(a[(r, col)]).to_string())
                        .collect(),
                });
            };
            if p != col {
                for j in 0..n {
                    let (x, y) = (a[(p, j)], a[(col, j)]);
                    a[(p, j)] = y;
                    a[(col, j)] = x;
                }
                for j in 0..m {
                    let (x, y) = (b[(p, j)], b[(col, j)]);
                    b[(p, j)] = y;
                    b[(col, j)] = x;
                }
                rows.swap(p, col);
                det = self.neg(det)?;
            }
            pivot_rows.push(rows[col]);
            let pivot = a[(col, col)];
            det = self.mul(det, pivot)?;
            let inv = self.recip(pivot)?;
            for j in col..n {
                let x = self.mul(a[(col, j)], inv)?;
                a[(col, j)] = self.expand_outside_functions(x, self.limits.max_terms)?;
            }
            for j in 0..m {
                let x = self.mul(b[(col, j)], inv)?;
                b[(col, j)] = self.expand_outside_functions(x, self.limits.max_terms)?;
            }
            for r in 0..n {
                if r == col || self.is_zero(a[(r, col)]) {
                    continue;
                }
                let f = a[(r, col)];
                for j in col..n {
                    let t = self.mul(f, a[(col, j)])?;
                    let x = self.sub(a[(r, j)], t)?;
                    a[(r, j)] = self.expand_outside_functions(x, self.limits.max_terms)?;
                }
                for j in 0..m {
                    let t = self.mul(f, b[(col, j)])?;
                    let x = self.sub(b[(r, j)], t)?;
                    b[(r, j)] = self.expand_outside_functions(x, self.limits.max_terms)?;
                }
            }
        }
        Ok(LinearSolution {
            x: b,
            determinant: det,
            pivot_rows,
        })
    }
}

/// The most terms a 2×2 block's determinant may take while it is expanded
/// to be proved non-zero. A rotation's expands to a constant through a
/// handful; one that needs thousands is no pivot worth having, and trying
/// every block of a long chain's rows at the general term limit costs
/// minutes.
const BLOCK_DETERMINANT_TERMS: usize = 1000;

/// `Ok(None)` for an expansion that exceeded the term limit, so that the
/// caller can take another way; other errors pass.
fn give_up_on_term_limit<T>(r: Result<T>) -> Result<Option<T>> {
    match r {
        Ok(x) => Ok(Some(x)),
        Err(SymbolicError::TermLimit { .. }) => Ok(None),
        Err(e) => Err(e),
    }
}

#[cfg(test)]
mod tests {
    use crate::{Assumptions, Graph, Sign, SymMatrix, SymbolicError};

    #[test]
    fn structurally_singular() {
        let mut g = Graph::new();
        let a = SymMatrix::parse(&mut g, &[&["1", "0"], &["x", "0"]]).unwrap();
        let b = SymMatrix::parse(&mut g, &[&["1"], &["1"]]).unwrap();
        assert_eq!(
            g.solve_linear(&a, &b, &Assumptions::new()).unwrap_err(),
            SymbolicError::StructurallySingular { column: 1 }
        );
    }
    #[test]
    fn an_elimination_too_large_to_expand_is_left_to_the_numeric_solve() {
        // Clearing p below the first pivot would expand p·(a + b + c + d)
        // into 16 terms, over the limit of 10: both unknowns stay free.
        let mut g = Graph::with_limits(crate::Limits {
            max_terms: 10,
            ..crate::Limits::default()
        });
        let a = SymMatrix::parse(&mut g, &[&["1", "0"], &["e + f + h + i", "1"]]).unwrap();
        let b = SymMatrix::parse(&mut g, &[&["a + b + c + d"], &["0"]]).unwrap();
        let sol = g.eliminate(&a, &b, &Assumptions::new()).unwrap();
        assert!(sol.pivot_cols.is_empty());
        assert_eq!(sol.free_cols, vec![0, 1]);
        assert_eq!(sol.s, a);
        assert_eq!(sol.s_rhs, b);
    }

    #[test]
    fn refuses_a_pivot_that_may_vanish() {
        let mut g = Graph::new();
        let a = SymMatrix::parse(&mut g, &[&["cos(q)"]]).unwrap();
        let b = SymMatrix::parse(&mut g, &[&["1"]]).unwrap();
        assert!(matches!(
            g.solve_linear(&a, &b, &Assumptions::new()),
            Err(SymbolicError::NoProvablyNonzeroPivot { column: 0, .. })
        ));
    }
    #[test]
    fn declared_nonzero_expression_is_a_pivot() {
        let mut g = Graph::new();
        let a = SymMatrix::parse(&mut g, &[&["cos(q)"]]).unwrap();
        let b = SymMatrix::parse(&mut g, &[&["sin(q)"]]).unwrap();
        let assume = Assumptions::new().nonzero_expr(a[(0, 0)]);
        let s = g.solve_linear(&a, &b, &assume).unwrap();
        assert_eq!(g.display(s.x[(0, 0)]).to_string(), "sin(q)/cos(q)");
    }
    #[test]
    fn row_swap_flips_determinant() {
        let mut g = Graph::new();
        let a = SymMatrix::parse(&mut g, &[&["0", "1"], &["1", "0"]]).unwrap();
        let b = SymMatrix::parse(&mut g, &[&["u"], &["v"]]).unwrap();
        let s = g.solve_linear(&a, &b, &Assumptions::new()).unwrap();
        assert_eq!(g.display(s.determinant).to_string(), "-1");
        assert_eq!(g.display(s.x[(0, 0)]).to_string(), "v");
    }
    #[test]
    fn prefers_constant_pivot() {
        let mut g = Graph::new();
        let a = g.parameter("a").unwrap();
        let m = SymMatrix::parse(&mut g, &[&["a", "0"], &["1", "2"]]).unwrap();
        let b = SymMatrix::parse(&mut g, &[&["1"], &["0"]]).unwrap();
        let s = g
            .solve_linear(&m, &b, &Assumptions::new().positive(a))
            .unwrap();
        assert_eq!(s.pivot_rows[0], 1);
        assert_eq!(g.display(s.x[(1, 0)]).to_string(), "-1/2/a");
    }
    #[test]
    fn a_determinant_that_may_vanish_is_refused() {
        // det = 2a − 1 vanishes at a = 1/2 although a > 0.
        let mut g = Graph::new();
        let a = g.parameter("a").unwrap();
        let m = SymMatrix::parse(&mut g, &[&["a", "1"], &["1", "2"]]).unwrap();
        let b = SymMatrix::parse(&mut g, &[&["1"], &["0"]]).unwrap();
        let r = g.solve_linear(&m, &b, &Assumptions::new().positive(a));
        assert!(matches!(
            r,
            Err(SymbolicError::NoProvablyNonzeroPivot { column: 1, .. })
        ));
    }
    #[test]
    fn sum_of_squares_plus_positive_is_positive() {
        let mut g = Graph::new();
        let e = g.parse("x^2 + y^2 + 1").unwrap();
        assert_eq!(g.sign(e, &Assumptions::new()), Sign::Positive);
    }
    #[test]
    fn sum_of_squares_alone_may_vanish() {
        let mut g = Graph::new();
        let e = g.parse("x^2 + y^2").unwrap();
        assert_eq!(g.sign(e, &Assumptions::new()), Sign::Unknown);
    }
    #[test]
    fn negative_product() {
        let mut g = Graph::new();
        let m = g.parameter("m").unwrap();
        let e = g.parse("-3*m").unwrap();
        assert_eq!(g.sign(e, &Assumptions::new().positive(m)), Sign::Negative);
    }
}
