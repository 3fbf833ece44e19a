//! Forward-mode derivatives without `std`: [`DualVec`], a number that
//! carries `W` directional derivatives beside its value over any
//! [`Scalar`]; [`rhs_jacobian_by_duals`], the rhs's Jacobians from
//! ⌈(s + i) / W⌉ passes of the model's own rhs in it; and
//! [`inverse_dynamics_derivatives_by_duals`], likewise for the inverse
//! dynamics.
//!
//! The derive writes `rhs_jacobian` this way for a model whose symbolic
//! derivatives would cost more than the passes (or grow its code past the
//! derive's bound): the generated code is one call here, so the model's
//! code does not grow, and the Jacobian keeps everything the rhs has (no
//! allocation, any scalar, `no_std`).
//!
//! The arithmetic and the elementary functions are kept out of line
//! (`#[inline(never)]`): inlined, a large model's rhs in `DualVec` becomes
//! one function about `W` times the rhs's size, whose compile time grows
//! much faster than its size, and the passes run no faster for it (the
//! measurements are in `docs/optimization-log.md`).

use core::fmt::Debug;
use core::ops::{Add, AddAssign, Div, DivAssign, Mul, MulAssign, Neg, Sub, SubAssign};

use crate::{Model, ModelError, OpCounts, Scalar};

/// A value and `W` derivatives of it: `re + Σ eps[k] ε_k` with
/// ε_j ε_k = 0. Arithmetic on it carries the derivatives along by the chain
/// rule, so one evaluation of a function gives the function and `W` of its
/// directional derivatives.
///
/// ```
/// use appell_core::{dual::DualVec, Scalar};
/// // x = 0.5 along the first direction, y = 2 along the second.
/// let x = DualVec::<f64, 2>::variable(0.5, 0);
/// let y = DualVec::<f64, 2>::variable(2.0, 1);
/// let f = x.sin() * y;
/// assert_eq!(f.re, 0.5_f64.sin() * 2.0);
/// assert_eq!(f.eps, [0.5_f64.cos() * 2.0, 0.5_f64.sin()]);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DualVec<T, const W: usize> {
    /// The value.
    pub re: T,
    /// The derivatives along each of the `W` directions.
    pub eps: [T; W],
}

impl<T: Scalar, const W: usize> DualVec<T, W> {
    /// A constant: `x` with zero derivatives.
    #[inline]
    pub fn constant(x: T) -> Self {
        DualVec {
            re: x,
            eps: [T::zero(); W],
        }
    }

    /// `x` as the variable of direction `k` (derivative one there, zero
    /// elsewhere); a constant when `k >= W`.
    #[inline]
    pub fn variable(x: T, k: usize) -> Self {
        let mut d = Self::constant(x);
        if k < W {
            d.eps[k] = T::one();
        }
        d
    }

    /// The value `f(re)` with derivatives `f'(re) · eps`. Where the slope
    /// is infinite (√ and ln at 0) a direction the argument does not move
    /// along stays zero rather than 0 · ∞.
    #[inline]
    fn chain(self, value: T, slope: T) -> Self {
        let finite = slope.re().is_finite();
        DualVec {
            re: value,
            eps: self.eps.map(|e| {
                if finite || e.re() != 0.0 {
                    e * slope
                } else {
                    e
                }
            }),
        }
    }
}

impl<T: Scalar, const W: usize> Add for DualVec<T, W> {
    type Output = Self;
    #[inline]
    fn add(mut self, o: Self) -> Self {
        self += o;
        self
    }
}

impl<T: Scalar, const W: usize> Sub for DualVec<T, W> {
    type Output = Self;
    #[inline]
    fn sub(mut self, o: Self) -> Self {
        self -= o;
        self
    }
}

impl<T: Scalar, const W: usize> Mul for DualVec<T, W> {
    type Output = Self;
    #[inline]
    fn mul(mut self, o: Self) -> Self {
        self *= o;
        self
    }
}

impl<T: Scalar, const W: usize> Div for DualVec<T, W> {
    type Output = Self;
    #[inline]
    fn div(mut self, o: Self) -> Self {
        self /= o;
        self
    }
}

impl<T: Scalar, const W: usize> Neg for DualVec<T, W> {
    type Output = Self;
    #[inline(never)]
    fn neg(self) -> Self {
        DualVec {
            re: -self.re,
            eps: self.eps.map(|e| -e),
        }
    }
}

