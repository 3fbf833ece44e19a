//! The tree's numbers in the model's graph: [`TreeSpec::lower`] turns a
//! tree as written (every number an expression of parameters and
//! numbers, which the tree's checks admitted) into one of graph nodes, so
//! the structured form reads nodes and never the syntax.

use appell_symbolic::{Func, Graph, Id, SymbolicError};

use super::{Axis, CentralInertia, LinkSpec, MassSpec, Motion, Term, TreeSpec, Turns};
use crate::ast::{BinOp, Expr};

type R<T> = Result<T, SymbolicError>;

impl TreeSpec<Expr> {
    /// The tree with its numbers in `g`, lowered link by link in
    /// declaration order (each link's fields in order, then gravity): the
    /// order the nodes are made in, which the terms of the generated code
    /// follow.
    ///
    /// ```
    /// use appell_codegen::{ctxt::Ctxt, model::tree, parse};
    /// use appell_symbolic::Graph;
    ///
    /// let input: syn::DeriveInput = syn::parse_str(r#"
    ///     #[appell(joint(j_1, revolute(z), parent = N, child = link_1, actuated))]
    ///     #[appell(body(link_1, frame = link_1, mass = 2 * m, center = origin(link_1) + 0.5 * link_1.x,
    ///                   inertia = principal(0.1, 0.2, 0.3)))]
    ///     struct Arm { m: f64 }
    /// "#).unwrap();
    /// let cx = Ctxt::new();
    /// let ast = parse::parse(&cx, &input);
    /// cx.check().unwrap();
    /// let mut g = Graph::new();
    /// g.parameter("m").unwrap();
    /// let spec = tree::tree_spec(&ast).unwrap().lower(&mut g).unwrap();
    /// let mass = spec.links[0].bodies[0].mass;
    /// assert_eq!(g.eval_named(mass, &[("m", 1.5)]).unwrap(), 3.0);
    /// ```
    pub fn lower(self, g: &mut Graph) -> R<TreeSpec> {
        let links = self
            .links
            .into_iter()
            .map(|l| lower_link(g, l))
            .collect::<R<_>>()?;
        Ok(TreeSpec {
            links,
            gravity: lower_terms(g, self.gravity)?,
            plain: self.plain,
        })
    }
}

fn lower_link(g: &mut Graph, l: LinkSpec<Expr>) -> R<LinkSpec> {
    let parent_turns = lower_turns(g, l.parent_turns)?;
    let parent_origin = lower_terms(g, l.parent_origin)?;
    let xyz = l.xyz.map(|v| lower_three(g, v)).transpose()?;
    let rpy = l.rpy.map(|v| lower_three(g, v)).transpose()?;
    let motion = match l.motion {
        None => None,
        Some(Motion::Revolute(a)) => Some(Motion::Revolute(lower_axis(g, a)?)),
        Some(Motion::Prismatic(a)) => Some(Motion::Prismatic(lower_axis(g, a)?)),
        Some(Motion::Spherical) => Some(Motion::Spherical),
        Some(Motion::Free) => Some(Motion::Free),
    };
    let bodies = l
        .bodies
        .into_iter()
        .map(|b| lower_mass(g, b))
        .collect::<R<_>>()?;
    Ok(LinkSpec {
        joint: l.joint,
        parent: l.parent,
        parent_turns,
        parent_origin,
        xyz,
        rpy,
        motion,
        coordinates: l.coordinates,
        speeds: l.speeds,
        actuated: l.actuated,
        bodies,
    })
}

fn lower_mass(g: &mut Graph, b: MassSpec<Expr>) -> R<MassSpec> {
    let mass = lower_constant(g, &b.mass)?;
    let center = lower_terms(g, b.center)?;
    let inertia = match b.inertia {
        None => None,
        Some((turns, central)) => {
            let turns = lower_turns(g, turns)?;
            let central = match central {
                CentralInertia::Principal(d) => CentralInertia::Principal(lower_three(g, d)?),
                CentralInertia::Matrix(e) => {
                    let v: Vec<Id> = e.iter().map(|x| lower_constant(g, x)).collect::<R<_>>()?;
                    CentralInertia::Matrix([v[0], v[1], v[2], v[3], v[4], v[5]])
                }
            };
            Some((turns, central))
        }
    };
    Ok(MassSpec {
        name: b.name,
        mass,
        center,
        inertia,
    })
}

fn lower_axis(g: &mut Graph, a: Axis<Expr>) -> R<Axis> {
    Ok(match a {
        Axis::Unit(k, negative) => Axis::Unit(k, negative),
        Axis::Components(c) => Axis::Components(lower_three(g, c)?),
    })
}

fn lower_terms(g: &mut Graph, terms: Vec<Term<Expr>>) -> R<Vec<Term>> {
    terms
        .into_iter()
        .map(|t| {
            Ok(Term {
                coefficient: lower_constant(g, &t.coefficient)?,
                turns: lower_turns(g, t.turns)?,
                axis: t.axis,
                link: t.link,
            })
        })
        .collect()
}

fn lower_turns(g: &mut Graph, turns: Turns<Expr>) -> R<Turns> {
    turns
        .into_iter()
        .map(|(k, angle)| Ok((k, lower_constant(g, &angle)?)))
        .collect()
}

fn lower_three(g: &mut Graph, v: [Expr; 3]) -> R<[Id; 3]> {
    Ok([
        lower_constant(g, &v[0])?,
        lower_constant(g, &v[1])?,
        lower_constant(g, &v[2])?,
    ])
}

/// A constant of the model language (numbers, parameters and functions of
/// them) in the graph.
fn lower_constant(g: &mut Graph, e: &Expr) -> R<Id> {
    match e {
        Expr::Int(i, _) => g.int(*i),
        Expr::Float(x, _) => g.float(*x),
        Expr::Name(n) => match g.symbol_named(&n.to_string()) {
            Some(s) => g.sym(s),
            None => Err(SymbolicError::UnknownSymbol {
                name: n.to_string(),
            }),
        },
        Expr::Neg(x, _) => {
            let x = lower_constant(g, x)?;
            g.neg(x)
        }
        Expr::Binary(op, x, y, _) => {
            let (x, y) = (lower_constant(g, x)?, lower_constant(g, y)?);
            match op {
                BinOp::Add => g.add(x, y),
                BinOp::Sub => g.sub(x, y),
                BinOp::Mul => g.mul(x, y),
                BinOp::Div => g.div(x, y),
            }
        }
        Expr::Call(f, args, _) if args.len() == 1 => {
            let x = lower_constant(g, &args[0])?;
            match Func::from_name(&f.to_string()) {
                Some(func) => g.func(func, x),
                None => Err(SymbolicError::UnknownSymbol {
                    name: f.to_string(),
                }),
            }
        }
        _ => Err(SymbolicError::UnknownSymbol {
            name: "a vector in a scalar".into(),
        }),
    }
}
