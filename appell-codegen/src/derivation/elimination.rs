//! Stage 3: elimination of the unknown rates (eqs. 27-29).
//!
//! The unknowns x (the dependent rates ż, or every rate with
//! quasi-velocities) solve D' x = −D'' ẏ − d, or [D; W] q̇ = [−d; u − w]:
//! with the privileged speeds as columns, A x = R [ẏ; 1]. Unknowns whose
//! pivots are provably non-zero are eliminated symbolically, including 2×2
//! rotation blocks (`Graph::eliminate`). What remains is the Schur
//! complement S x_f = R_s [ẏ; 1], solved numerically at run time: its
//! unknowns X_f stand as auxiliary symbols in every later expression, and
//! [`SchurComplement`] carries S, R_s and the row operations T that
//! produced them (S x_f − R_s [ẏ; 1] = T (D q̇ + d), tracked by an identity
//! block beside the right sides).

use appell_symbolic::{Id, SymMatrix, Symbol, SymbolKind, SymbolicError};

use super::speeds::SpeedDefinitions;
use super::structure::{structural_solution, unmatched_column};
use crate::algebra::expanded;
use crate::ctxt::Ctxt;
use crate::model::Model;

/// The numeric remainder of the elimination, S X = R with X the free
/// unknowns' rows of [B | b].
pub struct SchurComplement {
    /// Number of unknowns left to the numeric solve.
    pub k: usize,
    /// The symbols of X (k×(l+1)), row-major.
    pub x: Vec<Symbol>,
    /// X's entries as they stand in expressions: the symbol, or zero where
    /// S and R force it.
    pub x_values: Vec<Id>,
    /// S (k×k), row-major.
    pub s: Vec<Id>,
    /// R (k×(l+1)), row-major.
    pub r: Vec<Id>,
    /// The free unknowns, as indices into the unknowns.
    pub free: Vec<usize>,
    /// T (k × unknowns), the row operations, when the rows are the
    /// constraint rows themselves (empty with quasi-velocities).
    pub row_ops: Vec<Id>,
}

/// The output of stage 3.
pub struct SolvedRates {
    /// [B | b] row by row for the unknowns (unknowns × (l+1)): x = B ẏ + b,
    /// in terms of X where the elimination is numeric.
    pub x: Vec<Id>,
    /// The numeric part, if any.
    pub schur: Option<SchurComplement>,
    /// Symbols of X's last column that are identically zero (R's column
    /// from d vanishes: a scleronomic system). They stay through the
    /// differentiation, since their rate carries w = Ẋ [ẏ; 1] into the
    /// accelerations, and are set to zero afterwards.
    pub vanishing: Vec<Symbol>,
}

