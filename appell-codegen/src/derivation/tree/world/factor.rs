//! M = L D Lᵀ in the graph, the speeds taken leaves first so that a tree's
//! M factors without fill (Featherstone's LTDL order), and solves by it:
//! ÿ = M⁻¹ (τ − h), and the Jacobian's columns −M⁻¹ ∂R/∂c.

use appell_symbolic::{Id, SymbolicError};

use super::super::spatial::Algebra;

type R<T> = Result<T, SymbolicError>;

/// M's factors over the speeds in elimination order: a speed after every
/// speed of its subtree. Every entry is held, so a solve multiplies each
/// once.
pub struct MassFactor {
    /// The speed at each position of the elimination order.
    order: Vec<usize>,
    /// L below the diagonal in that order, row-major; literal zeros where a
    /// row's speed does not move the column's.
    lower: Vec<Vec<Id>>,
    /// 1 / dᵢ.
    reciprocals: Vec<Id>,
    /// Whether L has no zero below its diagonal.
    dense: bool,
}

impl MassFactor {
    /// The factors of `mass` (l×l row-major over the speeds), eliminated
    /// in `order`: every speed after the speeds of its subtree.
    pub fn new(a: &mut Algebra, order: Vec<usize>, mass: &[Id]) -> R<MassFactor> {
        let l = order.len();
        let m = |i: usize, j: usize| mass[order[i] * l + order[j]];
        let mut lower = vec![vec![a.zero(); l]; l];
        let mut pivots = vec![a.zero(); l];
        let mut reciprocals = vec![a.zero(); l];
        for j in 0..l {
            // dⱼ = Mⱼⱼ − Σ Lⱼₖ² dₖ; Lᵢⱼ = (Mᵢⱼ − Σ Lᵢₖ Lⱼₖ dₖ) / dⱼ, with
            // Lⱼₖ dₖ formed once per k.
            let mut scaled = vec![None; j];
            for (k, slot) in scaled.iter_mut().enumerate() {
                if !a.g.is_zero(lower[j][k]) {
                    *slot = Some(a.g.mul(lower[j][k], pivots[k])?);
                }
            }
            let taken = a.dot((0..j).filter_map(|k| scaled[k].map(|ld| (ld, lower[j][k]))))?;
            let pivot = a.g.sub(m(j, j), taken)?;
            pivots[j] = a.g.hold(pivot)?;
            let recip = a.g.recip(pivots[j])?;
            reciprocals[j] = a.g.hold(recip)?;
            for i in j + 1..l {
                let taken = a.dot((0..j).filter_map(|k| scaled[k].map(|ld| (ld, lower[i][k]))))?;
                let rest = a.g.sub(m(i, j), taken)?;
                if a.g.is_zero(rest) {
                    continue;
                }
                let entry = a.g.mul(rest, reciprocals[j])?;
                lower[i][j] = a.g.hold(entry)?;
            }
        }
        let dense = (1..l).all(|i| (0..i).all(|k| !a.g.is_zero(lower[i][k])));
        Ok(MassFactor {
            order,
            lower,
            reciprocals,
            dense,
        })
    }

    /// M⁻¹ b for `b` in speed order, each entry of the result held.
    pub fn solve(&self, a: &mut Algebra, b: &[Id]) -> R<Vec<Id>> {
        let l = self.order.len();
        let mut x: Vec<Id> = self.order.iter().map(|&s| b[s]).collect();
        for i in 0..l {
            let taken = a.dot((0..i).map(|k| (self.lower[i][k], x[k])))?;
            let rest = a.g.sub(x[i], taken)?;
            x[i] = a.g.hold(rest)?;
        }
        for i in 0..l {
            let scaled = a.dot([(x[i], self.reciprocals[i])])?;
            x[i] = scaled;
        }
        for i in (0..l).rev() {
            let taken = a.dot((i + 1..l).map(|k| (self.lower[k][i], x[k])))?;
            let rest = a.g.sub(x[i], taken)?;
            x[i] = a.g.hold(rest)?;
        }
        let mut out = vec![a.zero(); l];
        for (p, &s) in self.order.iter().enumerate() {
            out[s] = x[p];
        }
        Ok(out)
    }
}

impl MassFactor {
    /// The speed at each position of the elimination order.
    pub fn order(&self) -> &[usize] {
        &self.order
    }

    /// L's entry at positions (i, k), k < i, in the elimination order (a
    /// literal zero where a row's speed does not move the column's).
    pub fn lower(&self, i: usize, k: usize) -> Id {
        self.lower[i][k]
    }

    /// 1 / dᵢ at each position of the elimination order.
    pub fn reciprocals(&self) -> &[Id] {
        &self.reciprocals
    }

    /// Whether L has no zero below its diagonal: M of a chain (one speed
    /// per link).
    pub fn is_dense(&self) -> bool {
        self.dense
    }

    /// M⁻¹ = L⁻ᵀ D⁻¹ L⁻¹, l×l row-major in speed order, each entry held
    /// (symmetric: each formed once).
    pub fn inverse(&self, a: &mut Algebra) -> R<Vec<Id>> {
        let l = self.order.len();
        let one = a.g.int(1)?;
        // X = L⁻¹, unit lower: Xᵢⱼ = −Σ_{j ≤ k < i} Lᵢₖ Xₖⱼ.
        let mut x = vec![vec![a.zero(); l]; l];
        for j in 0..l {
            x[j][j] = one;
            for i in j + 1..l {
                let taken = a.dot((j..i).map(|k| (self.lower[i][k], x[k][j])))?;
                let entry = a.g.neg(taken)?;
                x[i][j] = a.g.hold(entry)?;
            }
        }
        // (M⁻¹)ₚₖ = Σ_{k ≥ max(p, q)} Xₖₚ / dₖ Xₖq.
        let mut scaled = vec![vec![a.zero(); l]; l];
        for k in 0..l {
            for p in 0..=k {
                let entry = a.dot([(x[k][p], self.reciprocals[k])])?;
                scaled[k][p] = a.g.hold(entry)?;
            }
        }
        let mut out = vec![a.zero(); l * l];
        for p in 0..l {
            for q in p..l {
                let entry = a.dot((q..l).map(|k| (scaled[k][p], x[k][q])))?;
                let entry = a.g.hold(entry)?;
                let (sp, sq) = (self.order[p], self.order[q]);
                out[sp * l + sq] = entry;
                out[sq * l + sp] = entry;
            }
        }
        Ok(out)
    }
}
