//! Random mechanisms written in the model language: one to three
//! subsystems drawn from families that together use every kind of item
//! (trees of joints of every kind with their springs, dampers, friction
//! and actuation; a four-bar closed by `holonomic(P == Q)`; a rolling
//! disc; a sleigh whose forward speed is a quasi-velocity; a puck with a
//! spring, a damper and sliding friction; a pendulum whose first joint is
//! driven by an input), under gravity or not, with scenes.

use std::fmt::Write;

/// xorshift64*: the generator's only source of chance (seeded).
pub struct Rng(pub u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }
    /// Uniform in `0..n`.
    pub fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }
    /// True with probability `p`.
    fn chance(&mut self, p: f64) -> bool {
        self.uniform(0.0, 1.0) < p
    }
    /// Uniform in `[lo, hi)`, rounded to 3 decimals so the text is short.
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        let x = lo + (hi - lo) * (self.next() >> 11) as f64 / (1u64 << 53) as f64;
        (x * 1000.0).round() / 1000.0
    }
}

/// One random mechanism: the attributes, the struct's fields and values,
/// and what the checks need to know.
pub struct Mechanism {
    pub name: String,
    /// The `#[appell(...)]` attributes, one per line.
    pub attributes: Vec<String>,
    /// The parameters (struct fields) and their values.
    pub fields: Vec<(String, f64)>,
    /// The scenes' names.
    pub scenes: Vec<String>,
    /// The scene with the conservative loads and the inputs' only, whose
    /// energy rate must equal the input power (None where the model has
    /// driven coordinates, whose drives do work too).
    pub conservative: Option<String>,
    /// The families it was made of, for the report.
    pub families: Vec<&'static str>,
}

impl Mechanism {
    /// The model as a user writes it: attributes and struct.
    pub fn source(&self) -> String {
        let mut s = String::new();
        for a in &self.attributes {
            writeln!(s, "#[appell({a})]").unwrap();
        }
        write!(s, "pub struct {} {{", self.name).unwrap();
        for (f, _) in &self.fields {
            write!(s, " pub {f}: f64,").unwrap();
        }
        s.push_str(" }");
        s
    }
}

/// What the subsystems add to one model.
#[derive(Default)]
struct Parts {
    coordinates: Vec<String>,
    /// Entries of `speeds(...)` (names or `name = definition`).
    speeds: Vec<String>,
    inputs: Vec<String>,
    items: Vec<String>,
    fields: Vec<(String, f64)>,
    effects: Vec<&'static str>,
    driven: bool,
    families: Vec<&'static str>,
}

impl Parts {
    /// A parameter named `name` with a random value in `[lo, hi)`.
    fn param(&mut self, rng: &mut Rng, name: String, lo: f64, hi: f64) -> String {
        self.fields.push((name.clone(), rng.uniform(lo, hi)));
        name
    }
    fn effect(&mut self, e: &'static str) {
        if !self.effects.contains(&e) {
            self.effects.push(e);
        }
    }
    /// A principal inertia that obeys the triangle inequality: each moment
    /// in [0.6, 1) times a scale, some as parameters.
    fn inertia(&mut self, rng: &mut Rng, prefix: &str) -> String {
        let scale = rng.uniform(0.02, 0.5);
        let moments: Vec<String> = (0..3)
            .map(|k| {
                let v = scale * rng.uniform(0.6, 1.0);
                if rng.chance(0.3) {
                    self.param(rng, format!("{prefix}i{k}"), v, v + 1e-3)
                } else {
                    format!("{:.4}", v)
                }
            })
            .collect();
        if rng.chance(0.2) {
            // A general inertia: the principal one with small products.
            let p = rng.uniform(-0.05, 0.05) * scale;
            return format!(
                "matrix({}, {}, {}, {p:.4}, 0, 0)",
                moments[0], moments[1], moments[2]
            );
        }
        format!("principal({}, {}, {})", moments[0], moments[1], moments[2])
    }
}

