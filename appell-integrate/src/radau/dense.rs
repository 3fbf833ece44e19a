//! Dense output: the collocation polynomial of an accepted step, and its
//! extrapolation as the next step's first Newton iterate.

use super::coefficients::{C, P};
use crate::implicit::Dense;

/// The coefficients `q_k = Σ_i P[i][k] z_i` of the collocation polynomial
/// from the stage increments `z` (stacked, `n` components each).
pub(super) fn coefficients(z: &[f64], q: &mut [f64], n: usize) {
    for i in 0..n {
        let (a, b, c) = (z[i], z[n + i], z[2 * n + i]);
        for k in 0..3 {
            q[k * n + i] = P[0][k] * a + P[1][k] * b + P[2][k] * c;
        }
    }
}

/// The derivative at the end (`s = 1`) of the collocation polynomial with
/// coefficients `q` of a step of signed size `h`: `(q_0 + 2 q_1 + 3 q_2)/h`
/// into `dx`. It equals `f` at the end of the step up to the residual of
/// the converged Newton iteration, and costs no rhs call.
pub(super) fn end_derivative(q: &[f64], h: f64, dx: &mut [f64]) {
    let n = dx.len();
    let (q0, rest) = q.split_at(n);
    let (q1, q2) = rest.split_at(n);
    for (((d, a), b), c) in dx.iter_mut().zip(q0).zip(q1).zip(q2) {
        *d = (a + 2.0 * b + 3.0 * c) / h;
    }
}

/// `x0 + Σ_k q_k s^(k+1)` appended to `slot`.
fn polynomial(x0: &[f64], q: &[f64], s: f64, slot: &mut Vec<f64>) {
    let n = x0.len();
    slot.extend((0..n).map(|i| x0[i] + s * (q[i] + s * (q[n + i] + s * q[2 * n + i]))));
}

/// The collocation polynomial of one accepted step of signed size `h` from
/// `(t, x0)` to `(t1, x1)`: `x0 + Σ_k q_k s^(k+1)`, `s = (τ − t)/h`.
pub(super) struct Collocation<'a> {
    pub(super) t: f64,
    /// The end of the step (exactly).
    pub(super) t1: f64,
    pub(super) h: f64,
    pub(super) x0: &'a [f64],
    pub(super) q: &'a [f64],
    pub(super) x1: &'a [f64],
}

impl<'a> Collocation<'a> {
    /// The collocation polynomial `q` of the step of signed size `h` from
    /// `x0` at `t` to `x1` at `t1`.
    pub(super) fn between(
        (t, x0): (f64, &'a [f64]),
        (t1, x1): (f64, &'a [f64]),
        h: f64,
        q: &'a [f64],
    ) -> Self {
        Collocation {
            t,
            t1,
            h,
            x0,
            q,
            x1,
        }
    }
}

impl Dense for Collocation<'_> {
    fn start(&self) -> f64 {
        self.t
    }

    fn end(&self) -> f64 {
        self.t1
    }

    fn end_state(&self) -> &[f64] {
        self.x1
    }

    /// The state at `tau` (the end state exactly at the end of the step).
    fn at(&self, tau: f64, slot: &mut Vec<f64>) {
        slot.clear();
        if tau == self.t1 {
            slot.extend_from_slice(self.x1);
        } else {
            polynomial(self.x0, self.q, (tau - self.t) / self.h, slot);
        }
    }
}

/// The polynomial of the last accepted step, kept to start the next one.
pub(super) struct Previous {
    /// Its start state.
    pub(super) x0: Vec<f64>,
    /// Its coefficients.
    pub(super) q: Vec<f64>,
    /// Its signed size; 0 before the first accepted step.
    pub(super) h: f64,
}

impl Previous {
    /// None yet, for a state of `n` components.
    pub(super) fn new(n: usize) -> Self {
        Previous {
            x0: vec![0.0; n],
            q: vec![0.0; 3 * n],
            h: 0.0,
        }
    }

    /// Keeps the accepted step of signed size `hs` from `x` with the
    /// polynomial coefficients `q`, and moves `x` to its end `x_new` (`q`
    /// becomes scratch).
    pub(super) fn keep(&mut self, x: &mut Vec<f64>, q: &mut Vec<f64>, x_new: &[f64], hs: f64) {
        core::mem::swap(&mut self.x0, x);
        core::mem::swap(&mut self.q, q);
        self.h = hs;
        x.copy_from_slice(x_new);
    }

    /// Newton's first iterate for the step of signed size `hs` from `x`
    /// (the end of the previous step, possibly projected) into `z`: the
    /// previous polynomial extrapolated to the new stage times, minus `x`;
    /// zero before the first accepted step.
    pub(super) fn extrapolate(&self, hs: f64, x: &[f64], z: &mut [f64]) {
        if self.h == 0.0 {
            z.fill(0.0);
            return;
        }
        let n = x.len();
        let (q0, rest) = self.q.split_at(n);
        let (q1, q2) = rest.split_at(n);
        for (k, c) in C.iter().enumerate() {
            let s = 1.0 + c * hs / self.h;
            let zk = &mut z[k * n..(k + 1) * n];
            let terms = q0.iter().zip(q1).zip(q2).zip(&self.x0).zip(x);
            for (zi, ((((a, b), c), x0), xi)) in zk.iter_mut().zip(terms) {
                *zi = x0 + s * (a + s * (b + s * c)) - xi;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_end_derivative_is_the_polynomial_s() {
        // x(s) = s + 2 s² + 3 s³ (one component) through the stages c_i:
        // x'(1) = 14 per unit s, 14/h per unit time.
        let z: Vec<f64> = C
            .iter()
            .map(|&c| c + 2.0 * c * c + 3.0 * c * c * c)
            .collect();
        let mut q = [0.0; 3];
        coefficients(&z, &mut q, 1);
        for (a, b) in q.iter().zip([1.0, 2.0, 3.0]) {
            assert!((a - b).abs() < 1e-12, "{q:?}");
        }
        let mut dx = [0.0];
        end_derivative(&q, -0.5, &mut dx);
        assert!((dx[0] + 28.0).abs() < 1e-11, "{dx:?}");
    }
}
