//! Which links are bodies, checked as the rigid bodies the dynamics sees.
//!
//! Links joined by fixed (or welded) joints move as one rigid body, and
//! Pinocchio merges their inertias into one. Real URDFs lean on it: a dummy
//! root link of 1e-6 kg with an inertia no body can have (ANYmal, Go1, B1,
//! HyQ), a camera whose inertia breaks the triangle inequality, a foot of
//! zero mass with a small inertia (Bolt). So the physical rules apply to the
//! merged body of each such group, not to each link: a link whose own
//! inertia is unphysical is a body as written when its group's is not, and
//! the model does not check it again. A link of zero mass with an inertia
//! has it added to a link of its group that has mass. A group whose merged
//! inertia is still unphysical is an error that names `unchecked_inertia`,
//! which takes the links it names as written, as Pinocchio does.
//!
//! Entries below 1e-12 of the robot's largest inertia entry are rounding
//! noise to the check (iCub's head: a point mass of 1.3 kg written with
//! ixz 2.4e-35), which takes them as zero.
//!
//! The group of the root link does not move when the robot is fixed in N
//! (`base = fixed` and no `parent`): its inertia takes no part in the
//! dynamics (Pinocchio puts it on the universe) and is not checked.
//!
//! A group with a number `parameters(...)` made an expression (a link's
//! inertial, a fixed joint's origin) is checked link by link, its numbers
//! that are expressions by nobody at compile time.

use proc_macro2::Span;

use super::inertia::{self, from_six, merged, part, turned, Mass, Part, Pose};
use super::numbers::LinkNumbers;
use super::options::{Base, Promotion, Spec};
use super::read::Read;
use super::tree::Tree;
use crate::ast::Expr;
use crate::ast::JointKind;
use crate::ctxt::Ctxt;

/// The links that are bodies, and those the model must take as they are.
pub(super) struct Bodies {
    /// Whether each link is a body.
    pub body: Vec<bool>,
    /// Links whose inertia the model does not check: the reader checked
    /// the rigid body they are part of, or was told not to.
    pub unchecked: Vec<usize>,
}

fn number(e: &Expr) -> Option<f64> {
    match e {
        Expr::Float(x, _) => Some(*x),
        _ => None,
    }
}

fn numbers<const N: usize>(e: &[Expr; N]) -> Option<[f64; N]> {
    let v: Vec<f64> = e.iter().map(number).collect::<Option<_>>()?;
    v.try_into().ok()
}

/// A link's inertial as numbers: mass, xyz, rpy, the six inertia entries.
type Numbers = (f64, [f64; 3], [f64; 3], [f64; 6]);

fn link_numbers(n: &LinkNumbers) -> Option<Numbers> {
    Some((
        number(&n.mass)?,
        numbers(&n.xyz)?,
        numbers(&n.rpy)?,
        numbers(&n.inertia)?,
    ))
}

/// The bodies of the robot; errors go to `cx`. `links` may change: the
/// inertia of a link of zero mass is added to a link of its group with
/// mass. `joint_origins` are each joint's xyz and rpy, as numbers where
/// they are.
pub(super) fn bodies(
    cx: &Ctxt,
    read: &Read,
    tree: &Tree,
    spec: &Spec,
    kinds: &[Option<JointKind>],
    joint_origins: &[([Expr; 3], [Expr; 3])],
    links: &mut [LinkNumbers],
) -> Bodies {
    let n = links.len();
    let groups = Groups::new(tree, kinds, joint_origins, n);
    let unchecked_group = unchecked_groups(cx, spec, tree, &groups);
    let checking = Checking {
        cx,
        read,
        tree,
        span: spec.path.span(),
        groups: &groups,
        unchecked_group: &unchecked_group,
        frozen_root: (spec.base == Base::Fixed && spec.parent.is_none()).then_some(tree.root),
        noise: noise(links),
    };
    let mut out = Bodies {
        body: vec![false; n],
        unchecked: Vec::new(),
    };
    for g in (0..n).filter(|&g| groups.group[g] == g) {
        checking.group(g, links, &mut out);
    }
    out
}

