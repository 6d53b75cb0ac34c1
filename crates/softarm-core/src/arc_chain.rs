//! An n-segment arc chain in configuration space (planning paper eq. 1–5).

use crate::arc::ArcParams;
use crate::chain::{SectionModel, SectionState};
use crate::error::{check_bounded, check_len, check_parameter, Error, Result, MAX_COORDINATE};
use crate::kinematics::Kinematics;
use crate::math::{Mat3, Vec3};

/// A chain of constant-curvature segments with coordinates `q_i = [L_i, Θ_i, φ_i]`:
/// length, bending angle and bending direction. Segment i's tip frame relative to its
/// base is `R_i = Rz(φ_i) Ry(Θ_i)` (eq. 2) at position `P_i` (eq. 3); segments follow
/// each other with no offset (eq. 4).
///
/// Note that at `Θ_i = 0` the direction `φ_i` only twists the following segments about
/// their common axis: that is the paper's parametrisation, and its Jacobian is exact.
#[derive(Debug, Clone, PartialEq)]
pub struct ArcChain {
    lengths: Vec<f64>,
    lower: Vec<f64>,
    upper: Vec<f64>,
}

impl ArcChain {
    /// Smallest static segment length (m).
    pub const MIN_LENGTH: f64 = 1e-6;
    /// Largest static segment length (m); the default length limits (1.5 L) then stay well
    /// inside [`crate::error::MAX_COORDINATE`].
    pub const MAX_LENGTH: f64 = 1e4;

    /// A chain with static segment lengths `lengths` and default limits: length in
    /// [0.5, 1.5]·L0, Θ in [−π, π], φ in [−2π, 2π].
    ///
    /// # Errors
    /// [`Error::Shape`] for no segment, [`Error::Parameter`] for a length outside
    /// [[`ArcChain::MIN_LENGTH`], [`ArcChain::MAX_LENGTH`]].
    pub fn new(lengths: &[f64]) -> Result<Self> {
        if lengths.is_empty() {
            return Err(Error::shape("lengths", "at least one segment", "none"));
        }
        for (i, &l) in lengths.iter().enumerate() {
            check_parameter(
                &format!("lengths[{i}]"),
                l,
                Self::MIN_LENGTH,
                Self::MAX_LENGTH,
            )?;
        }
        let pi = std::f64::consts::PI;
        let lower = lengths
            .iter()
            .flat_map(|&l| [0.5 * l, -pi, -2.0 * pi])
            .collect();
        let upper = lengths
            .iter()
            .flat_map(|&l| [1.5 * l, pi, 2.0 * pi])
            .collect();
        Ok(ArcChain {
            lengths: lengths.to_vec(),
            lower,
            upper,
        })
    }

    /// The same chain with explicit limits (3 per segment).
    ///
    /// # Errors
    /// [`Error::Shape`], [`Error::NonFinite`], [`Error::OutOfRange`] for a limit beyond
    /// [`crate::error::MAX_COORDINATE`], or [`Error::Parameter`] when a lower limit
    /// is not below its upper limit or a length limit is not positive.
    pub fn with_limits(mut self, lower: &[f64], upper: &[f64]) -> Result<Self> {
        let n = 3 * self.lengths.len();
        check_len("lower", lower, n)?;
        check_len("upper", upper, n)?;
        check_bounded("lower", lower, MAX_COORDINATE)?;
        check_bounded("upper", upper, MAX_COORDINATE)?;
        for i in 0..n {
            if lower[i] >= upper[i] {
                return Err(Error::parameter(
                    &format!("lower[{i}]"),
                    lower[i],
                    format!("must be smaller than upper[{i}] = {}", upper[i]),
                ));
            }
            if i % 3 == 0 && lower[i] <= 0.0 {
                return Err(Error::parameter(
                    &format!("lower[{i}]"),
                    lower[i],
                    "a length limit must be positive",
                ));
            }
        }
        self.lower = lower.to_vec();
        self.upper = upper.to_vec();
        Ok(self)
    }

    /// Static segment lengths.
    pub fn lengths(&self) -> &[f64] {
        &self.lengths
    }

    /// The straight configuration at the static lengths.
    pub fn straight(&self) -> Vec<f64> {
        self.lengths.iter().flat_map(|&l| [l, 0.0, 0.0]).collect()
    }
}

impl SectionModel for ArcChain {
    fn n_sections(&self) -> usize {
        self.lengths.len()
    }

    #[inline]
    fn section_state(&self, _i: usize, qi: &[f64]) -> SectionState {
        let (len, bend, dir) = (qi[0], qi[1], qi[2]);
        let (s, c) = dir.sin_cos();
        SectionState {
            arc: ArcParams {
                length: len,
                ux: bend * c,
                uy: bend * s,
            },
            // ∂(L, Θ cos φ, Θ sin φ)/∂(L, Θ, φ)
            d_arc: Mat3::new(1.0, 0.0, 0.0, 0.0, c, -bend * s, 0.0, s, bend * c),
            offset: 0.0,
            // Rz(φ) Ry(Θ) = [Rz(φ) Ry(Θ) Rz(−φ)] · Rz(φ): the arc, then a twist by φ.
            twist: (c, s),
            d_twist: Vec3::new(0.0, 0.0, 1.0),
        }
    }
}

impl Kinematics for ArcChain {
    fn lower(&self) -> &[f64] {
        &self.lower
    }
    fn upper(&self) -> &[f64] {
        &self.upper
    }
}
