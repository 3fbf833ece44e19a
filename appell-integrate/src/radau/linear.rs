//! Dense LU factorization with partial pivoting over real and complex
//! entries: the real and the complex Newton system of each step.

use core::ops::{Add, Div, Mul, Neg, Sub};

/// A complex number, for the complex Newton system.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(super) struct C64 {
    pub(super) re: f64,
    pub(super) im: f64,
}

impl C64 {
    pub(super) const fn new(re: f64, im: f64) -> Self {
        C64 { re, im }
    }
}

impl Add for C64 {
    type Output = C64;
    fn add(self, o: C64) -> C64 {
        C64::new(self.re + o.re, self.im + o.im)
    }
}

impl Sub for C64 {
    type Output = C64;
    fn sub(self, o: C64) -> C64 {
        C64::new(self.re - o.re, self.im - o.im)
    }
}

impl Mul for C64 {
    type Output = C64;
    fn mul(self, o: C64) -> C64 {
        C64::new(
            self.re * o.re - self.im * o.im,
            self.re * o.im + self.im * o.re,
        )
    }
}

impl Div for C64 {
    type Output = C64;
    /// Smith's division (no overflow of `|o|²` for large entries).
    fn div(self, o: C64) -> C64 {
        if o.re.abs() >= o.im.abs() {
            let r = o.im / o.re;
            let d = o.re + o.im * r;
            C64::new((self.re + self.im * r) / d, (self.im - self.re * r) / d)
        } else {
            let r = o.re / o.im;
            let d = o.re * r + o.im;
            C64::new((self.re * r + self.im) / d, (self.im * r - self.re) / d)
        }
    }
}

impl Neg for C64 {
    type Output = C64;
    fn neg(self) -> C64 {
        C64::new(-self.re, -self.im)
    }
}

/// The arithmetic an LU factorization needs.
pub(super) trait Entry:
    Copy + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + Div<Output = Self>
{
    const ZERO: Self;
    /// A real entry.
    fn real(v: f64) -> Self;
    /// The magnitude used to choose pivots (`|re| + |im|` for complex).
    fn magnitude(self) -> f64;
}

impl Entry for f64 {
    const ZERO: f64 = 0.0;
    fn real(v: f64) -> f64 {
        v
    }
    fn magnitude(self) -> f64 {
        self.abs()
    }
}

impl Entry for C64 {
    const ZERO: C64 = C64::new(0.0, 0.0);
    fn real(v: f64) -> C64 {
        C64::new(v, 0.0)
    }
    fn magnitude(self) -> f64 {
        self.re.abs() + self.im.abs()
    }
}

/// The LU factors of an n×n matrix (row-major, unit lower triangle
/// implied), the reciprocals of the pivots and the row exchanges of
/// partial pivoting.
pub(super) struct Lu<T> {
    n: usize,
    a: Vec<T>,
    inv_diag: Vec<T>,
    pivots: Vec<usize>,
}

impl<T: Entry> Lu<T> {
    /// Room for an n×n factorization.
    pub(super) fn new(n: usize) -> Self {
        Lu {
            n,
            a: vec![T::ZERO; n * n],
            inv_diag: vec![T::ZERO; n],
            pivots: vec![0; n],
        }
    }

    /// Factors `shift · I − J` (`jac` row-major n×n); false when a pivot
    /// is zero or not finite (the factors are then unusable).
    #[cfg(test)]
    pub(super) fn factor_shifted(&mut self, shift: T, jac: &[f64]) -> bool {
        let n = self.n;
        for (v, &j) in self.a.iter_mut().zip(jac) {
            *v = T::real(-j);
        }
        for i in 0..n {
            self.a[i * n + i] = self.a[i * n + i] + shift;
        }
        self.factor()
    }

    /// In-place Doolittle factorization with partial pivoting.
    #[cfg(test)]
    fn factor(&mut self) -> bool {
        (0..self.n).all(|k| self.eliminate(k))
    }

