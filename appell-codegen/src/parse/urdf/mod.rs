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
//! - Each link with a positive mass is a body of its name: centre the
//!   inertial origin (the point `{link}_center` unless it is the link's
//!   origin), inertia `matrix(ixx, iyy, izz, ixy, iyz, ixz)` in the link's
//!   frame turned by the inertial rpy (`{link}_inertial` unless zero).
//! - A mimic joint is `dependent`, tied by
//!   `holonomic(joint == multiplier * other + offset)`, and not actuated.
//! - Numbers are the doubles of the decimals as written, float constants.
//!
//! Options: `weld(joint, ...)` fixes movable joints at 0;
//! `parameters(element.field = expression, ...)` puts an expression of the
//! model (a struct field) in place of a number of the file: a joint's
//! `xyz.x`, ..., `rpy.roll`, `rpy.pitch`, `rpy.yaw`, a link's `mass`, `ixx`,
//! `iyy`, `izz`, `ixy`, `iyz`, `ixz`, `xyz.x`, ..., `rpy.yaw` (its
//! inertial's).
//!
//! Names of the file that cannot be Rust names are made so
//! (`tree::model_name`: `base_link-base_fixed_joint` is
//! `base_link_base_fixed_joint`).
//!
//! | module | role |
//! | --- | --- |
//! | `read` | finding, reading and checking the file; errors that name the element and its line |
//! | `options` | the item's syntax: the path, `weld`, `parameters`, `parent`, `at` |
//! | `tree` | model names, the root, the joints from the root |
//! | `inertia` | the mass and inertia checks |
//! | `lower` | the items |

mod inertia;
mod lower;
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
            lower::check_links(cx, &read, &spec, span);
            return Ok(());
        }
    };
    lower::lower(cx, ast, &read, &tree, &spec)
}
