//! Points, bodies, constraints, loads and rolling contacts.

use appell_symbolic::{Id, SymbolicError};

use crate::algebra::dot;

use super::builder::Builder;
use super::expr::Val;
use super::{Body, Constraint, Load, Point, Rolling, Vec3};
use crate::ast::*;

/// The loads of a model: its forces and torques with their effects.
pub(super) struct Loads {
    /// Effect names in order of first use.
    pub effects: Vec<String>,
    /// Forces, each body's weight first when there is `gravity(...)`.
    pub forces: Vec<Load>,
    /// Torques.
    pub torques: Vec<Load>,
    /// The `gravity(...)` acceleration.
    pub gravity: Option<Vec3>,
}

impl Builder<'_> {
    pub(super) fn add_point(&mut self, p: &PointDef) {
        self.context = format!("point `{}`", p.name);
        match self.eval(&p.location) {
            Some(Val::Point(pos)) => self.points.push(Point {
                name: p.name.to_string(),
                pos,
            }),
            Some(_) => self.cx.error_at(
                p.location.span(),
                "a point is located from another point: `P = O + vector` or `P = Q + vector`",
            ),
            None => {}
        }
    }

    /// The body `d` declares; its inertia checked when `check` (a URDF
    /// body the URDF reader checked is not checked again).
    pub(super) fn add_body(&mut self, d: &BodyDef, check: bool) -> Option<Body> {
        let center = self.point_named(&d.center);
        let frame = match &d.frame {
            Some(f) => Some(self.frame_named(f)?),
            None => None,
        };
        self.context = format!("body `{}`", d.name);
        let mass = self.scalar(&d.mass);
        if let Some(m) = mass {
            self.check_mass(d, m);
        }
        let zero = self.g.int(0).ok()?;
        let mut inertia = [[zero; 3]; 3];
        match &d.inertia {
            Some(Inertia::Principal(m)) => {
                for (i, e) in m.iter().enumerate() {
                    inertia[i][i] = self.scalar(e)?;
                }
            }
            Some(Inertia::Matrix(m)) => {
                let v: Vec<Id> = m.iter().map(|e| self.scalar(e)).collect::<Option<_>>()?;
                inertia = [[v[0], v[3], v[5]], [v[3], v[1], v[4]], [v[5], v[4], v[2]]];
            }
            None => {}
        }
        if let (Some(i), true) = (&d.inertia, check) {
            self.check_inertia(d, i, &inertia);
        }
        Some(Body {
            name: d.name.to_string(),
            center: center?,
            frame,
            mass: mass?,
            inertia,
        })
    }

    /// A mass that is a number must be positive.
    fn check_mass(&mut self, d: &BodyDef, m: Id) {
        let Some(value) = self.g.as_number(m).map(|n| n.to_f64()) else {
            return;
        };
        let rule = if value == 0.0 {
            "zero mass"
        } else if value < 0.0 {
            "a negative mass"
        } else {
            return;
        };
        self.cx.error_at(
            d.mass.span(),
            format!(
                "`{}` has {rule} ({value}): a body's mass must be positive",
                d.name
            ),
        );
    }

    /// An inertia whose entries are all numbers must be one a rigid body can
    /// have: positive semidefinite and within the triangle inequality. The
    /// error points at the largest principal moment of a `principal(...)`,
    /// else at the first entry.
    fn check_inertia(&mut self, d: &BodyDef, written: &Inertia, inertia: &[[Id; 3]; 3]) {
        let mut m = [[0.0; 3]; 3];
        for (r, row) in inertia.iter().enumerate() {
            for (c, e) in row.iter().enumerate() {
                let Some(n) = self.g.as_number(*e) else {
                    return;
                };
                m[r][c] = n.to_f64();
            }
        }
        let Err(rule) = crate::physical::check_matrix(&m) else {
            return;
        };
        let span = match written {
            Inertia::Principal(e) => {
                let largest = (0..3).fold(0, |b, k| if m[k][k] > m[b][b] { k } else { b });
                e[largest].span()
            }
            Inertia::Matrix(e) => e[0].span(),
        };
        let hint = match written {
            Inertia::Principal(_) if m[0][0] == 0.0 && m[1][1] == 0.0 => "a rigid body's principal moments are non-negative, each at most the sum of the other two; in a planar model only the moment about the normal enters, so write the body as a plate: `principal(i / 2, i / 2, i)`",
            Inertia::Principal(_) => "a rigid body's principal moments are non-negative, each at most the sum of the other two",
            Inertia::Matrix(_) => "`matrix(...)` takes ixx, iyy, izz, ixy, iyz, izx, and a rigid body's is positive semidefinite with each principal moment at most the sum of the other two",
        };
        let rule = rule.trim_start_matches("its ");
        self.cx
            .error_at(span, format!("`{}`'s {rule}\n  hint: {hint}", d.name));
    }

    /// A constraint's residuals, lhs − rhs: one for an equation between
    /// scalars; for one between points or vectors (a loop closure), one per
    /// component along N's axes, identically zero ones dropped, or along the
    /// `along` directions. Either side may be the literal `0`.
    pub(super) fn constraint(&mut self, c: &ConstraintDef) -> Vec<Constraint> {
        self.context = "a constraint".to_string();
        let residuals = match self.constraint_sides(c) {
            Some(Side::Scalar(l, r)) => {
                if let Some(first) = c.along.as_ref().and_then(|a| a.first()) {
                    self.cx.error_at(
                        first.span(),
                        "`along` is for an equation between points or vectors; this one is between scalars",
                    );
                    return Vec::new();
                }
                self.g.sub(l, r).map(|e| vec![e])
            }
            Some(Side::Vector(l, r)) => self.vector_residuals(c, l, r),
            None => return Vec::new(),
        };
        match residuals {
            Ok(v) => v
                .into_iter()
                .map(|residual| Constraint {
                    residual,
                    at: c.at.clone(),
                    effect: c.effect.as_ref().map(|e| e.to_string()),
                    contact: None,
                })
                .collect(),
            Err(e) => {
                self.cx.error_spanned_by(&c.at, e);
                Vec::new()
            }
        }
    }

    /// Both sides of `c`, as scalars or as vectors (a point's position, or
    /// zero where a side is the literal `0` facing a point or a vector).
    pub(super) fn constraint_sides(&mut self, c: &ConstraintDef) -> Option<Side> {
        let zero_literal = |e: &Expr| matches!(e, Expr::Int(0, _));
        let (l, r) = match (zero_literal(&c.lhs), zero_literal(&c.rhs)) {
            (true, false) => {
                let r = self.eval(&c.rhs)?;
                (zero_like(&mut self.g, r)?, r)
            }
            (false, true) => {
                let l = self.eval(&c.lhs)?;
                let z = zero_like(&mut self.g, l)?;
                (l, z)
            }
            _ => (self.eval(&c.lhs)?, self.eval(&c.rhs)?),
        };
        match (l, r) {
            (Val::Scalar(a), Val::Scalar(b)) => Some(Side::Scalar(a, b)),
            (Val::Point(a), Val::Point(b)) | (Val::Vector(a), Val::Vector(b)) => {
                Some(Side::Vector(a, b))
            }
            (a, b) => {
                self.cx.error_spanned_by(
                    &c.at,
                    format!(
                        "the two sides of this constraint are a {} and a {}: write an equation between scalars, between points (a loop closure, `P == Q`), or between vectors",
                        a.kind(),
                        b.kind()
                    ),
                );
                None
            }
        }
    }

    /// The components of l − r along `c.along`, or along N's axes with the
    /// identically zero ones dropped.
    fn vector_residuals(
        &mut self,
        c: &ConstraintDef,
        l: Vec3,
        r: Vec3,
    ) -> Result<Vec<Id>, SymbolicError> {
        let g = &mut self.g;
        let diff = [g.sub(l[0], r[0])?, g.sub(l[1], r[1])?, g.sub(l[2], r[2])?];
        let Some(list) = &c.along else {
            return Ok(diff.into_iter().filter(|e| !g.is_zero(*e)).collect());
        };
        let mut out = Vec::new();
        for e in list {
            let Some(dir) = self.vector(e) else {
                continue;
            };
            let component = dot(&mut self.g, diff, dir)?;
            if self.g.is_zero(component) {
                self.cx.error_at(
                    e.span(),
                    "the constraint's component along this direction is identically zero: it constrains nothing",
                );
                continue;
            }
            out.push(component);
        }
        Ok(out)
    }

    /// Each body's weight (effect `gravity`), then the forces and torques.
    pub(super) fn loads(&mut self, ast: &ModelAst, bodies: &[Body]) -> Option<Loads> {
        let zero = self.g.int(0).ok()?;
        let mut effects = Vec::new();
        let mut forces = Vec::new();
        let mut torques = Vec::new();
        let mut gravity = None;
        if let Some(gvec) = &ast.gravity {
            self.context = "`gravity(...)`".to_string();
            if let Some(v) = self.vector(gvec) {
                gravity = Some(v);
                for (index, body) in bodies.iter().enumerate() {
                    let f = self.scale3(v, body.mass);
                    if let Some(f) = f {
                        forces.push(Load {
                            point: body.center,
                            frame: 0,
                            vector: f,
                            effect: "gravity".into(),
                            weight_of: Some(index),
                        });
                    }
                }
                effects.push("gravity".to_string());
            }
        }
        for l in &ast.forces {
            let Some(p) = self.point_named(&l.target) else {
                continue;
            };
            let Some((vector, effect)) = self.load_value(l, &mut effects) else {
                continue;
            };
            forces.push(Load {
                point: p,
                frame: 0,
                vector,
                effect,
                weight_of: None,
            });
        }
        for l in &ast.torques {
            let Some(fi) = self.frame_named(&l.target) else {
                continue;
            };
            let Some((vector, effect)) = self.load_value(l, &mut effects) else {
                continue;
            };
            torques.push(Load {
                point: [zero; 3],
                frame: fi,
                vector,
                effect,
                weight_of: None,
            });
        }
        Some(Loads {
            effects,
            forces,
            torques,
            gravity,
        })
    }

    /// A force's or torque's vector and effect; a new effect is added to
    /// `effects` in order of first use.
    fn load_value(&mut self, l: &LoadDef, effects: &mut Vec<String>) -> Option<(Vec3, String)> {
        self.context = format!("a load on `{}`", l.target);
        let v = self.vector(&l.vector)?;
        let effect = l.effect.to_string();
        if !effects.contains(&effect) {
            effects.push(effect.clone());
        }
        Some((v, effect))
    }

    /// The `rolls(...)` contacts: a rigid body, a contact point, and
    /// optionally the directions constrained.
    pub(super) fn rolling_contacts(&mut self, ast: &ModelAst, bodies: &[Body]) -> Vec<Rolling> {
        let mut rolling = Vec::new();
        for r in &ast.rolls {
            let name = r.body.to_string();
            let Some(bi) = bodies.iter().position(|x| x.name == name) else {
                if ast.massless_links.contains(&name) {
                    self.cx.error_spanned_by(&r.body, format!("`{name}` is a link of the URDF without mass, so no body rolls as it; name a link with mass, or give this one a mass with `parameters({name}.mass = m)`"));
                    continue;
                }
                let names: Vec<&str> = bodies.iter().map(|x| x.name.as_str()).collect();
                let h = crate::ctxt::suggest(&name, names.iter().copied())
                    .map(|s| format!("; did you mean `{s}`?"))
                    .unwrap_or_else(|| match names.len() {
                        1..=16 => format!("; the bodies are `{}`", names.join("`, `")),
                        _ => String::new(),
                    });
                self.cx
                    .error_spanned_by(&r.body, format!("unknown body `{name}`{h}"));
                continue;
            };
            if bodies[bi].frame.is_none() {
                self.cx.error_spanned_by(
                    &r.body,
                    format!("`{name}` is a particle; only a rigid body rolls"),
                );
                continue;
            }
            let Some(contact) = self.point_named(&r.contact) else {
                continue;
            };
            let along = match &r.along {
                Some(list) => {
                    let dirs: Vec<Vec3> = list.iter().filter_map(|e| self.vector(e)).collect();
                    if dirs.len() != list.len() {
                        continue;
                    }
                    if dirs.is_empty() {
                        self.cx
                            .error_spanned_by(&r.at, "`along` needs at least one direction");
                        continue;
                    }
                    Some(dirs)
                }
                None => None,
            };
            rolling.push(Rolling {
                effect: r.effect.as_ref().map(|e| e.to_string()),
                body: bi,
                contact,
                along,
                point: r.contact.to_string(),
                at: r.at.clone(),
            });
        }
        rolling
    }
}

/// The two sides of a constraint.
pub(super) enum Side {
    /// lhs and rhs, scalars.
    Scalar(Id, Id),
    /// lhs and rhs, N components of points or vectors.
    Vector(Vec3, Vec3),
}

/// A zero of the same kind as `v` (a scalar, or the zero vector for a
/// point or a vector).
fn zero_like(g: &mut appell_symbolic::Graph, v: Val) -> Option<Val> {
    let zero = g.int(0).ok()?;
    Some(match v {
        Val::Scalar(_) => Val::Scalar(zero),
        Val::Point(_) => Val::Point([zero; 3]),
        Val::Vector(_) => Val::Vector([zero; 3]),
    })
}
