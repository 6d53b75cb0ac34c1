//! # softarm-core
//!
//! Kinematics, Jacobians, redundancy resolution and distance queries for constant-
//! curvature continuum arms, as specified by two papers:
//!
//! - *Design, Modeling, and Redundancy Resolution of a soft arm for blackberry
//!   harvesting* (the "redundancy paper"): actuator-space kinematics eq. (1)–(6);
//! - *Efficient Path Planning of Soft Robotic Arms in the Presence of Obstacles* (the
//!   "planning paper"): configuration-space arc chains eq. (1)–(6).
//!
//! Conventions: SI units; poses are 4×4 homogeneous matrices; Jacobian rows are
//! [vx, vy, vz, wx, wy, wz] in the base frame; sections are numbered from 0 (proximal).
//! Every public function validates its input and returns [`Result`]; nothing reachable
//! from user input panics.
//!
//! # Example
//! ```
//! use softarm_core::{Kinematics, SoftArm};
//! let arm = SoftArm::blackberry();
//! let q = [0.0; 9];
//! let pose = arm.forward(&q).unwrap();
//! // Straight arm: 3 × 0.15 m arcs, 2 × 12 mm plates and a 60 mm gripper offset.
//! assert!((pose[(2, 3)] - 0.534).abs() < 1e-12);
//! ```
#![warn(missing_docs)]

pub mod arc;
pub mod arc_chain;
pub mod body;
pub mod chain;
pub mod distance;
pub mod error;
pub mod kinematics;
pub mod math;
pub mod planner;
pub mod pneumatic;
pub mod soft_arm;

pub use arc::ArcParams;
pub use arc_chain::ArcChain;
pub use body::{Body, BodyGap, Part, ACTUATOR_RADIUS, CANE_RADIUS, GRIPPER_RADIUS};
pub use distance::{
    closest, Closest, Obstacle, PointCloud, PolynomialCurve, Segment, TriangleMesh,
};
pub use error::{Error, Result};
pub use kinematics::Kinematics;
pub use math::{Frame, Mat3, Mat4, Vec3};
pub use planner::{Plan, PlannerOptions, PotentialFieldPlanner, Termination};
pub use soft_arm::{Section, SoftArm};
pub mod resolver;
pub use resolver::{Gains, Mode, Resolver, Schedule, Solution, SolveOptions, Target};
