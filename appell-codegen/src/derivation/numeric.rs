//! Stage 5: the numeric part of the elimination, as the generated code
//! solves it.
//!
//! S X = R gives the dependent rates' coefficients X. The accelerations need
//! Ẋ only in the combination w = Ẋ [ẏ; 1], the dependent acceleration
//! remainder: every β̄_k is linear in the column X_k, so Σ_k β̄̇_k ẏ_k + β̄̇
//! sees Σ_k Ẋ_k ẏ_k + Ẋ_l. The rate rules therefore take X_fk → 0 (k < l)
//! and X_fl → w_f, and w solves S w = (Ṙ − Ṡ X) [ẏ; 1]: one right-hand side
//! instead of l + 1.
//!
//! That right side is minus the rate of the rows S q̇_f − R [ẏ; 1] taken
//! along q̇ with the rates held fixed, the rates then replaced by their
//! values. Those rows are T (D q̇ + d), and D q̇ + d vanishes at the rates
//! used, so the rate of T drops out: S w = −T ∂(D q̇ + d), with each
//! constraint row differentiated as the model wrote it, which shares its
//! work with the bodies' acceleration remainders.

use appell_symbolic::{Graph, Id, Substitution, Symbol, SymbolKind, SymbolicError};

use super::elimination::SchurComplement;
use super::energies::Energies;
use super::loads::Equations;
use super::rows::ConstraintRows;
use super::speed_map::{Rates, SpeedMap};
use crate::model::{ConstraintSet, Model};
use crate::probe::same_function;

/// How the dependent speeds are obtained.
#[derive(Clone)]
pub enum Elimination {
    /// B and b are expressions.
    Symbolic,
    /// B and b are solved numerically in the generated code.
    Numeric(NumericElimination),
}

/// The numeric part of the elimination: after the unknowns with safe
/// pivots are eliminated symbolically, the remaining k dependent rates solve
/// S X = R (X = the free rows of [B | b]); for the accelerations,
/// S w = (Ṙ − Ṡ X) [ẏ; 1] with w = Ẋ [ẏ; 1].
#[derive(Clone)]
pub struct NumericElimination {
    /// Number of unknowns solved numerically.
    pub k: usize,
    /// S (k×k), row-major.
    pub s: Vec<Id>,
    /// R (k×(l+1)), row-major.
    pub r: Vec<Id>,
    /// (Ṙ − Ṡ X) [ẏ; 1] (k), the right side for w; contains X and ẏ. With
    /// the row operations T it is built as −T ∂(D q̇ + d), each constraint
    /// row differentiated as written (see the module docs).
    pub rhs_rate: Vec<Id>,
    /// The columns j of R that are not identically zero (X_fj = 0 in the
    /// others, and their symbols occur nowhere).
    pub columns: Vec<usize>,
    /// Symbols of X (k×(l+1)).
    pub x: Vec<Symbol>,
    /// Symbols of w = Ẋ [ẏ; 1] (k), the dependent acceleration remainder.
    pub w: Vec<Symbol>,
}

impl NumericElimination {
    /// The expressions the generated code evaluates: S, R and the right
    /// side for w.
    pub fn expressions(&self) -> impl Iterator<Item = &Id> {
        self.s.iter().chain(&self.r).chain(&self.rhs_rate)
    }

    /// The same, to rewrite in place.
    pub fn expressions_mut(&mut self) -> impl Iterator<Item = &mut Id> {
        self.s
            .iter_mut()
            .chain(self.r.iter_mut())
            .chain(self.rhs_rate.iter_mut())
    }
}

/// What stage 5 reads besides the Schur complement.
pub struct NumericInputs<'a> {
    /// The constraints and speeds derived with.
    pub set: &'a ConstraintSet,
    /// Stage 1's rows.
    pub rows: &'a ConstraintRows,
    /// The unknowns' coordinates.
    pub dependent: &'a [usize],
    /// Stage 4's C, c and q̇.
    pub map: &'a SpeedMap,
    /// X's vanishing last column (see `SolvedRates::vanishing`).
    pub vanishing: &'a [Symbol],
}

