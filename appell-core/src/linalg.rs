//! Small dense solves on fixed-size arrays, generic over the scalar, with no
//! allocation. The generated code calls them for Appell's mass matrix (when
//! it is not small enough to unroll) and for the dependent-speed block D'
//! when a symbolic elimination could not be proven safe.
//!
//! Singular systems are reported as [`ModelError`]s, never as NaN.

// Index loops mirror the textbook elimination formulas (rows, columns,
// pivots); iterator chains would hide which entry is which.
#![allow(clippy::needless_range_loop)]

use crate::scalar::Scalar;
use crate::ModelError;

/// Solves `A X = B` in place by LU with partial pivoting: on success `b`
/// holds `X`. A pivot smaller than `1e-12 ×` the largest entry of `A` and `B`
/// in magnitude is reported as [`ModelError::SingularConstraints`] (the use
/// this solve has in generated code, where `A` is the dependent block D' and
/// `B` holds −D'' and −d: a pivot is negligible relative to the whole
/// constraint matrix, not only to D'). [`lu_solve_ops`] counts its
/// arithmetic.
///
/// ```
/// use appell_core::linalg::lu_solve;
/// let mut a = [[0.0, 2.0], [1.0, 1.0]];
/// let mut b = [[4.0], [3.0]];
/// lu_solve(&mut a, &mut b).unwrap();
/// assert_eq!(b, [[1.0], [2.0]]);
///
/// let mut s = [[1.0, 2.0], [2.0, 4.0]];
/// let mut r = [[1.0], [1.0]];
/// assert!(lu_solve(&mut s, &mut r).is_err());
/// ```
pub fn lu_solve<T: Scalar, const N: usize, const M: usize>(
    a: &mut [[T; N]; N],
    b: &mut [[T; M]; N],
) -> Result<(), ModelError> {
    // The same arithmetic as eliminating `b` along with `a`: every row of
    // `b` gets the same updates in the same order.
    let swaps = lu_factor(a, max_abs(b))?;
    lu_substitute(a, &swaps, b);
    Ok(())
}

/// The largest finite magnitude among the entries of `b` (0 when there is
/// none): the right side's share of [`lu_factor`]'s pivot tolerance.
///
/// ```
/// use appell_core::linalg::max_abs;
/// assert_eq!(max_abs(&[[1.0, -3.0], [f64::NAN, 2.0]]), 3.0);
/// ```
#[inline]
pub fn max_abs<T: Scalar, const N: usize, const M: usize>(b: &[[T; M]; N]) -> f64 {
    let mut v = [[0.0f64; M]; N];
    for (row, out) in b.iter().zip(v.iter_mut()) {
        for (x, o) in row.iter().zip(out.iter_mut()) {
            let m = x.re().abs();
            // False for NaN and ±∞, which count as 0.
            *o = if m <= f64::MAX { m } else { 0.0 };
        }
    }
    pairwise(v.as_flattened_mut(), |a, b| if a > b { a } else { b })
}

/// Reduces `v` by `op` pairwise (a tree of depth log₂ n rather than a
/// chain of n − 1), overwriting it; 0 for an empty slice.
#[inline(always)]
fn pairwise(v: &mut [f64], op: impl Fn(f64, f64) -> f64) -> f64 {
    let mut n = v.len();
    if n == 0 {
        return 0.0;
    }
    while n > 1 {
        let half = n / 2;
        for i in 0..half {
            v[i] = op(v[i], v[n - half + i]);
        }
        n -= half;
    }
    v[0]
}

/// The scale a constraint matrix's pivots are judged against: the largest
/// magnitude among the entries of `a` and `rhs_scale` (a non-finite
/// `rhs_scale` counts as 0). A non-finite entry of `a` is
/// [`ModelError::NonFinite`].
///
/// ```
/// use appell_core::linalg::constraint_scale;
/// assert_eq!(constraint_scale(&[[1.0, -3.0], [0.5, 2.0]], 2.0), Ok(3.0));
/// assert_eq!(constraint_scale(&[[1.0]], 7.0), Ok(7.0));
/// assert!(constraint_scale(&[[f64::NAN]], 1.0).is_err());
/// ```
#[inline]
pub fn constraint_scale<T: Scalar, const N: usize, const M: usize>(
    a: &[[T; M]; N],
    rhs_scale: f64,
) -> Result<f64, ModelError> {
    let mut v = [[0.0f64; M]; N];
    for (row, out) in a.iter().zip(v.iter_mut()) {
        for (x, o) in row.iter().zip(out.iter_mut()) {
            *o = x.re().abs();
        }
    }
    // A NaN entry makes the sum NaN, an infinite one the maximum infinite.
    let mut w = v;
    let sum = pairwise(w.as_flattened_mut(), |a, b| a + b);
    let scale = pairwise(v.as_flattened_mut(), |a, b| if a > b { a } else { b });
    if sum.is_nan() || scale > f64::MAX {
        return Err(ModelError::NonFinite {
            what: "the constraint matrix",
        });
    }
    // `rhs_scale > scale` is false for NaN, so a NaN right side counts as 0.
    Ok(if rhs_scale > scale && rhs_scale <= f64::MAX {
        rhs_scale
    } else {
        scale
    })
}

