//! `rhs_jacobian`: the reduced rhs and its Jacobians A = ∂rhs/∂state and
//! B = ∂rhs/∂inputs in one call, from stage 14's derivatives.
//!
//! Of the two candidates the one with fewer operations per call is
//! written: the closed form (one program for M, f, q̇ and their
//! derivatives; M factored once by LDLᵀ; ÿ, then each column
//! ∂ÿ/∂c = M⁻¹ (∂f/∂c − (∂M/∂c) ÿ) by the same factors), or the
//! structured form (one program for the articulated-body algorithm's ÿ and
//! its derivatives). Parameter-only work is not hoisted: the function
//! needs no `Prepared`.

use appell_symbolic::{Id, OpCount};
use proc_macro2::TokenStream;
use quote::{format_ident, quote};

use super::code::{braced, code, Code, Target};
use super::{int, p, Emitter};
use crate::derivation::jacobian::{ClosedJacobian, Jacobians};

/// The generated `rhs_jacobian` and the `Option<JacobianInfo>` it is
/// described by.
pub(super) struct JacobianParts {
    /// `fn rhs_jacobian`, or nothing (the trait's default).
    pub function: TokenStream,
    /// `Some(JacobianInfo { .. })` or `None`.
    pub info: TokenStream,
    /// How it is computed, or why there is none, for the equations text.
    pub summary: String,
}

/// The most expressions a Jacobian written by default may have, as a
/// multiple of the values it differentiates (q̇ and ÿ, or M, f and q̇):
/// beyond it the generated code would grow past about twice the model's
/// (`jacobian(on)` writes it anyway).
pub const SIZE_LIMIT: usize = 4;

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
    /// `rhs_jacobian` and its info, from the candidate with fewer
    /// expressions; nothing where stage 14 has none, or (unless the model
    /// says `jacobian(on)`) where the chosen one has more than
    /// [`SIZE_LIMIT`] times the expressions of the values it differentiates.
    pub(super) fn jacobian(&self, common: &super::functions::Common) -> JacobianParts {
        let none = |why: String| JacobianParts {
            function: TokenStream::new(),
            info: quote!(::core::option::Option::None),
            summary: format!("none ({why}; tools use dual numbers through the rhs)"),
        };
        let Some(j) = &self.d.jacobians else {
            return none("not derived".to_string());
        };
        if self.model.jacobian == Some(false) {
            return none("turned off by `jacobian(off)`".to_string());
        }
        let layout = self.layout(j);
        let g = &self.model.g;
        // Each candidate's roots (values first) and its size against its
        // values', counted in distinct expressions before lowering.
        let closed = j
            .closed
            .as_ref()
            .ok()
            .map(|c| self.closed_roots(c, &layout, j));
        let structured = j
            .structured
            .as_ref()
            .ok()
            .map(|s| self.structured_roots(s, &layout, j));
        let size = |r: &Roots| (g.dag_size(&r.all), g.dag_size(&r.all[..r.values]));
        let sizes = (closed.as_ref().map(size), structured.as_ref().map(size));
        let use_closed = match sizes {
            (Some(c), Some(s)) => c.0 <= s.0,
            (Some(_), None) => true,
            (None, Some(_)) => false,
            (None, None) => {
                let c = j.closed.as_ref().err().cloned().unwrap_or_default();
                let s = j.structured.as_ref().err().cloned().unwrap_or_default();
                return none(format!("closed form: {c}; structured: {s}"));
            }
        };
        let (total, values) = if use_closed { sizes.0 } else { sizes.1 }.expect("a candidate");
        let other = if use_closed { sizes.1 } else { sizes.0 };
        if self.model.jacobian != Some(true) && total > SIZE_LIMIT * values.max(1) {
            return none(format!(
                "its {total} expressions are more than {SIZE_LIMIT} times the rhs's {values}; `jacobian(on)` writes it"
            ));
        }
        let chosen = if use_closed {
            self.closed_candidate(closed.expect("closed roots"), &layout)
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
            info,
            summary: form,
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
        Roots { all: roots, values }
    }

    /// The closed form: values, M's factors, ÿ, then one solve per column
    /// whose ∂f or ∂M is not zero.
    fn closed_candidate(&self, roots: Roots, layout: &Layout) -> Candidate {
        let (l, nr) = (self.d.l, layout.retained);
        let tri = l * (l + 1) / 2;
        let (head, per) = (roots.values, l + nr + tri);
        let mut program = code(&self.model.g, &roots.all, Target::Generic { hoist: false });
        let statements = program.take_statements();
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
        let (factor, factor_ops) = self.ldlt_factor(&lower(&program.outputs[..tri]), true);
        let (solve, solve_ops) = self.ldlt_solve(&program.outputs[tri..tri + l]);
        let mut body = quote!(#statements #factor #solve);
        for k in 0..nr {
            let (value, k) = (&program.outputs[tri + l + k], int(k));
            body.extend(quote!(__dstate[#k] = #value;));
        }
        for k in 0..l {
            let (y, at) = (format_ident!("__y_{}", k), int(nr + k));
            body.extend(quote!(__dstate[#at] = #y;));
        }
        let mut extra = factor_ops + solve_ops;
        for (w, _) in layout.columns.iter().enumerate() {
            let base = head + w * per;
            let (column, ops) = self.closed_column(&program, base, w, layout);
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
        program: &Code,
        base: usize,
        w: usize,
        layout: &Layout,
    ) -> (TokenStream, usize) {
        let (l, nr) = (self.d.l, layout.retained);
        let tri_base = base + l + nr;
        // M's lower triangle: entry (i, k), k ≤ i, at i(i+1)/2 + k.
        let dm = |i: usize, k: usize| {
            let (i, k) = (i.max(k), i.min(k));
            tri_base + i * (i + 1) / 2 + k
        };
        let mut out = TokenStream::new();
        for r in 0..nr {
            if !program.zero[base + l + r] {
                let (value, at) = (&program.outputs[base + l + r], layout.entry(r, w));
                out.extend(quote!(#at = #value;));
            }
        }
        let mut ops = 0;
        let mut rows = Vec::with_capacity(l);
        let mut any = false;
        for k in 0..l {
            let mut e = if program.zero[base + k] {
                quote!(<__T as ::appell::__private::Scalar>::zero())
            } else {
                any = true;
                let v = &program.outputs[base + k];
                quote!((#v))
            };
            for i in 0..l {
                if !program.zero[dm(k, i)] {
                    any = true;
                    let (v, y) = (&program.outputs[dm(k, i)], format_ident!("__y_{}", i));
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
        let retained = &self.d.reduction.retained;
        let g = &self.model.g;
        let state_q = retained.iter().enumerate().map(|(k, &r)| {
            let (q, k) = (self.coord(r), int(k));
            quote!(let #q = __state[#k];)
        });
        let state_u = self.model.speed_specs.iter().enumerate().map(|(k, spec)| {
            let (u, k) = (
                self.ident(g.symbol_name(spec.symbol)),
                int(retained.len() + k),
            );
            quote!(let #u = __state[#k];)
        });
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
        let diagnose = self.non_finite_diagnosis();
        let closure_body = braced([
            quote! {
                #params_t #(#state_q)* #(#state_u)* #bind_inputs #quaternions
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