/// Each link's rigid group, named by its first link (the child of a moving
/// joint, or the root); its pose in that link's frame, `None` where an
/// origin is an expression; and its parent within the group.
struct Groups {
    group: Vec<usize>,
    pose: Vec<Option<Pose>>,
    parent_in_group: Vec<Option<usize>>,
}

impl Groups {
    fn new(
        tree: &Tree,
        kinds: &[Option<JointKind>],
        joint_origins: &[([Expr; 3], [Expr; 3])],
        n: usize,
    ) -> Groups {
        let mut group: Vec<usize> = (0..n).collect();
        let mut pose: Vec<Option<Pose>> = vec![Some(Pose::IDENTITY); n];
        let mut parent_in_group: Vec<Option<usize>> = vec![None; n];
        for &j in &tree.order {
            let (p, c) = tree.ends[j];
            if matches!(kinds[j], Some(JointKind::Weld)) {
                group[c] = group[p];
                parent_in_group[c] = Some(p);
                let (xyz, rpy) = &joint_origins[j];
                pose[c] = match (pose[p], numbers(xyz), numbers(rpy)) {
                    (Some(at), Some(xyz), Some(rpy)) => Some(at.then(xyz, rpy)),
                    _ => None,
                };
            }
        }
        Groups {
            group,
            pose,
            parent_in_group,
        }
    }

    /// The links of group `g`.
    fn members(&self, g: usize) -> Vec<usize> {
        (0..self.group.len())
            .filter(|&l| self.group[l] == g)
            .collect()
    }
}

/// For each group, whether `unchecked_inertia(...)` names one of its
/// links; a name that is no link is an error.
fn unchecked_groups(cx: &Ctxt, spec: &Spec, tree: &Tree, groups: &Groups) -> Vec<bool> {
    let mut unchecked = vec![false; groups.group.len()];
    for name in &spec.unchecked_inertia {
        match tree.links.iter().position(|l| l == name) {
            Some(l) => unchecked[groups.group[l]] = true,
            None => {
                let all: Vec<String> = tree.links.iter().map(|l| l.to_string()).collect();
                let hint = crate::ctxt::suggest(&name.to_string(), all.iter().map(|s| s.as_str()))
                    .map(|s| format!("; did you mean `{s}`?"))
                    .unwrap_or_default();
                cx.error_spanned_by(name, format!("`{name}` is not a link of the URDF{hint}"));
            }
        }
    }
    unchecked
}

/// Inertia entries below this are rounding noise to the check: 1e-12 of
/// the robot's largest.
fn noise(links: &[LinkNumbers]) -> f64 {
    1e-12
        * links
            .iter()
            .filter_map(link_numbers)
            .flat_map(|(_, _, _, six)| six)
            .filter(|x| x.is_finite())
            .fold(0.0f64, |a, x| a.max(x.abs()))
}

/// What checking one group reads.
struct Checking<'a> {
    cx: &'a Ctxt,
    read: &'a Read,
    tree: &'a Tree,
    span: Span,
    groups: &'a Groups,
    unchecked_group: &'a [bool],
    /// The root's group, where it does not move (fixed in N).
    frozen_root: Option<usize>,
    noise: f64,
}