/// Stage 3. `None` when errors were recorded in `cx`.
pub fn eliminate(
    cx: &Ctxt,
    model: &mut Model,
    d: &[Id],
    d0: &[Id],
    speeds: &SpeedDefinitions,
) -> Result<Option<SolvedRates>, SymbolicError> {
    let n = model.coords.len();
    let l = model.speed_specs.len();
    let m = d0.len();
    let dependent = &speeds.dependent;
    let quasi = speeds.quasi;
    let g = &mut model.g;
    let (zero, one) = (g.int(0)?, g.int(1)?);
    let k_unknowns = dependent.len();
    let mut dp = Vec::with_capacity(k_unknowns * k_unknowns);
    let mut rhs = Vec::with_capacity(k_unknowns * (l + 1));
    if quasi {
        dp.extend(d.iter().copied());
        dp.extend(speeds.w.iter().copied());
        for r in 0..m {
            rhs.extend((0..l).map(|_| zero));
            rhs.push(g.neg(d0[r])?);
        }
        for k in 0..l {
            rhs.extend((0..l).map(|j| if j == k { one } else { zero }));
            rhs.push(g.neg(speeds.w0[k])?);
        }
    } else {
        for r in 0..m {
            for &c in dependent {
                dp.push(d[r * n + c]);
            }
            for &k in &model.speeds {
                rhs.push(g.neg(d[r * n + k])?);
            }
            rhs.push(g.neg(d0[r])?);
        }
    }
    // The structural rank of the system (a matching of rows to unknowns).
    if let Some(col) = unmatched_column(g, &dp, k_unknowns) {
        let name = model.coords[dependent[col]].0.to_string();
        cx.error_spanned_by(
            &model.speeds_at,
            format!("with these privileged speeds the constraints cannot determine the rate of `{name}`: the dependent block D' is structurally singular; choose other speeds"),
        );
        return Ok(None);
    }
    let assume = model.assumptions();
    let g = &mut model.g;
    let dp_m = SymMatrix::from_rows(k_unknowns, k_unknowns, dp)?;
    // Without quasi-velocities the rows are the constraint rows themselves:
    // an identity block carried beside the right sides records T.
    let track = !quasi;
    let width = if track { l + 1 + k_unknowns } else { l + 1 };
    let mut rhs_aug = Vec::with_capacity(k_unknowns * width);
    for r in 0..k_unknowns {
        rhs_aug.extend(&rhs[r * (l + 1)..(r + 1) * (l + 1)]);
        if track {
            rhs_aug.extend((0..k_unknowns).map(|c| if c == r { one } else { zero }));
        }
    }
    let rhs_m = SymMatrix::from_rows(k_unknowns, width, rhs_aug)?;
    if k_unknowns == 0 {
        return Ok(Some(SolvedRates {
            x: Vec::new(),
            schur: None,
            vanishing: Vec::new(),
        }));
    }
    match g.eliminate(&dp_m, &rhs_m, &assume) {
        Ok(part) => Ok(Some(solved_rates(g, &part, k_unknowns, l, track)?)),
        Err(SymbolicError::StructurallySingular { column }) => {
            let name = model.coords[dependent[column]].0.to_string();
            cx.error_spanned_by(
                &model.speeds_at,
                format!("with these privileged speeds the constraints cannot determine the rate of `{name}` (D' is singular after elimination); choose other speeds"),
            );
            Ok(None)
        }
        Err(e) => Err(e),
    }
}

/// [B | b] from the partial elimination: X symbols for the free unknowns
/// (zero where S and R force it), the pivot unknowns in terms of them.
fn solved_rates(
    g: &mut appell_symbolic::Graph,
    part: &appell_symbolic::PartialSolution,
    k_unknowns: usize,
    l: usize,
    track: bool,
) -> Result<SolvedRates, SymbolicError> {
    let k = part.free_cols.len();
    let zero = g.int(0)?;
    let mut x_entries = vec![zero; k_unknowns * (l + 1)];
    let mut syms = Vec::new();
    let mut ids = Vec::new();
    let mut vanishing = Vec::new();
    // A column of R that is identically zero has X = 0 there. A speed
    // column's symbols are replaced by zero at once; the last column's stay
    // (see `SolvedRates::vanishing`).
    let zero_column: Vec<bool> = (0..=l)
        .map(|j| (0..k).all(|i| g.is_zero(part.s_rhs[(i, j)])))
        .collect();
    let nonzero = structural_solution(g, &part.s, &part.s_rhs, k, l + 1);
    for f in 0..k {
        for j in 0..=l {
            let s = g.declare(&format!("__x_{f}_{j}"), SymbolKind::Auxiliary)?;
            ids.push(if (zero_column[j] || !nonzero[f][j]) && j < l {
                zero
            } else {
                g.sym(s)?
            });
            if zero_column[j] && j == l {
                vanishing.push(s);
            }
            syms.push(s);
        }
    }
    for (f, &col) in part.free_cols.iter().enumerate() {
        for j in 0..=l {
            x_entries[col * (l + 1) + j] = ids[f * (l + 1) + j];
        }
    }
    for (i, &col) in part.pivot_cols.iter().enumerate() {
        for j in 0..=l {
            let mut terms = vec![part.pivot_rhs[(i, j)]];
            for f in 0..k {
                let t = g.mul(part.pivot_free[(i, f)], ids[f * (l + 1) + j])?;
                terms.push(g.neg(t)?);
            }
            let sum = g.sum(&terms)?;
            x_entries[col * (l + 1) + j] = expanded(g, sum)?;
        }
    }
    let schur = (k > 0).then(|| SchurComplement {
        k,
        x: syms,
        x_values: ids,
        s: part.s.entries().to_vec(),
        r: (0..k)
            .flat_map(|i| (0..=l).map(move |j| (i, j)))
            .map(|(i, j)| part.s_rhs[(i, j)])
            .collect(),
        free: part.free_cols.clone(),
        row_ops: if track {
            (0..k)
                .flat_map(|i| (0..k_unknowns).map(move |j| (i, j)))
                .map(|(i, j)| part.s_rhs[(i, l + 1 + j)])
                .collect()
        } else {
            Vec::new()
        },
    });
    Ok(SolvedRates {
        x: x_entries,
        schur,
        vanishing,
    })
}

