//! What the assembly reads from a model besides its equations: the index
//! sets of its [`ModelInfo`], its geometry at one `(q, t)`, and finiteness
//! checks.

use super::error::OracleError;
use appell_core::dynamic::DynModel;
use appell_core::Scalar;
use appell_core::{ModelError, ModelInfo};
use num_dual::Dual64;

/// Coordinate index sets derived from a validated [`ModelInfo`].
pub(super) struct Layout {
    pub(super) n: usize,
    pub(super) m: usize,
    pub(super) bodies: usize,
    pub(super) points: usize,
    pub(super) frames: usize,
    pub(super) inputs: usize,
    pub(super) l: usize,
    pub(super) retained: Vec<usize>,
}

fn index_of(info: &ModelInfo, name: &str, list: &str) -> Result<usize, OracleError> {
    info.coordinate_index(name).ok_or_else(|| {
        OracleError::InvalidInfo(format!("`{name}` in `{list}` is not a coordinate"))
    })
}

impl Layout {
    pub(super) fn new(info: &ModelInfo) -> Result<Self, OracleError> {
        let n = info.coordinates.len();
        for (i, c) in info.coordinates.iter().enumerate() {
            if info.coordinates[..i].contains(c) {
                return Err(OracleError::InvalidInfo(format!(
                    "coordinate `{c}` is declared twice"
                )));
            }
        }
        let l = info.speeds.len();
        if info.constraints + l != n {
            return Err(OracleError::InvalidInfo(format!(
                "{n} coordinates, {l} privileged speeds and {} constraint rows: the rows and the speeds' definitions must determine exactly the {n} rates",
                info.constraints
            )));
        }
        let retained = info
            .retained
            .iter()
            .map(|r| index_of(info, r, "retained"))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Layout {
            n,
            m: info.constraints,
            bodies: info.bodies.len(),
            points: info.force_points,
            frames: info.torques,
            inputs: info.inputs.len(),
            l,
            retained,
        })
    }
}

/// Everything position-like a model gives at one `(q, t)`, in one scalar.
pub(super) struct Geometry<T> {
    pub(super) positions: Vec<[T; 3]>,
    pub(super) rotations: Vec<[T; 9]>,
    pub(super) points: Vec<[T; 3]>,
    pub(super) frames: Vec<[T; 9]>,
}

/// The scalars the oracle evaluates the geometry in, each with the
/// [`DynModel`] methods of its own.
pub(super) trait GeometryScalar: Scalar {
    fn body_poses<K: DynModel + ?Sized>(
        model: &K,
        t: Self,
        q: &[Self],
        positions: &mut [[Self; 3]],
        rotations: &mut [[Self; 9]],
    ) -> Result<(), ModelError>;

    fn load_geometry<K: DynModel + ?Sized>(
        model: &K,
        t: Self,
        q: &[Self],
        points: &mut [[Self; 3]],
        frames: &mut [[Self; 9]],
    ) -> Result<(), ModelError>;
}

impl GeometryScalar for f64 {
    fn body_poses<K: DynModel + ?Sized>(
        model: &K,
        t: f64,
        q: &[f64],
        positions: &mut [[f64; 3]],
        rotations: &mut [[f64; 9]],
    ) -> Result<(), ModelError> {
        model.dyn_body_poses(t, q, positions, rotations)
    }

    fn load_geometry<K: DynModel + ?Sized>(
        model: &K,
        t: f64,
        q: &[f64],
        points: &mut [[f64; 3]],
        frames: &mut [[f64; 9]],
    ) -> Result<(), ModelError> {
        model.dyn_load_geometry(t, q, points, frames)
    }
}

impl GeometryScalar for Dual64 {
    fn body_poses<K: DynModel + ?Sized>(
        model: &K,
        t: Dual64,
        q: &[Dual64],
        positions: &mut [[Dual64; 3]],
        rotations: &mut [[Dual64; 9]],
    ) -> Result<(), ModelError> {
        model.dyn_body_poses_dual(t, q, positions, rotations)
    }

    fn load_geometry<K: DynModel + ?Sized>(
        model: &K,
        t: Dual64,
        q: &[Dual64],
        points: &mut [[Dual64; 3]],
        frames: &mut [[Dual64; 9]],
    ) -> Result<(), ModelError> {
        model.dyn_load_geometry_dual(t, q, points, frames)
    }
}

impl<T: GeometryScalar> Geometry<T> {
    pub(super) fn eval<K: DynModel + ?Sized>(
        model: &K,
        lay: &Layout,
        t: T,
        q: &[T],
    ) -> Result<Self, OracleError> {
        let mut g = Geometry {
            positions: vec![[T::zero(); 3]; lay.bodies],
            rotations: vec![[T::zero(); 9]; lay.bodies],
            points: vec![[T::zero(); 3]; lay.points],
            frames: vec![[T::zero(); 9]; lay.frames],
        };
        T::body_poses(model, t, q, &mut g.positions, &mut g.rotations)?;
        T::load_geometry(model, t, q, &mut g.points, &mut g.frames)?;
        Ok(g)
    }
}

pub(crate) fn finite_all(
    xs: impl IntoIterator<Item = f64>,
    what: &'static str,
) -> Result<(), OracleError> {
    for x in xs {
        if !x.is_finite() {
            return Err(ModelError::NonFinite { what }.into());
        }
    }
    Ok(())
}