/// The `count`-th mechanism of the run seeded with `seed`.
pub fn mechanism(seed: u64, count: usize) -> Mechanism {
    let mut rng = Rng(seed ^ (count as u64 + 1).wrapping_mul(0x9e37_79b9_7f4a_7c15));
    for _ in 0..4 {
        rng.next();
    }
    let mut parts = Parts::default();
    let subsystems = 1 + rng.below(2) as usize + usize::from(rng.chance(0.15));
    for k in 0..subsystems {
        match rng.below(12) {
            0..=4 => tree(&mut rng, &mut parts, k),
            5 => four_bar(&mut rng, &mut parts, k),
            6 | 7 => rolling_disc(&mut rng, &mut parts, k),
            8 => sleigh(&mut rng, &mut parts, k),
            9 | 10 => puck(&mut rng, &mut parts, k),
            _ => driven_pendulum(&mut rng, &mut parts, k),
        }
    }
    assemble(&mut rng, parts, format!("Random{count}"))
}

/// The model's attributes from its parts: coordinates, speeds, inputs,
/// gravity, and the scenes.
fn assemble(rng: &mut Rng, mut parts: Parts, name: String) -> Mechanism {
    let mut attributes = Vec::new();
    if !parts.coordinates.is_empty() {
        attributes.push(format!("coordinates({})", parts.coordinates.join(", ")));
    }
    if !parts.speeds.is_empty() {
        attributes.push(format!("speeds({})", parts.speeds.join(", ")));
    }
    if !parts.inputs.is_empty() {
        attributes.push(format!("inputs({})", parts.inputs.join(", ")));
    }
    if rng.chance(0.8) {
        let g = parts.param(rng, "g".into(), 1.0, 12.0);
        let axis = ["N.z", "N.z", "N.y", "N.x"][rng.below(4) as usize];
        attributes.push(format!("gravity(-{g} * {axis})"));
        parts.effect("gravity");
    }
    attributes.append(&mut parts.items);
    let mut scenes = Vec::new();
    let kept: Vec<&str> = parts
        .effects
        .iter()
        .copied()
        .filter(|e| matches!(*e, "gravity" | "actuation" | "push"))
        .collect();
    let conservative = (!parts.driven && kept.len() < parts.effects.len()).then(|| {
        attributes.push(format!("scene(conservative, effects({}))", kept.join(", ")));
        scenes.push("conservative".to_string());
        "conservative".to_string()
    });
    if parts.effects.contains(&"gravity") && parts.effects.len() > 1 && rng.chance(0.5) {
        let others: Vec<&str> = parts
            .effects
            .iter()
            .copied()
            .filter(|e| *e != "gravity")
            .collect();
        attributes.push(format!("scene(weightless, effects({}))", others.join(", ")));
        scenes.push("weightless".to_string());
    }
    let conservative = if parts.driven {
        None
    } else {
        // Without left-out loads the model itself is conservative.
        conservative.or_else(|| Some(String::new()))
    };
    Mechanism {
        name,
        attributes,
        fields: parts.fields,
        scenes,
        conservative,
        families: parts.families,
    }
}

/// A joint's kind, at most one quaternion joint per tree.
fn joint_kind(rng: &mut Rng, quaternion_left: &mut bool) -> (&'static str, String) {
    let axis = |rng: &mut Rng| -> String {
        match rng.below(9) {
            0 => "x".into(),
            1 | 2 => "y".into(),
            3..=5 => "z".into(),
            6 => "-y".into(),
            _ => format!(
                "[{}, {}, {}]",
                rng.below(3) as i64 - 1,
                rng.below(3),
                1 + rng.below(2)
            ),
        }
    };
    loop {
        return match rng.below(20) {
            0..=7 => ("revolute", format!("revolute({})", axis(rng))),
            8..=10 => ("prismatic", format!("prismatic({})", axis(rng))),
            11 | 12 => ("cylindrical", format!("cylindrical({})", axis(rng))),
            13 => ("planar", "planar(z)".to_string()),
            14 | 15 if *quaternion_left => {
                *quaternion_left = false;
                ("spherical", "spherical".to_string())
            }
            16 if *quaternion_left => {
                *quaternion_left = false;
                ("free", "free".to_string())
            }
            17..=19 => ("weld", "weld".to_string()),
            _ => continue,
        };
    }
}

