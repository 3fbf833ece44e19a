//! The stages of a step: the simplified Newton iteration of the
//! collocation system in the transformed variables, and the embedded error
//! estimate.

use super::coefficients::{ALPHA, BETA, C, E, GAMMA, T, TI};
use super::control::FAC_FAIL;
use super::iteration::Iteration;
use super::linear::C64;
use super::stats::Radau5Stats;
use crate::implicit::{all_finite, wrms};
use appell_core::ModelError;

/// A contraction rate at or above this is divergence.
const THETA_DIVERGE: f64 = 0.99;

/// How a Newton solve of the stages ended (model errors are passed on).
pub(super) enum Newton {
    /// Converged in `iterations`, with the contraction rate `theta`
    /// (0 when one iteration sufficed).
    Converged { theta: f64, iterations: usize },
    /// Diverged, too slow, or a non-finite value: retry with the step
    /// times `factor`.
    Failed { factor: f64, non_finite: bool },
}

impl Newton {
    /// A singular iteration matrix: no iteration, the step shrinks.
    pub(super) const SINGULAR: Newton = Newton::Failed {
        factor: FAC_FAIL,
        non_finite: false,
    };
}

/// The work vectors of a step: the stage increments `z_i = x(t + c_i h) −
/// x` (component `j` of stage `i` at `i n + j`), their transforms `w =
/// T⁻¹ z`, the stage derivatives, the Newton corrections and the error
/// estimate.
pub(super) struct Stages {
    n: usize,
    pub(super) z: Vec<f64>,
    w: Vec<f64>,
    fz: Vec<f64>,
    y: Vec<f64>,
    real: Vec<f64>,
    complex: Vec<C64>,
    est: Vec<f64>,
    scale: Vec<f64>,
    /// The Newton rate estimate η = θ/(1 − θ), carried between steps.
    faccon: f64,
}

/// `out_i = Σ_j m[i][j] v_j` for three stacked vectors of length `n`.
fn transform(m: &[[f64; 3]; 3], v: &[f64], out: &mut [f64], n: usize) {
    for i in 0..n {
        let (a, b, c) = (v[i], v[n + i], v[2 * n + i]);
        for (k, row) in m.iter().enumerate() {
            out[k * n + i] = row[0] * a + row[1] * b + row[2] * c;
        }
    }
}

impl Stages {
    /// Work vectors for a state of `n` components, `z = 0`.
    pub(super) fn new(n: usize) -> Self {
        Stages {
            n,
            z: vec![0.0; 3 * n],
            w: vec![0.0; 3 * n],
            fz: vec![0.0; 3 * n],
            y: vec![0.0; n],
            real: vec![0.0; n],
            complex: vec![C64::default(); n],
            est: vec![0.0; n],
            scale: vec![0.0; n],
            faccon: 1.0,
        }
    }

    /// Solves the collocation system of the step of signed size `hs` from
    /// `(t, x)` by simplified Newton from the iterate in `z`, with the
    /// factorizations of `it`, the weights `scal` and the tolerance
    /// `fnewt` (RADAU5's iteration, its stopping rule and its early
    /// rejection of an iteration too slow to converge).
    #[allow(clippy::too_many_arguments)] // the step, its start and the Newton settings
    pub(super) fn newton<F>(
        &mut self,
        it: &Iteration,
        f: &mut F,
        t: f64,
        hs: f64,
        x: &[f64],
        scal: &[f64],
        fnewt: f64,
        max_iter: usize,
        stats: &mut Radau5Stats,
    ) -> Result<Newton, ModelError>
    where
        F: FnMut(f64, &[f64], &mut [f64]) -> Result<(), ModelError>,
    {
        let failed = |factor, non_finite| Ok(Newton::Failed { factor, non_finite });
        transform(&TI, &self.z, &mut self.w, self.n);
        self.faccon = self.faccon.max(f64::EPSILON).powf(0.8);
        let mut theta = 0.0;
        let (mut norm_old, mut thq_old) = (0.0, 0.0);
        for k in 1..=max_iter {
            if !self.stage_derivatives(f, t, hs, x, stats)? {
                return failed(0.5, true);
            }
            let norm = self.corrections(it, hs, scal);
            stats.newton_iterations += 1;
            if !norm.is_finite() {
                return failed(0.5, true);
            }
            if k > 1 && k < max_iter {
                let thq = norm / norm_old;
                theta = if k == 2 { thq } else { (thq * thq_old).sqrt() };
                thq_old = thq;
                if theta >= THETA_DIVERGE {
                    return failed(0.5, false);
                }
                self.faccon = theta / (1.0 - theta);
                // The error predicted after the iterations left.
                let left = (max_iter - 1 - k) as i32;
                let predicted = self.faccon * norm * theta.powi(left) / fnewt;
                if predicted >= 1.0 {
                    let q = predicted.clamp(1e-4, 20.0);
                    let factor = 0.8 * q.powf(-1.0 / (4.0 + left as f64));
                    return failed(factor, false);
                }
            }
            norm_old = norm.max(f64::EPSILON);
            self.apply_corrections();
            if self.faccon * norm <= fnewt {
                return Ok(Newton::Converged {
                    theta,
                    iterations: k,
                });
            }
        }
        failed(0.5, false)
    }