impl<T: Scalar, const W: usize> AddAssign for DualVec<T, W> {
    #[inline(never)]
    fn add_assign(&mut self, o: Self) {
        self.re += o.re;
        for (e, f) in self.eps.iter_mut().zip(o.eps) {
            *e += f;
        }
    }
}

impl<T: Scalar, const W: usize> SubAssign for DualVec<T, W> {
    #[inline(never)]
    fn sub_assign(&mut self, o: Self) {
        self.re -= o.re;
        for (e, f) in self.eps.iter_mut().zip(o.eps) {
            *e -= f;
        }
    }
}

impl<T: Scalar, const W: usize> MulAssign for DualVec<T, W> {
    #[inline(never)]
    fn mul_assign(&mut self, o: Self) {
        for (e, f) in self.eps.iter_mut().zip(o.eps) {
            *e = f.fma(self.re, *e * o.re);
        }
        self.re *= o.re;
    }
}

impl<T: Scalar, const W: usize> DivAssign for DualVec<T, W> {
    #[inline(never)]
    fn div_assign(&mut self, o: Self) {
        // (a / b)' = (a' − (a / b) b') / b; the value by T's own division,
        // as the rhs divides.
        let inv = T::one() / o.re;
        let q = self.re / o.re;
        for (e, f) in self.eps.iter_mut().zip(o.eps) {
            *e = (*e - q * f) * inv;
        }
        self.re = q;
    }
}

impl<T: Scalar, const W: usize> Scalar for DualVec<T, W> {
    #[inline]
    fn from_f64(x: f64) -> Self {
        Self::constant(T::from_f64(x))
    }
    #[inline]
    fn re(self) -> f64 {
        self.re.re()
    }
    #[inline(never)]
    fn sin(self) -> Self {
        self.chain(self.re.sin(), self.re.cos())
    }
    #[inline(never)]
    fn cos(self) -> Self {
        self.chain(self.re.cos(), -self.re.sin())
    }
    #[inline(never)]
    fn tan(self) -> Self {
        let t = self.re.tan();
        self.chain(t, t.fma(t, T::one()))
    }
    #[inline(never)]
    fn exp(self) -> Self {
        let e = self.re.exp();
        self.chain(e, e)
    }
    #[inline(never)]
    fn ln(self) -> Self {
        self.chain(self.re.ln(), T::one() / self.re)
    }
    #[inline(never)]
    fn abs(self) -> Self {
        if self.re.re() < 0.0 {
            -self
        } else {
            self
        }
    }
    #[inline(never)]
    fn sqrt(self) -> Self {
        let s = self.re.sqrt();
        self.chain(s, T::from_f64(0.5) / s)
    }
    #[inline(never)]
    fn powi(self, n: i32) -> Self {
        if n == 0 {
            return Self::one();
        }
        let value = self.re.powi(n);
        let below = match n.checked_sub(1) {
            Some(m) => self.re.powi(m),
            None => value / self.re,
        };
        self.chain(value, T::from_f64(f64::from(n)) * below)
    }
    #[inline(never)]
    fn sinh(self) -> Self {
        self.chain(self.re.sinh(), self.re.cosh())
    }
    #[inline(never)]
    fn cosh(self) -> Self {
        self.chain(self.re.cosh(), self.re.sinh())
    }
    #[inline(never)]
    fn tanh(self) -> Self {
        let t = self.re.tanh();
        self.chain(t, T::one() - t * t)
    }
    #[inline(never)]
    fn asin(self) -> Self {
        let c = ((T::one() - self.re) * (T::one() + self.re)).sqrt();
        self.chain(self.re.asin(), T::one() / c)
    }
    #[inline(never)]
    fn acos(self) -> Self {
        let c = ((T::one() - self.re) * (T::one() + self.re)).sqrt();
        self.chain(self.re.acos(), -(T::one() / c))
    }
    #[inline(never)]
    fn atan(self) -> Self {
        let r = self.re;
        self.chain(r.atan(), T::one() / r.fma(r, T::one()))
    }
    #[inline(never)]
    fn powf(self, y: Self) -> Self {
        // d(x^y) = y x^(y−1) dx + x^y ln x dy; the second term only along
        // directions the exponent moves in (a negative base to a constant
        // power stays finite, as T's powf).
        let value = self.re.powf(y.re);
        let slope = y.re * self.re.powf(y.re - T::one());
        let mut eps = self.eps.map(|e| e * slope);
        for (e, f) in eps.iter_mut().zip(y.eps) {
            if f.re() != 0.0 {
                *e += value * self.re.ln() * f;
            }
        }
        DualVec { re: value, eps }
    }
    #[inline(never)]
    fn atan2(self, x: Self) -> Self {
        // d atan2(y, x) = (x dy − y dx) / (x² + y²).
        let (y, r) = (self.re, x.re);
        let inv = T::one() / r.fma(r, y * y);
        let mut eps = self.eps;
        for (e, f) in eps.iter_mut().zip(x.eps) {
            *e = (r * *e - y * f) * inv;
        }
        DualVec {
            re: y.atan2(r),
            eps,
        }
    }
    #[inline(never)]
    fn fused_mul_add(self, a: Self, b: Self) -> Self {
        let mut eps = b.eps;
        for ((e, s), t) in eps.iter_mut().zip(self.eps).zip(a.eps) {
            *e = self.re.fma(t, s.fma(a.re, *e));
        }
        DualVec {
            re: self.re.fma(a.re, b.re),
            eps,
        }
    }
}