/// A tree of one to three joints of random kinds, each child a body.
fn tree(rng: &mut Rng, parts: &mut Parts, k: usize) {
    parts.families.push("tree");
    let joints = 1 + rng.below(3) as usize;
    let mut quaternion_left = joints <= 2;
    let mut frames: Vec<String> = vec!["N".into()];
    let mut movable = false;
    for j in 0..joints {
        let parent = frames[rng.below(frames.len() as u64) as usize].clone();
        let (kind, written) = joint_kind(rng, &mut quaternion_left);
        let kind = if j + 1 == joints && !movable && kind == "weld" {
            // Every tree moves: its last joint turns if none did.
            ("revolute", "revolute(z)".to_string())
        } else {
            (kind, written)
        };
        movable |= kind.0 != "weld";
        let child = format!("S{k}L{j}");
        let name = format!("s{k}j{j}");
        let mut joint = format!(
            "joint({name}, {}, parent = {parent}, child = {child}",
            kind.1
        );
        let xyz = [
            rng.uniform(-0.5, 0.5),
            rng.uniform(-0.5, 0.5),
            rng.uniform(-0.5, 0.5),
        ];
        write!(joint, ", xyz = [{}, {}, {}]", xyz[0], xyz[1], xyz[2]).unwrap();
        if rng.chance(0.3) {
            let r = [
                rng.uniform(-1.5, 1.5),
                rng.uniform(-1.5, 1.5),
                rng.uniform(-1.5, 1.5),
            ];
            write!(joint, ", rpy = [{}, {}, {}]", r[0], r[1], r[2]).unwrap();
        }
        if matches!(kind.0, "revolute" | "prismatic") {
            if rng.chance(0.3) {
                joint.push_str(", actuated");
                parts.effect("actuation");
            }
            if rng.chance(0.2) {
                let stiffness = parts.param(rng, format!("s{k}k{j}"), 0.5, 20.0);
                write!(
                    joint,
                    ", stiffness = {stiffness}, rest = {}",
                    rng.uniform(-0.5, 0.5)
                )
                .unwrap();
                parts.effect("springs");
            }
            if rng.chance(0.2) {
                write!(joint, ", damping = {}", rng.uniform(0.01, 2.0)).unwrap();
                parts.effect("dampers");
            }
            if rng.chance(0.1) {
                write!(
                    joint,
                    ", friction = {}, friction_smoothing = 0.1",
                    rng.uniform(0.01, 0.5)
                )
                .unwrap();
                parts.effect("friction");
            }
        }
        joint.push(')');
        parts.items.push(joint);
        let mass = if rng.chance(0.4) {
            parts.param(rng, format!("s{k}m{j}"), 0.2, 3.0)
        } else {
            format!("{}", rng.uniform(0.2, 3.0))
        };
        let inertia = parts.inertia(rng, &format!("s{k}b{j}"));
        let (cx, cz) = (rng.uniform(-0.4, 0.4), rng.uniform(-0.4, 0.4));
        parts.items.push(format!(
            "body(s{k}b{j}, center = origin({child}) + {cx} * {child}.x + {cz} * {child}.z, frame = {child}, mass = {mass}, inertia = {inertia})"
        ));
        frames.push(child);
    }
    if rng.chance(0.25) && frames.len() > 2 {
        // A spring between the origins of two links.
        let (a, b) = (&frames[1], &frames[frames.len() - 1]);
        let l0 = rng.uniform(0.0, 0.5);
        parts.items.push(format!(
            "point(s{k}SpringA = {a}_origin + 0.1 * {a}.y), point(s{k}SpringB = {b}_origin + 0.2 * {b}.x)"
        ));
        parts.items.push(format!(
            "spring(s{k}SpringA, s{k}SpringB, stiffness = {}, length = {l0})",
            rng.uniform(1.0, 30.0)
        ));
        parts.effect("springs");
    }
}

