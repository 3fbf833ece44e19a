//! Spatial (6D) vector algebra in the expression graph, in Featherstone's
//! conventions: a motion vector is (angular, linear) about a link's
//! origin in the link's axes, a force vector (moment, force). Products
//! with literal zeros and ones are not made, so a joint axis along z or a
//! placement along one axis leaves only the terms that remain.

use appell_symbolic::{Graph, Id, SymbolicError};

type R<T> = Result<T, SymbolicError>;

/// A 3-vector of expressions.
pub type V3 = [Id; 3];
/// A 3×3 matrix of expressions, row-major.
pub type M3 = [[Id; 3]; 3];
/// A spatial vector: (angular, linear) for motion, (moment, force) for
/// force.
pub type V6 = [Id; 6];
/// A 6×6 matrix of expressions, row-major.
pub type M6 = [[Id; 6]; 6];

/// The graph with the few operations the recursions use.
pub struct Algebra<'g> {
    /// The model's graph.
    pub g: &'g mut Graph,
    zero: Id,
}

/// A coordinate transform from a parent link to a child: the child's axes
/// in the parent's (columns of `rot`) and the child's origin in the
/// parent's axes.
#[derive(Clone, Copy)]
pub struct Transform {
    /// Columns: the child's unit vectors in the parent's axes.
    pub rot: M3,
    /// The child's origin from the parent's, in the parent's axes.
    pub pos: V3,
}

