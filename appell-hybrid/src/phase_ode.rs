//! A hybrid phase's equations as the integrators see them: x = (q, u) on
//! every coordinate, q̇ from the coordinate rates, u̇ from the reduced rhs,
//! and their Jacobian.

use std::cell::RefCell;

use num_dual::Dual64;

use super::Phase;
use appell_core::dynamic::DynRhs;
use appell_core::ModelError;

/// A phase's equations on every coordinate and its speeds, x = (q, u):
/// q̇ from the coordinate rates, u̇ from the rhs on the reduced state.
pub(super) struct PhaseOde<'p> {
    phase: &'p Phase<'p>,
    prepared: Box<dyn DynRhs + 'p>,
    retained: Vec<usize>,
    /// The number of coordinates.
    pub(super) n: usize,
    /// The number of speeds.
    pub(super) l: usize,
    /// The reduced state and its rates, reused by every call.
    reduced: RefCell<(Vec<f64>, Vec<f64>)>,
    /// The inputs, reused by every call.
    inputs: RefCell<Vec<f64>>,
}

impl<'p> PhaseOde<'p> {
    pub(super) fn new(phase: &'p Phase<'p>) -> Self {
        let info = phase.model.dyn_info();
        PhaseOde {
            phase,
            prepared: phase.model.dyn_prepare(),
            retained: info
                .retained
                .iter()
                .filter_map(|name| info.coordinate_index(name))
                .collect(),
            n: info.coordinates.len(),
            l: info.speeds.len(),
            reduced: RefCell::new((vec![0.0; info.state_len()], vec![0.0; info.state_len()])),
            inputs: RefCell::new(phase.inputs.clone()),
        }
    }

    /// The reduced state of `x`: the retained coordinates, then the speeds.
    pub(super) fn reduce<T: Copy>(&self, x: &[T], state: &mut [T]) {
        let (n, r) = (self.n, self.retained.len());
        for (s, &k) in state.iter_mut().zip(&self.retained) {
            *s = x[k];
        }
        state[r..].copy_from_slice(&x[n..n + self.l]);
    }

    /// ẋ at `(t, x)`.
    pub(super) fn rates(&self, t: f64, x: &[f64], dx: &mut [f64]) -> Result<(), ModelError> {
        let (n, l, r) = (self.n, self.l, self.retained.len());
        let (q, u) = (&x[..n], &x[n..n + l]);
        let (state, reduced) = &mut *self.reduced.borrow_mut();
        let inputs = &mut *self.inputs.borrow_mut();
        if let Some(f) = &self.phase.state_inputs {
            inputs.copy_from_slice(&self.phase.inputs);
            f(t, q, u, inputs)?;
        }
        self.reduce(x, state);
        self.prepared.rhs(t, state, inputs, reduced)?;
        self.phase
            .model
            .dyn_driven_coordinate_rates(t, q, u, inputs, &mut dx[..n])?;
        dx[n..n + l].copy_from_slice(&reduced[r..]);
        Ok(())
    }

    /// ∂ẋ/∂x at `(t, x)` (row-major), the inputs held at their values: u̇'s
    /// rows by the model's generated [`Model::rhs_jacobian`](appell_core::Model::rhs_jacobian)
    /// where it has one and `by_duals` is false (the ignorable
    /// coordinates' columns are zero: u̇ does not read them), else by dual
    /// numbers as q̇'s always are ([`PhaseOde::dual_jacobian`]).
    pub(super) fn jacobian(
        &self,
        t: f64,
        x: &[f64],
        jac: &mut [f64],
        by_duals: bool,
    ) -> Result<(), ModelError> {
        let (n, l, r) = (self.n, self.l, self.retained.len());
        let (m, s) = (n + l, r + l);
        let inputs = self.phase.inputs_at(t, &x[..n], &x[n..m])?;
        if by_duals || !self.prepared.has_generated_jacobian() {
            return self.dual_jacobian(t, x, &inputs, jac, true);
        }
        let (mut state, mut values) = (vec![0.0; s], vec![0.0; s]);
        let (mut a, mut b) = (vec![0.0; s * s], vec![0.0; s * inputs.len()]);
        self.reduce(x, &mut state);
        if !self
            .prepared
            .generated_jacobian(t, &state, &inputs, &mut values, &mut a, &mut b)?
        {
            return self.dual_jacobian(t, x, &inputs, jac, true);
        }
        self.dual_jacobian(t, x, &inputs, jac, false)?;
        for i in 0..l {
            let row = &mut jac[(n + i) * m..(n + i + 1) * m];
            row.fill(0.0);
            let from = &a[(r + i) * s..(r + i + 1) * s];
            for (k, &c) in self.retained.iter().enumerate() {
                row[c] = from[k];
            }
            row[n..].copy_from_slice(&from[r..]);
        }
        Ok(())
    }

