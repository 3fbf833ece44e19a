//! `rhs_jacobian`: the reduced rhs and its Jacobians A = ∂rhs/∂state and
//! B = ∂rhs/∂inputs in one call, from stage 14's derivatives.
//!
//! Of three candidates the cheapest is written: the closed form (one
//! program for M, f, q̇ and their derivatives; M factored once by LDLᵀ; ÿ,
//! then each column ∂ÿ/∂c = M⁻¹ (∂f/∂c − (∂M/∂c) ÿ) by the same factors),
//! the structured form (one program for the articulated-body algorithm's ÿ
//! and its derivatives), or dual numbers (the model's own rhs evaluated in
//! W-wide dual numbers, ⌈columns / W⌉ times, by the runtime's
//! `rhs_jacobian_by_duals`: no code of its own). The symbolic ones are
//! compared by their distinct expressions against the rhs's; dual numbers
//! cost about 1 + 2W expressions per rhs expression and pass. Parameter-only
//! work is not hoisted: the function needs no `Prepared`.

use appell_symbolic::{Id, OpCount};
use proc_macro2::TokenStream;
use quote::{format_ident, quote};

use super::code::{braced, code, Target};
use super::solve::Solver;
use super::{int, p, Emitter};
use crate::derivation::jacobian::{ClosedJacobian, Jacobians, SIZE_LIMIT};
use crate::derivation::{singleton_rows, Elimination, NumericElimination};

/// The generated `rhs_jacobian` and the `Option<JacobianInfo>` it is
/// described by.
pub(super) struct JacobianParts {
    /// `fn rhs_jacobian`, or nothing (the trait's default).
    pub function: TokenStream,
    /// How `ModelInfo::jacobian` is written ([`JacobianParts::info`]).
    info: InfoParts,
    /// How it is computed, or why there is none, for the equations text.
    pub summary: String,
}

/// What `ModelInfo::jacobian` says.
enum InfoParts {
    /// `None`.
    Nothing,
    /// A symbolic candidate's `Some(JacobianInfo { .. })`.
    Symbolic(TokenStream),
    /// Dual numbers: W directions a pass, the passes; the cost follows
    /// from the rhs's.
    Dual(usize, usize),
}

impl JacobianParts {
    /// `ModelInfo::jacobian`'s value for a model whose rhs costs `rhs`.
    pub(super) fn info(&self, rhs: appell_core::OpCounts) -> TokenStream {
        let p = p();
        match &self.info {
            InfoParts::Nothing => quote!(::core::option::Option::None),
            InfoParts::Symbolic(info) => info.clone(),
            &InfoParts::Dual(width, passes) => {
                // The runtime's count of the passes, taken here.
                let c = appell_core::dual::pass_costs(rhs, width, passes);
                let form = &self.summary;
                let (add, mul, div, calls, total) = (
                    int(c.add),
                    int(c.mul),
                    int(c.div),
                    int(c.calls),
                    int(c.total),
                );
                quote! {
                    ::core::option::Option::Some(#p::JacobianInfo {
                        form: #form,
                        ops: #p::OpCounts { add: #add, mul: #mul, div: #div, calls: #calls, total: #total },
                    })
                }
            }
        }
    }
}

/// Dual numbers over `columns` columns: (W, passes), at most 8 directions
/// a pass (a large rhs's temporaries stay small) spread evenly over the
/// fewest passes (9 columns: 5 and 4, not 8 and 1).
pub(super) fn dual_width(columns: usize) -> (usize, usize) {
    let passes = columns.div_ceil(8).max(1);
    (columns.div_ceil(passes).max(1), passes)
}

/// A candidate's roots: the values, then the derivatives.
struct Roots {
    /// Every root.
    all: Vec<Id>,
    /// How many of them are values.
    values: usize,
}

/// One candidate's statements and cost.
struct Candidate {
    /// Everything after the bindings of state and inputs.
    body: TokenStream,
    /// The program's operations.
    ops: OpCount,
    /// Operations besides the program's (the factorization and solves).
    extra: usize,
}

