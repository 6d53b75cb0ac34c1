//! The kinematic methods every arm model offers, checked and allocating.

use nalgebra::{DMatrix, Matrix3xX};

use crate::body::Body;
use crate::chain::{self, SectionModel};
use crate::error::Result;
use crate::math::{Mat4, Vec3};

/// The kinematic methods shared by [`SoftArm`] and [`crate::ArcChain`].
pub trait Kinematics: SectionModel {
    /// Lower limit of every coordinate.
    fn lower(&self) -> &[f64];
    /// Upper limit of every coordinate.
    fn upper(&self) -> &[f64];

    /// The body a [`crate::Resolver`] on this model measures unless it is given another
    /// ([`crate::Resolver::with_body`]): the bare backbone ([`Body::bare`]) unless the
    /// model declares its radii ([`SoftArm`]: [`Body::for_arm`] with the gripper ending
    /// at the end-effector frame).
    fn default_body(&self) -> Body {
        Body::bare(self.n_sections())
    }

    /// End-effector pose (4×4) in the base frame.
    ///
    /// # Errors
    /// [`Error::Shape`] / [`Error::NonFinite`] for a bad `q`.
    fn forward(&self, q: &[f64]) -> Result<Mat4> {
        chain::forward(self, q)
    }
    /// 6×n Jacobian, rows [vx, vy, vz, wx, wy, wz] in the base frame.
    ///
    /// # Errors
    /// As [`Kinematics::forward`].
    fn jacobian(&self, q: &[f64]) -> Result<DMatrix<f64>> {
        chain::jacobian(self, q)
    }
    /// Pose and Jacobian in one pass.
    ///
    /// # Errors
    /// As [`Kinematics::forward`].
    fn forward_jacobian(&self, q: &[f64]) -> Result<(Mat4, DMatrix<f64>)> {
        chain::forward_jacobian(self, q)
    }
    /// Backbone point at fraction `s ∈ [0, 1]` of `section` and its 3×n Jacobian.
    ///
    /// # Errors
    /// As [`Kinematics::forward`], plus [`Error::OutOfRange`] for `section` or `s`.
    fn point(&self, q: &[f64], section: usize, s: f64) -> Result<(Vec3, Matrix3xX<f64>)> {
        chain::point(self, q, section, s)
    }
    /// Base frame of every section, then the end effector.
    ///
    /// # Errors
    /// As [`Kinematics::forward`].
    fn frames(&self, q: &[f64]) -> Result<Vec<Mat4>> {
        chain::frames(self, q)
    }
    /// `samples` points per section along the backbone (both ends included).
    ///
    /// # Errors
    /// As [`Kinematics::forward`], plus [`Error::OutOfRange`] for `samples` outside
    /// [2, [`crate::error::MAX_SAMPLES`]].
    fn backbone(&self, q: &[f64], samples: usize) -> Result<Vec<Vec3>> {
        chain::backbone(self, q, samples)
    }
}