/// A planar four-bar: crank and rocker pinned to the ground, the coupler
/// on the crank, the loop closed at the coupler's tip.
fn four_bar(rng: &mut Rng, parts: &mut Parts, k: usize) {
    parts.families.push("four-bar");
    let a = parts.param(rng, format!("s{k}a"), 0.3, 0.6);
    let (b, c, d) = (
        rng.uniform(0.8, 1.2),
        rng.uniform(0.7, 1.1),
        rng.uniform(0.9, 1.3),
    );
    let z = rng.uniform(-0.5, 0.5);
    parts.items.push(format!(
        "joint(s{k}crank, revolute(z), parent = N, child = S{k}C, xyz = [0, 0, {z}])"
    ));
    parts.items.push(format!(
        "joint(s{k}coupler, revolute(z), parent = S{k}C, child = S{k}K, xyz = [{a}, 0, 0], dependent)"
    ));
    parts.items.push(format!(
        "joint(s{k}rocker, revolute(z), parent = N, child = S{k}R, xyz = [{d}, 0, {z}], dependent)"
    ));
    for (body, frame, len) in [
        ("crank", "C", a.clone()),
        ("coupler", "K", b.to_string()),
        ("rocker", "R", c.to_string()),
    ] {
        let m = rng.uniform(0.3, 2.0);
        parts.items.push(format!(
            "body(s{k}{body}, center = origin(S{k}{frame}) + {len} / 2 * S{k}{frame}.x, frame = S{k}{frame}, mass = {m}, inertia = principal(0.001, {m} * {len} * {len} / 12, {m} * {len} * {len} / 12))"
        ));
    }
    parts.items.push(format!(
        "holonomic(S{k}K_origin + {b} * S{k}K.x == S{k}R_origin + {c} * S{k}R.x, along = [N.x, N.y])"
    ));
    if rng.chance(0.5) {
        parts.inputs.push(format!("s{k}tau"));
        parts
            .items
            .push(format!("torque(S{k}C, s{k}tau * N.z, effect = push)"));
        parts.effect("push");
    }
}

/// A thin disc rolling without slip on the plane z = 0.
fn rolling_disc(rng: &mut Rng, parts: &mut Parts, k: usize) {
    parts.families.push("rolling disc");
    let r = parts.param(rng, format!("s{k}r"), 0.1, 0.6);
    let m = parts.param(rng, format!("s{k}m"), 0.5, 3.0);
    for c in ["yaw", "lean", "spin", "x", "y"] {
        parts.coordinates.push(format!("s{k}{c}"));
    }
    for c in ["yaw", "lean", "spin"] {
        parts.speeds.push(format!("s{k}{c}"));
    }
    parts.items.push(format!(
        "frame(S{k}A = N.rotate_z(s{k}yaw)), frame(S{k}B = S{k}A.rotate_x(s{k}lean)), frame(S{k}W = S{k}B.rotate_y(s{k}spin))"
    ));
    parts.items.push(format!(
        "point(s{k}D = O + s{k}x * N.x + s{k}y * N.y + {r} * cos(s{k}lean) * N.z), point(s{k}P = s{k}D - {r} * S{k}B.z)"
    ));
    parts.items.push(format!(
        "body(s{k}disc, center = s{k}D, frame = S{k}W, mass = {m}, inertia = principal({m} * {r} * {r} / 4, {m} * {r} * {r} / 2, {m} * {r} * {r} / 4))"
    ));
    parts
        .items
        .push(format!("rolls(s{k}disc, contact = s{k}P)"));
    if rng.chance(0.4) {
        parts.inputs.push(format!("s{k}drive"));
        parts
            .items
            .push(format!("torque(S{k}W, s{k}drive * S{k}B.y, effect = push)"));
        parts.effect("push");
    }
}

