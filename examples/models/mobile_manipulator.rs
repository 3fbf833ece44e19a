//! A UR5 arm, read from its URDF, on a differential-drive base: the
//! mechanism no peer derives in closed form.

use appell::Appell;

/// A differential-drive base carrying the UR5.
///
/// The chassis moves in the plane (a planar joint `base`: `base_x`,
/// `base_y`, `base_angle`, made `dependent`), carried by two wheels of
/// radius `r` on an axle of half-track `w` that roll without slipping
/// (`left`, `right`, driven by `tau_left`, `tau_right`) and by a caster,
/// modelled as a frictionless support (the chassis stays level). The wheel
/// contacts give three constraints: both wheels roll along the chassis'
/// heading, and the axle does not slide sideways (one lateral row serves
/// both wheels). The UR5's root link is fixed at `Mount`, `h` above the
/// axle, and its joints bring their coordinates, speeds and torques
/// `tau_<joint>`.
///
/// The reduced equations keep the arm's six angles and eight speeds (the
/// wheels' and the arm's): the base's position and heading are cyclic and
/// the wheel angles ignorable, so they leave the state, and the three
/// contact rows are eliminated in closed form. M and f come from the
/// tree's recursions projected onto the eight speeds (`info().form`),
/// cheaper than Appell's closed form for this mechanism.
#[derive(Appell, Clone, Debug, PartialEq)]
#[appell(positive(r, w), gravity(-g * N.z))]
#[appell(
    joint(base, planar(z), parent = N, child = Chassis, xyz = [0, 0, r], dependent),
    joint(left, revolute(y), parent = Chassis, child = LeftWheel, xyz = [0, w, 0], actuated),
    joint(right, revolute(y), parent = Chassis, child = RightWheel, xyz = [0, -w, 0], actuated),
    point(LeftContact = LeftWheel_origin - r * N.z),
    point(RightContact = RightWheel_origin - r * N.z),
    point(Mount = Chassis_origin + h * Chassis.z)
)]
#[appell(
    body(chassis, center = Chassis_origin + c * Chassis.x + d * Chassis.z, frame = Chassis,
         mass = m_chassis, inertia = principal(ixx, iyy, izz)),
    body(left_wheel, center = LeftWheel_origin, frame = LeftWheel,
         mass = m_wheel, inertia = principal(i_wheel, 2 * i_wheel, i_wheel)),
    body(right_wheel, center = RightWheel_origin, frame = RightWheel,
         mass = m_wheel, inertia = principal(i_wheel, 2 * i_wheel, i_wheel)),
    rolls(left_wheel, contact = LeftContact, along = [Chassis.x, Chassis.y]),
    rolls(right_wheel, contact = RightContact, along = [Chassis.x])
)]
#[appell(urdf("examples/robots/ur5/ur5_robot.urdf", parent = Chassis, at = Mount))]
pub struct MobileManipulator {
    /// Wheel radius [m].
    pub r: f64,
    /// Half the distance between the wheels [m].
    pub w: f64,
    /// Height of the arm's mount above the axle [m].
    pub h: f64,
    /// Chassis mass centre ahead of the axle [m].
    pub c: f64,
    /// Chassis mass centre above the axle [m].
    pub d: f64,
    /// Chassis mass [kg].
    pub m_chassis: f64,
    /// Chassis central moments of inertia [kg m²].
    pub ixx: f64,
    /// About the chassis' y axis.
    pub iyy: f64,
    /// About the chassis' z axis.
    pub izz: f64,
    /// Wheel mass [kg].
    pub m_wheel: f64,
    /// Wheel moment about a diameter [kg m²] (twice that about its axle).
    pub i_wheel: f64,
    /// Gravity [m/s²].
    pub g: f64,
}

impl Default for MobileManipulator {
    /// A 40 kg chassis on 0.1 m wheels, 0.25 m apart from the centre.
    fn default() -> Self {
        MobileManipulator {
            r: 0.1,
            w: 0.25,
            h: 0.3,
            c: -0.1,
            d: 0.1,
            m_chassis: 40.0,
            ixx: 1.2,
            iyy: 1.5,
            izz: 2.0,
            m_wheel: 2.0,
            i_wheel: 0.005,
            g: 9.81,
        }
    }
}
