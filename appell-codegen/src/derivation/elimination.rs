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
use crate::model::{ConstraintSet, Model};

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
    set: &ConstraintSet,
    d: &[Id],
    d0: &[Id],
    speeds: &SpeedDefinitions,
) -> Result<Option<SolvedRates>, SymbolicError> {
    let n = model.coords.len();
    let l = set.speed_specs.len();
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
            for &k in &set.speeds {
                rhs.push(g.neg(d[r * n + k])?);
            }
            rhs.push(g.neg(d0[r])?);
        }
    }
    // Quaternion rates in closed form; the rest of the system without them.
    let quaternions = model.quaternions.clone();
    let norms = unit_norms(g, &quaternions, &model.coords, &set.holonomic)?;
    let closed = if quasi {
        closed_form_blocks(g, (&quaternions, &norms), dependent, &dp, &rhs, l)?
    } else {
        ClosedForm::none(k_unknowns)
    };
    let (dp, rhs) = closed.reduce(g, &dp, &rhs, l)?;
    let dependent: Vec<usize> = closed.remaining.iter().map(|&c| dependent[c]).collect();
    let k_unknowns = dependent.len();
    // The structural rank of the system (a matching of rows to unknowns).
    if let Some(col) = unmatched_column(g, &dp, k_unknowns) {
        let name = model.coords[dependent[col]].0.to_string();
        cx.error_spanned_by(
            &set.speeds_at,
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
        let none = SolvedRates {
            x: Vec::new(),
            schur: None,
            vanishing: Vec::new(),
        };
        return Ok(Some(closed.merge(none, l)));
    }
    match g.eliminate(&dp_m, &rhs_m, &assume) {
        Ok(part) => Ok(Some(
            closed.merge(solved_rates(g, &part, k_unknowns, l, track)?, l),
        )),
        Err(SymbolicError::StructurallySingular { column }) => {
            let name = model.coords[dependent[column]].0.to_string();
            cx.error_spanned_by(
                &set.speeds_at,
                format!("with these privileged speeds the constraints cannot determine the rate of `{name}` (D' is singular after elimination); choose other speeds"),
            );
            Ok(None)
        }
        Err(e) => Err(e),
    }
}

/// Unknowns solved in closed form before the general elimination: the
/// rates of a quaternion's components.
///
/// With quasi-velocities, the rows whose only unknowns are a quaternion's
/// four rates (its unit norm's row 2 e·ė and the rows of its angular
/// velocity speeds, 2 (e0 ė − ė0 e⃗ − e⃗ × ė)) form a block A with
/// A Aᵀ = c I for every e (c = 4 |e|²), so A x = R is x = Aᵀ R / c: no
/// pivot to prove, no run-time solve. A block is used only when that
/// identity holds symbolically; where the model holds |e|² = 1 (every
/// ball's and free joint's norm), c is taken at that value.
struct ClosedForm {
    /// The unknowns solved here, with their rows of [B | b].
    solved: Vec<(usize, Vec<Id>)>,
    /// The rows used.
    rows: Vec<usize>,
    /// The unknowns left to the general elimination, in order.
    remaining: Vec<usize>,
    /// The number of unknowns in all.
    unknowns: usize,
}

impl ClosedForm {
    fn none(unknowns: usize) -> ClosedForm {
        ClosedForm {
            solved: Vec::new(),
            rows: Vec::new(),
            remaining: (0..unknowns).collect(),
            unknowns,
        }
    }

    /// The system without the solved unknowns and their rows: every other
    /// row's right side less its terms in them.
    fn reduce(
        &self,
        g: &mut appell_symbolic::Graph,
        dp: &[Id],
        rhs: &[Id],
        l: usize,
    ) -> Result<(Vec<Id>, Vec<Id>), SymbolicError> {
        let k = self.unknowns;
        let mut a = Vec::new();
        let mut r = Vec::new();
        for row in (0..k).filter(|row| !self.rows.contains(row)) {
            a.extend(self.remaining.iter().map(|&c| dp[row * k + c]));
            for j in 0..=l {
                let mut terms = vec![rhs[row * (l + 1) + j]];
                for (col, x) in &self.solved {
                    let t = g.mul(dp[row * k + col], x[j])?;
                    terms.push(g.neg(t)?);
                }
                let sum = g.sum(&terms)?;
                r.push(expanded(g, sum)?);
            }
        }
        Ok((a, r))
    }