    /// ∂ẋ/∂x at `(t, x)` (row-major) by one pass in dual numbers per
    /// column, the inputs held at their values `inputs`: q̇'s rows, and
    /// u̇'s when `with_speeds` (else they are left as they are).
    pub(super) fn dual_jacobian(
        &self,
        t: f64,
        x: &[f64],
        inputs: &[f64],
        jac: &mut [f64],
        with_speeds: bool,
    ) -> Result<(), ModelError> {
        let (n, l, r) = (self.n, self.l, self.retained.len());
        let m = n + l;
        let td = Dual64::from_re(t);
        let inputs: Vec<Dual64> = inputs.iter().map(|&v| Dual64::from_re(v)).collect();
        let mut xd: Vec<Dual64> = x.iter().map(|&v| Dual64::from_re(v)).collect();
        let zero = Dual64::from_re(0.0);
        let (mut qdot, mut state, mut reduced) =
            (vec![zero; n], vec![zero; r + l], vec![zero; r + l]);
        for k in 0..m {
            xd[k].eps = 1.0;
            self.reduce(&xd, &mut state);
            let (q, u) = (&xd[..n], &xd[n..]);
            let speeds = if with_speeds {
                self.prepared.rhs_dual(td, &state, &inputs, &mut reduced)
            } else {
                Ok(())
            };
            let result = speeds.and_then(|()| {
                self.phase
                    .model
                    .dyn_driven_coordinate_rates_dual(td, q, u, &inputs, &mut qdot)
            });
            xd[k].eps = 0.0;
            result?;
            let rows = if with_speeds { m } else { n };
            for (i, v) in qdot.iter().chain(&reduced[r..]).take(rows).enumerate() {
                jac[i * m + k] = v.eps;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::super::Phase;
    use super::PhaseOde;
    use appell_core::__doc_model::Pendulum;

    /// A phase's Jacobian by the generated rhs_jacobian equals the one by
    /// dual numbers.
    #[test]
    fn a_phase_takes_the_generated_jacobian() {
        let model = Pendulum { g_over_l: 9.81 };
        let mut phase = Phase::new("swing", &model);
        phase.inputs = vec![0.4];
        let ode = PhaseOde::new(&phase);
        assert!(ode.prepared.has_generated_jacobian());
        let x = [0.7, -1.3];
        let (mut generated, mut duals) = ([f64::NAN; 4], [f64::NAN; 4]);
        ode.jacobian(0.0, &x, &mut generated, false).unwrap();
        ode.jacobian(0.0, &x, &mut duals, true).unwrap();
        let expected = [0.0, 1.0, -9.81 * 0.7f64.cos(), 0.0];
        for (a, b) in generated.iter().zip(&expected) {
            assert!((a - b).abs() < 1e-14, "{generated:?} against {expected:?}");
        }
        for (a, b) in generated.iter().zip(&duals) {
            assert!((a - b).abs() < 1e-15, "{generated:?} against {duals:?}");
        }
        // Without the rhs's passes, u̇'s row is left as it was.
        let mut untouched = [f64::NAN; 4];
        ode.dual_jacobian(0.0, &x, &[0.4], &mut untouched, false)
            .unwrap();
        assert_eq!(untouched[..2], [0.0, 1.0]);
        assert!(untouched[2..].iter().all(|v| v.is_nan()));
    }
}
