//! Frames: each one a rotation of a parent frame, about one of the
//! parent's axes or about a fixed axis, with its angular velocity; in the
//! twin, the matrix entries that depend on the coordinates stand as
//! direction-cosine symbols (see [`super::Cut`]).

use appell_symbolic::{Graph, Id, Number, RateRules, Symbol, SymbolKind, SymbolicError};

use super::builder::{engine_error, Builder};
use super::{Cut, Frame, Mat3, Vec3};
use crate::algebra::{cross, dot, mat_mul, mat_t_vec};
use crate::ast::*;

impl Builder<'_> {
    pub(super) fn add_frame(&mut self, f: &FrameDef) {
        self.context = format!("frame `{}`", f.name);
        let Some(pi) = self.frame_named(&f.parent) else {
            return;
        };
        let mut rot = self.frames[pi].rot;
        let mut omega = self.frames[pi].omega;
        // Each rotation is about an axis of the frame the previous one made.
        for (axis, angle_expr) in &f.rotations {
            let Some(angle) = self.scalar(angle_expr) else {
                return;
            };
            let result = match axis {
                RotationAxis::Parent(k) => self.parent_axis_rotation(*k, angle, rot, omega),
                RotationAxis::Vector(v) => {
                    let Some(u) = self.vector(v) else { return };
                    // The twin's matrices are symbols; the model's build
                    // has checked the axis.
                    let checked = if self.cut_from.is_some() {
                        Ok(true)
                    } else {
                        self.fixed_in(u, &rot)
                    };
                    match checked {
                        Ok(true) => {}
                        Ok(false) => {
                            self.cx.error_at(
                                v.span(),
                                "the axis of `rotate(axis, angle)` must be fixed in the frame it rotates from (write it with that frame's unit vectors and constants); this one turns relative to it as the coordinates change",
                            );
                            return;
                        }
                        Err(e) => {
                            engine_error(self.cx, v.span(), e);
                            return;
                        }
                    }
                    self.axis_rotation(u, angle, rot, omega)
                }
            };
            match result {
                Ok((r, w)) => {
                    rot = r;
                    omega = w;
                }
                Err(e) => {
                    engine_error(self.cx, angle_expr.span(), e);
                    return;
                }
            }
        }
        if let Some(q) = &f.quaternion {
            let mut e = Vec::with_capacity(4);
            for x in q.iter() {
                let Some(v) = self.scalar(x) else { return };
                e.push(v);
            }
            let e: [Id; 4] = e.try_into().expect("four");
            self.note_quaternion(f, q, e);
            match self.quaternion_rotation(e, rot, omega) {
                Ok((r, w)) => {
                    rot = r;
                    omega = w;
                }
                Err(err) => {
                    engine_error(self.cx, q[0].span(), err);
                    return;
                }
            }
        }
        if let Some(values) = &self.cut_from {
            let index = self.frames.len();
            let values = values[index];
            match self.cut_rotation(index, rot, omega, values) {
                Ok(r) => rot = r,
                Err(e) => {
                    engine_error(self.cx, f.name.span(), e);
                    return;
                }
            }
        }
        self.frames.push(Frame {
            name: f.name.to_string(),
            rot,
            omega,
        });
    }

    /// In the twin: replaces the entries of a frame's matrix that depend on
    /// the coordinates by symbols (see [`Cut`]) whose values are the
    /// model's entries.
    pub(super) fn cut_rotation(
        &mut self,
        index: usize,
        rot: Mat3,
        omega: Vec3,
        values: Mat3,
    ) -> Result<Mat3, SymbolicError> {
        let g = &mut self.g;
        let mut out = rot;
        let mut symbols = [[None; 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                if g.is_parameter_only(rot[i][j]) {
                    continue;
                }
                let s = g.declare(&format!("__r{index}_{i}{j}"), SymbolKind::Auxiliary)?;
                symbols[i][j] = Some(s);
                out[i][j] = g.sym(s)?;
            }
        }
        for j in 0..3 {
            let column = [out[0][j], out[1][j], out[2][j]];
            let rate = cross(g, omega, column)?;
            for i in 0..3 {
                if let Some(s) = symbols[i][j] {
                    self.rules = std::mem::take(&mut self.rules).with(s, rate[i]);
                    self.cuts.push(Cut {
                        symbol: s,
                        value: values[i][j],
                        rate: rate[i],
                    });
                }
            }
        }
        Ok(out)
    }

    /// Whether the vector `u` (N components) is fixed in the frame with
    /// rotation `rot`: its components there do not change with time, checked
    /// at three pseudo-random configurations and rates (any failure to
    /// evaluate counts as not fixed).
    pub(super) fn fixed_in(&mut self, u: Vec3, rot: &Mat3) -> Result<bool, SymbolicError> {
        // A quaternion frame's matrix is a rotation only for a unit
        // quaternion turning tangentially (e · ė = 0): those values are
        // drawn so, or an axis fixed in such a frame would look turning.
        let blocks: Vec<[(Symbol, Symbol); 4]> = self
            .quaternions
            .iter()
            .map(|b| b.map(|i| (self.coords[i].1.q, self.coords[i].1.rate)))
            .collect();
        let g = &mut self.g;
        let local = mat_t_vec(g, rot, u)?;
        let rules = RateRules::coordinates();
        let rates = [
            g.time_derivative(local[0], &rules)?,
            g.time_derivative(local[1], &rules)?,
            g.time_derivative(local[2], &rules)?,
        ];
        if rates.iter().all(|&r| g.is_zero(r)) {
            return Ok(true);
        }
        let mut roots = rates.to_vec();
        roots.extend(local);
        let tape = appell_symbolic::Tape::new(g, &roots);
        for trial in 0..3u64 {
            let mut unit: Vec<(Symbol, f64)> = Vec::new();
            for block in &blocks {
                let e = block.map(|(q, _)| crate::probe::pseudo_value(g, q, trial));
                let norm = e.iter().map(|x| x * x).sum::<f64>().sqrt().max(1e-3);
                let e = e.map(|x| x / norm);
                let de = block.map(|(_, r)| crate::probe::pseudo_value(g, r, trial));
                let along: f64 = e.iter().zip(&de).map(|(a, b)| a * b).sum();
                for k in 0..4 {
                    unit.push((block[k].0, e[k]));
                    unit.push((block[k].1, de[k] - along * e[k]));
                }
            }
            let env = |s: Symbol| match unit.iter().find(|(u, _)| *u == s) {
                Some((_, v)) => Some(*v),
                None => Some(crate::probe::pseudo_value(g, s, trial)),
            };
            let Ok(v) = tape.eval(&env) else {
                return Ok(false);
            };
            let scale = 1.0 + v[3..].iter().fold(0.0f64, |a, x| a.max(x.abs()));
            if v[..3].iter().any(|r| r.is_nan() || r.abs() > 1e-9 * scale) {
                return Ok(false);
            }
        }
        Ok(true)
    }

    /// Rotation about the parent's axis `k`: R = R_parent Rk(θ),
    /// ω = ω_parent + θ̇ (parent axis k).
    pub(super) fn parent_axis_rotation(
        &mut self,
        k: usize,
        angle: Id,
        parent_rot: Mat3,
        parent_omega: Vec3,
    ) -> Result<(Mat3, Vec3), SymbolicError> {
        let g = &mut self.g;
        let rate = g.time_derivative(angle, &RateRules::coordinates())?;
        let c = g.cos(angle)?;
        let s = g.sin(angle)?;
        let local = simple_rotation(g, k, c, s)?;
        let rot = mat_mul(g, &parent_rot, &local)?;
        let mut omega = parent_omega;
        for i in 0..3 {
            let t = g.mul(rate, parent_rot[i][k])?;
            omega[i] = g.add(omega[i], t)?;
        }
        Ok((rot, omega))
    }

    /// Records a quaternion of four coordinates for the closed-form
    /// elimination of their rates, and its squared length for a run-time
    /// error where it vanishes (no orientation).
    fn note_quaternion(&mut self, f: &FrameDef, q: &[Expr; 4], e: [Id; 4]) {
        if self.cut_from.is_some() {
            return;
        }
        let index = |x: &Expr| match x {
            Expr::Name(n) => self.coords.iter().position(|(c, _)| c == n),
            _ => None,
        };
        let found: Vec<usize> = q.iter().filter_map(index).collect();
        let distinct = found
            .iter()
            .enumerate()
            .all(|(i, a)| !found[..i].contains(a));
        if let (Ok(block), true) = (<[usize; 4]>::try_from(found), distinct) {
            self.quaternions.push(block);
        }
        let squares: Result<Vec<Id>, _> = e.iter().map(|&x| self.g.mul(x, x)).collect();
        if let Ok(n2) = squares.and_then(|s| self.g.sum(&s)) {
            self.norms
                .push((n2, format!("the quaternion of frame `{}`", f.name)));
        }
    }

    /// Rotation by the unit quaternion e = (e0, e1, e2, e3), scalar first,
    /// relative to the parent: R = R_parent R(e) with R(e)'s entries the
    /// quadratic forms of Euler parameters (exact rotations on |e| = 1,
    /// which the model's unit-norm constraint keeps), and
    /// ω = ω_parent + R_parent · 2 (e0 ė − ė0 e⃗ + e⃗ × ė), the relative
    /// angular velocity in the parent's axes.
    pub(super) fn quaternion_rotation(
        &mut self,
        e: [Id; 4],
        parent_rot: Mat3,
        parent_omega: Vec3,
    ) -> Result<(Mat3, Vec3), SymbolicError> {
        let g = &mut self.g;
        let mut rate = [e[0]; 4];
        for k in 0..4 {
            rate[k] = g.time_derivative(e[k], &RateRules::coordinates())?;
        }
        let two = g.int(2)?;
        // Products e_i e_j, i ≤ j.
        let mut p = [[e[0]; 4]; 4];
        for i in 0..4 {
            for j in i..4 {
                p[i][j] = g.mul(e[i], e[j])?;
                p[j][i] = p[i][j];
            }
        }
        let mut local = [[e[0]; 3]; 3];
        for i in 0..3 {
            // Diagonal: e0² + e_i² − the other two squares.
            let (a, b) = ((i + 1) % 3, (i + 2) % 3);
            let plus = g.add(p[0][0], p[i + 1][i + 1])?;
            let minus = g.add(p[a + 1][a + 1], p[b + 1][b + 1])?;
            local[i][i] = g.sub(plus, minus)?;
            // Off-diagonal (i, a) and (a, i): 2 (e_i e_a ∓ e0 e_b).
            let sym = p[i + 1][a + 1];
            let skew = p[0][b + 1];
            let lower = g.add(sym, skew)?;
            let upper = g.sub(sym, skew)?;
            local[a][i] = g.mul(two, lower)?;
            local[i][a] = g.mul(two, upper)?;
        }
        let rot = mat_mul(g, &parent_rot, &local)?;
        // 2 (e0 ė − ė0 e⃗ + e⃗ × ė) in the parent's axes.
        let mut relative = [e[0]; 3];
        for i in 0..3 {
            let (a, b) = ((i + 1) % 3, (i + 2) % 3);
            let t1 = g.mul(e[0], rate[i + 1])?;
            let t2 = g.mul(rate[0], e[i + 1])?;
            let c1 = g.mul(e[a + 1], rate[b + 1])?;
            let c2 = g.mul(e[b + 1], rate[a + 1])?;
            let s = g.sub(t1, t2)?;
            let c = g.sub(c1, c2)?;
            let sum = g.add(s, c)?;
            relative[i] = g.mul(two, sum)?;
        }
        let mut omega = parent_omega;
        for i in 0..3 {
            for k in 0..3 {
                let t = g.mul(parent_rot[i][k], relative[k])?;
                omega[i] = g.add(omega[i], t)?;
            }
        }
        Ok((rot, omega))
    }

    /// Rotation by `angle` about the unit vector of `u` (N components, fixed
    /// in the parent): R = Rot(û, θ) R_parent (Rodrigues), ω = ω_parent + θ̇ û.
    pub(super) fn axis_rotation(
        &mut self,
        u: Vec3,
        angle: Id,
        parent_rot: Mat3,
        parent_omega: Vec3,
    ) -> Result<(Mat3, Vec3), SymbolicError> {
        let g = &mut self.g;
        let n2 = dot(g, u, u)?;
        if g.is_zero(n2) {
            return Err(SymbolicError::DivisionByZero {
                expr: "a zero-length rotation axis".into(),
            });
        }
        let n = g.sqrt(n2)?;
        let mut uh = [u[0]; 3];
        for i in 0..3 {
            uh[i] = g.div(u[i], n)?;
        }
        let c = g.cos(angle)?;
        let s = g.sin(angle)?;
        let one = g.int(1)?;
        let omc = g.sub(one, c)?;
        let mut r = [[one; 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                let uu = g.mul(uh[i], uh[j])?;
                let mut e = g.mul(omc, uu)?;
                if i == j {
                    e = g.add(e, c)?;
                }
                // [û]× entries: (i, j) = −ε_ijk û_k
                if i != j {
                    let k = 3 - i - j;
                    let sign = if (i + 1) % 3 == j { -1 } else { 1 };
                    let t = g.mul(s, uh[k])?;
                    let t = g.scale(t, Number::int(sign))?;
                    e = g.add(e, t)?;
                }
                r[i][j] = e;
            }
        }
        let rot = mat_mul(g, &r, &parent_rot)?;
        let rate = g.time_derivative(angle, &RateRules::coordinates())?;
        let mut omega = parent_omega;
        for i in 0..3 {
            let t = g.mul(rate, uh[i])?;
            omega[i] = g.add(omega[i], t)?;
        }
        Ok((rot, omega))
    }
}

/// Rotation about local axis `k` by an angle with cosine `c` and sine `s`.
fn simple_rotation(g: &mut Graph, k: usize, c: Id, s: Id) -> Result<Mat3, SymbolicError> {
    let zero = g.int(0)?;
    let one = g.int(1)?;
    let ms = g.neg(s)?;
    Ok(match k {
        0 => [[one, zero, zero], [zero, c, ms], [zero, s, c]],
        1 => [[c, zero, s], [zero, one, zero], [ms, zero, c]],
        _ => [[c, ms, zero], [s, c, zero], [zero, zero, one]],
    })
}
