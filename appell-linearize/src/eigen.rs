//! The complex eigenvalues of a real square matrix, sorted.

use super::error::LinearizeError;
use nalgebra::DMatrix;

/// The eigenvalues `(re, im)` of a real square matrix, by nalgebra's real
/// Schur decomposition, sorted by real part, then imaginary part (a complex
/// pair appears as `(re, −im)`, `(re, im)`; a zero imaginary part is `+0.0`).
///
/// Errors: [`LinearizeError::NotSquare`], [`LinearizeError::NonFinite`] for a
/// NaN or infinite entry, and [`LinearizeError::DecompositionFailed`] if the
/// Schur iteration does not converge (within `100 n` iterations).
///
/// ```
/// use appell_linearize::eigenvalues;
/// use nalgebra::DMatrix;
///
/// // The undamped oscillator ẍ = −4 x: ±2i.
/// let a = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, -4.0, 0.0]);
/// let eig = eigenvalues(&a).unwrap();
/// assert!(eig[0].0.abs() < 1e-15 && (eig[0].1 + 2.0).abs() < 1e-15);
/// assert!(eig[1].0.abs() < 1e-15 && (eig[1].1 - 2.0).abs() < 1e-15);
///
/// // Triangular: the diagonal, sorted.
/// let t = DMatrix::from_row_slice(3, 3, &[3.0, 1.0, 2.0, 0.0, -1.0, 5.0, 0.0, 0.0, 0.5]);
/// let re: Vec<f64> = eigenvalues(&t).unwrap().iter().map(|e| e.0).collect();
/// assert_eq!(re, [-1.0, 0.5, 3.0]);
///
/// assert!(eigenvalues(&DMatrix::<f64>::zeros(2, 3)).is_err());
/// assert!(eigenvalues(&DMatrix::from_element(2, 2, f64::NAN)).is_err());
/// ```
pub fn eigenvalues(a: &DMatrix<f64>) -> Result<Vec<(f64, f64)>, LinearizeError> {
    let (rows, cols) = a.shape();
    if rows != cols {
        return Err(LinearizeError::NotSquare { rows, cols });
    }
    if !a.iter().all(|x| x.is_finite()) {
        return Err(LinearizeError::NonFinite { what: "the matrix" });
    }
    if rows == 0 {
        return Ok(Vec::new());
    }
    let schur = nalgebra::Schur::try_new(a.clone(), f64::EPSILON, 100 * rows)
        .ok_or(LinearizeError::DecompositionFailed { what: "Schur" })?;
    // −0.0 → +0.0, so the order does not depend on the sign of a zero.
    let clean = |x: f64| if x == 0.0 { 0.0 } else { x };
    let mut out: Vec<(f64, f64)> = schur
        .complex_eigenvalues()
        .iter()
        .map(|z| (clean(z.re), clean(z.im)))
        .collect();
    if !out.iter().all(|(re, im)| re.is_finite() && im.is_finite()) {
        return Err(LinearizeError::NonFinite {
            what: "an eigenvalue",
        });
    }
    out.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.total_cmp(&y.1)));
    Ok(out)
}