/// Stage 5: S and R read off the rows as written where they agree, w and
/// the right side S w = (Ṙ − Ṡ X) [ẏ; 1]. Adds X's rates to `rates.reduced`.
pub fn numeric_elimination(
    model: &mut Model,
    schur: SchurComplement,
    inputs: NumericInputs<'_>,
    rates: &mut Rates,
    uncut: &mut Substitution,
) -> Result<NumericElimination, SymbolicError> {
    let NumericInputs {
        set,
        rows,
        dependent,
        map,
        vanishing,
    } = inputs;
    let l = set.speed_specs.len();
    let k = schur.k;
    let k_unknowns = dependent.len();
    let coordinate_rates = model.coordinate_rates();
    let (mut s_mat, mut s_rhs) = (schur.s, schur.r);
    if !schur.row_ops.is_empty() {
        let speed_cols: Vec<Symbol> = set
            .speeds
            .iter()
            .map(|&sp| model.coords[sp].1.rate)
            .collect();
        let free: Vec<Symbol> = schur
            .free
            .iter()
            .map(|&c| model.coords[dependent[c]].1.rate)
            .collect();
        if let Some((new_s, new_r)) = schur_as_written(
            &mut model.g,
            SchurRows {
                rows: &rows.as_written,
                row_ops: &schur.row_ops,
                width: k_unknowns,
                rates: &coordinate_rates,
                free: &free,
                speeds: &speed_cols,
            },
            uncut,
            (&s_mat, &s_rhs),
        )? {
            s_mat = new_s;
            s_rhs = new_r;
        }
    }
    let g = &mut model.g;
    let (zero, one) = (g.int(0)?, g.int(1)?);
    let mut w = Vec::with_capacity(k);
    for f in 0..k {
        w.push(g.declare(&format!("__w_{f}"), SymbolKind::Auxiliary)?);
    }
    for f in 0..k {
        for j in 0..=l {
            let rate = if j == l { g.sym(w[f])? } else { zero };
            rates.reduced = std::mem::take(&mut rates.reduced).with(schur.x[f * (l + 1) + j], rate);
        }
    }
    let free_rates: Vec<Id> = schur
        .free
        .iter()
        .map(|&c| g.sym(model.coords[dependent[c]].1.rate))
        .collect::<Result<_, _>>()?;
    let raw_rates = if schur.row_ops.is_empty() {
        Vec::new()
    } else {
        rates_as_written(g, rows, rates, uncut)?
    };
    let mut rhs_rate = Vec::with_capacity(k);
    for i in 0..k {
        if !raw_rates.is_empty() {
            let mut terms = Vec::new();
            for (j, &rate) in raw_rates.iter().enumerate() {
                let t = schur.row_ops[i * k_unknowns + j];
                if !g.is_zero(t) {
                    terms.push(g.mul(t, rate)?);
                }
            }
            let sum = g.sum(&terms)?;
            rhs_rate.push(g.neg(sum)?);
            continue;
        }
        let mut terms = Vec::new();
        for f in 0..k {
            terms.push(g.mul(s_mat[i * k + f], free_rates[f])?);
        }
        for j in 0..=l {
            let weight = if j == l {
                one
            } else {
                g.sym(map.speed_rates[j])?
            };
            let t = g.mul(s_rhs[i * (l + 1) + j], weight)?;
            terms.push(g.neg(t)?);
        }
        let row = g.sum(&terms)?;
        let rate = g.time_derivative(row, &rates.along)?;
        let rate = rates.fixed.apply(g, rate)?;
        rhs_rate.push(g.neg(rate)?);
    }
    let columns = (0..=l)
        .filter(|&j| {
            (0..k).any(|f| !g.is_zero(schur.x_values[f * (l + 1) + j]))
                && !vanishing.contains(&schur.x[j])
        })
        .collect();
    Ok(NumericElimination {
        k,
        columns,
        s: s_mat,
        r: s_rhs,
        rhs_rate,
        x: schur.x,
        w,
    })
}

