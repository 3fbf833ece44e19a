//! Stage 4: q̇ = C ẏ + c (eqs. 30-31) and the rate rules of the reduced
//! system.
//!
//! C_rk and c_r come from the elimination's [B | b] for the unknowns and
//! from unit columns for the privileged coordinates. The stage also builds
//! the three ways later stages differentiate:
//!
//! - `reduced`: d/dt on the reduced system (q → C ẏ + c, a quasi-velocity
//!   → its acceleration symbol, and, once the numeric elimination adds
//!   them, X → its rate);
//! - `along`: the directional derivative along q̇ with every rate held
//!   constant (the twin's direction cosines turning with their frames);
//! - `fixed`: the substitution of the dependent rates by C ẏ + c, applied
//!   after `along`.

use appell_symbolic::{Id, RateRules, Substitution, Symbol, SymbolicError};

use super::elimination::SolvedRates;
use super::speeds::SpeedDefinitions;
use super::Calculus;
use crate::model::{ConstraintSet, Model};

/// C, c and q̇ = C ẏ + c.
#[derive(Clone)]
pub struct SpeedMap {
    /// C (n×l), row-major.
    pub c: Vec<Id>,
    /// c (n).
    pub c0: Vec<Id>,
    /// q̇_r = Σ C_rk ẏ_k + c_r.
    pub qdot: Vec<Id>,
    /// The symbols ẏ_k.
    pub speed_rates: Vec<Symbol>,
    /// The symbols ÿ_k.
    pub accels: Vec<Symbol>,
}

/// The rate rules later stages differentiate with (see the module docs).
pub struct Rates {
    /// d/dt on the reduced system.
    pub reduced: RateRules,
    /// The directional derivative along q̇, rates held constant.
    pub along: RateRules,
    /// The dependent rates replaced by C ẏ + c.
    pub fixed: Substitution,
}

/// Stage 4.
pub fn speed_map(
    model: &mut Model,
    set: &ConstraintSet,
    speeds: &SpeedDefinitions,
    solved: &SolvedRates,
    calculus: &Calculus,
) -> Result<(SpeedMap, Rates), SymbolicError> {
    let n = model.coords.len();
    let l = set.speed_specs.len();
    let g = &mut model.g;
    let zero = g.int(0)?;
    let one = g.int(1)?;
    let mut c = vec![zero; n * l];
    let mut c0 = vec![zero; n];
    if !speeds.quasi {
        for (k, &s) in set.speeds.iter().enumerate() {
            c[s * l + k] = one;
        }
    }
    for (i, &r) in speeds.dependent.iter().enumerate() {
        for k in 0..l {
            c[r * l + k] = solved.x[i * (l + 1) + k];
        }
        c0[r] = solved.x[i * (l + 1) + l];
    }
    let speed_rates: Vec<Symbol> = set.speed_specs.iter().map(|s| s.symbol).collect();
    let accels: Vec<Symbol> = set.speed_specs.iter().map(|s| s.accel).collect();
    let mut qdot = Vec::with_capacity(n);
    for r in 0..n {
        let mut terms = vec![c0[r]];
        for k in 0..l {
            let y = g.sym(speed_rates[k])?;
            terms.push(g.mul(c[r * l + k], y)?);
        }
        qdot.push(g.sum(&terms)?);
    }
    let rates = model.input_rates.clone();
    let mut reduced = Model::with_input_rates(g, &rates, RateRules::coordinates())?;
    for (r, (_, coord)) in model.coords.iter().enumerate() {
        reduced = reduced.with(coord.q, qdot[r]);
    }
    for spec in set.speed_specs.iter().filter(|s| s.definition.is_some()) {
        let a = g.sym(spec.accel)?;
        reduced = reduced.with(spec.symbol, a);
    }
    let mut along = Model::with_input_rates(g, &rates, RateRules::coordinates())?;
    for (_, coord) in &model.coords {
        along = along.constant(coord.rate);
    }
    for &r in &speed_rates {
        along = along.constant(r);
    }
    if let Some(t) = &calculus.twin {
        for c in &t.cuts {
            along = along.with(c.symbol, c.rate);
        }
    }
    let mut fixed = Substitution::new();
    for &r in &speeds.dependent {
        fixed.insert(model.coords[r].1.rate, qdot[r]);
    }
    let map = SpeedMap {
        c,
        c0,
        qdot,
        speed_rates,
        accels,
    };
    Ok((
        map,
        Rates {
            reduced,
            along,
            fixed,
        },
    ))
}

#[cfg(test)]
mod tests {
    use super::super::testing::{self, assert_agrees};

    #[test]
    fn c_has_unit_rows_for_the_speeds_and_the_solution_for_the_rest() {
        // ẋ = −r φ̇, φ̇ = φ̇: C = [−r; 1], c = 0.
        let mut run = testing::run(testing::DISC_ON_A_LINE);
        let g = &mut run.model.g;
        assert_agrees(g, run.map.c[0], "-r");
        assert_agrees(g, run.map.c[1], "1");
        assert!(run.map.c0.iter().all(|e| g.is_zero(*e)));
        assert_agrees(g, run.map.qdot[0], "-r*phi_dot");
        assert_agrees(g, run.map.qdot[1], "phi_dot");
    }

    #[test]
    fn a_numeric_unknown_stands_as_its_symbol_in_c() {
        // The knife edge: ẏ = X ẋ + X_l, with X_l the vanishing symbol.
        let mut run = testing::run(testing::SLEIGH);
        let g = &mut run.model.g;
        let l = 2;
        assert_agrees(g, run.map.c[0], "1");
        assert_agrees(g, run.map.c[l], "__x_0_0");
        assert!(g.is_zero(run.map.c[l + 1]));
        assert_agrees(g, run.map.c[2 * l + 1], "1");
        assert_agrees(g, run.map.qdot[1], "__x_0_0*x_dot + __x_0_2");
    }
}
