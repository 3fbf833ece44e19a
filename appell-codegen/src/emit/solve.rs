//! The numeric part of the elimination in the generated code.
//!
//! S X = R gives the dependent rates' coefficients X, and S w = (Ṙ − Ṡ X)
//! [ẏ; 1] their acceleration remainder w (see `derivation::numeric`). In
//! the rhs both are solved inside the one program that computes M and f,
//! which the engine splits into stages by the symbols each statement reads:
//! S and R first (stage 0), then X, then the right side for w (stage 1),
//! then w, then M, f and the rates (stage 2). Rows of S with a single entry
//! among the unknowns not yet solved are solved one by one (each costs a
//! division, and no other entry changes, so there is nothing for pivoting
//! to protect); LU with partial pivoting takes the rest, factored once for
//! both right sides. The other functions solve S X = R alone with
//! `lu_solve`.

use std::collections::HashSet;

use appell_core::linalg::{lu_factor_ops, lu_substitute_ops};
use appell_symbolic::Id;
use proc_macro2::TokenStream;
use quote::{format_ident, quote};

use super::code::{code, code_with, options, Code, Target};
use super::{int, p, Emitter};
use crate::derivation::{singleton_rows, Elimination, NumericElimination, SingletonOrder};

/// The m×w matrix of `outputs[offset..]`, row-major, as nested arrays.
pub(super) fn matrix(outputs: &[TokenStream], offset: usize, m: usize, w: usize) -> TokenStream {
    let rows = (0..m).map(|i| {
        let row = &outputs[offset + i * w..offset + (i + 1) * w];
        quote!([#(#row),*])
    });
    quote!(#(#rows),*)
}

impl Emitter<'_> {
    /// S X = R (and S w = (Ṙ − Ṡ X)[ẏ; 1] when `rates`) solved with
    /// `lu_solve`, binding the auxiliary symbols `__x_i_j` (and `__w_i`).
    /// Without `rates` the values are the dependent rates themselves, so
    /// where the reduction fixed coordinates only M and f do not depend on
    /// through the solve, the model's own elimination is solved.
    pub(super) fn elimination(&self, rates: bool) -> TokenStream {
        let own = !rates && !self.d.reduction.through_solve.is_empty();
        let elimination = if own {
            &self.d.unreduced.elimination
        } else {
            &self.d.elimination
        };
        let Elimination::Numeric(ne) = elimination else {
            return TokenStream::new();
        };
        let (m, l) = (ne.k, self.d.l);
        let cols = &ne.columns;
        let mi = int(m);
        let wi = int(cols.len());
        let rhs: Vec<Id> = (0..m)
            .flat_map(|i| cols.iter().map(move |&j| ne.r[i * (l + 1) + j]))
            .collect();
        let first = self.lu_block(ne, &rhs, cols.len(), 0);
        let binds = (0..m).flat_map(|i| {
            cols.iter().enumerate().map(move |(c, j)| {
                let x = format_ident!("__x_{}_{}", i, j);
                let (i, c) = (int(i), int(c));
                quote!(let #x = __x0[#i][#c];)
            })
        });
        let mut out = quote! {
            let __x0: [[__T; #wi]; #mi];
            #first
            #(#binds)*
        };
        if rates {
            let second = self.lu_block(ne, &ne.rhs_rate, 1, 1);
            let binds = (0..m).map(|i| {
                let w = format_ident!("__w_{}", i);
                let i = int(i);
                quote!(let #w = __x1[#i][0];)
            });
            out.extend(quote! {
                let __x1: [[__T; 1]; #mi];
                #second
                #(#binds)*
            });
        }
        out
    }

    /// `{ S and rhs; lu_solve; __x{tag} = solution }`.
    fn lu_block(
        &self,
        ne: &NumericElimination,
        rhs: &[Id],
        width: usize,
        tag: usize,
    ) -> TokenStream {
        let p = p();
        let m = ne.k;
        let mut roots: Vec<Id> = ne.s.clone();
        roots.extend_from_slice(rhs);
        let mut c = code(&self.model.g, &roots, Target::Generic { hoist: false });
        let statements = c.take_statements();
        let a_rows = matrix(&c.outputs, 0, m, m);
        let b_rows = matrix(&c.outputs, m * m, m, width);
        let (a, b, x) = (
            format_ident!("__a{}", tag),
            format_ident!("__b{}", tag),
            format_ident!("__x{}", tag),
        );
        let (mi, wi) = (int(m), int(width));
        quote! {{
            #statements
            let mut #a: [[__T; #mi]; #mi] = [#a_rows];
            let mut #b: [[__T; #wi]; #mi] = [#b_rows];
            #p::lu_solve(&mut #a, &mut #b)?;
            #x = #b;
        }}
    }

    /// The rhs as one program sharing every common subexpression (see the
    /// module docs). Returns the code (outputs: `roots` only), the
    /// statements with the solves between the stages, and the solves'
    /// operation count.
    pub(super) fn staged_rhs(&self, roots: &[Id]) -> (Code, TokenStream, usize) {
        let d = self.d;
        let Elimination::Numeric(ne) = &d.elimination else {
            let c = code(&self.model.g, roots, Target::Generic { hoist: true });
            let body = &c.body;
            let text = quote!(#(#body)*);
            return (c, text, 0);
        };
        let (m, l) = (ne.k, d.l);
        let cols = &ne.columns;
        let mut all: Vec<Id> = ne.s.clone();
        for i in 0..m {
            all.extend(cols.iter().map(|&j| ne.r[i * (l + 1) + j]));
        }
        all.extend(&ne.rhs_rate);
        let head = all.len();
        all.extend(roots);
        let mut o = options(Target::Generic { hoist: true });
        for &x in &ne.x {
            o.symbol_stage.insert(x, 1);
        }
        for &w in &ne.w {
            o.symbol_stage.insert(w, 2);
        }
        let mut c = code_with(&self.model.g, &all, &o);
        let eo: Vec<TokenStream> = c.outputs.drain(..head).collect();
        c.zero.drain(..head);
        let width = cols.len();
        let entry = |i: usize, j: usize| !self.model.g.is_zero(ne.s[i * m + j]);
        let solver = Solver {
            order: singleton_rows(m, entry),
            entry: &entry,
        };
        let p = p();
        let (mi, wi) = (int(m), int(width));
        let s_rows = matrix(&eo, 0, m, m);
        let x_rows = matrix(&eo, m * m, m, width);
        let mut out = c.take_stage(0);
        out.extend(quote! {
            let __s: [[__T; #mi]; #mi] = [#s_rows];
            let __x0: [[__T; #wi]; #mi] = [#x_rows];
            let __scale = #p::constraint_scale(&__s, #p::max_abs(&__x0))?;
        });
        let mut solve_ops = 0;
        for (t, &(i, j)) in solver.order.peeled.iter().enumerate() {
            let inv = format_ident!("__inv_{}", t);
            let (i, j) = (int(i), int(j));
            out.extend(quote! {
                #p::check_pivot(__s[#i][#j], __scale, #j)?;
                let #inv = <__T as #p::Scalar>::one() / __s[#i][#j];
            });
            solve_ops += 1;
        }
        let x_name = |j: usize, k: usize| format_ident!("__x_{}_{}", j, cols[k]);
        let rhs_zero = |i: usize, k: usize| self.model.g.is_zero(ne.r[i * (l + 1) + cols[k]]);
        let (x_solve, x_ops) = solver.solve("__x0", width, &x_name, &rhs_zero, true);
        out.extend(x_solve);
        out.extend(c.take_stage(1));
        let w_rows = matrix(&eo, m * m + m * width, m, 1);
        out.extend(quote!(let __x1: [[__T; 1]; #mi] = [#w_rows];));
        let w_name = |j: usize, _k: usize| format_ident!("__w_{}", j);
        let (w_solve, w_ops) = solver.solve("__x1", 1, &w_name, &|_, _| false, false);
        out.extend(w_solve);
        out.extend(c.take_stage(2));
        c.body.clear();
        (c, out, solve_ops + x_ops + w_ops)
    }
}

/// Solves with S: its singleton rows one by one, then its remaining block
/// by LU.
pub(super) struct Solver<'a> {
    pub(super) order: SingletonOrder,
    /// Whether S's entry (i, j) can be non-zero.
    pub(super) entry: &'a dyn Fn(usize, usize) -> bool,
}

impl Solver<'_> {
    /// Solves for the right sides `rhs` (an array of `w` columns):
    /// `name(j, k)` is the solved unknown j's value in column k; `zero(i,
    /// k)` says the right side's entry is identically zero (an unknown
    /// solved from zeros alone is zero and costs nothing, and no update
    /// multiplies by it). `factor` factors the block (the first solve);
    /// later solves reuse `__sb` and `__swaps`. Returns the statements and
    /// their operation count.
    pub(super) fn solve(
        &self,
        rhs: &str,
        w: usize,
        name: &dyn Fn(usize, usize) -> syn::Ident,
        zero: &dyn Fn(usize, usize) -> bool,
        factor: bool,
    ) -> (TokenStream, usize) {
        let p = p();
        let SingletonOrder {
            peeled,
            rows_left,
            cols_left,
        } = &self.order;
        let entry = self.entry;
        let rhs_ident = format_ident!("{}", rhs);
        let mut out = TokenStream::new();
        let mut ops = 0;
        let mut vanishing = HashSet::new();
        for (t, &(i, j)) in peeled.iter().enumerate() {
            for k in 0..w {
                let (ii, ki) = (int(i), int(k));
                let mut e = quote!(#rhs_ident[#ii][#ki]);
                let mut terms = 0;
                for &(_, jj) in &peeled[..t] {
                    if entry(i, jj) && !vanishing.contains(&(jj, k)) {
                        let (jji, known) = (int(jj), name(jj, k));
                        e = quote!(#e - __s[#ii][#jji] * #known);
                        ops += 2;
                        terms += 1;
                    }
                }
                let unknown = name(j, k);
                if terms == 0 && zero(i, k) {
                    vanishing.insert((j, k));
                    out.extend(quote!(let #unknown = <__T as #p::Scalar>::zero();));
                    continue;
                }
                let inv = format_ident!("__inv_{}", t);
                out.extend(quote!(let #unknown = (#e) * #inv;));
                ops += 1;
            }
        }
        let b = rows_left.len();
        if b == 0 {
            return (out, ops);
        }
        let rows = rows_left.iter().map(|&r| {
            let ri = int(r);
            let row = (0..w).map(|k| {
                let ki = int(k);
                let mut e = quote!(#rhs_ident[#ri][#ki]);
                for &(_, jj) in peeled {
                    if entry(r, jj) && !vanishing.contains(&(jj, k)) {
                        let (jji, known) = (int(jj), name(jj, k));
                        e = quote!(#e - __s[#ri][#jji] * #known);
                        ops += 2;
                    }
                }
                e
            });
            quote!([#(#row),*])
        });
        let rows: Vec<TokenStream> = rows.collect();
        let block_rhs = format_ident!("{}b", rhs);
        let (bi, wi) = (int(b), int(w));
        out.extend(quote!(let mut #block_rhs: [[__T; #wi]; #bi] = [#(#rows),*];));
        if factor {
            let block = rows_left.iter().map(|&r| {
                let ri = int(r);
                let row = cols_left.iter().map(|&c| {
                    let ci = int(c);
                    quote!(__s[#ri][#ci])
                });
                quote!([#(#row),*])
            });
            // The block's column numbers are S's.
            let columns = cols_left.iter().map(|&c| int(c));
            out.extend(quote! {
                let mut __sb: [[__T; #bi]; #bi] = [#(#block),*];
                let __swaps = match #p::lu_factor(&mut __sb, __scale) {
                    Ok(swaps) => swaps,
                    Err(#p::ModelError::SingularConstraints { column, pivot }) => return Err(#p::ModelError::SingularConstraints { column: [#(#columns),*][column], pivot }),
                    Err(e) => return Err(e)
                };
            });
            ops += lu_factor_ops(b);
        }
        out.extend(quote!(#p::lu_substitute(&__sb, &__swaps, &mut #block_rhs);));
        ops += lu_substitute_ops(b, w);
        for (q, &c) in cols_left.iter().enumerate() {
            for k in 0..w {
                let (unknown, qi, ki) = (name(c, k), int(q), int(k));
                out.extend(quote!(let #unknown = #block_rhs[#qi][#ki];));
            }
        }
        (out, ops)
    }
}