/// Sets the symbols of X's vanishing last column to zero everywhere: they
/// have done their work (carrying w into the accelerations).
pub fn drop_vanishing(
    g: &mut Graph,
    vanishing: &[Symbol],
    map: &mut SpeedMap,
    equations: &mut Equations,
    energies: &mut Energies,
    elimination: &mut Elimination,
) -> Result<(), SymbolicError> {
    if vanishing.is_empty() {
        return Ok(());
    }
    let zero = g.int(0)?;
    let mut zero_x = Substitution::new();
    for &s in vanishing {
        zero_x.insert(s, zero);
    }
    let mut fix = |g: &mut Graph, e: &mut Id| -> Result<(), SymbolicError> {
        *e = zero_x.apply(g, *e)?;
        Ok(())
    };
    for e in map
        .c
        .iter_mut()
        .chain(map.c0.iter_mut())
        .chain(map.qdot.iter_mut())
    {
        fix(g, e)?;
    }
    for e in equations
        .mass
        .iter_mut()
        .chain(equations.forcing.iter_mut())
    {
        fix(g, e)?;
    }
    for e in [
        &mut energies.kinetic,
        &mut energies.potential,
        &mut energies.input_power,
    ] {
        fix(g, e)?;
    }
    for e in equations.inertial_terms.iter_mut().flatten() {
        fix(g, e)?;
    }
    for (_, terms) in equations.load_terms.iter_mut() {
        for e in terms.iter_mut() {
            fix(g, e)?;
        }
    }
    for (_, e) in energies.power_terms.iter_mut() {
        fix(g, e)?;
    }
    if let Elimination::Numeric(ne) = elimination {
        for e in ne.expressions_mut() {
            fix(g, e)?;
        }
    }
    Ok(())
}

/// The rate of each constraint row as written, along q̇, rates fixed. When
/// a contact's material velocity v vanishes on the constrained motion, the
/// rate of v·e is (rate of v)·e: the term v·ė is zero there, though only
/// numerically once the dependent rates are X [ẏ; 1].
fn rates_as_written(
    g: &mut appell_symbolic::Graph,
    rows: &ConstraintRows,
    rates: &mut Rates,
    uncut: &mut Substitution,
) -> Result<Vec<Id>, SymbolicError> {
    let mut out = Vec::new();
    for (&row, direction) in rows.as_written.iter().zip(&rows.directions) {
        let rate = match direction {
            Some((contact, e)) if rows.contacts[*contact].complete => {
                let v = rows.contacts[*contact].velocity;
                let mut terms = Vec::with_capacity(3);
                for i in 0..3 {
                    if g.is_zero(e[i]) {
                        continue;
                    }
                    let r = g.time_derivative(v[i], &rates.along)?;
                    terms.push(g.mul(r, e[i])?);
                }
                g.sum(&terms)?
            }
            _ => g.time_derivative(row, &rates.along)?,
        };
        let rate = uncut.apply(g, rate)?;
        out.push(rates.fixed.apply(g, rate)?);
    }
    Ok(out)
}

/// S's and R's entries, row by row.
type SchurParts = (Vec<Id>, Vec<Id>);

/// The constraint rows as written and what [`schur_as_written`] reads off
/// them.
struct SchurRows<'a> {
    /// The rows as the model wrote them (the twin's, when there is one).
    rows: &'a [Id],
    /// T, the elimination's row operations, k × `width`.
    row_ops: &'a [Id],
    width: usize,
    /// Every coordinate rate (set to zero for the rows' remainders).
    rates: &'a [Symbol],
    /// The rates of the free unknowns (S's columns).
    free: &'a [Symbol],
    /// The rates of the privileged speeds (R's first columns).
    speeds: &'a [Symbol],
}

