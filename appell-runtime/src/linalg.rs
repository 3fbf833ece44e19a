//! Small dense solves on fixed-size arrays, generic over the scalar, with no
//! allocation. The generated code calls them for Appell's mass matrix (when
//! it is not small enough to unroll) and for the dependent-speed block D'
//! when a symbolic elimination could not be proven safe.
//!
//! Singular systems are reported as [`ModelError`]s, never as NaN.

// Index loops mirror the textbook elimination formulas (rows, columns,
// pivots); iterator chains would hide which entry is which.
#![allow(clippy::needless_range_loop)]

use crate::model::ModelError;
use crate::scalar::Scalar;

/// Solves `A X = B` in place by LU with partial pivoting: on success `b`
/// holds `X`. A pivot smaller than `1e-12 ×` the largest entry of `A` and `B`
/// in magnitude is reported as [`ModelError::SingularConstraints`] (the use
/// this solve has in generated code, where `A` is the dependent block D' and
/// `B` holds −D'' and −d: a pivot is negligible relative to the whole
/// constraint matrix, not only to D').
///
/// ```
/// use appell_runtime::linalg::lu_solve;
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
    let mut scale = 0.0f64;
    for row in a.iter() {
        for x in row {
            let v = x.re().abs();
            if !v.is_finite() {
                return Err(ModelError::NonFinite {
                    what: "the constraint matrix",
                });
            }
            scale = scale.max(v);
        }
    }
    for row in b.iter() {
        for x in row {
            let v = x.re().abs();
            if v.is_finite() {
                scale = scale.max(v);
            }
        }
    }
    let tol = 1e-12 * scale;
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
        if best <= tol || best == 0.0 {
            return Err(ModelError::SingularConstraints {
                column: col,
                pivot: best,
            });
        }
        a.swap(p, col);
        b.swap(p, col);
        let inv = T::one() / a[col][col];
        for r in col + 1..N {
            let f = a[r][col] * inv;
            if f.re() == 0.0 {
                continue;
            }
            for j in col..N {
                let t = a[col][j];
                a[r][j] -= f * t;
            }
            for j in 0..M {
                let t = b[col][j];
                b[r][j] -= f * t;
            }
        }
    }
    for col in (0..N).rev() {
        let inv = T::one() / a[col][col];
        for j in 0..M {
            let mut s = b[col][j];
            for k in col + 1..N {
                s -= a[col][k] * b[k][j];
            }
            b[col][j] = s * inv;
        }
    }
    Ok(())
}

/// Solves `M x = f` for a symmetric positive definite `M` by an LDLᵀ
/// factorization; a pivot that is not positive (relative to the diagonal's
/// scale) is reported as [`ModelError::SingularMassMatrix`].
///
/// ```
/// use appell_runtime::linalg::ldlt_solve;
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

#[cfg(test)]
mod tests {
    use super::*;

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
}