#[cfg(test)]
mod tests {
    use super::super::testing::{self, assert_agrees};
    use super::*;

    #[test]
    fn a_constant_pivot_is_eliminated_symbolically() {
        // ẋ + r φ̇ = 0 → ẋ = −r φ̇: [B | b] = [−r, 0].
        let (mut m, _, _, _, solved) = testing::solve(testing::DISC_ON_A_LINE);
        assert!(solved.schur.is_none());
        assert_agrees(&mut m.g, solved.x[0], "-r");
        assert!(m.g.is_zero(solved.x[1]));
        assert!(solved.vanishing.is_empty());
    }

    #[test]
    fn a_pivot_not_provably_nonzero_is_left_to_the_numeric_solve() {
        // The knife edge: cos θ ẏ = sin θ ẋ. S = [cos θ], R = [sin θ, 0, 0]
        // (columns ẋ, θ̇, 1); X is a symbol where R can be non-zero, zero in
        // the θ̇ column, and a vanishing symbol in the last.
        let (mut m, _, _, _, solved) = testing::solve(testing::SLEIGH);
        let schur = solved.schur.expect("a numeric part");
        assert_eq!((schur.k, schur.free.clone()), (1, vec![0]));
        assert_agrees(&mut m.g, schur.s[0], "cos(theta)");
        assert_agrees(&mut m.g, schur.r[0], "sin(theta)");
        assert!(m.g.is_zero(schur.r[1]) && m.g.is_zero(schur.r[2]));
        let names: Vec<&str> = schur.x.iter().map(|s| m.g.symbol_name(*s)).collect();
        assert_eq!(names, vec!["__x_0_0", "__x_0_1", "__x_0_2"]);
        assert!(!m.g.is_zero(schur.x_values[0]));
        assert!(m.g.is_zero(schur.x_values[1]));
        assert_eq!(solved.vanishing, vec![schur.x[2]]);
        // T: the one row is the constraint row itself.
        assert_agrees(&mut m.g, schur.row_ops[0], "1");
    }

    #[test]
    fn an_unknown_no_row_reaches_is_reported() {
        let src = r#"
            #[appell(coordinates(x, y, z), speeds(x))]
            #[appell(point(P = O + x * N.x + y * N.y + z * N.z), particle(P, mass = m))]
            #[appell(nonholonomic(dt(y) == dt(x)), nonholonomic(dt(y) == 2 * dt(x)))]
            struct Bad { m: f64 }
        "#;
        let (mut model, calculus) = testing::model_and_calculus(src);
        let cx = Ctxt::new();
        let rows = super::super::rows::constraint_rows(&cx, &mut model, &calculus)
            .unwrap()
            .unwrap();
        let speeds = super::super::speeds::speed_definitions(&cx, &mut model, &rows)
            .unwrap()
            .unwrap();
        let solved = eliminate(&cx, &mut model, &rows.d, &rows.d0, &speeds).unwrap();
        assert!(solved.is_none());
        let err = cx.check().expect_err("an error").to_string();
        assert!(err.contains("cannot determine the rate of `z`"), "{err}");
    }
}
