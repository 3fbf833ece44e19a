//! The keywords of `#[appell(...)]`, one constant per spelling: the model
//! items (whose list an unknown item's "did you mean" offers), then the
//! options and values inside them. Each is spelled once, for the parsers'
//! matches.

/// `coordinates(...)`.
pub const COORDINATES: &str = "coordinates";
/// `speeds(...)`.
pub const SPEEDS: &str = "speeds";
/// `inputs(...)`.
pub const INPUTS: &str = "inputs";
/// `positive(...)`.
pub const POSITIVE: &str = "positive";
/// `frame(...)`.
pub const FRAME: &str = "frame";
/// `point(...)`.
pub const POINT: &str = "point";
/// `particle(...)`.
pub const PARTICLE: &str = "particle";
/// `body(...)`.
pub const BODY: &str = "body";
/// `holonomic(...)`.
pub const HOLONOMIC: &str = "holonomic";
/// `nonholonomic(...)`.
pub const NONHOLONOMIC: &str = "nonholonomic";
/// `force(...)`.
pub const FORCE: &str = "force";
/// `torque(...)`.
pub const TORQUE: &str = "torque";
/// `gravity(...)`.
pub const GRAVITY: &str = "gravity";
/// `spring(...)`.
pub const SPRING: &str = "spring";
/// `damper(...)`.
pub const DAMPER: &str = "damper";
/// `friction(...)`.
pub const FRICTION: &str = "friction";
/// `rolls(...)`.
pub const ROLLS: &str = "rolls";
/// `contact(...)`.
pub const CONTACT: &str = "contact";
/// `scene(...)`.
pub const SCENE: &str = "scene";
/// `joint(...)`.
pub const JOINT: &str = "joint";
/// `repeat(...)`.
pub const REPEAT: &str = "repeat";
/// `urdf(...)`.
pub const URDF: &str = "urdf";
/// `jacobian(...)`.
pub const JACOBIAN: &str = "jacobian";

// Options and values inside the items (a joint's kind and properties, a
// body's, a scene's, a URDF's, an element's, a contact's kind).
/// `actuated`.
pub const ACTUATED: &str = "actuated";
/// `along`.
pub const ALONG: &str = "along";
/// `at`.
pub const AT: &str = "at";
/// `ball`.
pub const BALL: &str = "ball";
/// `base`.
pub const BASE: &str = "base";
/// `center`.
pub const CENTER: &str = "center";
/// `child`.
pub const CHILD: &str = "child";
/// `cylindrical`.
pub const CYLINDRICAL: &str = "cylindrical";
/// `damping`.
pub const DAMPING: &str = "damping";
/// `dependent`.
pub const DEPENDENT: &str = "dependent";
/// `effect`.
pub const EFFECT: &str = "effect";
/// `effects`.
pub const EFFECTS: &str = "effects";
/// `off`.
pub const OFF: &str = "off";
/// `on`.
pub const ON: &str = "on";
/// `fixed`.
pub const FIXED: &str = "fixed";
/// `flat`.
pub const FLAT: &str = "flat";
/// `floating`.
pub const FLOATING: &str = "floating";
/// `free`.
pub const FREE: &str = "free";
/// `friction_smoothing`.
pub const FRICTION_SMOOTHING: &str = "friction_smoothing";
/// `inertia`.
pub const INERTIA: &str = "inertia";
/// `lock`.
pub const LOCK: &str = "lock";
/// `mass`.
pub const MASS: &str = "mass";
/// `mimic`.
pub const MIMIC: &str = "mimic";
/// `mu`.
pub const MU: &str = "mu";
/// `normal`.
pub const NORMAL: &str = "normal";
/// `outputs`.
pub const OUTPUTS: &str = "outputs";
/// `parameters`.
pub const PARAMETERS: &str = "parameters";
/// `parent`.
pub const PARENT: &str = "parent";
/// `planar`.
pub const PLANAR: &str = "planar";
/// `plane`.
pub const PLANE: &str = "plane";
/// `prismatic`.
pub const PRISMATIC: &str = "prismatic";
/// `rest`.
pub const REST: &str = "rest";
/// `revolute`.
pub const REVOLUTE: &str = "revolute";
/// `right_angles`.
pub const RIGHT_ANGLES: &str = "right_angles";
/// `rpy`.
pub const RPY: &str = "rpy";
/// `saturation`.
pub const SATURATION: &str = "saturation";
/// `slides`.
pub const SLIDES: &str = "slides";
/// `smoothing`.
pub const SMOOTHING: &str = "smoothing";
/// `spherical`.
pub const SPHERICAL: &str = "spherical";
/// `stiffness`.
pub const STIFFNESS: &str = "stiffness";
/// `unchecked_inertia`.
pub const UNCHECKED_INERTIA: &str = "unchecked_inertia";
/// `viscous`.
pub const VISCOUS: &str = "viscous";
/// `weld`.
pub const WELD: &str = "weld";
/// `xyz`.
pub const XYZ: &str = "xyz";

/// Every model item, in the order the model language lists them.
pub const ITEMS: &[&str] = &[
    COORDINATES,
    SPEEDS,
    INPUTS,
    POSITIVE,
    FRAME,
    POINT,
    PARTICLE,
    BODY,
    HOLONOMIC,
    NONHOLONOMIC,
    FORCE,
    TORQUE,
    GRAVITY,
    SPRING,
    DAMPER,
    FRICTION,
    ROLLS,
    CONTACT,
    SCENE,
    JOINT,
    REPEAT,
    URDF,
    JACOBIAN,
];
