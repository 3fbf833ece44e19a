//! Whether a rigid body's inertia can be physical: positive definite and
//! obeying the triangle inequality (each principal moment at most the sum
//! of the other two). Used on URDF inertials and on the constant inertias
//! a model writes.
//!
//! Both conditions are positivity tests, by principal minors, with no
//! eigenvalues: I is positive definite, and the second-moment matrix
//! S = tr(I)/2 · 1 − I (whose eigenvalues are (λⱼ + λₖ − λᵢ)/2, the
//! ∫x² dm of the principal axes) is positive semidefinite.

/// Checks a central inertia matrix (a zero one, a point mass, passes);
/// `Err` says which rule it breaks.
pub(crate) fn check_matrix(m: &[[f64; 3]; 3]) -> Result<(), String> {
    let scale = m.iter().flatten().fold(0.0f64, |a, x| a.max(x.abs()));
    if scale == 0.0 {
        return Ok(());
    }
    // Relative tolerances for rounding in the file's last digit.
    let tol = |order: i32| 1e-9 * scale.powi(order);
    if !positive_definite(m, &tol) {
        return Err(format!(
            "its inertia (ixx {}, iyy {}, izz {}, ixy {}, iyz {}, ixz {}) is not positive definite",
            m[0][0], m[1][1], m[2][2], m[0][1], m[1][2], m[0][2]
        ));
    }
    let half = (m[0][0] + m[1][1] + m[2][2]) / 2.0;
    let mut s = [[0.0; 3]; 3];
    for r in 0..3 {
        for c in 0..3 {
            s[r][c] = if r == c { half - m[r][c] } else { -m[r][c] };
        }
    }
    if !semidefinite(&s, &tol) {
        return Err(format!(
            "its inertia (ixx {}, iyy {}, izz {}, ixy {}, iyz {}, ixz {}) violates the triangle inequality: a principal moment exceeds the sum of the other two",
            m[0][0], m[1][1], m[2][2], m[0][1], m[1][2], m[0][2]
        ));
    }
    Ok(())
}

/// 2×2 principal minor of rows and columns a, b.
fn minor(m: &[[f64; 3]; 3], a: usize, b: usize) -> f64 {
    m[a][a] * m[b][b] - m[a][b] * m[b][a]
}

fn det(m: &[[f64; 3]; 3]) -> f64 {
    m[0][0] * minor(m, 1, 2) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
}

/// Sylvester's criterion: the leading principal minors are positive.
fn positive_definite(m: &[[f64; 3]; 3], tol: &dyn Fn(i32) -> f64) -> bool {
    m[0][0] > tol(1) && minor(m, 0, 1) > tol(2) && det(m) > tol(3)
}

/// Every principal minor is non-negative.
fn semidefinite(m: &[[f64; 3]; 3], tol: &dyn Fn(i32) -> f64) -> bool {
    (0..3).all(|k| m[k][k] >= -tol(1))
        && [(0, 1), (0, 2), (1, 2)]
            .iter()
            .all(|&(a, b)| minor(m, a, b) >= -tol(2))
        && det(m) >= -tol(3)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rules() {
        let diag = |a: f64, b: f64, c: f64| [[a, 0.0, 0.0], [0.0, b, 0.0], [0.0, 0.0, c]];
        assert_eq!(check_matrix(&diag(1.0, 1.0, 2.0)), Ok(()));
        assert_eq!(check_matrix(&diag(0.0, 0.0, 0.0)), Ok(()));
        let e = check_matrix(&diag(1.0, 1.0, 5.0)).unwrap_err();
        assert!(e.contains("triangle"), "{e}");
        let e = check_matrix(&diag(1.0, -1.0, 1.0)).unwrap_err();
        assert!(e.contains("not positive definite"), "{e}");
    }
}
