//! LDLᵀ of M that skips what is zero, for the inverse-dynamics candidate's
//! many solves by one M. A tree's M is zero between joints on different
//! branches; eliminated leaves first (the speeds in reverse order, parents
//! before children in the tree), its factor has no fill-in, as in
//! Featherstone's LTDL. The fill is found here symbolically for any order,
//! and a right side's zero entries (an input's column is a unit vector;
//! a joint's coordinate moves the rows of its ancestors and descendants
//! only) are skipped too.

use proc_macro2::TokenStream;
use quote::{format_ident, quote};

use crate::emit::{int, p};

/// The pattern of M's factor in the elimination order.
pub(super) struct SparseLdlt {
    /// The speed eliminated at each position.
    order: Vec<usize>,
    /// `lower[i][k]`, k < i: whether the factor's entry at positions
    /// (i, k) is not zero.
    lower: Vec<Vec<bool>>,
}

impl SparseLdlt {
    /// The pattern for an l×l M whose entry (i, k) of the lower triangle
    /// (speed indices, k ≤ i) is zero where `zero(i, k)`, eliminated in
    /// reverse speed order.
    pub(super) fn new(l: usize, zero: impl Fn(usize, usize) -> bool) -> SparseLdlt {
        let order: Vec<usize> = (0..l).rev().collect();
        let entry = |a: usize, b: usize| {
            let (i, k) = (order[a].max(order[b]), order[a].min(order[b]));
            !zero(i, k)
        };
        let mut lower: Vec<Vec<bool>> = (0..l)
            .map(|i| (0..i).map(|k| entry(i, k)).collect())
            .collect();
        for j in 0..l {
            let below: Vec<usize> = (j + 1..l).filter(|&i| lower[i][j]).collect();
            for (n, &i) in below.iter().enumerate() {
                for &k in &below[..n] {
                    lower[i][k] = true;
                }
            }
        }
        SparseLdlt { order, lower }
    }