    /// The whole [B | b]: the closed-form rows and the general
    /// elimination's, its free unknowns renumbered.
    fn merge(self, rest: SolvedRates, l: usize) -> SolvedRates {
        if self.solved.is_empty() {
            return rest;
        }
        let mut x = vec![None; self.unknowns];
        for (col, row) in self.solved {
            x[col] = Some(row);
        }
        for (i, &col) in self.remaining.iter().enumerate() {
            x[col] = Some(rest.x[i * (l + 1)..(i + 1) * (l + 1)].to_vec());
        }
        let schur = rest.schur.map(|mut s| {
            s.free = s.free.iter().map(|&f| self.remaining[f]).collect();
            s
        });
        SolvedRates {
            x: x.into_iter()
                .flat_map(|row| row.expect("every unknown"))
                .collect(),
            schur,
            vanishing: rest.vanishing,
        }
    }
}

/// Finds the quaternion blocks of [`ClosedForm`] among the unknowns
/// (`dependent`: every coordinate's rate, with quasi-velocities).
fn closed_form_blocks(
    g: &mut appell_symbolic::Graph,
    (quaternions, norms): (&[[usize; 4]], &[Option<Id>]),
    dependent: &[usize],
    dp: &[Id],
    rhs: &[Id],
    l: usize,
) -> Result<ClosedForm, SymbolicError> {
    let k = dependent.len();
    let mut closed = ClosedForm::none(k);
    for (q, norm) in quaternions.iter().zip(norms) {
        let Some(cols) = q
            .iter()
            .map(|c| dependent.iter().position(|d| d == c))
            .collect::<Option<Vec<usize>>>()
        else {
            continue;
        };
        let rows: Vec<usize> = (0..k)
            .filter(|&r| {
                let nonzero = |c: usize| !g.is_zero(dp[r * k + c]);
                cols.iter().any(|&c| nonzero(c)) && (0..k).all(|c| cols.contains(&c) || !nonzero(c))
            })
            .collect();
        if rows.len() != 4 || rows.iter().any(|r| closed.rows.contains(r)) {
            continue;
        }
        let a: Vec<Vec<Id>> = rows
            .iter()
            .map(|r| cols.iter().map(|c| dp[r * k + c]).collect())
            .collect();
        let Some(mut c) = orthogonal_scale(g, &a)? else {
            continue;
        };
        if let Some(n2) = norm {
            c = on_the_unit_sphere(g, c, *n2)?;
        }
        // x = Aᵀ R / c, one unknown at a time.
        for (i, &col) in cols.iter().enumerate() {
            let mut row = Vec::with_capacity(l + 1);
            for j in 0..=l {
                let mut terms = Vec::with_capacity(4);
                for (t, &r) in rows.iter().enumerate() {
                    terms.push(g.mul(a[t][i], rhs[r * (l + 1) + j])?);
                }
                let sum = g.sum(&terms)?;
                let x = g.div(sum, c)?;
                row.push(expanded(g, x)?);
            }
            closed.solved.push((col, row));
        }
        closed.rows.extend(rows);
    }
    closed
        .remaining
        .retain(|c| !closed.solved.iter().any(|(s, _)| s == c));
    Ok(closed)
}

/// For each quaternion block, |e|² when the model constrains it to 1 (a
/// holonomic `Σ e² == 1`, as every ball and free joint writes), else None.
fn unit_norms(
    g: &mut appell_symbolic::Graph,
    quaternions: &[[usize; 4]],
    coords: &[(syn::Ident, appell_symbolic::Coordinate)],
    holonomic: &[crate::model::Constraint],
) -> Result<Vec<Option<Id>>, SymbolicError> {
    let mut out = Vec::with_capacity(quaternions.len());
    for block in quaternions {
        let mut squares = Vec::with_capacity(4);
        for &c in block {
            let e = g.sym(coords[c].1.q)?;
            squares.push(g.mul(e, e)?);
        }
        let n2 = g.sum(&squares)?;
        let one = g.int(1)?;
        let residual = g.sub(n2, one)?;
        let mut found = false;
        for h in holonomic {
            let diff = g.sub(h.residual, residual)?;
            let diff = g.expand_outside_functions(diff, 64).unwrap_or(diff);
            found |= g.is_zero(diff);
        }
        out.push(found.then_some(n2));
    }
    Ok(out)
}

/// The scale c = k |e|² of a quaternion block's rows as its value k on the
/// unit sphere the model's constraint keeps (c itself when it is not a
/// multiple of |e|² = `n2`): the rates lose a division by |e|², the same
/// on the sphere.
fn on_the_unit_sphere(g: &mut appell_symbolic::Graph, c: Id, n2: Id) -> Result<Id, SymbolicError> {
    for k in [4, 1] {
        let value = g.int(k)?;
        let multiple = g.mul(value, n2)?;
        let diff = g.sub(c, multiple)?;
        let diff = g.expand_outside_functions(diff, 64).unwrap_or(diff);
        if g.is_zero(diff) {
            return Ok(value);
        }
    }
    Ok(c)
}