/// A sleigh on a knife edge at C, its forward speed a quasi-velocity.
fn sleigh(rng: &mut Rng, parts: &mut Parts, k: usize) {
    parts.families.push("sleigh");
    for c in ["x", "y", "th"] {
        parts.coordinates.push(format!("s{k}{c}"));
    }
    parts
        .speeds
        .push(format!("s{k}v = dot(velocity(s{k}C), S{k}B.x)"));
    parts.speeds.push(format!("s{k}th"));
    parts
        .items
        .push(format!("frame(S{k}B = N.rotate_z(s{k}th))"));
    let e = rng.uniform(0.1, 0.6);
    parts.items.push(format!(
        "point(s{k}C = O + s{k}x * N.x + s{k}y * N.y), point(s{k}G = s{k}C + {e} * S{k}B.x + 0.05 * S{k}B.y)"
    ));
    let inertia = parts.inertia(rng, &format!("s{k}sled"));
    parts.items.push(format!(
        "body(s{k}sled, center = s{k}G, frame = S{k}B, mass = {}, inertia = {inertia})",
        rng.uniform(0.5, 4.0)
    ));
    parts
        .items
        .push(format!("nonholonomic(dot(velocity(s{k}C), S{k}B.y) == 0)"));
    if rng.chance(0.5) {
        parts.inputs.push(format!("s{k}push"));
        parts
            .items
            .push(format!("force(s{k}G, s{k}push * S{k}B.x, effect = push)"));
        parts.effect("push");
    }
}

/// A puck on a table: a spring and a damper to a post, sliding friction.
fn puck(rng: &mut Rng, parts: &mut Parts, k: usize) {
    parts.families.push("puck");
    for c in ["x", "y"] {
        parts.coordinates.push(format!("s{k}{c}"));
        parts.speeds.push(format!("s{k}{c}"));
    }
    let m = parts.param(rng, format!("s{k}m"), 0.2, 2.0);
    parts.items.push(format!(
        "point(s{k}P = O + s{k}x * N.x + s{k}y * N.y + 0.3 * N.z), point(s{k}Post = O + 0.3 * N.z + 0.05 * N.x)"
    ));
    parts.items.push(format!("particle(s{k}P, mass = {m})"));
    if rng.chance(0.7) {
        parts.items.push(format!(
            "spring(s{k}Post, s{k}P, stiffness = {}, length = {})",
            rng.uniform(1.0, 20.0),
            rng.uniform(0.0, 0.4)
        ));
        parts.effect("springs");
    }
    if rng.chance(0.5) {
        parts.items.push(format!(
            "damper(s{k}Post, s{k}P, damping = {})",
            rng.uniform(0.05, 2.0)
        ));
        parts.effect("dampers");
    }
    if rng.chance(0.6) {
        parts.items.push(format!(
            "friction(s{k}P, mu = {}, normal = {m} * 9.81, smoothing = 0.05, viscous = {})",
            rng.uniform(0.05, 0.8),
            rng.uniform(0.0, 0.5)
        ));
        parts.effect("friction");
    }
}

/// A double pendulum whose first joint turns at a commanded rate.
fn driven_pendulum(rng: &mut Rng, parts: &mut Parts, k: usize) {
    parts.families.push("driven pendulum");
    parts.driven = true;
    for c in ["a", "b"] {
        parts.coordinates.push(format!("s{k}{c}"));
    }
    parts.speeds.push(format!("s{k}b"));
    parts.inputs.push(format!("s{k}w"));
    parts.items.push(format!(
        "frame(S{k}A = N.rotate_y(s{k}a)), frame(S{k}B = S{k}A.rotate_y(s{k}b))"
    ));
    let (l1, l2) = (rng.uniform(0.3, 1.0), rng.uniform(0.3, 1.0));
    parts.items.push(format!(
        "point(s{k}P = O + {l1} * S{k}A.x), point(s{k}Q = s{k}P + {l2} * S{k}B.x)"
    ));
    parts.items.push(format!(
        "particle(s{k}P, mass = {}), particle(s{k}Q, mass = {})",
        rng.uniform(0.2, 2.0),
        rng.uniform(0.2, 2.0)
    ));
    parts
        .items
        .push(format!("nonholonomic(dt(s{k}a) == s{k}w)"));
}
