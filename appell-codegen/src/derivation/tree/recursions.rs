//! The recursions over the links: articulated-body (ÿ), recursive
//! Newton–Euler (generalized forces) and composite-rigid-body (M), in
//! Featherstone's form (Rigid Body Dynamics Algorithms, 2008, Tables 5.1,
//! 6.2 and 7.1), with gravity as an acceleration of the ground.

use appell_symbolic::{Graph, Id, Number, SymbolicError};

use super::links::Link;
use super::spatial::{Algebra, M6, V3, V6};

type R<T> = Result<T, SymbolicError>;

/// The links and the graph the recursions write into.
pub struct Recursions<'g, 'l> {
    a: Algebra<'g>,
    links: &'l [Link],
    /// The ground's acceleration: −gravity.
    ground: V6,
    /// How many speeds the links' columns index.
    size: usize,
}

impl<'g, 'l> Recursions<'g, 'l> {
    /// The recursions over `links`, whose columns index `size` speeds,
    /// under `gravity` (in N's axes).
    pub fn new(
        g: &'g mut Graph,
        links: &'l [Link],
        gravity: V3,
        size: usize,
    ) -> R<Recursions<'g, 'l>> {
        let mut a = Algebra::new(g)?;
        let ground = a.ground(gravity)?;
        Ok(Recursions {
            a,
            links,
            ground,
            size,
        })
    }

    /// Σ Sᵢ xᵢ over link `i`'s columns, x indexed by speed.
    fn along_subspace(&mut self, i: usize, x: &[Id]) -> R<V6> {
        let link = &self.links[i];
        let mut out = self.a.scale(link.subspace[0], x[link.speeds[0]])?;
        for c in 1..link.subspace.len() {
            let more = self.a.scale(link.subspace[c], x[link.speeds[c]])?;
            out = self.a.add(out, more)?;
        }
        Ok(out)
    }

    /// Each link's velocity and the joint's velocity S q̇.
    fn velocities(&mut self, speeds: &[Id]) -> R<Vec<(V6, V6)>> {
        let mut out: Vec<(V6, V6)> = Vec::with_capacity(self.links.len());
        for i in 0..self.links.len() {
            let joint = self.along_subspace(i, speeds)?;
            let v = match self.links[i].parent {
                Some(p) => {
                    let moved = self.a.motion_to_child(&self.links[i].transform, out[p].0)?;
                    self.a.add(moved, joint)?
                }
                None => joint,
            };
            let v = self.a.hold(v)?;
            out.push((v, joint));
        }
        Ok(out)
    }

    /// The parent's acceleration in a link's axes.
    fn parent_acceleration(&mut self, i: usize, accels: &[V6]) -> R<V6> {
        let link = &self.links[i];
        let parent = match link.parent {
            Some(p) => accels[p],
            None => self.ground,
        };
        self.a.motion_to_child(&link.transform, parent)
    }

    /// Sᵀ x, one entry per column of link `i`.
    fn project(&mut self, i: usize, x: V6) -> R<Vec<Id>> {
        let columns = self.links[i].subspace.clone();
        columns
            .iter()
            .map(|s| self.a.dot((0..6).map(|k| (s[k], x[k]))))
            .collect()
    }

    /// The generalized forces M ÿ + h by recursive Newton–Euler, at
    /// accelerations `accels` (zero when None), with the velocity terms
    /// when `moving` (else at zero speeds: the gravity term).
    pub fn newton_euler(
        &mut self,
        speeds: &[Id],
        accels: Option<&[Id]>,
        moving: bool,
    ) -> R<Vec<Id>> {
        let n = self.links.len();
        let zero = self.a.zero();
        let rest = vec![zero; self.size];
        let speeds = if moving { speeds } else { &rest[..] };
        let vel = self.velocities(speeds)?;
        let mut acc: Vec<V6> = Vec::with_capacity(n);
        let mut forces: Vec<V6> = Vec::with_capacity(n);
        for i in 0..n {
            let mut a = self.parent_acceleration(i, &acc)?;
            if let Some(qdd) = accels {
                let sa = self.along_subspace(i, qdd)?;
                a = self.a.add(a, sa)?;
            }
            let (v, joint) = vel[i];
            let coriolis = self.a.cross_motion(v, joint)?;
            a = self.a.add(a, coriolis)?;
            a = self.a.hold(a)?;
            let inertia = self.links[i].inertia;
            let ia = self.a.mat6_vec(&inertia, a)?;
            let iv = self.a.mat6_vec(&inertia, v)?;
            let gyro = self.a.cross_force(v, iv)?;
            let f = self.a.add(ia, gyro)?;
            forces.push(self.a.hold(f)?);
            acc.push(a);
        }
        let mut tau = vec![zero; self.size];
        for i in (0..n).rev() {
            let projected = self.project(i, forces[i])?;
            for (c, value) in projected.into_iter().enumerate() {
                tau[self.links[i].speeds[c]] = value;
            }
            if let Some(p) = self.links[i].parent {
                let moved = self
                    .a
                    .force_to_parent(&self.links[i].transform, forces[i])?;
                let sum = self.a.add(forces[p], moved)?;
                forces[p] = self.a.hold(sum)?;
            }
        }
        Ok(tau)
    }

