//! Appell's equations M ÿ = f solved by an unrolled LDLᵀ factorization.
//!
//! M is symmetric positive definite wherever the model is regular; a pivot
//! below 1e-13 of M's largest diagonal entry is a `SingularMassMatrix`
//! error. Each update l_ik (l_jk d_k) reads the undivided product e_jk once.
//! A pivot's reciprocal is kept where it divides two values or more (see
//! `pivot_reciprocal`). With a constant M the factors are
//! computed once per parameter set, in `prepare`.

use proc_macro2::TokenStream;
use quote::{format_ident, quote};

use super::{p, Emitter};
use crate::derivation::Elimination;

impl Emitter<'_> {
    /// The factorization of M (its lower triangle given as expressions,
    /// row-major l×l): binds `__l_i_j`, `__e_i_j`, `__d_j` and the kept
    /// reciprocals `__r_j`, checking each pivot against `__tol` when
    /// `checks`. Returns the statements and their operation count.
    pub(super) fn ldlt_factor(&self, m: &[TokenStream], checks: bool) -> (TokenStream, usize) {
        let p = p();
        let l = self.d.l;
        let mut out = TokenStream::new();
        let mut ops = 0;
        for i in 0..l {
            for j in 0..=i {
                let (name, value) = (format_ident!("__m_{}_{}", i, j), &m[i * l + j]);
                out.extend(quote!(let #name = #value;));
            }
        }
        let diag: Vec<TokenStream> = (0..l)
            .map(|i| {
                let mii = format_ident!("__m_{}_{}", i, i);
                quote!(#p::Scalar::re(#mii).abs())
            })
            .collect();
        let largest = if l == 1 {
            diag[0].clone()
        } else {
            quote!([#(#diag),*].iter().fold(0.0f64, |a, b| a.max(*b)))
        };
        out.extend(quote!(let __tol = 1e-13 * #largest;));
        for j in 0..l {
            let mut e = {
                let mjj = format_ident!("__m_{}_{}", j, j);
                quote!(#mjj)
            };
            for k in 0..j {
                let (ljk, ejk) = (
                    format_ident!("__l_{}_{}", j, k),
                    format_ident!("__e_{}_{}", j, k),
                );
                e = quote!(#e - #ljk * #ejk);
                ops += 2;
            }
            let dj = format_ident!("__d_{}", j);
            out.extend(quote!(let #dj = #e;));
            if checks {
                out.extend(self.pivot_check(j, quote!(__tol)));
            }
            if self.pivot_reciprocal(j) {
                let rj = format_ident!("__r_{}", j);
                out.extend(quote!(let #rj = <__T as #p::Scalar>::one() / #dj;));
                ops += 1;
            }
            for i in j + 1..l {
                let mut e = {
                    let mij = format_ident!("__m_{}_{}", i, j);
                    quote!(#mij)
                };
                for k in 0..j {
                    let (lik, ejk) = (
                        format_ident!("__l_{}_{}", i, k),
                        format_ident!("__e_{}_{}", j, k),
                    );
                    e = quote!(#e - #lik * #ejk);
                    ops += 2;
                }
                let (eij, lij) = (
                    format_ident!("__e_{}_{}", i, j),
                    format_ident!("__l_{}_{}", i, j),
                );
                let divided = self.over_pivot(quote!(#eij), j);
                out.extend(quote!(let #eij = #e; let #lij = #divided;));
                ops += 1;
            }
        }
        (out, ops)
    }

    /// Whether the factorization keeps 1/d_j (`__r_j`) and multiplies by
    /// it. A pivot that divides two values or more (every pivot but the
    /// last: a multiplier l_ij and the solve's w_j) then costs one division
    /// and products, which a divider that is not pipelined runs much faster.
    /// The last pivot divides w only, so it keeps its division, except with
    /// a numeric elimination: M needs the dependent rates X but not their
    /// acceleration remainder w, and f needs both, so M is complete long
    /// before f, the division runs while f is computed, and the
    /// substitution that waits on f multiplies instead of dividing. With a
    /// constant M the factors are computed once per parameter set, so every
    /// reciprocal is kept there and the rhs divides by no pivot.
    pub(super) fn pivot_reciprocal(&self, j: usize) -> bool {
        j + 1 < self.d.l
            || matches!(self.d.elimination, Elimination::Numeric(_))
            || self.constant_mass()
    }

    /// Whether M depends on parameters only: its factorization then moves
    /// into `prepare`, and the rhs keeps only the two triangular solves.
    pub(super) fn constant_mass(&self) -> bool {
        let d = self.d;
        d.l > 0
            && d.equations
                .mass
                .iter()
                .all(|&e| self.model.g.is_parameter_only(e))
    }

    /// `value / d_j`, as a product with `__r_j` when it is kept.
    fn over_pivot(&self, value: TokenStream, j: usize) -> TokenStream {
        if self.pivot_reciprocal(j) {
            let rj = format_ident!("__r_{}", j);
            quote!(#value * #rj)
        } else {
            let dj = format_ident!("__d_{}", j);
            quote!(#value / #dj)
        }
    }

    /// A `SingularMassMatrix` error when pivot j is not above `tol`.
    pub(super) fn pivot_check(&self, j: usize, tol: TokenStream) -> TokenStream {
        let p = p();
        let dj = format_ident!("__d_{}", j);
        let index = super::int(j);
        quote!(if !(#p::Scalar::re(#dj) > #tol) { return #p::Err(#p::ModelError::SingularMassMatrix { index: #index, pivot: #p::Scalar::re(#dj) }); })
    }

    /// Forward and back substitution with the factors: binds `__y_k` = ÿ_k.
    pub(super) fn ldlt_solve(&self, f: &[TokenStream]) -> (TokenStream, usize) {
        let l = self.d.l;
        let mut out = TokenStream::new();
        let mut ops = 0;
        for i in 0..l {
            let fi = &f[i];
            let mut e = quote!((#fi));
            for k in 0..i {
                let (lik, zk) = (format_ident!("__l_{}_{}", i, k), format_ident!("__z_{}", k));
                e = quote!(#e - #lik * #zk);
                ops += 2;
            }
            let zi = format_ident!("__z_{}", i);
            out.extend(quote!(let #zi = #e;));
        }
        for i in 0..l {
            let (wi, zi) = (format_ident!("__w_{}", i), format_ident!("__z_{}", i));
            let value = self.over_pivot(quote!(#zi), i);
            out.extend(quote!(let #wi = #value;));
            ops += 1;
        }
        for i in (0..l).rev() {
            let wi = format_ident!("__w_{}", i);
            let mut e = quote!(#wi);
            for k in i + 1..l {
                let (lki, yk) = (format_ident!("__l_{}_{}", k, i), format_ident!("__y_{}", k));
                e = quote!(#e - #lki * #yk);
                ops += 2;
            }
            let yi = format_ident!("__y_{}", i);
            out.extend(quote!(let #yi = #e;));
        }
        (out, ops)
    }

    /// Names of the factors kept in `Prepared` when M is constant.
    pub(super) fn factor_names(&self) -> Vec<syn::Ident> {
        let l = self.d.l;
        let mut v = Vec::new();
        for i in 0..l {
            for j in 0..i {
                v.push(format_ident!("__l_{}_{}", i, j));
            }
        }
        for j in 0..l {
            v.push(format_ident!("__d_{}", j));
        }
        for j in (0..l).filter(|&j| self.pivot_reciprocal(j)) {
            v.push(format_ident!("__r_{}", j));
        }
        v.push(format_ident!("__tolv"));
        v
    }
}
