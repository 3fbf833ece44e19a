//! The world frame's candidate with its columns solved in loops: one
//! program for q̇, ÿ, M's factors and every column's right side
//! ∂τ/∂c − ∂Q/∂c, the right sides stored in a scratch matrix (a row per
//! speed, A's columns then B's); then the forward and back substitutions
//! by the factors, a whole row at a time (`linalg::substitute_row`), in
//! loops the compiler vectorizes over the columns; then the rows copied
//! into A and B (a free root's ṗ rows scaled first). Unrolled, a chain's
//! solves grow like l³ expressions; in loops they are 2l calls.

use proc_macro2::TokenStream;
use quote::{format_ident, quote};

use super::super::code::{code, Code, Target};
use super::super::{int, p, Emitter};
use super::{Candidate, Layout, Roots};
use crate::derivation::jacobian::{retained_rates, Jacobians, UnsolvedColumns, WorldJacobian};
use appell_core::linalg::ROW_CHUNK;

/// SIMD lanes the loops are assumed to fill when candidates are compared:
/// two f64 lanes, which every x86-64 (SSE2) and aarch64 (NEON) target has.
pub(super) const LANES: usize = 2;

/// A substitution call's cost besides its arithmetic, in operations'
/// worth (the call, its terms' array), when candidates are compared.
const CALL: usize = 8;

/// Where a loop candidate's roots sit after the values (q̇, ÿ).
struct Offsets {
    /// The retained rates' rows over the written columns.
    rates: usize,
    /// ÿ's right sides, l rows over the written columns, in speed order.
    forcing: usize,
    /// L's entries below the diagonal, row by row in elimination order.
    lower: usize,
    /// 1 / dᵢ in elimination order.
    reciprocals: usize,
    /// The scaled rows' scales and added terms, row after row.
    rows: usize,
}

impl Offsets {
    fn new(values: usize, retained: usize, l: usize, width: usize) -> Offsets {
        let rates = values;
        let forcing = rates + retained * width;
        let lower = forcing + l * width;
        let reciprocals = lower + l * l.saturating_sub(1) / 2;
        Offsets {
            rates,
            forcing,
            lower,
            reciprocals,
            rows: reciprocals + l,
        }
    }

    /// L's entry at positions (i, k), k < i.
    fn lower(&self, i: usize, k: usize) -> usize {
        self.lower + i * (i - 1) / 2 + k
    }
}