impl<'g> Algebra<'g> {
    /// The algebra over `g`.
    pub fn new(g: &'g mut Graph) -> R<Algebra<'g>> {
        let zero = g.int(0)?;
        Ok(Algebra { g, zero })
    }

    /// The literal 0.
    pub fn zero(&self) -> Id {
        self.zero
    }

    /// Σ aᵢ bᵢ over the pairs, leaving out products with a zero factor.
    pub fn dot(&mut self, pairs: impl IntoIterator<Item = (Id, Id)>) -> R<Id> {
        let mut terms = Vec::new();
        for (a, b) in pairs {
            if self.g.is_zero(a) || self.g.is_zero(b) {
                continue;
            }
            terms.push(self.g.mul(a, b)?);
        }
        self.g.sum(&terms)
    }

    /// Each entry held as one factor ([`Graph::hold`]).
    pub fn hold<const N: usize>(&mut self, a: [Id; N]) -> R<[Id; N]> {
        let mut out = a;
        for x in out.iter_mut() {
            *x = self.g.hold(*x)?;
        }
        Ok(out)
    }

    /// Each entry of a 6×6 matrix held as one factor.
    pub fn hold6(&mut self, m: &M6) -> R<M6> {
        let mut out = *m;
        for row in out.iter_mut() {
            *row = self.hold(*row)?;
        }
        Ok(out)
    }

    /// a + b, elementwise.
    pub fn add<const N: usize>(&mut self, a: [Id; N], b: [Id; N]) -> R<[Id; N]> {
        let mut out = [self.zero; N];
        for i in 0..N {
            out[i] = self.g.add(a[i], b[i])?;
        }
        Ok(out)
    }

    /// a − b, elementwise.
    pub fn sub<const N: usize>(&mut self, a: [Id; N], b: [Id; N]) -> R<[Id; N]> {
        let mut out = [self.zero; N];
        for i in 0..N {
            out[i] = self.g.sub(a[i], b[i])?;
        }
        Ok(out)
    }

    /// x + y for 6×6 matrices.
    pub fn add6(&mut self, x: &M6, y: &M6) -> R<M6> {
        let mut out = *x;
        for i in 0..6 {
            out[i] = self.add(x[i], y[i])?;
        }
        Ok(out)
    }

    /// k · a.
    pub fn scale<const N: usize>(&mut self, a: [Id; N], k: Id) -> R<[Id; N]> {
        let mut out = [self.zero; N];
        for i in 0..N {
            out[i] = self.g.mul(a[i], k)?;
        }
        Ok(out)
    }

    /// a × b.
    pub fn cross(&mut self, a: V3, b: V3) -> R<V3> {
        let mut out = [self.zero; 3];
        for i in 0..3 {
            let (j, k) = ((i + 1) % 3, (i + 2) % 3);
            let one = self.dot([(a[j], b[k])])?;
            let two = self.dot([(a[k], b[j])])?;
            out[i] = self.g.sub(one, two)?;
        }
        Ok(out)
    }

    /// m v.
    pub fn mat_vec(&mut self, m: &M3, v: V3) -> R<V3> {
        let mut out = [self.zero; 3];
        for i in 0..3 {
            out[i] = self.dot((0..3).map(|j| (m[i][j], v[j])))?;
        }
        Ok(out)
    }

    /// mᵀ v.
    pub fn mat_t_vec(&mut self, m: &M3, v: V3) -> R<V3> {
        let mut out = [self.zero; 3];
        for i in 0..3 {
            out[i] = self.dot((0..3).map(|j| (m[j][i], v[j])))?;
        }
        Ok(out)
    }

    /// a b.
    pub fn mat_mul(&mut self, a: &M3, b: &M3) -> R<M3> {
        let mut out = [[self.zero; 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                out[i][j] = self.dot((0..3).map(|k| (a[i][k], b[k][j])))?;
            }
        }
        Ok(out)
    }

    /// The motion vector `m` of the parent in the child's axes about the
    /// child's origin: ω' = Rᵀ ω, v' = Rᵀ (v − p × ω).
    pub fn motion_to_child(&mut self, x: &Transform, m: V6) -> R<V6> {
        let (w, v) = split(m);
        let w2 = self.mat_t_vec(&x.rot, w)?;
        let pw = self.cross(x.pos, w)?;
        let shifted = self.sub(v, pw)?;
        let v2 = self.mat_t_vec(&x.rot, shifted)?;
        Ok(join(w2, v2))
    }

    /// The force vector `f` of the child in the parent's axes about the
    /// parent's origin: f' = R f, n' = R n + p × f'.
    pub fn force_to_parent(&mut self, x: &Transform, f: V6) -> R<V6> {
        let (n, f) = split(f);
        let f2 = self.mat_vec(&x.rot, f)?;
        let rn = self.mat_vec(&x.rot, n)?;
        let pf = self.cross(x.pos, f2)?;
        let n2 = self.add(rn, pf)?;
        Ok(join(n2, f2))
    }

    /// The motion cross product a ×ₘ b.
    pub fn cross_motion(&mut self, a: V6, b: V6) -> R<V6> {
        let ((wa, va), (wb, vb)) = (split(a), split(b));
        let w = self.cross(wa, wb)?;
        let one = self.cross(wa, vb)?;
        let two = self.cross(va, wb)?;
        let v = self.add(one, two)?;
        Ok(join(w, v))
    }

    /// The force cross product a ×_f f.
    pub fn cross_force(&mut self, a: V6, f: V6) -> R<V6> {
        let ((wa, va), (n, fl)) = (split(a), split(f));
        let one = self.cross(wa, n)?;
        let two = self.cross(va, fl)?;
        let n2 = self.add(one, two)?;
        let f2 = self.cross(wa, fl)?;
        Ok(join(n2, f2))
    }

    /// m v for a 6×6 matrix.
    pub fn mat6_vec(&mut self, m: &M6, v: V6) -> R<V6> {
        let mut out = [self.zero; 6];
        for i in 0..6 {
            out[i] = self.dot((0..6).map(|j| (m[i][j], v[j])))?;
        }
        Ok(out)
    }

    /// Xᵀ I X for a symmetric I and the motion transform X of `x`: an
    /// inertia of the child in the parent's axes about the parent's
    /// origin. X = [Rᵀ 0; 0 Rᵀ] [1 0; −p̃ 1], so the blocks are turned
    /// first (R A Rᵀ, R B Rᵀ, R C Rᵀ) and then moved by the constant p,
    /// each step a product with a sparse factor.
    pub fn congruence(&mut self, x: &Transform, inertia: &M6) -> R<M6> {
        let zero = self.zero;
        let mut turn = [[zero; 6]; 6];
        for i in 0..3 {
            for j in 0..3 {
                turn[i][j] = x.rot[j][i];
                turn[i + 3][j + 3] = x.rot[j][i];
            }
        }
        let turned = self.symmetric_congruence(&turn, inertia)?;
        let mut shift = [[zero; 6]; 6];
        let one = self.g.int(1)?;
        for (i, row) in shift.iter_mut().enumerate() {
            row[i] = one;
        }
        // −p̃ in the lower left: (−p̃)[i][j] = −ε_ikj p_k.
        for j in 0..3 {
            let mut e = [zero; 3];
            e[j] = one;
            let pe = self.cross(x.pos, e)?;
            for i in 0..3 {
                shift[i + 3][j] = self.g.neg(pe[i])?;
            }
        }
        self.symmetric_congruence(&shift, &turned)
    }

    /// Xᵀ I X for a symmetric I, only the upper triangle formed.
    fn symmetric_congruence(&mut self, x: &M6, inertia: &M6) -> R<M6> {
        let mut ix = [[self.zero; 6]; 6];
        for i in 0..6 {
            for j in 0..6 {
                ix[i][j] = self.dot((0..6).map(|k| (inertia[i][k], x[k][j])))?;
            }
        }
        let mut out = [[self.zero; 6]; 6];
        for i in 0..6 {
            for j in i..6 {
                out[i][j] = self.dot((0..6).map(|k| (x[k][i], ix[k][j])))?;
                out[j][i] = out[i][j];
            }
        }
        Ok(out)
    }

    /// The ground's acceleration under `gravity`: (0, −g), gravity taken
    /// as an acceleration of the ground (Featherstone's device).
    pub fn ground(&mut self, gravity: V3) -> R<V6> {
        let up = [
            self.g.neg(gravity[0])?,
            self.g.neg(gravity[1])?,
            self.g.neg(gravity[2])?,
        ];
        Ok(join([self.zero; 3], up))
    }

    /// The spatial inertia about a link's origin of a body of mass `m`,
    /// mass centre `c` and central inertia `ic`, all in the link's axes:
    /// [[Ic − m c̃ c̃, m c̃], [−m c̃, m 1]].
    pub fn rigid_inertia(&mut self, m: Id, c: V3, ic: &M3) -> R<M6> {
        let mut out = [[self.zero; 6]; 6];
        let mc = self.scale(c, m)?;
        // m c̃ c̃ᵀ = m (|c|² 1 − c cᵀ).
        let cc = self.dot((0..3).map(|k| (c[k], c[k])))?;
        for i in 0..3 {
            for j in 0..3 {
                let outer = self.dot([(mc[i], c[j])])?;
                let shift = if i == j {
                    let d = self.g.mul(m, cc)?;
                    self.g.sub(d, outer)?
                } else {
                    self.g.neg(outer)?
                };
                out[i][j] = self.g.add(ic[i][j], shift)?;
            }
            out[i + 3][i + 3] = m;
        }
        // m c̃ (upper right) and its transpose.
        let tilde = [
            [None, Some((2, -1)), Some((1, 1))],
            [Some((2, 1)), None, Some((0, -1))],
            [Some((1, -1)), Some((0, 1)), None],
        ];
        for (i, row) in tilde.iter().enumerate() {
            for (j, entry) in row.iter().enumerate() {
                if let Some((k, sign)) = entry {
                    let v = if *sign > 0 {
                        mc[*k]
                    } else {
                        self.g.neg(mc[*k])?
                    };
                    out[i][j + 3] = v;
                    out[j + 3][i] = v;
                }
            }
        }
        Ok(out)
    }
}

/// (first three, last three).
pub fn split(v: V6) -> (V3, V3) {
    ([v[0], v[1], v[2]], [v[3], v[4], v[5]])
}

/// The spatial vector (a, b).
pub fn join(a: V3, b: V3) -> V6 {
    [a[0], a[1], a[2], b[0], b[1], b[2]]
}
