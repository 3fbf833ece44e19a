//! Whether a link's `<inertial>` can be a rigid body's: a positive mass and
//! a central inertia that is positive definite and obeys the triangle
//! inequality (each principal moment at most the sum of the other two).
//!
//! Both matrix conditions are positivity tests, by principal minors, with
//! no eigenvalues: I is positive definite, and the second-moment matrix
//! S = tr(I)/2 · 1 − I (whose eigenvalues are (λⱼ + λₖ − λᵢ)/2, the
//! ∫x² dm of the principal axes) is positive semidefinite.

/// What a link's inertial describes.
#[derive(Debug, PartialEq)]
pub(super) enum Mass {
    /// No mass and no inertia: a frame, not a body.
    None,
    /// A body.
    Body,
}

/// The inertia matrix from the URDF's six numbers.
fn matrix(i: &urdf_rs::Inertia) -> [[f64; 3]; 3] {
    [
        [i.ixx, i.ixy, i.ixz],
        [i.ixy, i.iyy, i.iyz],
        [i.ixz, i.iyz, i.izz],
    ]
}

/// Checks a link's mass and inertia as written; `Err` says what is wrong.
/// A zero inertia with a positive mass is a point mass, and allowed.
pub(super) fn check(mass: f64, inertia: &urdf_rs::Inertia) -> Result<Mass, String> {
    let m = matrix(inertia);
    let entries = m.iter().flatten();
    if !mass.is_finite() || entries.clone().any(|x| !x.is_finite()) {
        return Err("its mass or inertia is not a finite number".into());
    }
    let zero = entries.clone().all(|x| *x == 0.0);
    if mass < 0.0 {
        return Err(format!("its mass {mass} is negative"));
    }
    if mass == 0.0 {
        return if zero {
            Ok(Mass::None)
        } else {
            Err("its mass is zero but its inertia is not: a body needs a positive mass".into())
        };
    }
    if zero {
        return Ok(Mass::Body);
    }
    check_matrix(&m)?;
    Ok(Mass::Body)
}

/// Checks a central inertia matrix alone (the mass is a parameter).
pub(super) fn check_matrix(m: &[[f64; 3]; 3]) -> Result<(), String> {
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

    fn inertia(ixx: f64, iyy: f64, izz: f64, ixy: f64, iyz: f64, ixz: f64) -> urdf_rs::Inertia {
        urdf_rs::Inertia {
            ixx,
            iyy,
            izz,
            ixy,
            iyz,
            ixz,
        }
    }

    #[test]
    fn real_links_pass() {
        // The UR5's wrist (izz close to ixx + iyy) and a Panda link.
        assert_eq!(
            check(
                1.219,
                &inertia(0.111172755531, 0.111172755531, 0.21942, 0.0, 0.0, 0.0)
            ),
            Ok(Mass::Body)
        );
        assert_eq!(
            check(
                4.970684,
                &inertia(0.70337, 0.70661, 0.009117, -0.000139, 0.019169, 0.006772)
            ),
            Ok(Mass::Body)
        );
        assert_eq!(
            check(0.0, &inertia(0.0, 0.0, 0.0, 0.0, 0.0, 0.0)),
            Ok(Mass::None)
        );
        assert_eq!(
            check(2.0, &inertia(0.0, 0.0, 0.0, 0.0, 0.0, 0.0)),
            Ok(Mass::Body)
        );
    }

    #[test]
    fn bad_inertials_fail() {
        let e = check(-1.0, &inertia(1.0, 1.0, 1.0, 0.0, 0.0, 0.0)).unwrap_err();
        assert!(e.contains("negative"), "{e}");
        let e = check(0.0, &inertia(1.0, 1.0, 1.0, 0.0, 0.0, 0.0)).unwrap_err();
        assert!(e.contains("zero"), "{e}");
        let e = check(1.0, &inertia(1.0, 1.0, 1.0, 2.0, 0.0, 0.0)).unwrap_err();
        assert!(e.contains("not positive definite"), "{e}");
        let e = check(1.0, &inertia(1.0, 1.0, 3.0, 0.0, 0.0, 0.0)).unwrap_err();
        assert!(e.contains("triangle"), "{e}");
        // Positive definite, but off-diagonal terms make a principal moment
        // too large: eigenvalues of [[1, .9, 0], [.9, 1, 0], [0, 0, .15]]
        // are 1.9, 0.1, 0.15.
        let e = check(1.0, &inertia(1.0, 1.0, 0.15, 0.9, 0.0, 0.0)).unwrap_err();
        assert!(e.contains("triangle"), "{e}");
    }
}
