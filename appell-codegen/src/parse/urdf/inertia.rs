//! Whether a link's `<inertial>` can be a rigid body's: a positive mass and
//! a central inertia that [`crate::physical`] accepts.

pub(super) use crate::physical::check_matrix;

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
        assert!(e.contains("not positive semidefinite"), "{e}");
        let e = check(1.0, &inertia(1.0, 1.0, 3.0, 0.0, 0.0, 0.0)).unwrap_err();
        assert!(e.contains("triangle"), "{e}");
        // Positive definite, but off-diagonal terms make a principal moment
        // too large: eigenvalues of [[1, .9, 0], [.9, 1, 0], [0, 0, .15]]
        // are 1.9, 0.1, 0.15.
        let e = check(1.0, &inertia(1.0, 1.0, 0.15, 0.9, 0.0, 0.0)).unwrap_err();
        assert!(e.contains("triangle"), "{e}");
    }
}