    /// The stage derivatives `f(t + c_i h, x + z_i)`; false when one is not
    /// finite.
    fn stage_derivatives<F>(
        &mut self,
        f: &mut F,
        t: f64,
        hs: f64,
        x: &[f64],
        stats: &mut Radau5Stats,
    ) -> Result<bool, ModelError>
    where
        F: FnMut(f64, &[f64], &mut [f64]) -> Result<(), ModelError>,
    {
        let n = self.n;
        for (i, c) in C.iter().enumerate() {
            for ((y, a), z) in self.y.iter_mut().zip(x).zip(&self.z[i * n..]) {
                *y = a + z;
            }
            stats.rhs_calls += 1;
            let fi = &mut self.fz[i * n..(i + 1) * n];
            f(t + c * hs, &self.y, fi)?;
            if !all_finite(fi) {
                return Ok(false);
            }
        }
        Ok(true)
    }

    /// The Newton corrections of `w` from the stage derivatives: the real
    /// system for `w_0`, the complex one for `w_1 + i w_2`. Returns their
    /// RMS norm weighted by `scal`.
    fn corrections(&mut self, it: &Iteration, hs: f64, scal: &[f64]) -> f64 {
        let n = self.n;
        let (g, mu) = (GAMMA / hs, C64::new(ALPHA / hs, -BETA / hs));
        let (f0, rest) = self.fz.split_at(n);
        let (f1, f2) = rest.split_at(n);
        let (w0, rest) = self.w.split_at(n);
        let (w1, w2) = rest.split_at(n);
        let stages = f0.iter().zip(f1).zip(f2).zip(w0.iter().zip(w1).zip(w2));
        let out = self.real.iter_mut().zip(self.complex.iter_mut());
        for ((r, c), (((&a, &b), &d), ((&u, &v), &y))) in out.zip(stages) {
            let ti = |row: &[f64; 3]| row[0] * a + row[1] * b + row[2] * d;
            *r = ti(&TI[0]) - g * u;
            *c = C64::new(ti(&TI[1]), ti(&TI[2])) - mu * C64::new(v, y);
        }
        it.solve_both(&mut self.real, &mut self.complex);
        let mut s = 0.0;
        for ((a, z), sc) in self.real.iter().zip(&self.complex).zip(scal) {
            s += (a * a + z.re * z.re + z.im * z.im) / (sc * sc);
        }
        (s / (3 * n).max(1) as f64).sqrt()
    }

    /// `w += Δw`, `z = T w`.
    fn apply_corrections(&mut self) {
        let n = self.n;
        let (w0, rest) = self.w.split_at_mut(n);
        let (w1, w2) = rest.split_at_mut(n);
        let (z0, rest) = self.z.split_at_mut(n);
        let (z1, z2) = rest.split_at_mut(n);
        let w = w0.iter_mut().zip(w1.iter_mut()).zip(w2.iter_mut());
        let z = z0.iter_mut().zip(z1.iter_mut()).zip(z2.iter_mut());
        let d = self.real.iter().zip(&self.complex);
        for (((a, b), c), (((p, q), r), (dr, dc))) in w.zip(z.zip(d)) {
            *a += dr;
            *b += dc.re;
            *c += dc.im;
            *p = T[0][0] * *a + T[0][1] * *b + T[0][2] * *c;
            *q = T[1][0] * *a + T[1][1] * *b + T[1][2] * *c;
            *r = T[2][0] * *a + T[2][1] * *b + T[2][2] * *c;
        }
    }

    /// The new state `x + z_3` into `x_new`.
    pub(super) fn end_state(&self, x: &[f64], x_new: &mut [f64]) {
        let z3 = &self.z[2 * self.n..];
        for ((xn, a), b) in x_new.iter_mut().zip(x).zip(z3) {
            *xn = a + b;
        }
    }

    /// The error norm of the solved step of signed size `hs` from `(t, x)`
    /// (derivative `f0`) to `x_new`: `(γ/h − J)⁻¹ (f0 + Σ e_i z_i/h)` in
    /// the RMS norm weighted by `atol + rtol · max(|x_i|, |x_new_i|)`.
    /// With `refine`, an estimate above 1 is recomputed with `f(t, x +
    /// err)` in place of `f0` (one rhs call). Not finite when the estimate
    /// is not.
    #[allow(clippy::too_many_arguments)] // the step, its ends and the tolerances
    pub(super) fn error<F>(
        &mut self,
        it: &Iteration,
        f: &mut F,
        (t, hs): (f64, f64),
        (x, f0, x_new): (&[f64], &[f64], &[f64]),
        (atol, rtol): (f64, f64),
        refine: bool,
        stats: &mut Radau5Stats,
    ) -> Result<f64, ModelError>
    where
        F: FnMut(f64, &[f64], &mut [f64]) -> Result<(), ModelError>,
    {
        let n = self.n;
        for i in 0..n {
            let zsum = E[0] * self.z[i] + E[1] * self.z[n + i] + E[2] * self.z[2 * n + i];
            // The z part of the estimate, kept for a refinement.
            self.real[i] = zsum / hs;
            self.est[i] = f0[i] + self.real[i];
            self.scale[i] = atol + rtol * x[i].abs().max(x_new[i].abs());
        }
        it.solve_real(&mut self.est);
        let mut err = wrms(&self.est, &self.scale);
        if refine && err >= 1.0 && err.is_finite() {
            for ((y, a), e) in self.y.iter_mut().zip(x).zip(&self.est) {
                *y = a + e;
            }
            stats.rhs_calls += 1;
            f(t, &self.y, &mut self.est)?;
            for i in 0..n {
                self.est[i] += self.real[i];
            }
            it.solve_real(&mut self.est);
            err = wrms(&self.est, &self.scale);
        }
        Ok(if err.is_finite() {
            err.max(1e-10)
        } else {
            f64::INFINITY
        })
    }
}