/// S and R of the numeric elimination read off T (D q̇ + d) with the rows
/// as written: S_if = ∂(T rows)_i/∂ż_f, R_ik = −∂(T rows)_i/∂ẏ_k and
/// R_il = −(T rows)_i at q̇ = 0, the twin's symbols put back by `uncut`.
/// The rows' coefficients stay in the form the model gave them (a rolling
/// contact's (v + ω × r)·e with its unit vector unexpanded), which the
/// emitter shares with the other terms. `None` unless every nonzero entry
/// equals the elimination's (`known`) at the test points of
/// [`same_function`].
fn schur_as_written(
    g: &mut appell_symbolic::Graph,
    rows: SchurRows<'_>,
    uncut: &mut Substitution,
    known: (&[Id], &[Id]),
) -> Result<Option<SchurParts>, SymbolicError> {
    let (s_known, r_known) = known;
    let k = rows.free.len();
    let l = rows.speeds.len();
    let zero = g.int(0)?;
    let mut no_rates = Substitution::new();
    for &r in rows.rates {
        no_rates.insert(r, zero);
    }
    let mut s = s_known.to_vec();
    let mut r = r_known.to_vec();
    for i in 0..k {
        let mut terms = Vec::new();
        for (j, &row) in rows.rows.iter().enumerate() {
            let t = rows.row_ops[i * rows.width + j];
            if !g.is_zero(t) {
                terms.push(g.mul(t, row)?);
            }
        }
        let combined = g.sum(&terms)?;
        // (entry, its value: a coefficient or the remainder, and its sign)
        let mut entries: Vec<(&mut Id, Option<Symbol>, bool)> = Vec::new();
        let (s_row, r_row) = (
            &mut s[i * k..(i + 1) * k],
            &mut r[i * (l + 1)..(i + 1) * (l + 1)],
        );
        for (e, &rate) in s_row.iter_mut().zip(rows.free) {
            entries.push((e, Some(rate), false));
        }
        let (r_speeds, r_rest) = r_row.split_at_mut(l);
        for (e, &rate) in r_speeds.iter_mut().zip(rows.speeds) {
            entries.push((e, Some(rate), true));
        }
        entries.push((&mut r_rest[0], None, true));
        for (entry, rate, negate) in entries {
            if g.is_zero(*entry) {
                continue;
            }
            let c = match rate {
                Some(rate) => g.diff(combined, rate)?,
                None => no_rates.apply(g, combined)?,
            };
            let c = uncut.apply(g, c)?;
            let c = if negate { g.neg(c)? } else { c };
            if same_function(g, *entry, c) != Some(true) {
                return Ok(None);
            }
            *entry = c;
        }
    }
    Ok(Some((s, r)))
}

#[cfg(test)]
mod tests {
    use super::super::testing::{self, assert_agrees_with};
    use super::*;

    fn numeric(run: &testing::Run) -> &NumericElimination {
        match &run.elimination {
            Elimination::Numeric(ne) => ne,
            Elimination::Symbolic => panic!("a numeric elimination"),
        }
    }

    #[test]
    fn the_knife_edge_solves_for_x_and_w() {
        // S X = R: cos θ X = sin θ, so X = tan θ; w = Ẋ ẋ = θ̇ ẋ / cos² θ, and
        // S w = θ̇ ẋ / cos θ.
        let mut run = testing::run(testing::SLEIGH);
        let ne = numeric(&run).clone();
        let g = &mut run.model.g;
        assert_eq!(ne.columns, vec![0]);
        let x = g.parse("__x_0_0").unwrap();
        let s_x = g.mul(ne.s[0], x).unwrap();
        let tan = [("__x_0_0", "sin(theta)/cos(theta)")];
        assert_agrees_with(g, s_x, "sin(theta)", &tan);
        assert_agrees_with(g, ne.r[0], "sin(theta)", &tan);
        assert_agrees_with(
            g,
            ne.rhs_rate[0],
            "theta_dot*x_dot/cos(theta)",
            &[("__x_0_0", "sin(theta)/cos(theta)"), ("__x_0_2", "0")],
        );
        assert_eq!(g.symbol_name(ne.w[0]), "__w_0");
    }

    #[test]
    fn the_cartesian_pendulum_has_the_circles_acceleration_remainder() {
        // x ẋ + y ẏ = 0: ẏ = −x ẋ / y, and with ẍ = 0 the remainder of ÿ
        // is −(ẋ² + ẏ²) / y: w = (S w) / S.
        let mut run = testing::run(testing::CARTESIAN);
        let ne = numeric(&run).clone();
        let g = &mut run.model.g;
        let w = g.div(ne.rhs_rate[0], ne.s[0]).unwrap();
        assert_agrees_with(
            g,
            w,
            "-(x_dot^2 + (x*x_dot/y)^2)/y",
            &[("__x_0_0", "-x/y"), ("__x_0_1", "0")],
        );
    }
}