/// Accepts a pivot of the dependent block when its magnitude exceeds
/// `1e-12 × scale` (see [`constraint_scale`]) and is not zero; otherwise
/// [`ModelError::SingularConstraints`] for `column`. [`lu_factor`] judges
/// its pivots so, and so does generated code for the unknowns it solves
/// one by one (a row of the block with a single entry).
///
/// ```
/// use appell_core::linalg::check_pivot;
/// assert!(check_pivot(1e-3, 1.0, 0).is_ok());
/// assert!(check_pivot(1e-13, 1.0, 2).is_err());
/// assert!(check_pivot(0.0, 0.0, 0).is_err());
/// ```
#[inline]
pub fn check_pivot<T: Scalar>(pivot: T, scale: f64, column: usize) -> Result<(), ModelError> {
    let v = pivot.re().abs();
    if v <= 1e-12 * scale || v == 0.0 || v.is_nan() {
        return Err(ModelError::SingularConstraints { column, pivot: v });
    }
    Ok(())
}

/// Factors `A` in place by LU with partial pivoting (the multipliers below
/// the diagonal, U above it, and the reciprocals of U's pivots on it, so
/// that no substitution divides again) and returns the row exchanges, so that
/// several right sides can be solved with [`lu_substitute`], including
/// right sides that depend on an earlier solution. A pivot smaller than
/// `1e-12 ×` the largest magnitude among `A`'s entries and `rhs_scale` is
/// reported as [`ModelError::SingularConstraints`], as in [`lu_solve`].
/// [`lu_factor_ops`] counts its arithmetic.
///
/// ```
/// use appell_core::linalg::{lu_factor, lu_substitute};
/// let mut a = [[0.0, 2.0], [1.0, 1.0]];
/// let swaps = lu_factor(&mut a, 4.0).unwrap();
/// let mut b = [[4.0], [3.0]];
/// lu_substitute(&a, &swaps, &mut b);
/// assert_eq!(b, [[1.0], [2.0]]);
/// let mut c = [[2.0], [2.0]];
/// lu_substitute(&a, &swaps, &mut c);
/// assert_eq!(c, [[1.0], [1.0]]);
/// assert!(lu_factor(&mut [[1.0, 2.0], [2.0, 4.0]], 1.0).is_err());
/// ```
#[inline]
pub fn lu_factor<T: Scalar, const N: usize>(
    a: &mut [[T; N]; N],
    rhs_scale: f64,
) -> Result<[usize; N], ModelError> {
    let scale = constraint_scale(a, rhs_scale)?;
    let mut swaps = [0usize; N];
    for col in 0..N {
        let mut p = col;
        let mut best = a[col][col].re().abs();
        for r in col + 1..N {
            let v = a[r][col].re().abs();
            if v > best {
                best = v;
                p = r;
            }
        }
        swaps[col] = p;
        swap_rows(a, col, p);
        check_pivot(a[col][col], scale, col)?;
        let inv = T::one() / a[col][col];
        for r in col + 1..N {
            let f = a[r][col] * inv;
            a[r][col] = f;
            if f.re() == 0.0 {
                continue;
            }
            for j in col + 1..N {
                let t = a[col][j];
                a[r][j] -= f * t;
            }
        }
        a[col][col] = inv;
    }
    Ok(swaps)
}

