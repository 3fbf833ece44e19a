//! The robot's names as the model's, and its tree: the root link and the
//! joints in an order that declares each parent link before its children.

use proc_macro2::Span;
use syn::Ident;

use super::read::Lines;

/// The links and joints under their model names, and the order to declare
/// them in.
pub(super) struct Tree {
    /// Each link's name in the model, in the file's order.
    pub links: Vec<Ident>,
    /// Each joint's name in the model, in the file's order.
    pub joints: Vec<Ident>,
    /// Each joint's parent and child link (indices into `links`).
    pub ends: Vec<(usize, usize)>,
    /// The link no joint has as its child.
    pub root: usize,
    /// The joints, depth first from the root, children in the file's
    /// order: every joint comes after the joint of its parent link.
    pub order: Vec<usize>,
}

/// A URDF name as a Rust name: each character that cannot stand in one
/// becomes `_`, a leading digit gets a `_` before it, and a keyword an `_`
/// after it (`base_link-base_fixed_joint` is `base_link_base_fixed_joint`,
/// `type` is `type_`).
pub(super) fn model_name(urdf: &str) -> String {
    let mut s: String = urdf
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect();
    if s.is_empty() || s.starts_with(|c: char| c.is_ascii_digit()) {
        s.insert(0, '_');
    }
    if syn::parse_str::<Ident>(&s).is_err() {
        s.push('_');
    }
    s
}

impl Tree {
    /// The tree of `robot`, or what is wrong with it: repeated names, a
    /// joint whose parent or child link is unknown, a link that is the
    /// child of two joints, no root or several, a loop.
    pub(super) fn new(
        robot: &urdf_rs::Robot,
        lines: &Lines,
        span: Span,
    ) -> Result<Tree, Vec<String>> {
        let mut errors = Vec::new();
        let mut links = names(
            robot.links.iter().map(|l| l.name.as_str()),
            "link",
            lines,
            span,
            &mut errors,
        );
        let joints = names(
            robot.joints.iter().map(|j| j.name.as_str()),
            "joint",
            lines,
            span,
            &mut errors,
        );
        apart_from_joints(&mut links, &joints);
        let link_names: Vec<&str> = robot.links.iter().map(|l| l.name.as_str()).collect();
        let find = |name: &str, joint: &urdf_rs::Joint, role: &str, errors: &mut Vec<String>| {
            let found = link_names.iter().position(|l| *l == name);
            if found.is_none() {
                let hint = crate::ctxt::suggest(name, link_names.iter().copied())
                    .map(|s| format!("; did you mean `{s}`?"))
                    .unwrap_or_default();
                errors.push(format!(
                    "URDF {}: its {role} link `{name}` is not a link of the file{hint}",
                    lines.describe("joint", &joint.name)
                ));
            }
            found
        };
        let mut ends = Vec::new();
        let mut parent_joint: Vec<Option<usize>> = vec![None; robot.links.len()];
        for (k, j) in robot.joints.iter().enumerate() {
            let parent = find(&j.parent.link, j, "parent", &mut errors);
            let child = find(&j.child.link, j, "child", &mut errors);
            let (Some(parent), Some(child)) = (parent, child) else {
                continue;
            };
            if let Some(other) = parent_joint[child] {
                errors.push(format!(
                    "URDF {}: link `{}` is already the child of joint `{}`; a URDF is a tree, each link the child of one joint at most",
                    lines.describe("joint", &j.name),
                    j.child.link,
                    robot.joints[other].name
                ));
            }
            parent_joint[child] = Some(k);
            ends.push((parent, child));
        }
        if !errors.is_empty() {
            return Err(errors);
        }
        let roots: Vec<usize> = (0..links.len())
            .filter(|&l| parent_joint[l].is_none())
            .collect();
        let root = match roots[..] {
            [root] => root,
            [] => {
                return Err(vec![
                    "the URDF has no root link: its joints make a loop".into()
                ])
            }
            _ => {
                let names: Vec<String> = roots
                    .iter()
                    .map(|&l| format!("`{}`", robot.links[l].name))
                    .collect();
                return Err(vec![format!(
                    "the URDF has several root links ({}): join them with joints so that one link is the root",
                    names.join(", ")
                )]);
            }
        };
        let order = depth_first(root, &ends);
        if order.len() != ends.len() {
            return Err(vec![
                "the URDF's joints make a loop: some links cannot be reached from the root".into(),
            ]);
        }
        Ok(Tree {
            links,
            joints,
            ends,
            root,
            order,
        })
    }
}

