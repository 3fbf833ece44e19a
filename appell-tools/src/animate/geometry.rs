//! What is drawn, in N: each body's centre and equivalent inertia
//! ellipsoid, each contact point, at every frame; and the projection of
//! N onto the picture.

use nalgebra::{Matrix2, Matrix3, SymmetricEigen, Vector3};

use super::Frame;
use appell_core::dynamic::DynModel;
use appell_core::ModelError;

/// A body at one frame, in N.
#[derive(Clone, Copy, Debug)]
pub(super) struct Pose {
    /// The mass centre.
    pub centre: [f64; 3],
    /// The ellipsoid's semi-axes as columns (N components): R V diag(a).
    /// Zero for a particle.
    pub axes: Matrix3<f64>,
}

/// Every body's pose and every contact point at every frame.
pub(super) struct Scene {
    /// `poses[frame][body]`.
    pub poses: Vec<Vec<Pose>>,
    /// `contacts[frame][contact]`.
    pub contacts: Vec<Vec<[f64; 3]>>,
    /// Whether each body is rigid (else a particle).
    pub rigid: Vec<bool>,
}

/// The semi-axes (body frame, as columns) of the uniform solid ellipsoid
/// with mass `m` and central inertia `inertia` (row-major): along each
/// principal axis, a_i² = 5 (I_j + I_k − I_i) / (2 m).
pub(super) fn ellipsoid(m: f64, inertia: &[f64; 9]) -> Matrix3<f64> {
    let i = Matrix3::from_row_slice(inertia);
    let sym = (i + i.transpose()) * 0.5;
    let eig = SymmetricEigen::new(sym);
    let l = eig.eigenvalues;
    let mut out = eig.eigenvectors;
    for k in 0..3 {
        let (a, b) = ((k + 1) % 3, (k + 2) % 3);
        let squared = 5.0 * (l[a] + l[b] - l[k]) / (2.0 * m);
        let semi = if m > 0.0 && squared > 0.0 {
            squared.sqrt()
        } else {
            0.0
        };
        let mut column = out.column_mut(k);
        column *= semi;
    }
    out
}

/// Evaluates the model's geometry at every frame.
pub(super) fn scene<K: DynModel + ?Sized>(
    model: &K,
    frames: &[Frame],
) -> Result<Scene, ModelError> {
    let info = model.dyn_info();
    let nb = info.bodies.len();
    let mut masses = vec![0.0; nb];
    let mut inertias = vec![[0.0; 9]; nb];
    model.dyn_mass_properties(&mut masses, &mut inertias)?;
    let rigid: Vec<bool> = info.bodies.iter().map(|b| b.rigid).collect();
    let mut shapes: Vec<Matrix3<f64>> = (0..nb)
        .map(|b| match rigid[b] {
            true => ellipsoid(masses[b], &inertias[b]),
            false => Matrix3::zeros(),
        })
        .collect();
    let mut poses = Vec::with_capacity(frames.len());
    let mut contacts = Vec::with_capacity(frames.len());
    let mut positions = vec![[0.0; 3]; nb];
    let mut rotations = vec![[0.0; 9]; nb];
    let mut points = vec![[0.0; 3]; info.contacts.len()];
    let mut directions = vec![[0.0; 3]; info.constraints];
    // A rolling body's size is its rolling radius (the centre's distance
    // from the contact): the inertia says only how the mass spreads.
    if let (Some(f), false) = (frames.first(), points.is_empty()) {
        model.dyn_body_poses(f.t, &f.q, &mut positions, &mut rotations)?;
        model.dyn_contact_geometry(f.t, &f.q, &mut points, &mut directions)?;
        for (c, contact) in info.contacts.iter().enumerate() {
            let b = contact.body;
            let radius = distance(&points[c], &positions[b]);
            let largest = (0..3)
                .map(|k| shapes[b].column(k).norm())
                .fold(0.0, f64::max);
            if largest > 0.0 && radius > 0.0 {
                shapes[b] *= radius / largest;
            }
        }
    }
    for f in frames {
        model.dyn_body_poses(f.t, &f.q, &mut positions, &mut rotations)?;
        let at: Vec<Pose> = (0..nb)
            .map(|b| Pose {
                centre: positions[b],
                axes: Matrix3::from_row_slice(&rotations[b]) * shapes[b],
            })
            .collect();
        poses.push(at);
        if !points.is_empty() {
            model.dyn_contact_geometry(f.t, &f.q, &mut points, &mut directions)?;
        }
        contacts.push(points.clone());
    }
    Ok(Scene {
        poses,
        contacts,
        rigid,
    })
}

pub(super) fn distance(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    (0..3).map(|k| (a[k] - b[k]).powi(2)).sum::<f64>().sqrt()
}

/// An orthographic projection of N onto the picture: screen right and
/// screen up as unit vectors in N.
#[derive(Clone, Copy, Debug)]
pub(super) struct Projection {
    pub right: Vector3<f64>,
    pub up: Vector3<f64>,
    /// The N axis looked along; None for the oblique view.
    pub along: Option<usize>,
}