    /// The factorization of M, `m(i, k)` its entry (speed indices, k ≤ i):
    /// binds the pivots' reciprocals and the factor's entries, and returns
    /// a `SingularMassMatrix` error for a pivot not above 1e-13 times M's
    /// largest diagonal entry. Returns the statements and their operations.
    pub(super) fn factor(&self, m: impl Fn(usize, usize) -> TokenStream) -> (TokenStream, usize) {
        let p = p();
        let l = self.order.len();
        let entry = |a: usize, b: usize| {
            let (i, k) = (
                self.order[a].max(self.order[b]),
                self.order[a].min(self.order[b]),
            );
            m(i, k)
        };
        let diagonal: Vec<TokenStream> = (0..l)
            .map(|a| {
                let v = entry(a, a);
                quote!(#p::Scalar::re(#v).abs())
            })
            .collect();
        let mut out = quote! {
            let __stol = 1e-13 * [#(#diagonal),*].iter().fold(0.0f64, |a, b| a.max(*b));
        };
        let mut ops = 0;
        for j in 0..l {
            let mut d = entry(j, j);
            for k in (0..j).filter(|&k| self.lower[j][k]) {
                let (ljk, ejk) = (lower_name(j, k), product_name(j, k));
                d = quote!(#d - #ljk * #ejk);
                ops += 2;
            }
            let (dj, rj) = (format_ident!("__sd_{}", j), format_ident!("__sr_{}", j));
            let index = int(self.order[j]);
            out.extend(quote! {
                let #dj = #d;
                if !(#p::Scalar::re(#dj) > __stol) {
                    return #p::Err(#p::ModelError::SingularMassMatrix { index: #index, pivot: #p::Scalar::re(#dj) });
                }
                let #rj = <__T as #p::Scalar>::one() / #dj;
            });
            ops += 1;
            for i in (j + 1..l).filter(|&i| self.lower[i][j]) {
                let mut e = entry(i, j);
                for k in (0..j).filter(|&k| self.lower[i][k] && self.lower[j][k]) {
                    let (lik, ejk) = (lower_name(i, k), product_name(j, k));
                    e = quote!(#e - #lik * #ejk);
                    ops += 2;
                }
                let (eij, lij) = (product_name(i, j), lower_name(i, j));
                out.extend(quote!(let #eij = #e; let #lij = #eij * #rj;));
                ops += 1;
            }
        }
        (out, ops)
    }

    /// M x = b for `b` by speed (None where zero): the statements, x by
    /// speed (None where zero) and their operations. The statements bind
    /// names of their own; put them in a block of their own.
    pub(super) fn solve(
        &self,
        b: &[Option<TokenStream>],
    ) -> (TokenStream, Vec<Option<TokenStream>>, usize) {
        let l = self.order.len();
        let mut out = TokenStream::new();
        let mut ops = 0;
        let mut z = vec![false; l];
        for i in 0..l {
            let mut terms = b[self.order[i]].clone().map(|v| quote!((#v)));
            for k in (0..i).filter(|&k| self.lower[i][k] && z[k]) {
                let (lik, zk) = (lower_name(i, k), format_ident!("__sz_{}", k));
                terms = Some(minus(terms, quote!(#lik * #zk)));
                ops += 2;
            }
            if let Some(t) = terms {
                let zi = format_ident!("__sz_{}", i);
                out.extend(quote!(let #zi = #t;));
                z[i] = true;
            }
        }
        // Back substitution: y_i = z_i / d_i − Σ_{k>i} l_ki y_k.
        let mut y = vec![false; l];
        for i in (0..l).rev() {
            let mut terms = z[i].then(|| {
                let (zi, ri) = (format_ident!("__sz_{}", i), format_ident!("__sr_{}", i));
                ops += 1;
                quote!(#zi * #ri)
            });
            for k in (i + 1..l).filter(|&k| self.lower[k][i] && y[k]) {
                let (lki, yk) = (lower_name(k, i), format_ident!("__sy_{}", k));
                terms = Some(minus(terms, quote!(#lki * #yk)));
                ops += 2;
            }
            if let Some(t) = terms {
                let yi = format_ident!("__sy_{}", i);
                out.extend(quote!(let #yi = #t;));
                y[i] = true;
            }
        }
        let mut x = vec![None; l];
        for (i, &speed) in self.order.iter().enumerate() {
            if y[i] {
                let yi = format_ident!("__sy_{}", i);
                x[speed] = Some(quote!(#yi));
            }
        }
        (out, x, ops)
    }
}

/// `terms − product`, or `−(product)` where there are none yet.
fn minus(terms: Option<TokenStream>, product: TokenStream) -> TokenStream {
    match terms {
        Some(t) => quote!(#t - #product),
        None => quote!(-(#product)),
    }
}

fn lower_name(i: usize, k: usize) -> syn::Ident {
    format_ident!("__sl_{}_{}", i, k)
}

fn product_name(i: usize, k: usize) -> syn::Ident {
    format_ident!("__se_{}_{}", i, k)
}

#[cfg(test)]
mod tests {
    use super::SparseLdlt;

    /// A base (speed 0) carrying two legs of two joints each: M is zero
    /// between the legs.
    fn two_legs(i: usize, k: usize) -> bool {
        let leg = |s: usize| (s > 0).then(|| (s - 1) / 2);
        matches!((leg(i), leg(k)), (Some(a), Some(b)) if a != b)
    }

    #[test]
    fn a_tree_eliminated_leaves_first_has_no_fill() {
        let s = SparseLdlt::new(5, two_legs);
        let count: usize = s
            .lower
            .iter()
            .map(|r| r.iter().filter(|&&b| b).count())
            .sum();
        // Each leg joint couples to its leg mate and the base: 4 + 2.
        assert_eq!(count, 6);
    }

    #[test]
    fn a_dense_matrix_keeps_every_entry() {
        let s = SparseLdlt::new(4, |_, _| false);
        let count: usize = s
            .lower
            .iter()
            .map(|r| r.iter().filter(|&&b| b).count())
            .sum();
        assert_eq!(count, 6);
    }

    #[test]
    fn fill_is_found_for_an_arrow_eliminated_from_its_hub() {
        // Speed 3 couples to every other: eliminated first (reverse
        // order), it fills the rest.
        let arrow = |i: usize, k: usize| !(i == 3 || k == 3 || i == k);
        let s = SparseLdlt::new(4, arrow);
        let count: usize = s
            .lower
            .iter()
            .map(|r| r.iter().filter(|&&b| b).count())
            .sum();
        assert_eq!(count, 6);
    }
}
