//! The pneumatic soft arm in actuator space (redundancy paper eq. 1–6).

use crate::arc::ArcParams;
use crate::chain::{self, SectionModel, SectionState};
use crate::error::{check_len, check_parameter, Error, Result};
use crate::kinematics::Kinematics;
use crate::math::{Mat3, Vec3};
use crate::pneumatic::{arc_params_jacobian, polar_config, PolarConfig};

/// Geometry and limits of one pneumatic section.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Section {
    /// Distance of the actuators from the section's centre line, `r_i` (m).
    pub radius: f64,
    /// Rest length of the actuators, `L0` (m).
    pub rest_length: f64,
    /// Smallest allowed elongation (m).
    pub lower: f64,
    /// Largest allowed elongation (m).
    pub upper: f64,
    /// Offset `b_i` along z from the arc's tip to the next frame (m), eq. (3).
    pub offset: f64,
    /// Twist `β_i` about z from the arc's tip to the next frame (rad), eq. (3).
    pub twist: f64,
}

impl Section {
    /// Smallest actuator radius (m). Bending angles scale as elongation / radius: a
    /// radius far below a millimetre would bend a section thousands of turns (and a
    /// subnormal one overflows the kinematics to NaN).
    pub const MIN_RADIUS: f64 = 1e-4;
    /// Largest actuator radius, rest length, offset and |elongation limit| (m).
    pub const MAX_SIZE: f64 = 100.0;
    /// Smallest rest length (m).
    pub const MIN_REST_LENGTH: f64 = 1e-4;

    /// A validated section.
    ///
    /// # Errors
    /// [`Error::Parameter`] for a non-finite value, a radius outside
    /// [[`Section::MIN_RADIUS`], [`Section::MAX_SIZE`]], a rest length outside
    /// [[`Section::MIN_REST_LENGTH`], [`Section::MAX_SIZE`]], limits or an offset beyond
    /// [`Section::MAX_SIZE`], `lower >= upper`, a lower limit that would give a
    /// non-positive arc length, a negative offset, or a twist beyond one turn.
    pub fn new(
        radius: f64,
        rest_length: f64,
        lower: f64,
        upper: f64,
        offset: f64,
        twist: f64,
    ) -> Result<Self> {
        let tau = std::f64::consts::TAU;
        check_parameter("radius", radius, Self::MIN_RADIUS, Self::MAX_SIZE)?;
        check_parameter(
            "rest_length",
            rest_length,
            Self::MIN_REST_LENGTH,
            Self::MAX_SIZE,
        )?;
        check_parameter("lower", lower, -Self::MAX_SIZE, Self::MAX_SIZE)?;
        check_parameter("upper", upper, -Self::MAX_SIZE, Self::MAX_SIZE)?;
        check_parameter("offset", offset, 0.0, Self::MAX_SIZE)?;
        check_parameter("twist", twist, -tau, tau)?;
        if lower >= upper {
            return Err(Error::parameter(
                "lower",
                lower,
                format!("must be smaller than upper = {upper}"),
            ));
        }
        if lower <= -rest_length {
            return Err(Error::parameter(
                "lower",
                lower,
                format!("must exceed -rest_length = {}", -rest_length),
            ));
        }
        Ok(Section {
            radius,
            rest_length,
            lower,
            upper,
            offset,
            twist,
        })
    }
}

/// A pneumatically actuated continuum arm: sections of three extending actuators each,
/// numbered from 0 (proximal, at the base). Coordinates are the actuator elongations
/// `q = [l11, l12, l13, l21, …]` (m).
#[derive(Debug, Clone, PartialEq)]
pub struct SoftArm {
    sections: Vec<Section>,
    d_arc: Vec<Mat3>,
    twist_cs: Vec<(f64, f64)>,
    lower: Vec<f64>,
    upper: Vec<f64>,
}

impl SoftArm {
    /// An arm from its sections, proximal first.
    ///
    /// # Errors
    /// [`Error::Shape`] for an empty list.
    pub fn new(sections: Vec<Section>) -> Result<Self> {
        if sections.is_empty() {
            return Err(Error::shape("sections", "at least one section", "none"));
        }
        Ok(SoftArm::from_sections(sections))
    }

    /// Builds the cached per-section data; `sections` is non-empty.
    fn from_sections(sections: Vec<Section>) -> Self {
        let d_arc = sections
            .iter()
            .map(|s| arc_params_jacobian(s.radius))
            .collect();
        let twist_cs = sections
            .iter()
            .map(|s| (s.twist.cos(), s.twist.sin()))
            .collect();
        let lower = sections.iter().flat_map(|s| [s.lower; 3]).collect();
        let upper = sections.iter().flat_map(|s| [s.upper; 3]).collect();
        SoftArm {
            sections,
            d_arc,
            twist_cs,
            lower,
            upper,
        }
    }

