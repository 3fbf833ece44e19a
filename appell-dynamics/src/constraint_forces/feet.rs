//! The ground's reaction on each foot a scene holds
//! (`contact(link, point | flat)`): the force at the link's origin and, on
//! a flat foot, the moment about it, with the friction the foot needs and a
//! flat foot's centre of pressure.
//!
//! A foot's rows hold its origin's velocity along N.x, N.y and N.z (and a
//! flat foot's angular velocity about them), so each row's multiplier is
//! the ground's force (moment) on the link along that axis: the foot's
//! force is its rows' multipliers, gathered by axis. The ground is the
//! plane normal to N.z.

use super::{norm, Friction};
use crate::oracle::{finite_all as finite, OracleError};
use appell_core::dynamic::DynModel;
use appell_core::RowSource;

/// The ground's reaction on one foot held by the model or scene (see
/// [`ConstraintForces::feet`](super::ConstraintForces::feet)).
#[derive(Clone, Debug, PartialEq)]
pub struct FootForce {
    /// Index into [`Model::contact_links`](appell_core::Model::contact_links).
    pub contact: usize,
    /// The foot's link.
    pub link: &'static str,
    /// The link's origin, N components.
    pub position: [f64; 3],
    /// The force on the link at its origin, N components (zero along an
    /// axis whose row was dropped as identically zero).
    pub force: [f64; 3],
    /// A flat foot's moment on the link about its origin, N components;
    /// `None` for a point foot.
    pub moment: Option<[f64; 3]>,
}

impl FootForce {
    /// The friction coefficient the foot needs not to slip: |F_t| / F_z,
    /// with F_t the force's part along the ground (N.x and N.y);
    /// [`Friction::LiftOff`] when the ground does not push (F_z ≤ 0).
    ///
    /// ```
    /// use appell_dynamics::constraint_forces::{FootForce, Friction};
    /// let foot = FootForce {
    ///     contact: 0,
    ///     link: "FL_FOOT",
    ///     position: [0.2, 0.1, 0.0],
    ///     force: [3.0, -4.0, 25.0],
    ///     moment: None,
    /// };
    /// assert!(matches!(foot.friction(), Friction::Required { mu, .. } if mu == 0.2));
    /// ```
    pub fn friction(&self) -> Friction {
        Friction::of(self.force[2], norm([self.force[0], self.force[1], 0.0]))
    }

    /// A flat foot's centre of pressure on the ground plane at height
    /// `ground` along N.z: the point of that plane about which the
    /// reaction's moment has no component along the plane. `None` for a
    /// point foot, where the ground does not push (F_z ≤ 0), or where the
    /// point overflows. It lies inside the sole exactly when the foot does
    /// not tip over its edge.
    ///
    /// ```
    /// use appell_dynamics::constraint_forces::FootForce;
    /// // 100 N pushing straight up at (0.05, 0, 0), an ankle 0.1 above it
    /// // at (0, 0, 0.1): the moment about the ankle is (0, -5, 0).
    /// let foot = FootForce {
    ///     contact: 0,
    ///     link: "left_ankle",
    ///     position: [0.0, 0.0, 0.1],
    ///     force: [0.0, 0.0, 100.0],
    ///     moment: Some([0.0, -5.0, 0.0]),
    /// };
    /// let p = foot.center_of_pressure(0.0).unwrap();
    /// assert!((p[0] - 0.05).abs() < 1e-15 && p[1].abs() < 1e-15 && p[2] == 0.0);
    /// ```
    pub fn center_of_pressure(&self, ground: f64) -> Option<[f64; 3]> {
        let m = self.moment?;
        let (f, o) = (self.force, self.position);
        if f[2].is_nan() || f[2] <= 0.0 {
            return None;
        }
        // The moment about p = (x, y, ground) is m + (o - p) × f; its N.x
        // and N.y components vanish for these offsets r = o - p.
        let rz = o[2] - ground;
        let rx = (m[1] + rz * f[0]) / f[2];
        let ry = (rz * f[1] - m[0]) / f[2];
        let p = [o[0] - rx, o[1] - ry, ground];
        p.iter().all(|x| x.is_finite()).then_some(p)
    }
}

/// A foot's force and, on a flat foot, moment.
type Wrench = ([f64; 3], Option<[f64; 3]>);

/// The feet the model's rows hold, in [`DynModel::dyn_contact_links`]
/// order, from the rows' `multipliers`.
pub(super) fn foot_forces<K: DynModel + ?Sized>(
    model: &K,
    t: f64,
    q: &[f64],
    multipliers: &[f64],
) -> Result<Vec<FootForce>, OracleError> {
    let info = model.dyn_info();
    let links = model.dyn_contact_links();
    let mut held: Vec<Option<Wrench>> = vec![None; links.len()];
    for (src, &lambda) in info.row_sources.iter().zip(multipliers) {
        let RowSource::Contact { contact, axis } = *src else {
            continue;
        };
        let invalid = || {
            OracleError::InvalidInfo(format!(
                "a contact row names axis {axis} of contact {contact} of {}",
                links.len()
            ))
        };
        let (force, moment) = held
            .get_mut(contact)
            .ok_or_else(invalid)?
            .get_or_insert(([0.0; 3], None));
        match axis {
            0..=2 => force[axis] += lambda,
            3..=5 => moment.get_or_insert([0.0; 3])[axis - 3] += lambda,
            _ => return Err(invalid()),
        }
    }
    if held.iter().all(Option::is_none) {
        return Ok(Vec::new());
    }
    let mut points = vec![[0.0; 3]; links.len()];
    model.dyn_contact_points(t, q, &mut points)?;
    finite(points.iter().flatten().copied(), "the feet's positions")?;
    Ok(held
        .into_iter()
        .enumerate()
        .filter_map(|(c, h)| {
            h.map(|(force, moment)| FootForce {
                contact: c,
                link: links[c],
                position: points[c],
                force,
                moment,
            })
        })
        .collect())
}