impl Checking<'_> {
    fn describe(&self, l: usize) -> String {
        self.read
            .lines
            .describe("link", &self.read.robot.links[l].name)
    }

    /// Group `g`: its links' own numbers, its merged inertia, then the
    /// inertia of its links of zero mass moved to one with mass.
    fn group(&self, g: usize, links: &mut [LinkNumbers], out: &mut Bodies) {
        let members = self.groups.members(g);
        let numeric: Option<Vec<Numbers>> = members
            .iter()
            .map(|&l| self.groups.pose[l].and(link_numbers(&links[l])))
            .collect();
        let Some(numeric) = numeric else {
            // Expressions: each link on its own, as written.
            for &l in &members {
                match is_body(&self.read.robot.links[l].inertial, &links[l].promoted) {
                    Ok(b) => out.body[l] = b,
                    Err(e) => self
                        .cx
                        .error_at(self.span, format!("URDF {}: {e}", self.describe(l))),
                }
            }
            return;
        };
        if !self.sound(&members, &numeric) {
            return;
        }
        let parts: Vec<(usize, Part)> = members
            .iter()
            .zip(&numeric)
            .filter(|(_, (m, _, _, six))| *m > 0.0 || six.iter().any(|x| *x != 0.0))
            .map(|(&l, &(m, xyz, rpy, six))| {
                let at = self.groups.pose[l].expect("numeric");
                (l, part(&at, m, xyz, rpy, &from_six(six)))
            })
            .collect();
        for &(l, ref p) in &parts {
            out.body[l] = p.mass > 0.0;
        }
        let frozen = self.frozen_root == Some(g);
        if !frozen && !self.physical(g, members.len(), &parts) {
            return;
        }
        if !frozen {
            self.move_massless(&members, &numeric, &parts, links, out);
        }
        // Bodies whose own inertia the model's check would refuse.
        for &l in members.iter().filter(|&&l| out.body[l]) {
            let (mass, _, _, six) = link_numbers(&links[l]).expect("numeric");
            let i = urdf_rs::Inertia {
                ixx: six[0],
                iyy: six[1],
                izz: six[2],
                ixy: six[3],
                iyz: six[4],
                ixz: six[5],
            };
            if inertia::check(mass, &i) != Ok(Mass::Body) || self.unchecked_group[g] {
                out.unchecked.push(l);
            }
        }
    }

    /// Whether every member's mass and inertia are finite and its mass not
    /// negative; an error for each that is not.
    fn sound(&self, members: &[usize], numeric: &[Numbers]) -> bool {
        let mut sound = true;
        for (&l, (mass, _, _, six)) in members.iter().zip(numeric) {
            let problem = if !mass.is_finite() || six.iter().any(|x| !x.is_finite()) {
                Some("its mass or inertia is not a finite number".to_string())
            } else if *mass < 0.0 {
                Some(format!("its mass {mass} is negative"))
            } else {
                None
            };
            if let Some(p) = problem {
                self.cx
                    .error_at(self.span, format!("URDF {}: {p}", self.describe(l)));
                sound = false;
            }
        }
        sound
    }

    /// Whether the merged body of group `g` (`members` links, `parts`
    /// those with mass or inertia) has a positive mass and, unless its
    /// inertia is unchecked, a physical one; an error where not.
    fn physical(&self, g: usize, members: usize, parts: &[(usize, Part)]) -> bool {
        let whole = merged(&parts.iter().map(|(_, p)| *p).collect::<Vec<_>>());
        if whole.mass == 0.0 {
            for &(l, _) in parts {
                let alone = if members == 1 {
                    ""
                } else {
                    ", and no link fixed to it has mass"
                };
                self.cx.error_at(
                    self.span,
                    format!(
                        "URDF {}: its mass is zero but its inertia is not{alone}: a body needs a positive mass",
                        self.describe(l)
                    ),
                );
            }
            return false;
        }
        if self.unchecked_group[g] {
            return true;
        }
        let cleaned = whole
            .inertia
            .map(|row| row.map(|x| if x.abs() < self.noise { 0.0 } else { x }));
        let Err(rule) = inertia::check_matrix(&cleaned) else {
            return true;
        };
        let (at, what) = match parts {
            [(l, _)] => (*l, format!("{}: {rule}", self.describe(*l))),
            _ => {
                let first = if parts.iter().any(|(l, _)| *l == g) {
                    g
                } else {
                    parts[0].0
                };
                let others: Vec<String> = parts
                    .iter()
                    .filter(|(l, _)| *l != first)
                    .map(|(l, _)| format!("`{}`", self.read.robot.links[*l].name))
                    .collect();
                let rule =
                    rule.replacen("its inertia", "their inertia about their centre of mass", 1);
                (
                    first,
                    format!(
                        "{} with the links fixed to it ({}): {rule}",
                        self.describe(first),
                        others.join(", ")
                    ),
                )
            }
        };
        self.cx.error_at(
            self.span,
            format!(
                "URDF {what}; `unchecked_inertia({})` among the `urdf(...)` options takes it as written, as Pinocchio does",
                self.tree.links[at]
            ),
        );
        false
    }

    /// A link of zero mass with an inertia: its inertia goes to the nearest
    /// link with mass above it in the group, or any with mass.
    fn move_massless(
        &self,
        members: &[usize],
        numeric: &[Numbers],
        parts: &[(usize, Part)],
        links: &mut [LinkNumbers],
        out: &Bodies,
    ) {
        for &(l, ref p) in parts.iter().filter(|(_, p)| p.mass == 0.0) {
            let mut carrier = self.groups.parent_in_group[l];
            while let Some(c) = carrier {
                if out.body[c] {
                    break;
                }
                carrier = self.groups.parent_in_group[c];
            }
            let carrier = carrier
                .or_else(|| members.iter().copied().find(|&m| out.body[m]))
                .expect("the group has mass");
            let (_, _, rpy, _) = numeric[members.iter().position(|&m| m == carrier).unwrap()];
            let axes = self.groups.pose[carrier]
                .expect("numeric")
                .then([0.0; 3], rpy)
                .axes;
            // The inertia along the carrier's inertial axes.
            let transpose = |a: &inertia::Mat| [0, 1, 2].map(|r| [0, 1, 2].map(|c| a[c][r]));
            let along = turned(&transpose(&axes), &p.inertia);
            let six = &mut links[carrier].inertia;
            for (k, (r, c)) in [(0, 0), (1, 1), (2, 2), (0, 1), (1, 2), (0, 2)]
                .into_iter()
                .enumerate()
            {
                let before = number(&six[k]).expect("numeric");
                six[k] = Expr::Float(before + along[r][c], self.span);
            }
        }
    }
}

