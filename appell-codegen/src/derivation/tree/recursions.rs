//! The recursions over the links: articulated-body (ÿ), recursive
//! Newton–Euler (generalized forces) and composite-rigid-body (M), in
//! Featherstone's form (Rigid Body Dynamics Algorithms, 2008, Tables 5.1,
//! 6.2 and 7.1), with gravity as an acceleration of the ground.

use appell_symbolic::{Graph, Id, Number, SymbolicError};

use super::links::Link;
use super::spatial::{join, Algebra, M6, V3, V6};

type R<T> = Result<T, SymbolicError>;

/// The links and the graph the recursions write into.
pub struct Recursions<'g, 'l> {
    a: Algebra<'g>,
    links: &'l [Link],
    /// The ground's acceleration: −gravity.
    ground: V6,
}

impl<'g, 'l> Recursions<'g, 'l> {
    /// The recursions over `links` under `gravity` (in N's axes).
    pub fn new(g: &'g mut Graph, links: &'l [Link], gravity: V3) -> R<Recursions<'g, 'l>> {
        let a = Algebra::new(g)?;
        let zero = a.zero();
        let up = [
            a.g.neg(gravity[0])?,
            a.g.neg(gravity[1])?,
            a.g.neg(gravity[2])?,
        ];
        Ok(Recursions {
            a,
            links,
            ground: join([zero; 3], up),
        })
    }

    /// Each link's velocity and the joint's velocity S q̇.
    fn velocities(&mut self, speeds: &[Id]) -> R<Vec<(V6, V6)>> {
        let mut out: Vec<(V6, V6)> = Vec::with_capacity(self.links.len());
        for (i, link) in self.links.iter().enumerate() {
            let joint = self.a.scale(link.subspace, speeds[i])?;
            let v = match link.parent {
                Some(p) => {
                    let moved = self.a.motion_to_child(&link.transform, out[p].0)?;
                    self.a.add(moved, joint)?
                }
                None => joint,
            };
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

    /// Sᵀ x.
    fn project(&mut self, i: usize, x: V6) -> R<Id> {
        let s = self.links[i].subspace;
        self.a.dot((0..6).map(|k| (s[k], x[k])))
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
        let rest = vec![zero; n];
        let speeds = if moving { speeds } else { &rest[..] };
        let vel = self.velocities(speeds)?;
        let mut acc: Vec<V6> = Vec::with_capacity(n);
        let mut forces: Vec<V6> = Vec::with_capacity(n);
        for i in 0..n {
            let mut a = self.parent_acceleration(i, &acc)?;
            if let Some(qdd) = accels {
                let sa = self.a.scale(self.links[i].subspace, qdd[i])?;
                a = self.a.add(a, sa)?;
            }
            let (v, joint) = vel[i];
            let coriolis = self.a.cross_motion(v, joint)?;
            a = self.a.add(a, coriolis)?;
            let inertia = self.links[i].inertia;
            let ia = self.a.mat6_vec(&inertia, a)?;
            let iv = self.a.mat6_vec(&inertia, v)?;
            let gyro = self.a.cross_force(v, iv)?;
            forces.push(self.a.add(ia, gyro)?);
            acc.push(a);
        }
        let mut tau = vec![zero; n];
        for i in (0..n).rev() {
            tau[i] = self.project(i, forces[i])?;
            if let Some(p) = self.links[i].parent {
                let moved = self
                    .a
                    .force_to_parent(&self.links[i].transform, forces[i])?;
                forces[p] = self.a.add(forces[p], moved)?;
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
        self.links.iter().map(|l| l.input).collect()
    }

    /// M by the composite-rigid-body algorithm, l×l row-major.
    pub fn composite_rigid_body(&mut self) -> R<Vec<Id>> {
        let n = self.links.len();
        let mut composite: Vec<M6> = self.links.iter().map(|l| l.inertia).collect();
        for i in (0..n).rev() {
            if let Some(p) = self.links[i].parent {
                let moved = self.a.congruence(&self.links[i].transform, &composite[i])?;
                composite[p] = self.a.add6(&composite[p], &moved)?;
            }
        }
        let mut m = vec![self.a.zero(); n * n];
        for i in 0..n {
            let mut f = self.a.mat6_vec(&composite[i], self.links[i].subspace)?;
            m[i * n + i] = self.project(i, f)?;
            let mut j = i;
            while let Some(p) = self.links[j].parent {
                f = self.a.force_to_parent(&self.links[j].transform, f)?;
                j = p;
                m[i * n + j] = self.project(j, f)?;
                m[j * n + i] = m[i * n + j];
            }
        }
        Ok(m)
    }

    /// ÿ by the articulated-body algorithm, the inputs as the joint forces.
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
        let zero = self.a.zero();
        let (mut u, mut d_inv, mut big_u) = (vec![zero; n], vec![zero; n], vec![[zero; 6]; n]);
        for i in (0..n).rev() {
            let s = self.links[i].subspace;
            big_u[i] = self.a.mat6_vec(&inertia[i], s)?;
            let d = self.project(i, big_u[i])?;
            d_inv[i] = self.a.g.recip(d)?;
            let sp = self.project(i, bias[i])?;
            u[i] = self.a.g.sub(self.links[i].input, sp)?;
            let Some(p) = self.links[i].parent else {
                continue;
            };
            let ud = self.a.scale(big_u[i], d_inv[i])?;
            let mut ia = inertia[i];
            for r in 0..6 {
                for c in r..6 {
                    let outer = self.a.dot([(ud[r], big_u[i][c])])?;
                    ia[r][c] = self.a.g.sub(ia[r][c], outer)?;
                    ia[c][r] = ia[r][c];
                }
            }
            let ic = self.a.mat6_vec(&ia, coriolis[i])?;
            let uu = self.a.scale(ud, u[i])?;
            let pa = self.a.add(bias[i], ic)?;
            let pa = self.a.add(pa, uu)?;
            let moved = self.a.congruence(&self.links[i].transform, &ia)?;
            inertia[p] = self.a.add6(&inertia[p], &moved)?;
            let pushed = self.a.force_to_parent(&self.links[i].transform, pa)?;
            bias[p] = self.a.add(bias[p], pushed)?;
        }
        let mut acc: Vec<V6> = Vec::with_capacity(n);
        let mut qdd = vec![zero; n];
        for i in 0..n {
            let parent = self.parent_acceleration(i, &acc)?;
            let a = self.a.add(parent, coriolis[i])?;
            let ua = self.a.dot((0..6).map(|k| (big_u[i][k], a[k])))?;
            let num = self.a.g.sub(u[i], ua)?;
            qdd[i] = self.a.g.mul(num, d_inv[i])?;
            let sa = self.a.scale(self.links[i].subspace, qdd[i])?;
            acc.push(self.a.add(a, sa)?);
        }
        Ok(qdd)
    }
}