    /// Step `k` of the factorization: the pivot of column `k`, the row
    /// exchange and the elimination below it (rows by slices, each with
    /// one multiplication by the pivot's reciprocal); false when the pivot
    /// is zero or not finite.
    #[inline(always)]
    fn eliminate(&mut self, k: usize) -> bool {
        let n = self.n;
        let a = &mut self.a;
        let mut p = k;
        let mut m = a[k * n + k].magnitude();
        for i in k + 1..n {
            let v = a[i * n + k].magnitude();
            if v > m {
                (p, m) = (i, v);
            }
        }
        if m == 0.0 || !m.is_finite() {
            return false;
        }
        self.pivots[k] = p;
        if p != k {
            let (upper, lower) = a.split_at_mut(p * n);
            upper[k * n..(k + 1) * n].swap_with_slice(&mut lower[..n]);
        }
        let (upper, lower) = a.split_at_mut((k + 1) * n);
        let pivot_row = &upper[k * n + k + 1..];
        let inv = T::real(1.0) / upper[k * n + k];
        self.inv_diag[k] = inv;
        for row in lower.chunks_exact_mut(n) {
            let l = row[k] * inv;
            row[k] = l;
            for (r, &u) in row[k + 1..].iter_mut().zip(pivot_row) {
                *r = *r - l * u;
            }
        }
        true
    }

    /// Solves `M y = b` in place with the factors of `M`.
    pub(super) fn solve(&self, b: &mut [T]) {
        let n = self.n;
        let (a, b) = (&self.a[..n * n], &mut b[..n]);
        for (k, &p) in self.pivots.iter().enumerate() {
            b.swap(k, p);
        }
        // Forward: column k of L once b_k is final.
        for k in 0..n {
            let y = b[k];
            for i in k + 1..n {
                b[i] = b[i] - a[i * n + k] * y;
            }
        }
        // Backward: column k of U once y_k is final.
        for k in (0..n).rev() {
            let y = b[k] * self.inv_diag[k];
            b[k] = y;
            for i in 0..k {
                b[i] = b[i] - a[i * n + k] * y;
            }
        }
    }
}

/// Factors `g · I − J` into `real` and `mu · I − J` into `complex` (as
/// [`Lu::factor_shifted`] of each), their eliminations interleaved column
/// by column so that the processor can overlap the two; false when either
/// matrix is singular.
pub(super) fn factor_pair(
    real: &mut Lu<f64>,
    complex: &mut Lu<C64>,
    g: f64,
    mu: C64,
    jac: &[f64],
) -> bool {
    let n = real.n;
    assert_eq!(complex.n, n);
    let entries = real.a.iter_mut().zip(complex.a.iter_mut()).zip(jac);
    for ((r, c), &j) in entries {
        *r = -j;
        *c = C64::real(-j);
    }
    for i in 0..n {
        real.a[i * n + i] += g;
        complex.a[i * n + i] = complex.a[i * n + i] + mu;
    }
    (0..n).all(|k| real.eliminate(k) && complex.eliminate(k))
}