/// `values` as dual numbers whose entry k is the variable of column
/// `first_column + k`, seen from a pass that starts at column `first`
/// (a constant outside the pass's W columns).
#[inline]
fn seed<T: Scalar, const W: usize>(
    duals: &mut [DualVec<T, W>],
    values: &[T],
    first_column: usize,
    first: usize,
) {
    for (k, (d, &v)) in duals.iter_mut().zip(values).enumerate() {
        *d = DualVec::variable(v, (first_column + k).wrapping_sub(first));
    }
}

/// A pass's derivatives into two row-major matrices with `rows.len()`
/// rows: its columns below `split` into `left` (`split` columns), the
/// others into `right` (`width` columns, numbered from `split`).
fn scatter<T: Scalar, const W: usize>(
    rows: &[DualVec<T, W>],
    first: usize,
    (left, split): (&mut [T], usize),
    (right, width): (&mut [T], usize),
) {
    for (row, d) in rows.iter().enumerate() {
        for (k, &e) in d.eps.iter().enumerate() {
            let c = first + k;
            if c < split {
                left[row * split + c] = e;
            } else if c < split + width {
                right[row * width + c - split] = e;
            }
        }
    }
}

/// The rhs's Jacobians by forward-mode dual numbers, in one call: `dstate`
/// as [`Model::rhs`] writes it, `a` = ∂rhs/∂state (S×S row-major) and
/// `b` = ∂rhs/∂inputs (S×I row-major), from ⌈(S + I) / W⌉ evaluations of
/// the model's rhs in [`DualVec<T, W>`], each seeded with the next `W`
/// columns. `S` and `I` are the model's state and input lengths. No
/// allocation; errors as the rhs's, and [`ModelError::NonFinite`] naming
/// the Jacobian when a derivative is not finite.
///
/// The derive writes `rhs_jacobian` as this call where it writes no
/// symbolic derivatives (they would cost more, or grow the code past its
/// bound, or the model is a scene with constraints of its own); any model
/// can call it. Each pass's dual numbers take 1 + W times the stack of the
/// rhs's values: a large model's rhs in `DualVec<f64, 8>` wants a few MiB
/// of stack in a debug build.
///
/// ```
/// use appell_core::dual::rhs_jacobian_by_duals;
/// use appell_core::ModelError;
/// // θ̈ = −(g/l) sin θ + τ, written by hand.
/// use appell_core::__doc_model::Pendulum;
///
/// let model = Pendulum { g_over_l: 9.81 };
/// let (mut ds, mut a, mut b) = ([0.0; 2], [0.0; 4], [0.0; 2]);
/// // Two directions per pass: the three columns take two passes.
/// rhs_jacobian_by_duals::<_, f64, 2, 1, 2>(&model, 0.0, &[0.3, 0.0], &[0.5], &mut ds, &mut a, &mut b)?;
/// assert_eq!(a, [0.0, 1.0, -9.81 * 0.3_f64.cos(), 0.0]);
/// assert_eq!(b, [0.0, 1.0]);
/// # Ok::<(), ModelError>(())
/// ```
#[allow(clippy::too_many_arguments)] // the rhs's arguments and the two Jacobians, as `Model::rhs_jacobian`
pub fn rhs_jacobian_by_duals<
    M: Model,
    T: Scalar,
    const S: usize,
    const I: usize,
    const W: usize,