/// The model names, with an error for a name given twice, before or after
/// [`model_name`].
fn names<'a>(
    all: impl Iterator<Item = &'a str>,
    tag: &str,
    lines: &Lines,
    span: Span,
    errors: &mut Vec<String>,
) -> Vec<Ident> {
    let mut out: Vec<(Ident, &str)> = Vec::new();
    for name in all {
        let model = model_name(name);
        if let Some((_, other)) = out.iter().find(|(i, _)| *i == model) {
            let same = if *other == name {
                format!("two {tag}s are named `{name}`")
            } else {
                format!("{tag}s `{other}` and `{name}` both stand as `{model}` in the model")
            };
            errors.push(format!("URDF {}: {same}", lines.describe(tag, name)));
        }
        out.push((Ident::new(&model, span), name));
    }
    out.into_iter().map(|(i, _)| i).collect()
}

/// A link named as a joint (URDF keeps links and joints apart; the SO-100
/// arm's `gripper` is both) gets `_link` after its name, as often as it
/// takes to be a name of neither: the joint keeps its name, which its
/// coordinate and Pinocchio's vectors go by.
fn apart_from_joints(links: &mut [Ident], joints: &[Ident]) {
    for k in 0..links.len() {
        if !joints.contains(&links[k]) {
            continue;
        }
        let mut name = links[k].to_string();
        while joints.iter().chain(links.iter()).any(|i| *i == name) {
            name.push_str("_link");
        }
        links[k] = Ident::new(&name, links[k].span());
    }
}

/// The joints from the root, depth first, each link's children in the
/// order of the file: a joint, then the joints below its child, then its
/// next sibling.
fn depth_first(root: usize, ends: &[(usize, usize)]) -> Vec<usize> {
    let children = |link: usize| (0..ends.len()).filter(move |&j| ends[j].0 == link);
    let mut order = Vec::new();
    let mut stack: Vec<usize> = children(root).collect();
    stack.reverse();
    while let Some(joint) = stack.pop() {
        order.push(joint);
        let below: Vec<usize> = children(ends[joint].1).collect();
        stack.extend(below.into_iter().rev());
    }
    order
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn urdf_names_become_rust_names() {
        assert_eq!(
            model_name("base_link-base_fixed_joint"),
            "base_link_base_fixed_joint"
        );
        assert_eq!(model_name("type"), "type_");
        assert_eq!(model_name("2nd"), "_2nd");
        assert_eq!(model_name("panda_joint1"), "panda_joint1");
    }

    #[test]
    fn a_link_named_as_a_joint_is_renamed() {
        let span = Span::call_site();
        let ids = |v: &[&str]| -> Vec<Ident> { v.iter().map(|n| Ident::new(n, span)).collect() };
        let mut links = ids(&["base", "gripper", "gripper_link"]);
        apart_from_joints(&mut links, &ids(&["gripper", "wrist"]));
        assert_eq!(links, ids(&["base", "gripper_link_link", "gripper_link"]));
    }

    #[test]
    fn parents_come_before_children() {
        // 0 -> 1 -> 2, 0 -> 3, listed out of order.
        let ends = [(1, 2), (0, 3), (0, 1)];
        assert_eq!(depth_first(0, &ends), [1, 2, 0]);
    }
}