    /// T = ½ Σ vᵢ · Iᵢ vᵢ over the links, from the velocity recursion.
    pub fn kinetic_energy(&mut self, speeds: &[Id]) -> R<Id> {
        let vel = self.velocities(speeds)?;
        let mut terms = Vec::with_capacity(vel.len());
        for (i, (v, _)) in vel.iter().enumerate() {
            let iv = self.a.mat6_vec(&self.links[i].inertia, *v)?;
            terms.push(self.a.dot((0..6).map(|k| (v[k], iv[k])))?);
        }
        let twice = self.a.g.sum(&terms)?;
        self.a.g.scale(twice, Number::ratio(1, 2).expect("1/2"))
    }

    /// The joints' inputs as generalized forces, in speed order.
    pub fn inputs(&self) -> Vec<Id> {
        let mut out = vec![self.a.zero(); self.size];
        for link in self.links {
            for (c, &input) in link.inputs.iter().enumerate() {
                out[link.speeds[c]] = input;
            }
        }
        out
    }

    /// M by the composite-rigid-body algorithm, row-major over the speeds.
    pub fn composite_rigid_body(&mut self) -> R<Vec<Id>> {
        let (n, size) = (self.links.len(), self.size);
        // Unlike the other recursions' quantities, the composite inertias
        // are not held: their entries collect over the subtree into few
        // terms, and holding them measured more operations, not fewer.
        let mut composite: Vec<M6> = self.links.iter().map(|l| l.inertia).collect();
        for i in (0..n).rev() {
            if let Some(p) = self.links[i].parent {
                let moved = self.a.congruence(&self.links[i].transform, &composite[i])?;
                composite[p] = self.a.add6(&composite[p], &moved)?;
            }
        }
        let mut m = vec![self.a.zero(); size * size];
        for i in 0..n {
            let columns = self.links[i].subspace.clone();
            for (c, s) in columns.iter().enumerate() {
                let row = self.links[i].speeds[c];
                let mut f = self.a.mat6_vec(&composite[i], *s)?;
                for (d, value) in self.project(i, f)?.into_iter().enumerate() {
                    let col = self.links[i].speeds[d];
                    m[row * size + col] = value;
                }
                let mut j = i;
                while let Some(p) = self.links[j].parent {
                    f = self.a.force_to_parent(&self.links[j].transform, f)?;
                    j = p;
                    for (d, value) in self.project(j, f)?.into_iter().enumerate() {
                        let col = self.links[j].speeds[d];
                        m[row * size + col] = value;
                        m[col * size + row] = value;
                    }
                }
            }
        }
        Ok(m)
    }