/// The links' inertials checked when the joints do not make a tree, so
/// that one build reports what is wrong with both; a number `parameters`
/// names is promoted as `lower` would promote it.
pub(super) fn check_links(cx: &Ctxt, read: &Read, spec: &Spec, span: Span) {
    for l in &read.robot.links {
        let name = super::tree::model_name(&l.name);
        let promoted: Vec<String> = spec
            .parameters
            .iter()
            .filter(|p| p.element == name)
            .map(Promotion::field_text)
            .collect();
        if let Err(e) = is_body(&l.inertial, &promoted) {
            let at = read.lines.describe("link", &l.name);
            cx.error_at(span, format!("URDF {at}: {e}"));
        }
    }
}

/// Whether an inertial is a body's, its numbers checked where they are the
/// file's (a parameter is checked by nobody at compile time).
pub(super) fn is_body(inertial: &urdf_rs::Inertial, promoted: &[String]) -> Result<bool, String> {
    let mass_promoted = promoted.iter().any(|f| f == "mass");
    let inertia_promoted = promoted.iter().any(|f| f.starts_with('i'));
    let (mass, i) = (inertial.mass.value, &inertial.inertia);
    let matrix = [
        [i.ixx, i.ixy, i.ixz],
        [i.ixy, i.iyy, i.iyz],
        [i.ixz, i.iyz, i.izz],
    ];
    if mass_promoted || mass > 0.0 {
        if !inertia_promoted {
            if mass_promoted {
                inertia::check_matrix(&matrix)?;
            } else {
                inertia::check(mass, i)?;
            }
        }
        return Ok(true);
    }
    if let (Some(f), true) = (promoted.first(), mass == 0.0) {
        return Err(format!(
            "it has no mass, so it is no body and its `{f}` cannot be a parameter; make its `mass` one too"
        ));
    }
    Ok(inertia::check(mass, i)? == Mass::Body)
}
