//! The inverse-dynamics candidate (a plain tree): M by the
//! composite-rigid-body algorithm, ÿ by the articulated-body algorithm and
//! the residual's derivatives −∂R/∂c in one program; M factored once
//! without its zeros ([`SparseLdlt`]), each column ∂ÿ/∂c = −M⁻¹ ∂R/∂c by
//! the same factors.

use appell_symbolic::Id;
use proc_macro2::TokenStream;
use quote::{format_ident, quote};

use super::sparse::SparseLdlt;
use super::{Candidate, Layout, Roots};
use crate::derivation::jacobian::{retained_rates, Jacobians, RecursiveJacobian};
use crate::emit::code::{code, Target};
use crate::emit::{int, Emitter};

impl Emitter<'_> {
    /// The roots: M's lower triangle, ÿ, q̇, then per written column −∂R
    /// (l) and ∂q̇ (retained).
    pub(super) fn recursive_roots(
        &self,
        r: &RecursiveJacobian,
        layout: &Layout,
        j: &Jacobians,
    ) -> Roots {
        let (l, nr, n) = (self.d.l, layout.retained, j.columns.len());
        let mut roots: Vec<Id> = r.mass.clone();
        roots.extend(&r.accelerations);
        roots.extend(retained_rates(self.d));
        let values = roots.len();
        for &col in &layout.columns {
            roots.extend((0..l).map(|k| r.forcing[k * n + col]));
            roots.extend((0..nr).map(|k| r.rates[k * n + col]));
        }
        Roots { all: roots, values }
    }

    /// The program, M's sparse factors, q̇ and ÿ as computed, then one
    /// solve per column whose −∂R is not zero, skipping zeros.
    pub(super) fn recursive_candidate(&self, roots: Roots, layout: &Layout) -> Candidate {
        let (l, nr) = (self.d.l, layout.retained);
        let tri = l * (l + 1) / 2;
        let (head, per) = (roots.values, l + nr);
        let mut program = code(&self.model.g, &roots.all, Target::Generic { hoist: false });
        let mut body = program.take_statements();
        let outputs = &program.outputs;
        let at = |i: usize, k: usize| i * (i + 1) / 2 + k;
        let ldlt = SparseLdlt::new(l, |i, k| program.zero[at(i, k)]);
        let (factor, mut extra) = ldlt.factor(|i, k| outputs[at(i, k)].clone());
        body.extend(factor);
        for k in 0..l {
            let (value, at) = (&outputs[tri + k], int(nr + k));
            body.extend(quote!(__dstate[#at] = #value;));
        }
        for k in 0..nr {
            let (value, at) = (&outputs[tri + l + k], int(k));
            body.extend(quote!(__dstate[#at] = #value;));
        }
        let value = |e: usize| (!program.zero[e]).then(|| outputs[e].clone());
        for w in 0..layout.columns.len() {
            let base = head + w * per;
            for r in 0..nr {
                if let Some(v) = value(base + l + r) {
                    let at = layout.entry(r, w);
                    body.extend(quote!(#at = #v;));
                }
            }
            let rows: Vec<Option<TokenStream>> = (base..base + l).map(value).collect();
            if rows.iter().all(Option::is_none) {
                continue;
            }
            let names: Vec<_> = (0..l).map(|k| format_ident!("__f_{}", k)).collect();
            let bind = rows
                .iter()
                .zip(&names)
                .filter_map(|(v, n)| v.as_ref().map(|v| quote!(let #n = #v;)));
            let named: Vec<Option<TokenStream>> = rows
                .iter()
                .zip(&names)
                .map(|(v, n)| v.as_ref().map(|_| quote!(#n)))
                .collect();
            let (solve, x, ops) = ldlt.solve(&named);
            extra += ops;
            let writes = x.iter().enumerate().filter_map(|(k, v)| {
                let at = layout.entry(nr + k, w);
                v.as_ref().map(|v| quote!(#at = #v;))
            });
            body.extend(quote!({ #(#bind)* #solve #(#writes)* }));
        }
        Candidate {
            body,
            ops: program.ops,
            extra,
            looped: 0,
            overhead: 0,
        }
    }
}