impl Emitter<'_> {
    /// The loop candidate's roots: q̇ and ÿ, then (see [`Offsets`]) the
    /// rates' rows, the right sides, L, the reciprocals and the scaled
    /// rows' scales and terms.
    pub(super) fn loop_roots(
        &self,
        world: &WorldJacobian,
        layout: &Layout,
        j: &Jacobians,
    ) -> Roots {
        let (n, l, u) = (j.columns.len(), self.d.l, &world.unsolved);
        let mut all = retained_rates(self.d);
        all.extend(&world.accelerations);
        let values = all.len();
        for row in 0..layout.retained {
            all.extend(layout.columns.iter().map(|&c| u.rates[row * n + c]));
        }
        for speed in 0..l {
            all.extend(layout.columns.iter().map(|&c| u.forcing[c][speed]));
        }
        for i in 0..l {
            all.extend(&u.lower[i][..i]);
        }
        all.extend(&u.reciprocals);
        for row in &u.rows {
            all.push(row.scale);
            all.extend(row.adds.iter().map(|&(_, term)| term));
        }
        Roots { all, values }
    }

    /// The loop candidate's body: the program and its values stored, ÿ's
    /// right sides into a scratch matrix (a row per speed, the columns of
    /// A then B padded to whole chunks of [`ROW_CHUNK`]), the forward and
    /// back substitutions (the pivots with the latter) a row at a time,
    /// and the solved rows copied into ÿ's rows of `__a` and `__b`.
    pub(super) fn loop_candidate(
        &self,
        roots: Roots,
        layout: &Layout,
        world: &WorldJacobian,
    ) -> Candidate {
        let (p, u) = (p(), &world.unsolved);
        let (l, width) = (self.d.l, layout.columns.len());
        let padded = width.div_ceil(ROW_CHUNK) * ROW_CHUNK;
        let at = Offsets::new(roots.values, layout.retained, l, width);
        let mut program = code(&self.model.g, &roots.all, Target::Generic { hoist: false });
        let statements = program.take_statements();
        let zero = quote!(<__T as #p::Scalar>::zero());
        let size = int(l * padded);
        let mut body = quote! {
            let mut __x = [#zero; #size];
            #statements
        };
        for k in 0..roots.values {
            let (value, k) = (&program.outputs[k], int(k));
            body.extend(quote!(__dstate[#k] = #value;));
        }
        // The rates' rows into A and B, ÿ's right sides into the scratch.
        for row in 0..layout.retained + l {
            for w in 0..width {
                let (root, entry) = if row < layout.retained {
                    (at.rates + row * width + w, layout.entry(row, w))
                } else {
                    let speed = row - layout.retained;
                    let k = int(speed * padded + w);
                    (at.forcing + speed * width + w, quote!(__x[#k]))
                };
                if !program.zero[root] {
                    let value = &program.outputs[root];
                    body.extend(quote!(#entry = #value;));
                }
            }
        }
        let mut solve = Solve {
            order: &u.order,
            padded,
            looped: 0,
            calls: 0,
            body: TokenStream::new(),
        };
        // The factor's entries, each bound once.
        let mut names = vec![vec![None; l]; l];
        for (i, row) in names.iter_mut().enumerate() {
            for (k, name) in row.iter_mut().enumerate().take(i) {
                let id = at.lower(i, k);
                if !program.zero[id] {
                    let (ident, value) = (format_ident!("__wl_{}_{}", i, k), &program.outputs[id]);
                    body.extend(quote!(let #ident = #value;));
                    *name = Some(quote!(#ident));
                }
            }
        }
        // Forward: z_i = b_i − Σ_{k<i} L_ik z_k.
        for i in 0..l {
            let terms: Vec<_> = (0..i)
                .filter_map(|k| names[i][k].clone().map(|n| (k, n)))
                .collect();
            solve.row(i, None, &terms);
        }
        // Back: y_i = z_i / d_i − Σ_{k>i} L_ki y_k.
        for i in (0..l).rev() {
            let terms: Vec<_> = (i + 1..l)
                .filter_map(|k| names[k][i].clone().map(|n| (k, n)))
                .collect();
            solve.row(i, Some(&program.outputs[at.reciprocals + i]), &terms);
        }
        body.extend(solve.body);
        body.extend(scaled_rows(u, layout, &program, at.rows, padded));
        body.extend(copy_out(layout, l, padded));
        Candidate {
            body,
            ops: program.ops,
            extra: 0,
            // The free roots' rows scaled, and their added terms.
            looped: solve.looped + u.rows.iter().map(|r| padded + r.adds.len()).sum::<usize>(),
            // The scratch zeroed and copied out, and the calls.
            overhead: l * (padded + width) + (solve.calls + u.rows.len()) * CALL,
        }
    }
}

/// After the solve, a free root's ṗ rows of the scratch scaled and the
/// quaternion's columns' terms added (`first`: the first scale's root).
fn scaled_rows(
    u: &UnsolvedColumns,
    layout: &Layout,
    program: &Code,
    first: usize,
    padded: usize,
) -> TokenStream {
    let p = p();
    let mut out = TokenStream::new();
    let mut at = first;
    for row in &u.rows {
        let (speed, width) = (int(row.speed), int(padded));
        let scale = &program.outputs[at];
        out.extend(quote! {
            #p::substitute_row(&mut __x, #width, #speed, #scale, &[]);
        });
        at += 1;
        for &(column, _) in &row.adds {
            let written = layout.columns.iter().position(|&c| c == column);
            if let (Some(w), false) = (written, program.zero[at]) {
                let (k, term) = (int(row.speed * padded + w), &program.outputs[at]);
                out.extend(quote!(__x[#k] = __x[#k] + #term;));
            }
            at += 1;
        }
    }
    out
}

/// The scratch's rows (a row per speed) into ÿ's rows of `__a` and `__b`.
fn copy_out(layout: &Layout, l: usize, padded: usize) -> TokenStream {
    let (s, ni, r) = (layout.states, layout.inputs, layout.retained);
    let (su, niu, ru, lu, pu) = (int(s), int(ni), int(r), int(l), int(padded));
    let inputs = (ni > 0).then(|| {
        quote! {
            __b[(#ru + __s) * #niu..(#ru + __s + 1) * #niu]
                .copy_from_slice(&__x[__s * #pu + #su..__s * #pu + #su + #niu]);
        }
    });
    quote! {
        for __s in 0..#lu {
            __a[(#ru + __s) * #su..(#ru + __s + 1) * #su]
                .copy_from_slice(&__x[__s * #pu..__s * #pu + #su]);
            #inputs
        }
    }
}

/// The substitutions' calls over the scratch, and their operations.
struct Solve<'a> {
    /// The speed at each position of the elimination order.
    order: &'a [usize],
    /// The scratch's row length.
    padded: usize,
    /// The operations in the loops.
    looped: usize,
    /// The calls.
    calls: usize,
    body: TokenStream,
}

impl Solve<'_> {
    /// Row i (a position) as `scale` (or one) times itself less Σ L times
    /// row k over `terms` (positions and the factor's entries); nothing
    /// where it would leave the row as it is.
    fn row(&mut self, i: usize, scale: Option<&TokenStream>, terms: &[(usize, TokenStream)]) {
        if terms.is_empty() && scale.is_none() {
            return;
        }
        let p = p();
        let one = quote!(<__T as #p::Scalar>::one());
        let scaled = scale.is_some();
        let scale = scale.unwrap_or(&one);
        let row = int(self.order[i]);
        let pairs = terms.iter().map(|(k, l)| {
            let rk = int(self.order[*k]);
            quote!((#rk, #l))
        });
        let (count, width) = (int(terms.len()), int(self.padded));
        self.body.extend(quote! {
            let __terms: [(usize, __T); #count] = [#(#pairs),*];
            #p::substitute_row(&mut __x, #width, #row, #scale, &__terms);
        });
        self.looped += self.padded * (2 * terms.len() + usize::from(scaled));
        self.calls += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::Offsets;

    #[test]
    fn the_offsets_follow_one_another() {
        // 2 values, 1 retained rate, 3 speeds, 4 columns.
        let at = Offsets::new(2, 1, 3, 4);
        assert_eq!(at.rates, 2);
        assert_eq!(at.forcing, 6);
        assert_eq!(at.lower, 18);
        assert_eq!(at.lower(1, 0), 18);
        assert_eq!(at.lower(2, 0), 19);
        assert_eq!(at.lower(2, 1), 20);
        assert_eq!(at.reciprocals, 21);
        assert_eq!(at.rows, 24);
    }
}