impl Candidate {
    fn total(&self) -> usize {
        self.ops.total() + self.extra
    }
}

/// Where the Jacobian's columns come from: each state column, then the
/// implementation's inputs (a scene may take fewer than the model).
struct Layout {
    /// Index into stage 14's columns of each column written, in order.
    columns: Vec<usize>,
    /// The state's length s.
    states: usize,
    /// The number of inputs taken.
    inputs: usize,
    /// The retained coordinates.
    retained: usize,
}

impl Layout {
    /// `__a[row * s + col]` or `__b[row * i + col - s]`.
    fn entry(&self, row: usize, col: usize) -> TokenStream {
        if col < self.states {
            let at = int(row * self.states + col);
            quote!(__a[#at])
        } else {
            let at = int(row * self.inputs + col - self.states);
            quote!(__b[#at])
        }
    }
}

impl Emitter<'_> {
    /// `rhs_jacobian` and its info: the symbolic candidate with fewer
    /// expressions where it has at most [`SIZE_LIMIT`] times the
    /// expressions of the values it differentiates and fewer than the dual
    /// passes' estimate (any size with `jacobian(on)`); otherwise, and
    /// where stage 14 has no candidate, the rhs in dual numbers; nothing
    /// with `jacobian(off)`.
    pub(super) fn jacobian(&self, common: &super::functions::Common) -> JacobianParts {
        if self.model.jacobian == Some(false) {
            return JacobianParts {
                function: TokenStream::new(),
                info: InfoParts::Nothing,
                summary:
                    "none (turned off by `jacobian(off)`; tools use dual numbers through the rhs)"
                        .to_string(),
            };
        }
        let (width, passes) = self.dual_shape();
        // Expressions per rhs expression, over all passes (see the module).
        let dual_ratio = passes * (1 + 2 * width);
        let Some(j) = &self.d.jacobians else {
            return self.dual_parts(
                "stage 14 does not differentiate a scene with constraints of its own".to_string(),
            );
        };
        let layout = self.layout(j);
        let g = &self.model.g;
        // Each candidate's roots (values first) and its size against its
        // values', counted in distinct expressions before lowering.
        let closed = j
            .closed
            .as_ref()
            .ok()
            .map(|c| (self.closed_roots(c, &layout, j), c));
        let structured = j
            .structured
            .as_ref()
            .ok()
            .map(|s| self.structured_roots(s, &layout, j));
        // A numeric elimination's S, R and right side count as the rhs's.
        let elimination: Vec<Id> = match &self.d.elimination {
            Elimination::Numeric(ne) => ne.expressions().copied().collect(),
            Elimination::Symbolic => Vec::new(),
        };
        let size = |r: &Roots| {
            let with = |roots: &[Id]| {
                let mut all = roots.to_vec();
                all.extend(&elimination);
                g.dag_size(&all)
            };
            (with(&r.all), with(&r.all[..r.values]))
        };
        let sizes = (
            closed.as_ref().map(|(r, _)| size(r)),
            structured.as_ref().map(size),
        );
        let use_closed = match sizes {
            (Some(c), Some(s)) => c.0 <= s.0,
            (Some(_), None) => true,
            (None, Some(_)) => false,
            (None, None) => {
                let c = j.closed.as_ref().err().cloned().unwrap_or_default();
                let s = j.structured.as_ref().err().cloned().unwrap_or_default();
                return self.dual_parts(format!("closed form: {c}; structured: {s}"));
            }
        };
        let (total, values) = if use_closed { sizes.0 } else { sizes.1 }.expect("a candidate");
        let other = if use_closed { sizes.1 } else { sizes.0 };
        if self.model.jacobian != Some(true) {
            if total > SIZE_LIMIT * values.max(1) {
                return self.dual_parts(format!(
                    "symbolic: its {total} expressions are more than {SIZE_LIMIT} times the rhs's {values}; `jacobian(on)` writes it"
                ));
            }
            if total > dual_ratio * values.max(1) {
                return self.dual_parts(format!(
                    "symbolic: its {total} expressions are more than the dual passes' {dual_ratio} times the rhs's {values}"
                ));
            }
        }
        let chosen = if use_closed {
            let (roots, c) = closed.expect("closed roots");
            self.closed_candidate(roots, &layout, c)
        } else {
            self.structured_candidate(structured.expect("structured roots"), &layout)
        };
        let what = if use_closed {
            "closed form: ∂M and ∂f, each column M⁻¹ (∂f − ∂M ÿ) by M's factors"
        } else {
            "structured: the articulated-body algorithm's accelerations differentiated"
        };
        let against = match other {
            Some((o, _)) => format!(", {total} expressions against the other form's {o}"),
            None => format!(", {total} expressions"),
        };
        let form = format!("{what}, {} operations per call{against}", chosen.total());
        let p = p();
        let o = chosen.ops;
        let (add, mul, div, calls, total) = (
            int(o.add),
            int(o.mul),
            int(o.div),
            int(o.calls),
            int(chosen.total()),
        );
        let info = quote! {
            ::core::option::Option::Some(#p::JacobianInfo {
                form: #form,
                ops: #p::OpCounts { add: #add, mul: #mul, div: #div, calls: #calls, total: #total },
            })
        };
        JacobianParts {
            function: self.jacobian_function(common, &layout, chosen.body),
            info: InfoParts::Symbolic(info),
            summary: form,
        }
    }

    /// The dual numbers' width W and passes over the state's and the
    /// inputs' columns.
    fn dual_shape(&self) -> (usize, usize) {
        dual_width(self.d.reduction.retained.len() + self.d.l + self.inputs().len())
    }

    /// `rhs_jacobian` as the runtime's `rhs_jacobian_by_duals` over this
    /// implementation's state and inputs; `why` says why not symbolic.
    fn dual_parts(&self, why: String) -> JacobianParts {
        let p = p();
        let (width, passes) = self.dual_shape();
        let (s, i) = (
            self.d.reduction.retained.len() + self.d.l,
            self.inputs().len(),
        );
        let (su, iu, wu) = (int(s), int(i), int(width));
        let function = quote! {
            fn rhs_jacobian<__T: #p::Scalar>(&self, t: __T, __state: &[__T], __inputs: &[__T], __dstate: &mut [__T], __a: &mut [__T], __b: &mut [__T]) -> #p::Result<(), #p::ModelError> {
                #p::rhs_jacobian_by_duals::<Self, __T, #su, #iu, #wu>(self, t, __state, __inputs, __dstate, __a, __b)
            }
        };
        let plural = if passes == 1 { "" } else { "es" };
        let summary = format!(
            "dual numbers: the rhs in {passes} pass{plural} of {width} directions over the {} columns ({why})",
            s + i
        );
        JacobianParts {
            function,
            info: InfoParts::Dual(width, passes),
            summary,
        }
    }

    /// The columns this implementation writes.
    fn layout(&self, j: &Jacobians) -> Layout {
        let states = j.columns.state.len();
        let mut columns: Vec<usize> = (0..states).collect();
        let inputs = self.inputs();
        for (_, s) in &inputs {
            let k = j.columns.inputs.iter().position(|x| x == s);
            columns.push(states + k.expect("an input of the model"));
        }
        Layout {
            columns,
            states,
            inputs: inputs.len(),
            retained: self.d.reduction.retained.len(),
        }
    }

    /// The closed form's roots: M's lower triangle, f, q̇, then per
    /// written column ∂f (l), ∂q̇ (retained) and ∂M's lower triangle.
    fn closed_roots(&self, c: &ClosedJacobian, layout: &Layout, j: &Jacobians) -> Roots {
        let (l, nr, n) = (self.d.l, layout.retained, j.columns.len());
        let mut roots: Vec<Id> = (0..l)
            .flat_map(|i| (0..=i).map(move |k| (i, k)))
            .map(|(i, k)| self.d.equations.mass[i * l + k])
            .collect();
        roots.extend(&self.d.equations.forcing);
        roots.extend(
            self.d
                .reduction
                .retained
                .iter()
                .map(|&r| self.d.map.qdot[r]),
        );
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
    fn closed_candidate(&self, roots: Roots, layout: &Layout, c: &ClosedJacobian) -> Candidate {
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
        }
    }

    /// Column `w`'s writes: ∂q̇ as computed, ∂ÿ = M⁻¹ (∂f − ∂M ÿ) (nothing
    /// where both vanish; the buffers were zeroed).
    fn closed_column(
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
        let Column { base, w, l, nr } = column;
        let (k, width, cols) = (ne.k, ne.columns.len(), &ne.columns);
        let g = &self.model.g;
        let entry = |i: usize, j: usize| !g.is_zero(ne.s[i * k + j]);
        let solver = Solver {
            order: singleton_rows(k, entry),
            entry: &entry,
        };
        let (mut out, mut ops) = (TokenStream::new(), 0);
        // ∂X: its right side, then the solve (skipped where all vanish).
        let x_name = |j: usize, kk: usize| format_ident!("__x_{}_{}", j, cols[kk]);
        let dx_name = |j: usize, kk: usize| format_ident!("__jx{}_{}_{}", w, j, kk);
        let mut dx_any = false;
        let mut rows = Vec::new();
        for i in 0..k {
            let mut row = Vec::with_capacity(width);
            for kk in 0..width {
                let mut terms = Vec::new();
                if let Some(v) = value(at.r(w, i, kk)) {
                    terms.push(v);
                }
                for j in 0..k {
                    if let Some(v) = value(at.s(w, i, j)) {
                        let x = x_name(j, kk);
                        terms.push(quote!(-(#v) * #x));
                        ops += 2;
                    }
                }
                dx_any |= !terms.is_empty();
                row.push(sum(terms));
            }
            rows.push(quote!([#(#row),*]));
        }
        let (ki, wi) = (int(k), int(width));
        if dx_any {
            let name = format!("__jdx{w}");
            let ident = format_ident!("{}", name);
            out.extend(quote!(let #ident: [[__T; #wi]; #ki] = [#(#rows),*];));
            let (solve, n) = solver.solve(&name, width, &dx_name, &|_, _| false, false);
            out.extend(solve);
            ops += n;
        }
        // ∂w.
        let mut dw_any = false;
        let mut w_rows = Vec::with_capacity(k);
        for i in 0..k {
            let mut terms = Vec::new();
            if let Some(v) = value(at.rate(w, i)) {
                terms.push(v);
            }
            if dx_any {
                for j in 0..k {
                    for kk in 0..width {
                        if let Some(v) = value(at.rate_x(i, j * width + kk)) {
                            let d = dx_name(j, kk);
                            terms.push(quote!((#v) * #d));
                            ops += 2;
                        }
                    }
                }
            }
            for j in 0..k {
                if let Some(v) = value(at.s(w, i, j)) {
                    let wj = format_ident!("__w_{}", j);
                    terms.push(quote!(-(#v) * #wj));
                    ops += 2;
                }
            }
            dw_any |= !terms.is_empty();
            let e = sum(terms);
            w_rows.push(quote!([#e]));
        }
        let dw_name = |j: usize, _: usize| format_ident!("__jw{}_{}", w, j);
        if dw_any {
            let name = format!("__jdw{w}");
            let ident = format_ident!("{}", name);
            out.extend(quote!(let #ident: [[__T; 1]; #ki] = [#(#w_rows),*];));
            let (solve, n) = solver.solve(&name, 1, &dw_name, &|_, _| false, false);
            out.extend(solve);
            ops += n;
        }
        // The values' total derivatives, in closed_column's order: ∂f (l),
        // ∂q̇ (nr), ∂M's triangle; the values' own order is M, f, q̇.
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
            if let Some(p) = value(base + e) {
                terms.push(p);
            }
            if dx_any {
                for j in 0..k {
                    for kk in 0..width {
                        if let Some(p) = value(at.value_x(v, j * width + kk)) {
                            let d = dx_name(j, kk);
                            terms.push(quote!((#p) * #d));
                            ops += 2;
                        }
                    }
                }
            }
            if dw_any {
                for j in 0..k {
                    if let Some(p) = value(at.value_w(v, j)) {
                        let d = dw_name(j, 0);
                        terms.push(quote!((#p) * #d));
                        ops += 2;
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
        (out, entries, ops)
    }

    /// The structured form's roots: q̇ and ÿ, then their derivatives row
    /// by row over the written columns.
    fn structured_roots(&self, jac: &[Id], layout: &Layout, j: &Jacobians) -> Roots {
        let n = j.columns.len();
        let s = self.d.structured.as_ref().expect("a structured candidate");
        let mut roots: Vec<Id> = self
            .d
            .reduction
            .retained
            .iter()
            .map(|&r| self.d.map.qdot[r])
            .collect();
        roots.extend(&s.accelerations);
        let values = roots.len();
        for row in 0..values {
            roots.extend(layout.columns.iter().map(|&col| jac[row * n + col]));
        }
        Roots { all: roots, values }
    }

    /// The structured form: one program for q̇, ÿ and their derivatives.
    fn structured_candidate(&self, roots: Roots, layout: &Layout) -> Candidate {
        let rows = roots.values;
        let mut program = code(&self.model.g, &roots.all, Target::Generic { hoist: false });
        let statements = program.take_statements();
        let mut body = quote!(#statements);
        for k in 0..rows {
            let (value, k) = (&program.outputs[k], int(k));
            body.extend(quote!(__dstate[#k] = #value;));
        }
        let width = layout.columns.len();
        for row in 0..rows {
            for w in 0..width {
                let at = rows + row * width + w;
                if !program.zero[at] {
                    let (value, entry) = (&program.outputs[at], layout.entry(row, w));
                    body.extend(quote!(#entry = #value;));
                }
            }
        }
        Candidate {
            body,
            ops: program.ops,
            extra: 0,
        }
    }

    /// `fn rhs_jacobian` around a candidate's body.
    fn jacobian_function(
        &self,
        common: &super::functions::Common,
        layout: &Layout,
        body: TokenStream,
    ) -> TokenStream {
        let p = p();
        let (s, ni) = (layout.states, layout.inputs);
        let checks = [
            self.check("__state", s),
            self.check("__inputs", ni),
            self.check("__dstate", s),
            self.check("__a", s * s),
            self.check("__b", s * ni),
        ];
        let (params_t, pos, bind_inputs) =
            (&common.params_t, &common.positivity, &common.bind_inputs);
        let quaternions = self.quaternion_length_checks();
        let bind_state = self.bind_state();
        let diagnose = self.non_finite_diagnosis();
        let closure_body = braced([
            quote! {
                #params_t #bind_state #bind_inputs #quaternions
                for __v in __a.iter_mut().chain(__b.iter_mut()) {
                    *__v = <__T as #p::Scalar>::zero();
                }
            },
            body,
            quote! {
                if !__dstate.iter().all(|__v| #p::Scalar::re(*__v).is_finite()) {
                    return #p::Err(#p::ModelError::NonFinite { what: "the state derivative" });
                }
                if !__a.iter().chain(__b.iter()).all(|__v| #p::Scalar::re(*__v).is_finite()) {
                    return #p::Err(#p::ModelError::NonFinite { what: "the rhs's Jacobian" });
                }
                #p::Ok(())
            },
        ]);
        quote! {
            fn rhs_jacobian<__T: #p::Scalar>(&self, t: __T, __state: &[__T], __inputs: &[__T], __dstate: &mut [__T], __a: &mut [__T], __b: &mut [__T]) -> #p::Result<(), #p::ModelError> {
                #(#checks)* #pos
                let __result: #p::Result<(), #p::ModelError> = (|| #closure_body)();
                match __result {
                    #p::Ok(()) => #p::Ok(()),
                    #p::Err(__e) => {
                        #diagnose
                        #p::Err(__e)
                    }
                }
            }
        }
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