>(
    model: &M,
    t: T,
    state: &[T],
    inputs: &[T],
    dstate: &mut [T],
    a: &mut [T],
    b: &mut [T],
) -> Result<(), ModelError> {
    crate::check_len("state", state, S)?;
    crate::check_len("inputs", inputs, I)?;
    crate::check_len("dstate", dstate, S)?;
    crate::check_len("a", a, S * S)?;
    crate::check_len("b", b, S * I)?;
    const { assert!(W > 0, "a pass carries at least one direction") };
    let prepared = model.prepare::<DualVec<T, W>>();
    let time = DualVec::constant(t);
    let mut x = [DualVec::<T, W>::constant(T::zero()); S];
    let mut u = [DualVec::<T, W>::constant(T::zero()); I];
    let mut dx = [DualVec::<T, W>::constant(T::zero()); S];
    let mut first = 0;
    // At least one pass, so that a model with no state and no inputs still
    // reports a failing rhs.
    loop {
        // Column c = first + k is direction k of this pass.
        seed(&mut x, state, 0, first);
        seed(&mut u, inputs, S, first);
        model.rhs(&prepared, time, &x, &u, &mut dx)?;
        scatter(&dx, first, (&mut *a, S), (&mut *b, I));
        first += W;
        if first >= S + I {
            break;
        }
    }
    for (d, x) in dstate.iter_mut().zip(&dx) {
        *d = x.re;
    }
    if !a.iter().chain(b.iter()).all(|v| v.re().is_finite()) {
        return Err(ModelError::NonFinite {
            what: "the rhs's Jacobian",
        });
    }
    Ok(())
}

/// The inverse dynamics and its derivatives by forward-mode dual numbers,
/// in one call: `forces` as [`Model::inverse_dynamics`] writes them,
/// `dq` = ∂Q/∂q (L×N row-major, one column per coordinate), `du` = ∂Q/∂u
/// (L×L) from ⌈(N + L) / W⌉ evaluations of the model's inverse dynamics in
/// [`DualVec<T, W>`], and `m` = ∂Q/∂accel = M from
/// [`Model::mass_matrix`]. `N` and `L` are the model's coordinates and
/// privileged speeds. No allocation; errors as the inverse dynamics', and
/// [`ModelError::NonFinite`] when a derivative is not finite.
///
/// The derive writes `inverse_dynamics_derivatives` as this call where it
/// does not differentiate the recursions symbolically (a model that is not
/// a tree of joints, a scene, or recursions whose derivatives would pass
/// its size bound).
///
/// ```
/// use appell_core::dual::inverse_dynamics_derivatives_by_duals;
/// use appell_core::ModelError;
/// // θ̈ = −(g/l) sin θ + τ: Q = θ̈ + (g/l) sin θ.
/// use appell_core::__doc_model::Pendulum;
///
/// let model = Pendulum { g_over_l: 9.81 };
/// let (mut q_force, mut dq, mut du, mut m) = ([0.0; 1], [0.0; 1], [0.0; 1], [0.0; 1]);
/// inverse_dynamics_derivatives_by_duals::<_, f64, 1, 1, 2>(
///     &model, 0.0, &[0.3], &[0.1], &[2.0], &mut q_force, &mut dq, &mut du, &mut m,
/// )?;
/// assert_eq!(q_force[0], 2.0 + 9.81 * 0.3_f64.sin());
/// assert_eq!((dq[0], du[0], m[0]), (9.81 * 0.3_f64.cos(), 0.0, 1.0));
/// # Ok::<(), ModelError>(())
/// ```
#[allow(clippy::too_many_arguments)] // Pinocchio's computeRNEADerivatives: q, u, accel in; Q and its three Jacobians out
pub fn inverse_dynamics_derivatives_by_duals<
    M: Model,
    T: Scalar,
    const N: usize,
    const L: usize,
    const W: usize,
