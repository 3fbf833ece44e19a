//! The model items of `#[appell(...)]`, one constant per keyword: each is
//! spelled once, for the parser's match and for the names an unknown
//! item's "did you mean" offers.

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
];