    /// The blackberry-harvesting arm of the redundancy paper, with the dimensions the
    /// paper leaves open filled in as assumptions:
    /// actuator radii 28, 22, 18 mm (proximal → distal; the paper only says the spacing
    /// grows towards the base), rest length 0.15 m (the 15 cm silicone core of II-A),
    /// elongation limits 0 to 0.0333 m (0–70 psi at 1/2100 m per psi, IV-A), plate
    /// offsets 12 mm, a gripper offset of 60 mm after the distal section, and the 60°
    /// twist between neighbouring sections of II-A.
    pub fn blackberry() -> Self {
        let upper = 70.0 / 2100.0;
        let twist = std::f64::consts::FRAC_PI_3;
        let sections = vec![
            Section {
                radius: 0.028,
                rest_length: 0.15,
                lower: 0.0,
                upper,
                offset: 0.012,
                twist,
            },
            Section {
                radius: 0.022,
                rest_length: 0.15,
                lower: 0.0,
                upper,
                offset: 0.012,
                twist,
            },
            Section {
                radius: 0.018,
                rest_length: 0.15,
                lower: 0.0,
                upper,
                offset: 0.060,
                twist: 0.0,
            },
        ];
        SoftArm::from_sections(sections)
    }

    /// The sections, proximal first.
    pub fn sections(&self) -> &[Section] {
        &self.sections
    }

    /// Number of actuators (3 per section).
    pub fn n_actuators(&self) -> usize {
        self.n_dofs()
    }

    /// Arc parameters (smooth form) of every section at `q`.
    ///
    /// # Errors
    /// As [`chain::check_q`].
    pub fn arc_params(&self, q: &[f64]) -> Result<Vec<ArcParams>> {
        chain::check_q(self, q)?;
        Ok(self
            .sections
            .iter()
            .enumerate()
            .map(|(i, _)| self.arc(i, &q[3 * i..3 * i + 3]))
            .collect())
    }

    /// Eq. (1) per section: (arc length, bending angle, bending direction).
    ///
    /// # Errors
    /// As [`chain::check_q`].
    pub fn polar_configs(&self, q: &[f64]) -> Result<Vec<PolarConfig>> {
        chain::check_q(self, q)?;
        Ok(self
            .sections
            .iter()
            .enumerate()
            .map(|(i, s)| polar_config(s.radius, s.rest_length, &q[3 * i..3 * i + 3]))
            .collect())
    }

    /// Eq. (1) for section `i` in its linear form `(L − L0, ux, uy) = ∂(L, ux, uy)/∂l · l`
    /// (see [`crate::pneumatic`]): the cached constant Jacobian multiplies where
    /// [`crate::pneumatic::arc_params`] divides, which matters in the kinematics' hot loop.
    #[inline]
    fn arc(&self, i: usize, qi: &[f64]) -> ArcParams {
        let u = self.d_arc[i] * Vec3::new(qi[0], qi[1], qi[2]);
        ArcParams {
            length: self.sections[i].rest_length + u.x,
            ux: u.y,
            uy: u.z,
        }
    }

    /// Clamps `q` into the limits in place; returns whether anything was clamped.
    ///
    /// # Errors
    /// [`Error::Shape`] for a wrong length.
    pub fn clamp(&self, q: &mut [f64]) -> Result<bool> {
        check_len("q", q, self.n_dofs())?;
        let mut clamped = false;
        for ((v, lo), hi) in q.iter_mut().zip(&self.lower).zip(&self.upper) {
            let c = v.clamp(*lo, *hi);
            clamped |= c != *v;
            *v = c;
        }
        Ok(clamped)
    }
}

impl SectionModel for SoftArm {
    fn n_sections(&self) -> usize {
        self.sections.len()
    }

    #[inline(always)]
    fn section_state(&self, i: usize, qi: &[f64]) -> SectionState {
        let s = &self.sections[i];
        SectionState {
            arc: self.arc(i, qi),
            d_arc: self.d_arc[i],
            offset: s.offset,
            twist: self.twist_cs[i],
            d_twist: Vec3::zeros(),
        }
    }
}

impl Kinematics for SoftArm {
    fn lower(&self) -> &[f64] {
        &self.lower
    }
    fn upper(&self) -> &[f64] {
        &self.upper
    }
    /// [`crate::Body::for_arm`] with the gripper ending at the end-effector frame (a grasp
    /// offset of 0).
    fn default_body(&self) -> crate::Body {
        // Every valid arm has a body: its radii and offsets are far below the body's bounds.
        crate::Body::for_arm(self, 0.0).unwrap_or_else(|_| crate::Body::bare(self.sections().len()))
    }
}