impl Projection {
    /// Looking along N's axis `k` (the picture is the plane of the other
    /// two, in cyclic order: along z shows x right and y up).
    pub fn along(k: usize) -> Projection {
        let mut right = Vector3::zeros();
        let mut up = Vector3::zeros();
        right[(k + 1) % 3] = 1.0;
        up[(k + 2) % 3] = 1.0;
        Projection {
            right,
            up,
            along: Some(k),
        }
    }

    /// An oblique view from azimuth 30° and 25° above the horizontal, with
    /// `up` (N components) pointing up the picture: for z up, from 30° off
    /// −y, x to the right.
    pub fn oblique(up: [f64; 3]) -> Projection {
        let u = Vector3::from(up)
            .try_normalize(1e-12)
            .unwrap_or(Vector3::z());
        let k = (0..3)
            .min_by(|&a, &b| u[a].abs().total_cmp(&u[b].abs()))
            .unwrap_or(0);
        let h1 = (Vector3::ith(k, 1.0) - u * u[k]).normalize();
        let h2 = u.cross(&h1);
        let (az, el) = (30f64.to_radians(), 25f64.to_radians());
        let eye = h1 * (az.sin() * el.cos()) - h2 * (az.cos() * el.cos()) + u * el.sin();
        let right = (-eye).cross(&u).normalize();
        let up = right.cross(&(-eye));
        Projection {
            right,
            up,
            along: None,
        }
    }

    /// The picture coordinates (right, up) of a point.
    pub fn point(&self, p: &[f64; 3]) -> [f64; 2] {
        let v = Vector3::new(p[0], p[1], p[2]);
        [self.right.dot(&v), self.up.dot(&v)]
    }

    /// The ellipse an ellipsoid projects to: its semi-axes (major first)
    /// and the major axis' angle from screen right, counter-clockwise.
    pub fn ellipse(&self, axes: &Matrix3<f64>) -> (f64, f64, f64) {
        let rows = nalgebra::Matrix2x3::from_rows(&[self.right.transpose(), self.up.transpose()]);
        let pl = rows * axes;
        let s: Matrix2<f64> = pl * pl.transpose();
        let eig = SymmetricEigen::new(s);
        let (i, j) = if eig.eigenvalues[0] >= eig.eigenvalues[1] {
            (0, 1)
        } else {
            (1, 0)
        };
        let major = eig.eigenvalues[i].max(0.0).sqrt();
        let minor = eig.eigenvalues[j].max(0.0).sqrt();
        let v = eig.eigenvectors.column(i);
        (major, minor, v[1].atan2(v[0]))
    }
}

/// The view: along the N axis the body centres do not move along (a
/// planar motion), else oblique.
pub(super) fn auto_projection(scene: &Scene, up: [f64; 3]) -> Projection {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in scene.poses.iter().flatten() {
        for k in 0..3 {
            lo[k] = lo[k].min(p.centre[k]);
            hi[k] = hi[k].max(p.centre[k]);
        }
    }
    let span: Vec<f64> = (0..3).map(|k| (hi[k] - lo[k]).max(0.0)).collect();
    let largest = span.iter().copied().fold(0.0, f64::max);
    match (0..3).find(|&k| span[k] <= 1e-9 * largest.max(1e-300)) {
        Some(k) => Projection::along(k),
        None => Projection::oblique(up),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_thin_discs_ellipsoid_is_flat_with_a_radius_near_its_own() {
        // A disc of mass 2 and radius 0.3 about its y axis.
        let (m, r) = (2.0, 0.3);
        let i = m * r * r / 4.0;
        let axes = ellipsoid(m, &[i, 0.0, 0.0, 0.0, 2.0 * i, 0.0, 0.0, 0.0, i]);
        let lengths: Vec<f64> = (0..3).map(|k| axes.column(k).norm()).collect();
        let mut sorted = lengths.clone();
        sorted.sort_by(f64::total_cmp);
        assert!(sorted[0] < 1e-12, "{lengths:?}");
        // a² = 5 (2 I) / (2 m) = 5 r² / 4.
        assert!((sorted[2] - (1.25f64).sqrt() * r).abs() < 1e-12);
    }

    #[test]
    fn a_sphere_projects_to_a_circle_in_every_view() {
        let axes = Matrix3::identity() * 0.5;
        let views = [
            Projection::along(2),
            Projection::along(0),
            Projection::oblique([0.0, 0.0, 1.0]),
            Projection::oblique([0.0, 0.0, -1.0]),
        ];
        for p in views {
            let (major, minor, _) = p.ellipse(&axes);
            assert!((major - 0.5).abs() < 1e-12 && (minor - 0.5).abs() < 1e-12);
        }
    }

    #[test]
    fn the_oblique_view_keeps_the_given_direction_up() {
        let p = Projection::oblique([0.0, 0.0, 1.0]);
        assert!(p.point(&[0.0, 0.0, 1.0])[1] > 0.9);
        assert!(p.right.z.abs() < 1e-15 && p.right.x > 0.8);
        // z down (the bicycle's convention): −z is up the picture.
        let down = Projection::oblique([0.0, 0.0, -1.0]);
        assert!(down.point(&[0.0, 0.0, -1.0])[1] > 0.9);
    }
}
