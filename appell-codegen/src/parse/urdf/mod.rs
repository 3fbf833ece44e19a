//! `urdf("path", options...)` (or `urdf = "path"`): a robot read from a URDF
//! file during expansion and written as the items it stands for, so the
//! rest of the language (constraints, loads, rolling contacts, scenes)
//! works on top of it and refers to its links and joints by name.
//!
//! - The root link is a frame with N's axes, its origin point `{root}_origin`
//!   at O (`parent = A, at = P` fix it elsewhere).
//! - Each joint is a `joint(...)`: revolute and continuous are `revolute`,
//!   prismatic `prismatic`, fixed `weld`, planar `planar` (its axis a unit
//!   axis); its child frame is the child link's, its origin point
//!   `{link}_origin`, its coordinate the joint's name, with the origin's
//!   xyz and rpy and the axis (`x`, `-y`, ... when the axis is exactly one,
//!   else its components). Revolute, continuous and prismatic joints are
//!   `actuated`: the input `tau_{joint}`. Floating joints are `free`
//!   (a floating base), spherical ones `spherical`, neither actuated.
//!   A continuous joint's coordinate is its angle, unbounded: Pinocchio's
//!   `JointModelRevoluteUnbounded` has nq = 2, (cos θ, sin θ), and nv = 1,
//!   the same θ̇.
//! - Each link with a positive mass is a body of its name: centre the
//!   inertial origin (the point `{link}_center` unless it is the link's
//!   origin), inertia `matrix(ixx, iyy, izz, ixy, iyz, ixz)` in the link's
//!   frame turned by the inertial rpy (`{link}_inertial` unless zero).
//!   Links joined by fixed joints move as one rigid body, and the physical
//!   rules (positive mass, a positive semidefinite inertia within the
//!   triangle inequality) apply to that body, their inertias merged as
//!   Pinocchio merges them (`bodies`): a dummy link of unphysical inertia
//!   fixed to a real one is fine. A link of zero mass with an inertia has
//!   it added to a link with mass of its rigid body. `unchecked_inertia(
//!   link, ...)` takes the inertia of the named links as written.
//! - A joint that moves no link with mass (a zero row of the mass matrix)
//!   is an error that names `weld(...)`.
//! - A mimic joint is `dependent`, tied by
//!   `holonomic(joint == multiplier * other + offset)`, and not actuated
//!   (Pinocchio's `buildModel(..., mimic=True)`); `mimic = false` makes it
//!   an independent actuated joint (Pinocchio's default). A fixed joint's
//!   mimic tag is ignored (Talos's gripper).
//! - Numbers are the doubles of the decimals as written, float constants.
//! - Only links (their name and first `<inertial>`, as urdfdom reads it)
//!   and joints are read: visuals, collisions, materials, `<transmission>`,
//!   `<gazebo>` and anything else are not.
//!
//! Options: `weld(joint, ...)` fixes movable joints at 0;
//! `parameters(element.field = expression, ...)` puts an expression of the
//! model (a struct field) in place of a number of the file: a joint's
//! `xyz.x`, ..., `rpy.roll`, `rpy.pitch`, `rpy.yaw`, a link's `mass`, `ixx`,
//! `iyy`, `izz`, `ixy`, `iyz`, `ixz`, `xyz.x`, ..., `rpy.yaw` (its
//! inertial's); `unchecked_inertia(link, ...)`; `mimic = true | false`;
//! `base`, `parent`, `at` (see `options`).
//!
//! Names of the file that cannot be Rust names are made so
//! (`tree::model_name`: `base_link-base_fixed_joint` is
//! `base_link_base_fixed_joint`); a link named as a joint (URDF keeps the
//! two apart) gets `_link` after its name.
//!
//! | module | role |
//! | --- | --- |
//! | `read` | finding, reading and checking the file; errors that name the element and its line |
//! | `options` | the item's syntax: the path, `weld`, `parameters`, `parent`, `at` |
//! | `tree` | model names, the root, the joints from the root |
//! | `inertia` | the mass and inertia checks, inertias merged |
//! | `bodies` | which links are bodies, checked as the rigid bodies links fixed together make |
//! | `numbers` | the file's numbers as expressions, the fields `parameters(...)` may name |
//! | `lower` | the items |

mod bodies;
mod inertia;
mod lower;
mod numbers;
mod options;
mod read;
mod tree;

use syn::parse::Parser;

use super::{FileRoots, Item};
use crate::ast::ModelAst;
use crate::ctxt::Ctxt;

/// Reads the URDF `item` names and adds the robot's items to `ast`. Errors
/// about the file and its elements go to `cx`, all of them, each pointing
/// at the path; the result's error is one in the item's syntax.
pub(super) fn add(
    cx: &Ctxt,
    ast: &mut ModelAst,
    item: &Item,
    roots: &FileRoots,
) -> syn::Result<()> {
    let spec = Parser::parse2(options::parse_spec, item.content.clone())?;
    let span = spec.path.span();
    let path = roots
        .find(&spec.path.value())
        .map_err(|e| syn::Error::new(span, e))?;
    let Some(absolute) = path.to_str() else {
        return Err(syn::Error::new(
            span,
            format!("the URDF's path `{}` is not UTF-8", path.display()),
        ));
    };
    let read = match read::read(&path) {
        Ok(read) => read,
        Err(errors) => {
            for e in errors {
                cx.error_at(span, e);
            }
            return Ok(());
        }
    };
    ast.files.push(absolute.to_string());
    let tree = match tree::Tree::new(&read.robot, &read.lines, span) {
        Ok(tree) => tree,
        Err(errors) => {
            for e in errors {
                cx.error_at(span, e);
            }
            bodies::check_links(cx, &read, &spec, span);
            return Ok(());
        }
    };
    lower::lower(cx, ast, &read, &tree, &spec)
}