>(
    model: &M,
    t: T,
    q: &[T],
    u: &[T],
    accel: &[T],
    forces: &mut [T],
    dq: &mut [T],
    du: &mut [T],
    m: &mut [T],
) -> Result<(), ModelError> {
    crate::check_len("q", q, N)?;
    crate::check_len("u", u, L)?;
    crate::check_len("accel", accel, L)?;
    crate::check_len("forces", forces, L)?;
    crate::check_len("dq", dq, L * N)?;
    crate::check_len("du", du, L * L)?;
    crate::check_len("m", m, L * L)?;
    const { assert!(W > 0, "a pass carries at least one direction") };
    let time = DualVec::constant(t);
    let mut qd = [DualVec::<T, W>::constant(T::zero()); N];
    let mut ud = [DualVec::<T, W>::constant(T::zero()); L];
    let mut ad = [DualVec::<T, W>::constant(T::zero()); L];
    for (a, &v) in ad.iter_mut().zip(accel) {
        *a = DualVec::constant(v);
    }
    let mut out = [DualVec::<T, W>::constant(T::zero()); L];
    let mut first = 0;
    loop {
        seed(&mut qd, q, 0, first);
        seed(&mut ud, u, N, first);
        model.inverse_dynamics(time, &qd, &ud, &ad, &mut out)?;
        scatter(&out, first, (&mut *dq, N), (&mut *du, L));
        first += W;
        if first >= N + L {
            break;
        }
    }
    for (f, x) in forces.iter_mut().zip(&out) {
        *f = x.re;
    }
    model.mass_matrix(t, q, m)?;
    if !dq.iter().chain(du.iter()).all(|v| v.re().is_finite()) {
        return Err(ModelError::NonFinite {
            what: "the inverse dynamics' Jacobian",
        });
    }
    Ok(())
}

/// The scalar operations [`rhs_jacobian_by_duals`] performs for a model
/// whose rhs costs `rhs`, in `passes` passes of `width` directions. Each
/// dual addition is 1 + W additions; each product 1 + 2W products and W
/// additions; each quotient two divisions, 2W products and W additions;
/// each call two calls and W products; the rest of the rhs's total (its
/// numeric solves, negations) 1 + 2W operations each.
///
/// ```
/// use appell_core::{dual::pass_costs, OpCounts};
/// let rhs = OpCounts { add: 10, mul: 10, div: 1, calls: 2, total: 25 };
/// let c = pass_costs(rhs, 4, 2);
/// assert_eq!(c.add, 2 * (10 * 5 + 10 * 4 + 4));
/// assert_eq!(c.total, c.add + c.mul + c.div + c.calls + 2 * 2 * 9);
/// ```
pub const fn pass_costs(rhs: OpCounts, width: usize, passes: usize) -> OpCounts {
    let w = width;
    let add = passes * (rhs.add * (1 + w) + rhs.mul * w + rhs.div * w);
    let mul = passes * (rhs.mul * (1 + 2 * w) + rhs.div * 2 * w + rhs.calls * w);
    let div = passes * rhs.div * 2;
    let calls = passes * rhs.calls * 2;
    let rest = rhs
        .total
        .saturating_sub(rhs.add + rhs.mul + rhs.div + rhs.calls);
    OpCounts {
        add,
        mul,
        div,
        calls,
        total: add + mul + div + calls + passes * rest * (1 + 2 * w),
    }
}

#[cfg(test)]
mod tests {
    use super::DualVec;
    use crate::Scalar;

    type D = DualVec<f64, 2>;

    /// f(x, y) and its gradient by hand, at (x, y).
    fn check(f: impl Fn(D, D) -> D, x: f64, y: f64, value: f64, grad: [f64; 2]) {
        let r = f(D::variable(x, 0), D::variable(y, 1));
        let scale = 1.0 + value.abs();
        assert!((r.re - value).abs() <= 1e-15 * scale, "{} vs {value}", r.re);
        for k in 0..2 {
            let s = 1.0 + grad[k].abs();
            assert!(
                (r.eps[k] - grad[k]).abs() <= 1e-14 * s,
                "{k}: {:?} vs {grad:?}",
                r.eps
            );
        }
    }