/// Solves `R y = b` and `C w = c` in place with the factors of the real
/// matrix `R` and the complex matrix `C` of the same size, as
/// [`Lu::solve`] of each but in one pass: each substitution is a chain of
/// dependent operations, and interleaving the two independent chains lets
/// the processor overlap them.
pub(super) fn solve_pair(real: &Lu<f64>, complex: &Lu<C64>, b: &mut [f64], c: &mut [C64]) {
    let n = real.n;
    assert_eq!(complex.n, n);
    let (ar, ac) = (&real.a[..n * n], &complex.a[..n * n]);
    let (b, c) = (&mut b[..n], &mut c[..n]);
    let pivots = real.pivots.iter().zip(&complex.pivots);
    for (k, (&p, &q)) in pivots.enumerate() {
        b.swap(k, p);
        c.swap(k, q);
    }
    for k in 0..n {
        let (y, z) = (b[k], c[k]);
        for i in k + 1..n {
            b[i] -= ar[i * n + k] * y;
            c[i] = c[i] - ac[i * n + k] * z;
        }
    }
    for k in (0..n).rev() {
        let y = b[k] * real.inv_diag[k];
        let z = c[k] * complex.inv_diag[k];
        b[k] = y;
        c[k] = z;
        for i in 0..k {
            b[i] -= ar[i * n + k] * y;
            c[i] = c[i] - ac[i * n + k] * z;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn real_solve_with_row_exchanges() {
        // 2 I − J with J = [[2, 1, 0], [1, 2, 3], [4, 0, 1]] is
        // [[0, −1, 0], [−1, 0, −3], [−4, 0, 1]]: the first pivot is zero.
        let jac = [2.0, 1.0, 0.0, 1.0, 2.0, 3.0, 4.0, 0.0, 1.0];
        let mut lu = Lu::<f64>::new(3);
        assert!(lu.factor_shifted(2.0, &jac));
        let x = [1.0, -2.0, 0.5];
        let m = [[0.0, -1.0, 0.0], [-1.0, 0.0, -3.0], [-4.0, 0.0, 1.0]];
        let mut b: Vec<f64> = m
            .iter()
            .map(|r| r.iter().zip(&x).map(|(a, b)| a * b).sum())
            .collect();
        lu.solve(&mut b);
        for (u, v) in b.iter().zip(&x) {
            assert!((u - v).abs() < 1e-15, "{b:?}");
        }
    }

    #[test]
    fn complex_solve_matches_a_known_solution() {
        // (1 + i) I − J, J = [[1, 2], [3, 4]]: [[i, −2], [−3, −3 + i]].
        let jac = [1.0, 2.0, 3.0, 4.0];
        let mut lu = Lu::<C64>::new(2);
        assert!(lu.factor_shifted(C64::new(1.0, 1.0), &jac));
        let x = [C64::new(1.0, -1.0), C64::new(0.5, 2.0)];
        let m = [
            [C64::new(0.0, 1.0), C64::new(-2.0, 0.0)],
            [C64::new(-3.0, 0.0), C64::new(-3.0, 1.0)],
        ];
        let mut b: Vec<C64> = m.iter().map(|r| r[0] * x[0] + r[1] * x[1]).collect();
        lu.solve(&mut b);
        for (u, v) in b.iter().zip(&x) {
            assert!((*u - *v).magnitude() < 1e-14, "{b:?}");
        }
        assert_eq!(C64::new(1.0, 2.0) / C64::new(0.0, 1.0), C64::new(2.0, -1.0));
        assert_eq!(-C64::new(1.0, -2.0), C64::new(-1.0, 2.0));
    }

    #[test]
    fn paired_factors_and_solves_match_the_separate_ones() {
        let jac = [2.0, 1.0, 0.0, 1.0, 2.0, 3.0, 4.0, 0.0, 1.0];
        let mu = C64::new(1.5, -0.7);
        let (mut lr, mut lc) = (Lu::<f64>::new(3), Lu::<C64>::new(3));
        assert!(lr.factor_shifted(2.0, &jac));
        assert!(lc.factor_shifted(mu, &jac));
        let (mut pr, mut pc) = (Lu::<f64>::new(3), Lu::<C64>::new(3));
        assert!(factor_pair(&mut pr, &mut pc, 2.0, mu, &jac));
        assert_eq!(
            (&pr.a, &pr.inv_diag, &pr.pivots),
            (&lr.a, &lr.inv_diag, &lr.pivots)
        );
        assert_eq!(
            (&pc.a, &pc.inv_diag, &pc.pivots),
            (&lc.a, &lc.inv_diag, &lc.pivots)
        );
        // Singular: 2 I − J with J = 2 I.
        assert!(!factor_pair(
            &mut pr,
            &mut pc,
            2.0,
            mu,
            &[2.0, 0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 2.0]
        ));
        let b = [1.0, -2.0, 0.5];
        let c = [
            C64::new(1.0, 2.0),
            C64::new(-0.5, 0.0),
            C64::new(0.25, -3.0),
        ];
        let (mut b1, mut c1) = (b, c);
        lr.solve(&mut b1);
        lc.solve(&mut c1);
        let (mut b2, mut c2) = (b, c);
        solve_pair(&lr, &lc, &mut b2, &mut c2);
        assert_eq!((b1, c1), (b2, c2));
    }

    #[test]
    fn singular_and_non_finite_matrices_are_reported() {
        let mut lu = Lu::<f64>::new(2);
        // I − J = 0.
        assert!(!lu.factor_shifted(1.0, &[1.0, 0.0, 0.0, 1.0]));
        assert!(!lu.factor_shifted(1.0, &[f64::NAN, 0.0, 0.0, 1.0]));
        let mut lc = Lu::<C64>::new(1);
        assert!(!lc.factor_shifted(C64::new(2.0, 0.0), &[2.0]));
        assert!(lc.factor_shifted(C64::new(2.0, 1e-300), &[2.0]));
    }
}