/// The smallest pivot of `a`'s LU factorization with partial pivoting,
/// relative to the largest magnitude among its entries: 1 for a multiple
/// of the identity, 0 for a matrix that is singular to working precision.
/// Its reciprocal is a cheap estimate of `a`'s condition number, in the
/// units in which [`lu_factor`] and [`check_pivot`] judge the dependent
/// block: they report [`ModelError::SingularConstraints`] where it falls
/// to 1e-12 (for the block alone; their scale may also include the right
/// side's). It costs one factorization of `a`'s real parts, N³/3
/// multiplications. A NaN or infinite entry is
/// [`ModelError::NonFinite`].
///
/// ```
/// use appell_core::linalg::pivot_margin;
/// assert_eq!(pivot_margin(&[[2.0, 0.0], [0.0, 2.0]]).unwrap(), 1.0);
/// // A four-bar-like block near a dead centre: 1/margin grows as 1/ε.
/// let eps = 1e-6;
/// let m = pivot_margin(&[[1.0, 1.0], [1.0, 1.0 + eps]]).unwrap();
/// assert!((m / eps - 1.0).abs() < 1e-4);
/// assert_eq!(pivot_margin(&[[1.0, 2.0], [2.0, 4.0]]).unwrap(), 0.0);
/// assert!(pivot_margin(&[[f64::NAN, 0.0], [0.0, 1.0]]).is_err());
/// ```
pub fn pivot_margin<T: Scalar, const N: usize>(a: &[[T; N]; N]) -> Result<f64, ModelError> {
    let mut u = [[0.0f64; N]; N];
    for (row, out) in a.iter().zip(u.iter_mut()) {
        for (x, o) in row.iter().zip(out.iter_mut()) {
            *o = x.re();
        }
    }
    if u.iter().flatten().any(|x| !x.is_finite()) {
        return Err(ModelError::NonFinite {
            what: "the dependent constraint block",
        });
    }
    let scale = u.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
    if scale == 0.0 {
        return Ok(if N == 0 { 1.0 } else { 0.0 });
    }
    let mut smallest = f64::INFINITY;
    for col in 0..N {
        let p = (col..N)
            .max_by(|&i, &j| u[i][col].abs().total_cmp(&u[j][col].abs()))
            .unwrap_or(col);
        u.swap(col, p);
        let pivot = u[col][col];
        smallest = smallest.min(pivot.abs());
        if pivot == 0.0 {
            break;
        }
        for r in col + 1..N {
            let f = u[r][col] / pivot;
            for j in col + 1..N {
                u[r][j] -= f * u[col][j];
            }
        }
    }
    Ok((smallest / scale).min(1.0))
}

/// Exchanges rows `i` and `p ≥ i` of `a`. Written with constant indices
/// (one test per candidate row), so that after unrolling a small matrix
/// stays in registers instead of being indexed in memory.
#[inline(always)]
fn swap_rows<T: Copy, const N: usize, const M: usize>(a: &mut [[T; M]; N], i: usize, p: usize) {
    for r in i + 1..N {
        if p == r {
            a.swap(i, r);
        }
    }
}

/// Solves `A X = B` in place with the factors and row exchanges of
/// [`lu_factor`]: on return `b` holds `X`. [`lu_substitute_ops`] counts its
/// arithmetic.
///
/// ```
/// use appell_core::linalg::{lu_factor, lu_substitute};
/// let mut a = [[4.0, 0.0], [0.0, 2.0]];
/// let swaps = lu_factor(&mut a, 0.0).unwrap();
/// let mut b = [[8.0, 4.0], [2.0, 6.0]];
/// lu_substitute(&a, &swaps, &mut b);
/// assert_eq!(b, [[2.0, 1.0], [1.0, 3.0]]);
/// ```
#[inline]
pub fn lu_substitute<T: Scalar, const N: usize, const M: usize>(
    a: &[[T; N]; N],
    swaps: &[usize; N],
    b: &mut [[T; M]; N],
) {
    // P A = L U with the exchanges applied to whole rows: P b first, then L.
    for col in 0..N {
        swap_rows(b, col, swaps[col]);
    }
    for col in 0..N {
        for r in col + 1..N {
            let f = a[r][col];
            if f.re() == 0.0 {
                continue;
            }
            for j in 0..M {
                let t = b[col][j];
                b[r][j] -= f * t;
            }
        }
    }
    for col in (0..N).rev() {
        let inv = a[col][col];
        for j in 0..M {
            let mut s = b[col][j];
            for k in col + 1..N {
                s -= a[col][k] * b[k][j];
            }
            b[col][j] = s * inv;
        }
    }
}