    #[test]
    fn arithmetic_follows_the_chain_rule() {
        let (x, y) = (0.7, -1.3);
        check(|a, b| a * b, x, y, x * y, [y, x]);
        check(|a, b| a / b, x, y, x / y, [1.0 / y, -x / (y * y)]);
        check(|a, b| a - b, x, y, x - y, [1.0, -1.0]);
        check(|a, b| -(a + b), x, y, -(x + y), [-1.0, -1.0]);
        check(|a, b| a.fma(b, a), x, y, x * y + x, [y + 1.0, x]);
        check(|a, b| b.atan2(a), x, y, y.atan2(x), {
            let r = x * x + y * y;
            [-y / r, x / r]
        });
    }

    #[test]
    fn functions_follow_the_chain_rule() {
        let x = 0.7;
        let one = |f: fn(D) -> D, value: f64, slope: f64| {
            check(|a, _| f(a), x, 0.0, value, [slope, 0.0]);
        };
        one(|a| a.sin(), x.sin(), x.cos());
        one(|a| a.cos(), x.cos(), -x.sin());
        one(|a| a.tan(), x.tan(), 1.0 / (x.cos() * x.cos()));
        one(|a| a.exp(), x.exp(), x.exp());
        one(|a| a.ln(), x.ln(), 1.0 / x);
        one(|a| a.sqrt(), x.sqrt(), 0.5 / x.sqrt());
        one(|a| a.powi(3), x.powi(3), 3.0 * x * x);
        one(|a| a.powi(0), 1.0, 0.0);
        one(|a| (-a).abs(), x, 1.0);
        one(|a| a.asin(), x.asin(), 1.0 / (1.0 - x * x).sqrt());
        one(|a| a.tanh(), x.tanh(), 1.0 - x.tanh().powi(2));
        one(|a| a.powi(-2), x.powi(-2), -2.0 * x.powi(-3));
        one(|a| a.acos(), x.acos(), -1.0 / (1.0 - x * x).sqrt());
        one(|a| a.atan(), x.atan(), 1.0 / (1.0 + x * x));
        one(|a| a.sinh(), x.sinh(), x.cosh());
        one(|a| a.cosh(), x.cosh(), x.sinh());
        // atan2 in the left half plane, and a power with both moving.
        check(|a, b| b.atan2(-a), x, 0.4, 0.4_f64.atan2(-x), {
            let r = x * x + 0.16;
            [0.4 / r, -x / r]
        });
        check(|a, b| a.powf(b), x, 1.7, x.powf(1.7), {
            [1.7 * x.powf(0.7), x.powf(1.7) * x.ln()]
        });
    }

    #[test]
    fn values_are_the_scalars_own() {
        // The value of a quotient, a power and a square root is T's, bit
        // for bit, so the Jacobians' values are the rhs's.
        let (x, y) = (0.7_f64, 0.3_f64);
        let (a, b) = (D::variable(x, 0), D::variable(y, 1));
        assert_eq!((a / b).re, x / y);
        assert_eq!(a.powi(5).re, x.powi(5));
        assert_eq!(a.powf(b).re, x.powf(y));
        assert_eq!(a.sqrt().re, x.sqrt());
        // A negative base to a constant power is finite, as for f64.
        let c = DualVec::<f64, 2>::constant(2.0);
        assert_eq!((-a).powf(c).re, (-x).powf(2.0));
        assert!((-a).powf(c).eps.iter().all(|e| e.is_finite()));
        // √ at zero along no direction stays zero.
        let zero = DualVec::<f64, 2>::constant(0.0).sqrt();
        assert_eq!(zero.eps, [0.0, 0.0]);
    }

    #[test]
    fn duals_of_duals_carry_second_derivatives() {
        // x ↦ x³ at 0.5: the inner dual's derivative of the outer one's is
        // the second derivative 6x.
        type Inner = DualVec<f64, 1>;
        let x = DualVec::<Inner, 1> {
            re: Inner::variable(0.5, 0),
            eps: [Inner::constant(1.0)],
        };
        let y = x.powi(3);
        assert_eq!(y.eps[0].re, 3.0 * 0.25);
        assert!((y.eps[0].eps[0] - 6.0 * 0.5).abs() < 1e-15);
    }

    #[test]
    fn a_direction_past_the_width_is_a_constant() {
        let d = DualVec::<f64, 2>::variable(1.5, 2);
        assert_eq!(d.eps, [0.0, 0.0]);
        assert_eq!(DualVec::<f32, 1>::from_f64(2.0).re(), 2.0);
    }
}
