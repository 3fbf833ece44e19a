//! Spatial inertias about the world origin and their variations by a
//! velocity, kept by their blocks: a mass, a 3-vector and a symmetric
//! 3×3 matrix instead of 36 entries.

use appell_symbolic::{Id, SymbolicError};

use super::super::spatial::{join, split, Algebra, Transform, M3, M6, V3, V6};

type R<T> = Result<T, SymbolicError>;

/// A symmetric 6×6 matrix of the shape of a spatial inertia about the
/// world origin, [[A, h̃], [−h̃, m 1]] (A symmetric): the inertia itself
/// (m, h = m c, A the rotational inertia about the origin), or with m = 0
/// its variation by a velocity.
#[derive(Clone, Copy)]
pub struct Shaped {
    /// The mass (0 for a variation).
    pub m: Id,
    /// h: m c for an inertia.
    pub h: V3,
    /// A, symmetric.
    pub a: M3,
}

impl Shaped {
    /// The zero inertia (a massless node).
    pub fn zero(al: &Algebra) -> Shaped {
        let z = al.zero();
        Shaped {
            m: z,
            h: [z; 3],
            a: [[z; 3]; 3],
        }
    }

    /// Y x = (A x_ω + h × x_ν, x_ω × h + m x_ν).
    pub fn apply(&self, al: &mut Algebra, x: V6) -> R<V6> {
        let (w, v) = split(x);
        let aw = al.mat_vec(&self.a, w)?;
        let hv = al.cross(self.h, v)?;
        let top = al.add(aw, hv)?;
        let wh = al.cross(w, self.h)?;
        let mv = al.scale(v, self.m)?;
        let bottom = al.add(wh, mv)?;
        Ok(join(top, bottom))
    }

    /// The entrywise sum.
    pub fn add(&self, al: &mut Algebra, other: &Shaped) -> R<Shaped> {
        let mut a = self.a;
        for (r, row) in a.iter_mut().enumerate() {
            for c in r..3 {
                row[c] = al.g.add(self.a[r][c], other.a[r][c])?;
            }
        }
        mirror(&mut a);
        Ok(Shaped {
            m: al.g.add(self.m, other.m)?,
            h: al.add(self.h, other.h)?,
            a,
        })
    }

    /// Each entry held.
    pub fn hold(&self, al: &mut Algebra) -> R<Shaped> {
        let mut a = self.a;
        for (r, row) in a.iter_mut().enumerate() {
            for c in r..3 {
                row[c] = al.g.hold(self.a[r][c])?;
            }
        }
        mirror(&mut a);
        Ok(Shaped {
            m: al.g.hold(self.m)?,
            h: al.hold(self.h)?,
            a,
        })
    }

    /// A link's inertia `y` (about its origin, in its axes) about the
    /// world origin in world axes, the link placed by `world`:
    /// h = R h_L + m p and A = R A_L Rᵀ − m p pᵀ + m |p|² 1 − h' pᵀ − p h'ᵀ
    /// + 2 (p · h') 1 with h' = R h_L.
    pub fn placed(al: &mut Algebra, y: &M6, world: &Transform) -> R<Shaped> {
        let (r, p) = (&world.rot, world.pos);
        let m = y[3][3];
        // h̃ is y's upper right block.
        let local = [y[2][4], y[0][5], y[1][3]];
        let turned = al.mat_vec(r, local)?;
        let mp = al.scale(p, m)?;
        let h = al.add(turned, mp)?;
        let a_local = [
            [y[0][0], y[0][1], y[0][2]],
            [y[1][0], y[1][1], y[1][2]],
            [y[2][0], y[2][1], y[2][2]],
        ];
        let ra = al.mat_mul(r, &a_local)?;
        let pp = al.dot((0..3).map(|k| (p[k], p[k])))?;
        let ph = al.dot((0..3).map(|k| (p[k], turned[k])))?;
        let mpp = al.g.mul(m, pp)?;
        let two = al.g.int(2)?;
        let twice = al.g.mul(two, ph)?;
        let diagonal = al.g.add(mpp, twice)?;
        let mut a = [[al.zero(); 3]; 3];
        for i in 0..3 {
            for j in i..3 {
                let rar = al.dot((0..3).map(|k| (ra[i][k], r[j][k])))?;
                let outer = al.dot([(mp[i], p[j]), (turned[i], p[j]), (p[i], turned[j])])?;
                let mut entry = al.g.sub(rar, outer)?;
                if i == j {
                    entry = al.g.add(entry, diagonal)?;
                }
                a[i][j] = entry;
            }
        }
        mirror(&mut a);
        Ok(Shaped { m, h, a })
    }

    /// v ×* Y − Y v× for the velocity v = (ω, ν), of the same shape with
    /// m = 0: A' = ω̃A − Aω̃ − h νᵀ − ν hᵀ + 2 (ν · h) 1, h' = ω × h + m ν.
    pub fn variation(&self, al: &mut Algebra, v: V6) -> R<Shaped> {
        let (w, nu) = split(v);
        let columns: Vec<V3> = (0..3)
            .map(|j| al.cross(w, [self.a[0][j], self.a[1][j], self.a[2][j]]))
            .collect::<R<_>>()?;
        let nh = al.dot((0..3).map(|k| (nu[k], self.h[k])))?;
        let two = al.g.int(2)?;
        let diagonal = al.g.mul(two, nh)?;
        let mut a = [[al.zero(); 3]; 3];
        for i in 0..3 {
            for j in i..3 {
                let turned = al.g.add(columns[j][i], columns[i][j])?;
                let outer = al.dot([(self.h[i], nu[j]), (nu[i], self.h[j])])?;
                let mut entry = al.g.sub(turned, outer)?;
                if i == j {
                    entry = al.g.add(entry, diagonal)?;
                }
                a[i][j] = entry;
            }
        }
        mirror(&mut a);
        let wh = al.cross(w, self.h)?;
        let mnu = al.scale(nu, self.m)?;
        Ok(Shaped {
            m: al.zero(),
            h: al.add(wh, mnu)?,
            a,
        })
    }
}

/// The lower triangle set from the upper.
fn mirror(a: &mut M3) {
    for r in 0..3 {
        for c in 0..r {
            a[r][c] = a[c][r];
        }
    }
}