/// The arithmetic operations [`lu_factor`] performs on an `n × n` matrix:
/// additions, subtractions, multiplications and divisions of the scalar,
/// each counted 1 (pivot search, comparisons, row exchanges and the pivot
/// tolerance, all on `f64` magnitudes, are not counted). Per column `c`: a
/// reciprocal of the pivot, then for each of the `n − c − 1` rows below it a
/// multiplier and a multiply-subtract per entry right of the pivot, so
/// `Σ_{c<n} 1 + (n − c − 1)(1 + 2(n − c − 1))`. A row whose multiplier is
/// zero is skipped, so this is the count for a matrix without zero
/// multipliers and an upper bound otherwise.
///
/// ```
/// use appell_core::linalg::lu_factor_ops;
/// assert_eq!(lu_factor_ops(0), 0);
/// assert_eq!(lu_factor_ops(1), 1); // the reciprocal of the pivot
/// assert_eq!(lu_factor_ops(2), 5); // 2 reciprocals, 1 multiplier, 1 multiply-subtract
/// assert_eq!(lu_factor_ops(3), 16);
/// // Usable in constants.
/// const OPS: usize = lu_factor_ops(4);
/// assert_eq!(OPS, 38);
/// ```
pub const fn lu_factor_ops(n: usize) -> usize {
    if n == 0 {
        return 0;
    }
    // n reciprocals, n(n − 1)/2 multipliers, 2 Σ_{m<n} m² for the updates.
    n + n * (n - 1) / 2 + n * (n - 1) * (2 * n - 1) / 3
}

/// The arithmetic operations [`lu_substitute`] performs with the factors of
/// an `n × n` matrix on a right side of `columns` columns, counted as for
/// [`lu_factor_ops`]: per right-hand column, a multiply-subtract for each
/// entry of L below the diagonal (forward), then a multiply-subtract for
/// each entry of U above the diagonal and a multiplication by the stored
/// reciprocal per row (backward), so
/// `columns · (n(n − 1) + n²) = columns · (2n² − n)`. Rows of L with a zero
/// multiplier are skipped, as in [`lu_factor_ops`].
///
/// ```
/// use appell_core::linalg::lu_substitute_ops;
/// assert_eq!(lu_substitute_ops(1, 1), 1); // one multiplication by 1/a
/// assert_eq!(lu_substitute_ops(3, 2), 2 * (2 * 9 - 3));
/// assert_eq!(lu_substitute_ops(4, 0), 0);
/// ```
pub const fn lu_substitute_ops(n: usize, columns: usize) -> usize {
    columns * (2 * n * n - n)
}

/// The arithmetic operations [`lu_solve`] performs on an `n × n` system with
/// `columns` right-hand columns: [`lu_factor_ops`]`(n)` plus
/// [`lu_substitute_ops`]`(n, columns)` (the right side's scale is computed
/// on `f64` magnitudes and not counted).
///
/// ```
/// use appell_core::linalg::{lu_factor_ops, lu_solve_ops, lu_substitute_ops};
/// assert_eq!(lu_solve_ops(3, 2), lu_factor_ops(3) + lu_substitute_ops(3, 2));
/// assert_eq!(lu_solve_ops(2, 1), 5 + 6);
/// ```
pub const fn lu_solve_ops(n: usize, columns: usize) -> usize {
    lu_factor_ops(n) + lu_substitute_ops(n, columns)
}

/// Solves `M x = f` for a symmetric positive definite `M` by an LDLᵀ
/// factorization; a pivot that is not positive (relative to the diagonal's
/// scale) is reported as [`ModelError::SingularMassMatrix`].
///
/// ```
/// use appell_core::linalg::ldlt_solve;
/// let m = [[4.0f64, 2.0], [2.0, 3.0]];
/// let x = ldlt_solve(&m, &[6.0, 5.0]).unwrap();
/// assert!((x[0] - 1.0).abs() < 1e-15 && (x[1] - 1.0).abs() < 1e-15);
/// assert!(ldlt_solve(&[[1.0, 1.0], [1.0, 1.0]], &[1.0, 1.0]).is_err());
/// ```
pub fn ldlt_solve<T: Scalar, const N: usize>(
    m: &[[T; N]; N],
    f: &[T; N],
) -> Result<[T; N], ModelError> {
    let mut scale = 0.0f64;
    for (i, row) in m.iter().enumerate() {
        scale = scale.max(row[i].re().abs());
    }
    let tol = 1e-13 * scale;
    let mut l = [[T::zero(); N]; N];
    let mut d = [T::zero(); N];
    for j in 0..N {
        let mut dj = m[j][j];
        for k in 0..j {
            dj -= l[j][k] * l[j][k] * d[k];
        }
        let pivot = dj.re();
        if pivot.is_nan() || pivot <= tol {
            return Err(ModelError::SingularMassMatrix { index: j, pivot });
        }
        d[j] = dj;
        let inv = T::one() / dj;
        for i in j + 1..N {
            let mut s = m[i][j];
            for k in 0..j {
                s -= l[i][k] * l[j][k] * d[k];
            }
            l[i][j] = s * inv;
        }
    }
    let mut x = *f;
    for i in 0..N {
        for k in 0..i {
            let t = l[i][k] * x[k];
            x[i] -= t;
        }
    }
    for i in 0..N {
        x[i] /= d[i];
    }
    for i in (0..N).rev() {
        for k in i + 1..N {
            let t = l[k][i] * x[k];
            x[i] -= t;
        }
    }
    Ok(x)
}

