//! The closed form's candidate: M, f, q̇ and their derivatives in one
//! program, M factored once, each column M⁻¹ (∂f − ∂M ÿ); through a numeric
//! elimination the partials become total derivatives first.

use proc_macro2::TokenStream;
use quote::{format_ident, quote};

use super::{Candidate, Layout, Roots};
use crate::derivation::jacobian::{lower_triangle, retained_rates, ClosedJacobian, Jacobians};
use crate::derivation::{singleton_rows, Elimination, NumericElimination};
use crate::emit::code::{code, Target};
use crate::emit::solve::Solver;
use crate::emit::{int, Emitter};

impl Emitter<'_> {
    /// The closed form's roots: M's lower triangle, f, q̇, then per
    /// written column ∂f (l), ∂q̇ (retained) and ∂M's lower triangle.
    pub(super) fn closed_roots(&self, c: &ClosedJacobian, layout: &Layout, j: &Jacobians) -> Roots {
        let (l, nr, n) = (self.d.l, layout.retained, j.columns.len());
        let mut roots = lower_triangle(&self.d.equations.mass, l);
        roots.extend(&self.d.equations.forcing);
        roots.extend(retained_rates(self.d));
        let values = roots.len();
        for &col in &layout.columns {
            roots.extend((0..l).map(|k| c.forcing[k * n + col]));
            roots.extend((0..nr).map(|r| c.rates[r * n + col]));
            roots.extend(&c.mass[col]);
        }
        if let Some(np) = &c.numeric {
            // Per written column ∂S, ∂R, ∂r; then ∂r/∂X, ∂e/∂X, ∂e/∂w.
            for &col in &layout.columns {
                roots.extend(&np.s[col]);
                roots.extend(&np.r[col]);
                roots.extend(&np.rate[col]);
            }
            roots.extend(&np.rate_x);
            roots.extend(&np.values_x);
            roots.extend(&np.values_w);
        }
        Roots { all: roots, values }
    }

    /// The closed form: values, M's factors, ÿ, then one solve per column
    /// whose ∂f or ∂M is not zero. With a numeric elimination the program
    /// is staged around its solves (as the rhs's), and each column's
    /// partials become total derivatives first.
    pub(super) fn closed_candidate(
        &self,
        roots: Roots,
        layout: &Layout,
        c: &ClosedJacobian,
    ) -> Candidate {
        let (l, nr) = (self.d.l, layout.retained);
        let tri = l * (l + 1) / 2;
        let (head, per) = (roots.values, l + nr + tri);
        let numeric = match (&self.d.elimination, &c.numeric) {
            (Elimination::Numeric(ne), Some(_)) => Some(ne),
            _ => None,
        };
        let (program, statements, elimination_ops) = if numeric.is_some() {
            // Parameter-only values inline: there is no `Prepared` here.
            let (mut program, staged, ops) = self.staged_rhs(&roots.all);
            let prepare = std::mem::take(&mut program.prepare);
            (program, quote!(#(#prepare)* #staged), ops)
        } else {
            let mut program = code(&self.model.g, &roots.all, Target::Generic { hoist: false });
            let statements = program.take_statements();
            (program, statements, 0)
        };
        let lower = |values: &[TokenStream]| {
            let mut m = vec![TokenStream::new(); l * l];
            let mut idx = 0;
            for i in 0..l {
                for k in 0..=i {
                    m[i * l + k] = values[idx].clone();
                    idx += 1;
                }
            }
            m
        };
        let mut body = statements;
        let mut extra = elimination_ops;
        let outputs = &program.outputs;
        let value = |e: usize| (!program.zero[e]).then(|| outputs[e].clone());
        let width = layout.columns.len();
        // Every column's entries; through a numeric elimination their total
        // derivatives come first, while its w is in scope (the LDLᵀ
        // solve below binds names of its own).
        let mut columns = Vec::with_capacity(width);
        for w in 0..width {
            let base = head + w * per;
            columns.push(match numeric {
                None => (base..base + per).map(value).collect::<Vec<_>>(),
                Some(ne) => {
                    let at = NumericAt::new(ne, head + width * per, width, tri + l + nr);
                    let column = Column { base, w, l, nr };
                    let (statements, entries, ops) =
                        self.total_derivatives(&value, &at, ne, column);
                    body.extend(statements);
                    extra += ops;
                    entries
                }
            });
        }
        let (factor, factor_ops) = self.ldlt_factor(&lower(&program.outputs[..tri]), true);
        let (solve, solve_ops) = self.ldlt_solve(&program.outputs[tri..tri + l]);
        body.extend(quote!(#factor #solve));
        extra += factor_ops + solve_ops;
        for k in 0..nr {
            let (value, k) = (&program.outputs[tri + l + k], int(k));
            body.extend(quote!(__dstate[#k] = #value;));
        }
        for k in 0..l {
            let (y, at) = (format_ident!("__y_{}", k), int(nr + k));
            body.extend(quote!(__dstate[#at] = #y;));
        }
        for (w, entries) in columns.iter().enumerate() {
            let (column, ops) = self.closed_column(entries, w, layout);
            body.extend(column);
            extra += ops;
        }
        Candidate {
            body,
            ops: program.ops,
            extra,
            looped: 0,
            overhead: 0,
        }
    }

    /// Column `w`'s writes: ∂q̇ as computed, ∂ÿ = M⁻¹ (∂f − ∂M ÿ) (nothing
    /// where both vanish; the buffers were zeroed).
    pub(super) fn closed_column(
        &self,
        entries: &[Option<TokenStream>],
        w: usize,
        layout: &Layout,
    ) -> (TokenStream, usize) {
        let (l, nr) = (self.d.l, layout.retained);
        let tri_base = l + nr;
        // M's lower triangle: entry (i, k), k ≤ i, at i(i+1)/2 + k.
        let dm = |i: usize, k: usize| {
            let (i, k) = (i.max(k), i.min(k));
            tri_base + i * (i + 1) / 2 + k
        };
        let mut out = TokenStream::new();
        for r in 0..nr {
            if let Some(value) = &entries[l + r] {
                let at = layout.entry(r, w);
                out.extend(quote!(#at = #value;));
            }
        }
        let mut ops = 0;
        let mut rows = Vec::with_capacity(l);
        let mut any = false;
        for k in 0..l {
            let mut e = match &entries[k] {
                None => quote!(<__T as ::appell::__private::Scalar>::zero()),
                Some(v) => {
                    any = true;
                    quote!((#v))
                }
            };
            for i in 0..l {
                if let Some(v) = &entries[dm(k, i)] {
                    any = true;
                    let y = format_ident!("__y_{}", i);
                    e = quote!(#e - (#v) * #y);
                    ops += 2;
                }
            }
            rows.push(e);
        }
        if !any {
            return (out, 0);
        }
        let names: Vec<_> = (0..l).map(|k| format_ident!("__f_{}", k)).collect();
        let name_tokens: Vec<TokenStream> = names.iter().map(|n| quote!(#n)).collect();
        let (solve, solve_ops) = self.ldlt_solve(&name_tokens);
        let ys = (0..l).map(|k| format_ident!("__y_{}", k));
        let col = format_ident!("__col_{}", w);
        out.extend(quote! {
            let #col = {
                #(let #names = #rows;)*
                #solve
                [#(#ys),*]
            };
        });
        for k in 0..l {
            let (at, k_) = (layout.entry(nr + k, w), int(k));
            out.extend(quote!(#at = #col[#k_];));
        }
        (out, ops + solve_ops)
    }

    /// A column's total derivatives of the closed form's values (∂f, ∂q̇,
    /// ∂M's lower triangle: the order `closed_column` reads) through a
    /// numeric elimination: ∂X = S⁻¹ (∂R − ∂S X), ∂w = S⁻¹ (∂r + ∂r/∂X ∂X
    /// − ∂S w) by S's factors, then ∂e + ∂e/∂X ∂X + ∂e/∂w ∂w. Returns the
    /// statements, the entries (`None` where zero) and their operations.
    fn total_derivatives(
        &self,
        value: &dyn Fn(usize) -> Option<TokenStream>,
        at: &NumericAt,
        ne: &NumericElimination,
        column: Column,
    ) -> (TokenStream, Vec<Option<TokenStream>>, usize) {
        let g = &self.model.g;
        let k = ne.k;
        let entry = |i: usize, j: usize| !g.is_zero(ne.s[i * k + j]);
        let t = Totals {
            value,
            at,
            ne,
            column,
            solver: Solver {
                order: singleton_rows(k, entry),
                entry: &entry,
            },
        };
        let (mut out, mut ops) = (TokenStream::new(), 0);
        let dx_any = t.dx(&mut out, &mut ops);
        let dw_any = t.dw(dx_any, &mut out, &mut ops);
        let entries = t.values(dx_any, dw_any, &mut out, &mut ops);
        (out, entries, ops)
    }
}

/// What one column's total derivatives read (see `total_derivatives`).
struct Totals<'a> {
    value: &'a dyn Fn(usize) -> Option<TokenStream>,
    at: &'a NumericAt,
    ne: &'a NumericElimination,
    column: Column,
    solver: Solver<'a>,
}

impl Totals<'_> {
    /// X's entry (j, kk).
    fn x_name(&self, j: usize, kk: usize) -> syn::Ident {
        format_ident!("__x_{}_{}", j, self.ne.columns[kk])
    }

    /// ∂X's entry (j, kk).
    fn dx_name(&self, j: usize, kk: usize) -> syn::Ident {
        format_ident!("__jx{}_{}_{}", self.column.w, j, kk)
    }

    /// ∂w's entry j.
    fn dw_name(&self, j: usize) -> syn::Ident {
        format_ident!("__jw{}_{}", self.column.w, j)
    }

    /// ∂X: its right side, then the solve (skipped where all vanish).
    /// Whether there is one.
    fn dx(&self, out: &mut TokenStream, ops: &mut usize) -> bool {
        let (k, width, w) = (self.ne.k, self.ne.columns.len(), self.column.w);
        let mut any = false;
        let mut rows = Vec::new();
        for i in 0..k {
            let mut row = Vec::with_capacity(width);
            for kk in 0..width {
                let mut terms = Vec::new();
                if let Some(v) = (self.value)(self.at.r(w, i, kk)) {
                    terms.push(v);
                }
                for j in 0..k {
                    if let Some(v) = (self.value)(self.at.s(w, i, j)) {
                        let x = self.x_name(j, kk);
                        terms.push(quote!(-(#v) * #x));
                        *ops += 2;
                    }
                }
                any |= !terms.is_empty();
                row.push(sum(terms));
            }
            rows.push(quote!([#(#row),*]));
        }
        if any {
            let (ki, wi) = (int(k), int(width));
            let name = format!("__jdx{w}");
            let ident = format_ident!("{}", name);
            out.extend(quote!(let #ident: [[__T; #wi]; #ki] = [#(#rows),*];));
            let dx_name = |j: usize, kk: usize| self.dx_name(j, kk);
            let (solve, n) = self
                .solver
                .solve(&name, width, &dx_name, &|_, _| false, false);
            out.extend(solve);
            *ops += n;
        }
        any
    }

    /// ∂w, after ∂X (`dx_any`). Whether there is one.
    fn dw(&self, dx_any: bool, out: &mut TokenStream, ops: &mut usize) -> bool {
        let (k, width, w) = (self.ne.k, self.ne.columns.len(), self.column.w);
        let mut any = false;
        let mut rows = Vec::with_capacity(k);
        for i in 0..k {
            let mut terms = Vec::new();
            if let Some(v) = (self.value)(self.at.rate(w, i)) {
                terms.push(v);
            }
            if dx_any {
                for j in 0..k {
                    for kk in 0..width {
                        if let Some(v) = (self.value)(self.at.rate_x(i, j * width + kk)) {
                            let d = self.dx_name(j, kk);
                            terms.push(quote!((#v) * #d));
                            *ops += 2;
                        }
                    }
                }
            }
            for j in 0..k {
                if let Some(v) = (self.value)(self.at.s(w, i, j)) {
                    let wj = format_ident!("__w_{}", j);
                    terms.push(quote!(-(#v) * #wj));
                    *ops += 2;
                }
            }
            any |= !terms.is_empty();
            let e = sum(terms);
            rows.push(quote!([#e]));
        }
        if any {
            let ki = int(k);
            let name = format!("__jdw{w}");
            let ident = format_ident!("{}", name);
            out.extend(quote!(let #ident: [[__T; 1]; #ki] = [#(#rows),*];));
            let dw_name = |j: usize, _: usize| self.dw_name(j);
            let (solve, n) = self.solver.solve(&name, 1, &dw_name, &|_, _| false, false);
            out.extend(solve);
            *ops += n;
        }
        any
    }

    /// The values' total derivatives, in closed_column's order: ∂f (l),
    /// ∂q̇ (nr), ∂M's triangle; the values' own order is M, f, q̇.
    fn values(
        &self,
        dx_any: bool,
        dw_any: bool,
        out: &mut TokenStream,
        ops: &mut usize,
    ) -> Vec<Option<TokenStream>> {
        let Column { base, w, l, nr } = self.column;
        let (k, width) = (self.ne.k, self.ne.columns.len());
        let tri = l * (l + 1) / 2;
        let value_index = |e: usize| {
            if e < l + nr {
                tri + e
            } else {
                e - l - nr
            }
        };
        let mut entries = Vec::with_capacity(l + nr + tri);
        for e in 0..l + nr + tri {
            let v = value_index(e);
            let mut terms = Vec::new();
            if let Some(p) = (self.value)(base + e) {
                terms.push(p);
            }
            if dx_any {
                for j in 0..k {
                    for kk in 0..width {
                        if let Some(p) = (self.value)(self.at.value_x(v, j * width + kk)) {
                            let d = self.dx_name(j, kk);
                            terms.push(quote!((#p) * #d));
                            *ops += 2;
                        }
                    }
                }
            }
            if dw_any {
                for j in 0..k {
                    if let Some(p) = (self.value)(self.at.value_w(v, j)) {
                        let d = self.dw_name(j);
                        terms.push(quote!((#p) * #d));
                        *ops += 2;
                    }
                }
            }
            if terms.is_empty() {
                entries.push(None);
            } else {
                let name = format_ident!("__jt{}_{}", w, e);
                let e = sum(terms);
                out.extend(quote!(let #name = #e;));
                entries.push(Some(quote!(#name)));
            }
        }
        entries
    }
}

/// `a + b + ...` (zero for none).
fn sum(terms: Vec<TokenStream>) -> TokenStream {
    let mut it = terms.into_iter();
    match it.next() {
        None => quote!(<__T as ::appell::__private::Scalar>::zero()),
        Some(first) => it.fold(first, |acc, t| quote!(#acc + #t)),
    }
}

/// One written column of the closed form: where its partials start among
/// the program's outputs, its index, l and the retained coordinates.
#[derive(Clone, Copy)]
struct Column {
    base: usize,
    w: usize,
    l: usize,
    nr: usize,
}

/// Where a numeric elimination's partials sit among the closed form's
/// program outputs (see `closed_roots`).
struct NumericAt {
    /// The first of them.
    start: usize,
    /// k (S is k×k).
    k: usize,
    /// R's non-zero columns.
    width: usize,
    /// X's symbols, k × width.
    nx: usize,
    /// The closed form's values (M's triangle, f, q̇).
    values: usize,
    /// The written columns.
    columns: usize,
}

impl NumericAt {
    fn new(ne: &NumericElimination, start: usize, columns: usize, values: usize) -> NumericAt {
        let (k, width) = (ne.k, ne.columns.len());
        NumericAt {
            start,
            k,
            width,
            nx: k * width,
            values,
            columns,
        }
    }

    /// Per written column: ∂S (k²), ∂R (k × width), ∂r (k).
    fn per_column(&self) -> usize {
        self.k * self.k + self.k * self.width + self.k
    }

    fn s(&self, w: usize, i: usize, j: usize) -> usize {
        self.start + w * self.per_column() + i * self.k + j
    }

    fn r(&self, w: usize, i: usize, kk: usize) -> usize {
        self.start + w * self.per_column() + self.k * self.k + i * self.width + kk
    }

    fn rate(&self, w: usize, i: usize) -> usize {
        self.start + w * self.per_column() + self.k * self.k + self.k * self.width + i
    }

    /// After every column's: ∂r/∂X (k × nx), ∂e/∂X, ∂e/∂w.
    fn shared(&self) -> usize {
        self.start + self.columns * self.per_column()
    }

    fn rate_x(&self, i: usize, x: usize) -> usize {
        self.shared() + i * self.nx + x
    }

    fn value_x(&self, v: usize, x: usize) -> usize {
        self.shared() + self.k * self.nx + v * self.nx + x
    }

    fn value_w(&self, v: usize, j: usize) -> usize {
        self.shared() + self.k * self.nx + self.values * self.nx + v * self.k + j
    }
}