    /// ÿ by the articulated-body algorithm, the inputs as the joint
    /// forces, in speed order.
    pub fn articulated_body(&mut self, speeds: &[Id]) -> R<Vec<Id>> {
        let n = self.links.len();
        let vel = self.velocities(speeds)?;
        let mut inertia: Vec<M6> = self.links.iter().map(|l| l.inertia).collect();
        let mut bias: Vec<V6> = Vec::with_capacity(n);
        let mut coriolis: Vec<V6> = Vec::with_capacity(n);
        for (i, (v, joint)) in vel.iter().enumerate() {
            coriolis.push(self.a.cross_motion(*v, *joint)?);
            let iv = self.a.mat6_vec(&self.links[i].inertia, *v)?;
            bias.push(self.a.cross_force(*v, iv)?);
        }
        let mut solved: Vec<Articulated> = Vec::with_capacity(n);
        for i in (0..n).rev() {
            let step = self.articulate(i, &inertia[i], bias[i])?;
            if let Some(p) = self.links[i].parent {
                let (ia, pa) = self.handed_on(i, &step, &inertia[i], bias[i], coriolis[i])?;
                let (ia, pa) = (self.a.hold6(&ia)?, self.a.hold(pa)?);
                let transform = self.links[i].transform;
                let moved = self.a.congruence(&transform, &ia)?;
                let sum = self.a.add6(&inertia[p], &moved)?;
                inertia[p] = self.a.hold6(&sum)?;
                let pushed = self.a.force_to_parent(&transform, pa)?;
                let sum = self.a.add(bias[p], pushed)?;
                bias[p] = self.a.hold(sum)?;
            }
            solved.push(step);
        }
        solved.reverse();
        let zero = self.a.zero();
        let mut acc: Vec<V6> = Vec::with_capacity(n);
        let mut qdd = vec![zero; self.size];
        for i in 0..n {
            let parent = self.parent_acceleration(i, &acc)?;
            let a = self.a.add(parent, coriolis[i])?;
            let step = &solved[i];
            let k = step.u.len();
            let mut free = Vec::with_capacity(k);
            for c in 0..k {
                let ua = self.a.dot((0..6).map(|r| (step.big_u[c][r], a[r])))?;
                free.push(self.a.g.sub(step.u[c], ua)?);
            }
            let solved = step.factor.solve(&mut self.a, &free)?;
            for (c, value) in solved.into_iter().enumerate() {
                qdd[self.links[i].speeds[c]] = value;
            }
            let sa = self.along_subspace(i, &qdd)?;
            let sum = self.a.add(a, sa)?;
            acc.push(self.a.hold(sum)?);
        }
        Ok(qdd)
    }

    /// Link `i`'s articulated quantities: U = I S, D⁻¹ = (Sᵀ U)⁻¹ and
    /// u = τ − Sᵀ p.
    fn articulate(&mut self, i: usize, inertia: &M6, bias: V6) -> R<Articulated> {
        let columns = self.links[i].subspace.clone();
        let k = columns.len();
        let mut big_u = Vec::with_capacity(k);
        for s in &columns {
            big_u.push(self.a.mat6_vec(inertia, *s)?);
        }
        let mut d = vec![vec![self.a.zero(); k]; k];
        for (c, row) in d.iter_mut().enumerate() {
            for (e, x) in row.iter_mut().enumerate().skip(c) {
                *x = self.project(i, big_u[e])?[c];
            }
        }
        for c in 0..k {
            for e in 0..c {
                d[c][e] = d[e][c];
            }
        }
        let factor = Factor::new(&mut self.a, &d)?;
        let sp = self.project(i, bias)?;
        let mut u = Vec::with_capacity(k);
        for c in 0..k {
            u.push(self.a.g.sub(self.links[i].inputs[c], sp[c])?);
        }
        Ok(Articulated { big_u, factor, u })
    }

    /// What link `i` hands its parent, in its own axes: its articulated
    /// inertia Iᴬ − U D⁻¹ Uᵀ and bias p + Iᴬ' c + U D⁻¹ u.
    fn handed_on(
        &mut self,
        i: usize,
        step: &Articulated,
        inertia: &M6,
        bias: V6,
        coriolis: V6,
    ) -> R<(M6, V6)> {
        let k = step.u.len();
        // U D⁻¹, a row of U at a time (D is symmetric).
        let mut ud = vec![[self.a.zero(); 6]; k];
        for r in 0..6 {
            let row: Vec<Id> = (0..k).map(|e| step.big_u[e][r]).collect();
            for (c, x) in step
                .factor
                .solve(&mut self.a, &row)?
                .into_iter()
                .enumerate()
            {
                ud[c][r] = x;
            }
        }
        // Rows and columns along a coordinate axis of the subspace vanish:
        // (Iᴬ − U D⁻¹ Uᵀ) S = 0.
        let axes = self.axes_of(i);
        let mut ia = *inertia;
        for r in 0..6 {
            for c in r..6 {
                if axes.contains(&r) || axes.contains(&c) {
                    ia[r][c] = self.a.zero();
                } else {
                    let outer = self.a.dot((0..k).map(|e| (ud[e][r], step.big_u[e][c])))?;
                    ia[r][c] = self.a.g.sub(ia[r][c], outer)?;
                }
                ia[c][r] = ia[r][c];
            }
        }
        let ic = self.a.mat6_vec(&ia, coriolis)?;
        let mut pushes = Vec::with_capacity(k);
        for c in 0..k {
            pushes.push(self.a.scale(ud[c], step.u[c])?);
        }
        let mut pa = self.a.add(bias, ic)?;
        for uu in pushes {
            pa = self.a.add(pa, uu)?;
        }
        Ok((ia, pa))
    }