/// The columns [`substitute_row`] takes at a time: rows of a multiple of
/// this many entries are taken in vector-wide steps only.
pub const ROW_CHUNK: usize = 8;

/// Row `i` of the row-major matrix `m` (rows of `width` entries) as
/// `scale` times itself less Σ lₖ times row k over `terms` (k ≠ i): one
/// row of a forward or back substitution by LDLᵀ factors, taken over
/// every column at once. A generated `rhs_jacobian` solves its many
/// columns by one M so, in loops the compiler vectorizes, rather than
/// column by column; the row is read and written once, the other rows
/// only read.
///
/// ```
/// use appell_core::linalg::substitute_row;
/// let mut m = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 1.0, 1.0, 1.0];
/// // Row 1 ← 0.5 row 1 − 2 row 0 − 1 row 2.
/// substitute_row(&mut m, 3, 1, 0.5, &[(0, 2.0), (2, 1.0)]);
/// assert_eq!(m[3..6], [-1.0, -2.5, -4.0]);
/// ```
///
/// `terms` must not name row `i` (a debug assertion).
///
/// # Panics
///
/// If a row is not within `m`: the generated calls name rows of their
/// own scratch array, sized for them.
#[inline]
pub fn substitute_row<T: Scalar>(
    m: &mut [T],
    width: usize,
    i: usize,
    scale: T,
    terms: &[(usize, T)],
) {
    debug_assert!(
        terms.iter().all(|&(k, _)| k != i),
        "substitute_row: a row less a multiple of itself"
    );
    let start = i * width;
    let mut c = 0;
    while c + ROW_CHUNK <= width {
        let own: &[T; ROW_CHUNK] = chunk(m, start + c);
        let mut acc = own.map(|x| x * scale);
        for &(k, l) in terms {
            let (minus, row): (T, &[T; ROW_CHUNK]) = (-l, chunk(m, k * width + c));
            for (a, &y) in acc.iter_mut().zip(row) {
                *a = y.fma(minus, *a);
            }
        }
        m[start + c..start + c + ROW_CHUNK].copy_from_slice(&acc);
        c += ROW_CHUNK;
    }
    // The last columns, fewer than a chunk (none where the caller pads
    // its rows to a multiple of ROW_CHUNK, as the generated code does).
    for col in c..width {
        let mut acc = m[start + col] * scale;
        for &(k, l) in terms {
            acc = m[k * width + col].fma(-l, acc);
        }
        m[start + col] = acc;
    }
}