/// c when the square matrix `a` has A Aᵀ = c I with c not identically
/// zero (after expansion), else None.
fn orthogonal_scale(
    g: &mut appell_symbolic::Graph,
    a: &[Vec<Id>],
) -> Result<Option<Id>, SymbolicError> {
    let n = a.len();
    let mut scale = None;
    for i in 0..n {
        for j in i..n {
            let products: Vec<Id> = (0..n)
                .map(|t| g.mul(a[i][t], a[j][t]))
                .collect::<Result<_, _>>()?;
            let sum = g.sum(&products)?;
            let s = g.expand_outside_functions(sum, 64).unwrap_or(sum);
            match (i == j, scale) {
                (false, _) if g.is_zero(s) => {}
                (false, _) => return Ok(None),
                (true, None) if !g.is_zero(s) => scale = Some(s),
                (true, Some(c)) => {
                    let diff = g.sub(s, c)?;
                    let diff = g.expand_outside_functions(diff, 64).unwrap_or(diff);
                    if !g.is_zero(diff) {
                        return Ok(None);
                    }
                }
                (true, None) => return Ok(None),
            }
        }
    }
    Ok(scale)
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
    fn a_quaternions_rates_are_solved_in_closed_form() {
        // A ball joint: ė = Aᵀ [0; ω] / (4 |e|²), A = 2 [e; G(e)], and its
        // unit norm makes 4 |e|² = 4: ė0 = −(e1 ωx + e2 ωy + e3 ωz) / 2.
        let src = r#"
            #[appell(joint(j, spherical, parent = N, child = B))]
            #[appell(body(b, center = B_origin, frame = B, mass = m, inertia = principal(a, b, c)))]
            struct Ball { m: f64, a: f64, b: f64, c: f64 }
        "#;
        let (mut m, _, _, _, solved) = testing::solve(src);
        assert!(solved.schur.is_none());
        // Columns: ωx, ωy, ωz, 1.
        assert_agrees(&mut m.g, solved.x[0], "-j_qx / 2");
        assert_agrees(&mut m.g, solved.x[1], "-j_qy / 2");
        assert_agrees(&mut m.g, solved.x[4], "j_qw / 2");
        assert!(m.g.is_zero(solved.x[3]));
    }

    #[test]
    fn a_quaternion_held_at_another_norm_keeps_the_division() {
        // A frame turned by a quaternion of coordinates whose norm is held
        // at another value: the rates keep 1 / |e|².
        let src = r#"
            #[appell(coordinates(e0, e1, e2, e3))]
            #[appell(frame(B = N.quaternion(e0, e1, e2, e3)))]
            #[appell(speeds(wx = 2 * (e0 * dt(e1) - dt(e0) * e1 - e2 * dt(e3) + e3 * dt(e2)),
                            wy = 2 * (e0 * dt(e2) - dt(e0) * e2 - e3 * dt(e1) + e1 * dt(e3)),
                            wz = 2 * (e0 * dt(e3) - dt(e0) * e3 - e1 * dt(e2) + e2 * dt(e1))))]
            #[appell(holonomic(e0 * e0 + e1 * e1 + e2 * e2 + e3 * e3 == 2))]
            #[appell(body(b, center = O, frame = B, mass = m, inertia = principal(a, b, c)))]
            struct Loose { m: f64, a: f64, b: f64, c: f64 }
        "#;
        let (mut m, _, _, _, solved) = testing::solve(src);
        let e2 = "e0^2 + e1^2 + e2^2 + e3^2";
        // ė0 along ωx: −e1 / (2 |e|²).
        assert_agrees(&mut m.g, solved.x[0], &format!("-e1 / (2 * ({e2}))"));
    }

    #[test]
    fn a_block_that_is_not_orthogonal_is_left_to_the_general_elimination() {
        let mut g = appell_symbolic::Graph::new();
        for s in ["a", "b"] {
            g.parameter(s).unwrap();
        }
        let rows = [["a", "b"], ["-b", "a"]].map(|r| r.map(|e| g.parse(e).unwrap()).to_vec());
        let c = orthogonal_scale(&mut g, &rows)
            .unwrap()
            .expect("a rotation-like block");
        assert_agrees(&mut g, c, "a^2 + b^2");
        let rows = [["a", "b"], ["b", "a"]].map(|r| r.map(|e| g.parse(e).unwrap()).to_vec());
        assert!(orthogonal_scale(&mut g, &rows).unwrap().is_none());
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
        let set = model.constraints.clone();
        let rows = super::super::rows::constraint_rows(&cx, &mut model, &set, &calculus)
            .unwrap()
            .unwrap();
        let speeds = super::super::speeds::speed_definitions(&cx, &mut model, &set, &rows)
            .unwrap()
            .unwrap();
        let solved = eliminate(&cx, &mut model, &set, &rows.d, &rows.d0, &speeds).unwrap();
        assert!(solved.is_none());
        let err = cx.check().expect_err("an error").to_string();
        assert!(err.contains("cannot determine the rate of `z`"), "{err}");
    }
}