    /// The axes (0..6) along which link `i`'s columns lie, when every
    /// column lies along one.
    fn axes_of(&self, i: usize) -> Vec<usize> {
        let g = &*self.a.g;
        let mut axes = Vec::new();
        for s in &self.links[i].subspace {
            let along: Vec<usize> = (0..6).filter(|&r| !g.is_zero(s[r])).collect();
            match along[..] {
                [r] => axes.push(r),
                _ => return Vec::new(),
            }
        }
        axes
    }
}

/// One link's quantities of the articulated-body algorithm.
struct Articulated {
    /// U = Iᴬ S, a column per speed.
    big_u: Vec<V6>,
    /// D = Sᵀ Iᴬ S, factored.
    factor: Factor,
    /// u = τ − Sᵀ pᴬ.
    u: Vec<Id>,
}

/// A symmetric positive definite k×k matrix as L diag(d) Lᵀ, unit lower
/// L, with the reciprocals of d: one joint's D of the articulated-body
/// algorithm (1×1 for one degree of freedom, 3×3 for a ball, 6×6 for a
/// free joint).
struct Factor {
    /// L below the diagonal, row-major.
    lower: Vec<Vec<Id>>,
    /// 1 / dᵢ.
    reciprocals: Vec<Id>,
}

impl Factor {
    /// The factors of `d`.
    fn new(a: &mut Algebra, d: &[Vec<Id>]) -> R<Factor> {
        let k = d.len();
        let mut lower = vec![vec![a.zero(); k]; k];
        let mut pivots = vec![a.zero(); k];
        let mut reciprocals = vec![a.zero(); k];
        for j in 0..k {
            // dⱼ = Dⱼⱼ − Σ Lⱼₘ² dₘ; Lᵢⱼ = (Dᵢⱼ − Σ Lᵢₘ Lⱼₘ dₘ) / dⱼ.
            let mut terms = Vec::with_capacity(j);
            for m in 0..j {
                let ld = a.g.mul(lower[j][m], pivots[m])?;
                terms.push((ld, lower[j][m]));
            }
            let taken = a.dot(terms)?;
            pivots[j] = a.g.sub(d[j][j], taken)?;
            reciprocals[j] = a.g.recip(pivots[j])?;
            for i in j + 1..k {
                let mut terms = Vec::with_capacity(j);
                for m in 0..j {
                    let ld = a.g.mul(lower[j][m], pivots[m])?;
                    terms.push((ld, lower[i][m]));
                }
                let taken = a.dot(terms)?;
                let rest = a.g.sub(d[i][j], taken)?;
                lower[i][j] = a.g.mul(rest, reciprocals[j])?;
            }
        }
        Ok(Factor { lower, reciprocals })
    }

    /// D⁻¹ b.
    fn solve(&self, a: &mut Algebra, b: &[Id]) -> R<Vec<Id>> {
        let k = b.len();
        let mut x = b.to_vec();
        for i in 0..k {
            let taken = a.dot((0..i).map(|m| (self.lower[i][m], x[m])))?;
            x[i] = a.g.sub(x[i], taken)?;
        }
        for i in 0..k {
            x[i] = a.dot([(x[i], self.reciprocals[i])])?;
        }
        for i in (0..k).rev() {
            let taken = a.dot((i + 1..k).map(|m| (self.lower[m][i], x[m])))?;
            x[i] = a.g.sub(x[i], taken)?;
        }
        Ok(x)
    }
}