/// The `N` entries of `m` from `at`, as an array (one bounds check).
#[inline(always)]
fn chunk<T, const N: usize>(m: &[T], at: usize) -> &[T; N] {
    m[at..at + N].try_into().expect("a slice of N entries")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A whole substitution by `substitute_row` equals a column-by-column
    /// one, over widths with and without a partial chunk.
    #[test]
    fn substituted_rows_solve_every_column() {
        // L (unit lower, positions) and 1/d of a 3×3 M; rows 0..3.
        let lower = [[0.0, 0.0, 0.0], [0.5, 0.0, 0.0], [-0.25, 0.75, 0.0]];
        let recip = [0.5, 2.0, 0.25];
        for width in [1, 7, 8, 13, 16] {
            let b: Vec<f64> = (0..3 * width).map(|k| (k as f64 * 0.37).sin()).collect();
            let mut x = b.clone();
            for i in 0..3 {
                let terms: Vec<(usize, f64)> = (0..i).map(|k| (k, lower[i][k])).collect();
                substitute_row(&mut x, width, i, 1.0, &terms);
            }
            for i in (0..3).rev() {
                let terms: Vec<(usize, f64)> = (i + 1..3).map(|k| (k, lower[k][i])).collect();
                substitute_row(&mut x, width, i, recip[i], &terms);
            }
            for c in 0..width {
                let mut z = [0.0; 3];
                for i in 0..3 {
                    z[i] = b[i * width + c] - (0..i).map(|k| lower[i][k] * z[k]).sum::<f64>();
                }
                let mut y = [0.0; 3];
                for i in (0..3).rev() {
                    y[i] = z[i] * recip[i] - (i + 1..3).map(|k| lower[k][i] * y[k]).sum::<f64>();
                }
                for i in 0..3 {
                    let got = x[i * width + c];
                    assert!(
                        (got - y[i]).abs() < 1e-14 * (1.0 + y[i].abs()),
                        "width {width}, column {c}: {got} against {}",
                        y[i]
                    );
                }
            }
        }
    }

    /// An `f64` that counts the arithmetic done on it: additions,
    /// subtractions, multiplications and divisions (assigning forms
    /// included) in `ARITHMETIC`, anything else (negation, elementary
    /// functions) in `OTHER`, per thread.
    #[derive(Clone, Copy, Debug)]
    struct Counted(f64);

    std::thread_local! {
        static ARITHMETIC: core::cell::Cell<usize> = const { core::cell::Cell::new(0) };
        static OTHER: core::cell::Cell<usize> = const { core::cell::Cell::new(0) };
    }

    fn tick(counter: &'static std::thread::LocalKey<core::cell::Cell<usize>>) {
        counter.with(|c| c.set(c.get() + 1));
    }

    /// The counts since the last call (arithmetic, other), resetting them.
    fn take_counts() -> (usize, usize) {
        (
            ARITHMETIC.with(|c| c.replace(0)),
            OTHER.with(|c| c.replace(0)),
        )
    }

    macro_rules! counted_op {
        ($op:ident, $f:ident, $op_assign:ident, $f_assign:ident, $sym:tt) => {
            impl core::ops::$op for Counted {
                type Output = Counted;
                fn $f(self, rhs: Counted) -> Counted {
                    tick(&ARITHMETIC);
                    Counted(self.0 $sym rhs.0)
                }
            }
            impl core::ops::$op_assign for Counted {
                fn $f_assign(&mut self, rhs: Counted) {
                    *self = core::ops::$op::$f(*self, rhs);
                }
            }
        };
    }
    counted_op!(Add, add, AddAssign, add_assign, +);
    counted_op!(Sub, sub, SubAssign, sub_assign, -);
    counted_op!(Mul, mul, MulAssign, mul_assign, *);
    counted_op!(Div, div, DivAssign, div_assign, /);

    impl core::ops::Neg for Counted {
        type Output = Counted;
        fn neg(self) -> Counted {
            tick(&OTHER);
            Counted(-self.0)
        }
    }

    impl Scalar for Counted {
        fn from_f64(x: f64) -> Self {
            Counted(x)
        }
        fn re(self) -> f64 {
            self.0
        }
        fn sin(self) -> Self {
            tick(&OTHER);
            Counted(self.0.sin())
        }
        fn cos(self) -> Self {
            tick(&OTHER);
            Counted(self.0.cos())
        }
        fn tan(self) -> Self {
            tick(&OTHER);
            Counted(self.0.tan())
        }
        fn exp(self) -> Self {
            tick(&OTHER);
            Counted(self.0.exp())
        }
        fn ln(self) -> Self {
            tick(&OTHER);
            Counted(self.0.ln())
        }
        fn abs(self) -> Self {
            tick(&OTHER);
            Counted(self.0.abs())
        }
        fn sqrt(self) -> Self {
            tick(&OTHER);
            Counted(self.0.sqrt())
        }
        fn powi(self, n: i32) -> Self {
            tick(&OTHER);
            Counted(self.0.powi(n))
        }
        fn atan2(self, x: Self) -> Self {
            tick(&OTHER);
            Counted(self.0.atan2(x.0))
        }
    }

    /// Counts the operations of `lu_factor`, `lu_substitute` and `lu_solve`
    /// on an `N × N` system with `M` right-hand columns whose entries are
    /// pseudo-random and non-zero (so no multiplier is zero and no row is
    /// skipped), and compares them with the formulas.
    fn check_lu_op_counts<const N: usize, const M: usize>(seed: &mut u64) {
        let mut next = || {
            *seed ^= *seed << 13;
            *seed ^= *seed >> 7;
            *seed ^= *seed << 17;
            // In ±[0.5, 1.5): never zero.
            let u = (*seed >> 11) as f64 / (1u64 << 53) as f64;
            if u < 0.5 {
                -(1.0 + u)
            } else {
                u
            }
        };
        let mut a = [[Counted(0.0); N]; N];
        for x in a.as_flattened_mut() {
            *x = Counted(next());
        }
        let mut b = [[Counted(0.0); M]; N];
        for x in b.as_flattened_mut() {
            *x = Counted(next());
        }
        take_counts();

        let mut factors = a;
        let swaps = lu_factor(&mut factors, max_abs(&b)).unwrap();
        let factor = take_counts();
        for row in 1..N {
            for col in 0..row {
                assert_ne!(factors[row][col].0, 0.0, "a zero multiplier skips a row");
            }
        }
        let mut x = b;
        lu_substitute(&factors, &swaps, &mut x);
        let substitute = take_counts();
        let (mut a2, mut x2) = (a, b);
        lu_solve(&mut a2, &mut x2).unwrap();
        let solve = take_counts();

        assert_eq!(factor, (lu_factor_ops(N), 0), "lu_factor, n = {N}");
        assert_eq!(
            substitute,
            (lu_substitute_ops(N, M), 0),
            "lu_substitute, n = {N}, {M} columns"
        );
        assert_eq!(
            solve,
            (lu_solve_ops(N, M), 0),
            "lu_solve, n = {N}, {M} columns"
        );
        // The counted solve is a solve.
        for i in 0..N {
            for j in 0..M {
                let r: f64 = (0..N).map(|k| a[i][k].0 * x[k][j].0).sum::<f64>() - b[i][j].0;
                assert!(r.abs() < 1e-9, "residual {r}");
            }
        }
    }

    #[test]
    fn lu_op_counts_are_the_operations_performed() {
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        macro_rules! sizes {
            ($($n:literal)*) => {$(
                check_lu_op_counts::<$n, 1>(&mut seed);
                check_lu_op_counts::<$n, 2>(&mut seed);
                check_lu_op_counts::<$n, 3>(&mut seed);
                check_lu_op_counts::<$n, 5>(&mut seed);
            )*};
        }
        sizes!(1 2 3 4 5 6);
        assert_eq!((lu_factor_ops(0), lu_substitute_ops(0, 3)), (0, 0));
        assert_eq!(lu_substitute_ops(4, 0), 0);

        // Zero multipliers skip rows: the formulas are then upper bounds.
        let mut a = [[Counted(0.0); 4]; 4];
        for i in 0..4 {
            a[i][i] = Counted(2.0);
        }
        take_counts();
        let swaps = lu_factor(&mut a, 1.0).unwrap();
        let (factor, _) = take_counts();
        let mut b = [[Counted(1.0); 2]; 4];
        lu_substitute(&a, &swaps, &mut b);
        let (substitute, _) = take_counts();
        assert!(factor < lu_factor_ops(4) && substitute < lu_substitute_ops(4, 2));
    }

    #[test]
    fn scales_read_every_entry_and_report_non_finite_ones() {
        // Seven entries (an odd count at every level of the pairwise
        // reduction), the largest in each position in turn.
        let entries = [0.5, -0.25, 0.125, 1.0, -2.0, 0.75, 1.5];
        for k in 0..7 {
            let rest = (0..7)
                .filter(|&j| j != k)
                .map(|j| f64::abs(entries[j]))
                .fold(0.0, f64::max);
            let mut a = [entries];
            a[0][k] = -9.0;
            assert_eq!(constraint_scale(&a, 3.0), Ok(9.0));
            assert_eq!(max_abs(&a), 9.0);
            a[0][k] = f64::INFINITY;
            assert!(constraint_scale(&a, 3.0).is_err());
            assert_eq!(max_abs(&a), rest);
            a[0][k] = f64::NAN;
            assert!(constraint_scale(&a, 3.0).is_err());
            assert_eq!(max_abs(&a), rest);
        }
        assert_eq!(constraint_scale(&[[1.0]], f64::NAN), Ok(1.0));
        assert_eq!(constraint_scale(&[[1.0]], f64::INFINITY), Ok(1.0));
        assert_eq!(max_abs::<f64, 0, 3>(&[]), 0.0);
    }

    #[test]
    fn every_row_exchange_is_applied() {
        // Pivots found in each later row in turn: the largest entry of the
        // first column moves through all three rows.
        for big in 0..3 {
            let mut a = [[1.0, 2.0, 0.5], [0.25, 1.0, 3.0], [2.0, -1.0, 1.0]];
            a[big][0] = 10.0;
            let a0 = a;
            let mut b = [[1.0], [2.0], [3.0]];
            lu_solve(&mut a, &mut b).unwrap();
            for i in 0..3 {
                let r: f64 = (0..3).map(|k| a0[i][k] * b[k][0]).sum::<f64>() - (i + 1) as f64;
                assert!(r.abs() < 1e-14, "row {big}: residual {r}");
            }
        }
    }

    #[test]
    fn lu_matches_a_known_solution() {
        let mut a = [[2.0, 1.0, 1.0], [4.0, -6.0, 0.0], [-2.0, 7.0, 2.0]];
        let mut b = [[5.0, 1.0], [-2.0, 0.0], [9.0, 0.0]];
        let a0 = a;
        let b0 = b;
        lu_solve(&mut a, &mut b).unwrap();
        for j in 0..2 {
            for i in 0..3 {
                let r: f64 = (0..3).map(|k| a0[i][k] * b[k][j]).sum::<f64>() - b0[i][j];
                assert!(r.abs() < 1e-13);
            }
        }
    }

    #[test]
    fn lu_pivot_is_judged_against_the_whole_system() {
        // 1×1 D' = cos(π/2) ≈ 6e-17 beside a right side of order 1.
        let mut a = [[std::f64::consts::FRAC_PI_2.cos()]];
        let mut b = [[1.0, 0.0]];
        assert!(matches!(
            lu_solve(&mut a, &mut b),
            Err(ModelError::SingularConstraints { column: 0, .. })
        ));
    }

    #[test]
    fn lu_rejects_nan() {
        let mut a = [[f64::NAN]];
        let mut b = [[1.0]];
        assert_eq!(
            lu_solve(&mut a, &mut b),
            Err(ModelError::NonFinite {
                what: "the constraint matrix"
            })
        );
    }

    #[test]
    fn ldlt_rejects_indefinite() {
        let m = [[1.0, 0.0], [0.0, -1.0]];
        assert!(matches!(
            ldlt_solve(&m, &[1.0, 1.0]),
            Err(ModelError::SingularMassMatrix { index: 1, .. })
        ));
    }

    #[test]
    fn ldlt_three_by_three() {
        let m = [[4.0, 1.0, 0.5], [1.0, 3.0, 0.2], [0.5, 0.2, 2.0]];
        let f = [1.0, 2.0, 3.0];
        let x = ldlt_solve(&m, &f).unwrap();
        for i in 0..3 {
            let r: f64 = (0..3).map(|k| m[i][k] * x[k]).sum::<f64>() - f[i];
            assert!(r.abs() < 1e-14);
        }
    }

    #[test]
    fn factored_solves_match_the_one_shot_solve_with_row_exchanges() {
        // Matrices whose pivots need exchanges at every step, and two right
        // sides solved one after the other from one factorization.
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        for _ in 0..200 {
            let mut a = [[0.0; 4]; 4];
            for (i, row) in a.iter_mut().enumerate() {
                for (j, x) in row.iter_mut().enumerate() {
                    // Small diagonal, large entries below it: partial
                    // pivoting must exchange rows.
                    *x = if i == j {
                        1e-3 * next()
                    } else {
                        next() * (1.0 + i as f64)
                    };
                }
            }
            let b = [
                [next(), next()],
                [next(), next()],
                [next(), next()],
                [next(), next()],
            ];
            let (mut a1, mut x1) = (a, b);
            lu_solve(&mut a1, &mut x1).unwrap();
            let mut f = a;
            let swaps = lu_factor(&mut f, max_abs(&b)).unwrap();
            let mut x2 = b;
            lu_substitute(&f, &swaps, &mut x2);
            let mut c = [[b[0][1]], [b[1][1]], [b[2][1]], [b[3][1]]];
            lu_substitute(&f, &swaps, &mut c);
            for i in 0..4 {
                for j in 0..2 {
                    let r: f64 = (0..4).map(|k| a[i][k] * x2[k][j]).sum::<f64>() - b[i][j];
                    assert!(r.abs() < 1e-11, "residual {r}");
                    assert!((x2[i][j] - x1[i][j]).abs() <= 1e-11 * (1.0 + x1[i][j].abs()));
                }
                assert_eq!(c[i][0], x2[i][1]);
            }
        }
    }

    #[test]
    fn factor_reports_singular_and_non_finite() {
        let mut s = [[1.0, 2.0], [2.0, 4.0]];
        assert!(matches!(
            lu_factor(&mut s, 1.0),
            Err(ModelError::SingularConstraints { column: 1, .. })
        ));
        let mut n = [[f64::INFINITY, 0.0], [0.0, 1.0]];
        assert!(matches!(
            lu_factor(&mut n, 1.0),
            Err(ModelError::NonFinite { .. })
        ));
    }
}
