//! The three simulations of the planning paper (tables 1–4): an arc chain of three
//! segments of length 1, a goal, and curve obstacles given by their equations.

use crate::distance::{Obstacle, PointCloud, PolynomialCurve};
use crate::error::Result;
use crate::math::Vec3;

/// One simulation of the paper.
#[derive(Debug, Clone)]
pub struct Scenario {
    /// "line", "curve" or "tree".
    pub name: &'static str,
    /// Tip goal.
    pub goal: Vec3,
    /// Curve obstacles (eq. 10).
    pub curves: Vec<PolynomialCurve>,
}

/// Static segment lengths of the simulated arm (table 1).
pub const SEGMENT_LENGTHS: [f64; 3] = [1.0; 3];

/// Points per segment of the discretised arm in the point baseline (table 1).
pub const ARM_POINTS_PER_SEGMENT: usize = 10;

/// Names of the scenarios, in the paper's order.
pub const NAMES: [&str; 3] = ["line", "curve", "tree"];

fn curve(c: &[[f64; 3]], u: (f64, f64)) -> Result<PolynomialCurve> {
    let v: Vec<Vec3> = c.iter().map(|r| Vec3::new(r[0], r[1], r[2])).collect();
    PolynomialCurve::new(&v, u)
}

/// The scenario called `name` ("line": table 2, "curve": table 3, "tree": table 4).
///
/// # Errors
/// [`crate::Error::Parameter`] for an unknown name.
pub fn scenario(name: &str) -> Result<Scenario> {
    // Coefficient rows are [x, y, z] of u^0, u^1, u^2.
    match name {
        // X = 1, Y = u, Z = 0.5 − u, −2 < u < 2.
        "line" => Ok(Scenario {
            name: "line",
            goal: Vec3::new(1.1, -0.8, 0.9),
            curves: vec![curve(&[[1.0, 0.0, 0.5], [0.0, 1.0, -1.0]], (-2.0, 2.0))?],
        }),
        // X = 0.5, Y = u, Z = 5u², −2 < u < 2.
        "curve" => Ok(Scenario {
            name: "curve",
            goal: Vec3::new(1.0, 1.0, 1.0),
            curves: vec![curve(
                &[[0.5, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 5.0]],
                (-2.0, 2.0),
            )?],
        }),
        "tree" => Ok(Scenario {
            name: "tree",
            goal: Vec3::new(1.0, 0.7, 1.45),
            curves: vec![
                // 1 − 0.2u, 1 − u, 2 − u², 0–1
                curve(
                    &[[1.0, 1.0, 2.0], [-0.2, -1.0, 0.0], [0.0, 0.0, -1.0]],
                    (0.0, 1.0),
                )?,
                // 1 − 0.5u, 1 + u − u², 1.7 + 0.3u, 0–1.5
                curve(
                    &[[1.0, 1.0, 1.7], [-0.5, 1.0, 0.3], [0.0, -1.0, 0.0]],
                    (0.0, 1.5),
                )?,
                // 1, 1 − u, 2 − 0.1u, 0–1.5
                curve(&[[1.0, 1.0, 2.0], [0.0, -1.0, -0.1]], (0.0, 1.5))?,
                // 1 + u − u², 1 − u, 1.7, 0–1
                curve(
                    &[[1.0, 1.0, 1.7], [1.0, -1.0, 0.0], [-1.0, 0.0, 0.0]],
                    (0.0, 1.0),
                )?,
                // 1, 1 − u, 1.5 + 0.1u, 0–1.5
                curve(&[[1.0, 1.0, 1.5], [0.0, -1.0, 0.1]], (0.0, 1.5))?,
                // 1, 1, u − u², 0–3
                curve(
                    &[[1.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, -1.0]],
                    (0.0, 3.0),
                )?,
            ],
        }),
        _ => Err(crate::error::Error::parameter(
            "scenario",
            f64::NAN,
            format!("unknown scenario {name:?}; expected one of {NAMES:?}"),
        )),
    }
}

impl Scenario {
    /// The obstacles of the proposed method: the curves themselves.
    pub fn curve_obstacles(&self) -> Vec<Obstacle> {
        self.curves.iter().cloned().map(Obstacle::Curve).collect()
    }

    /// The baseline's obstacles: each curve as `n` points evenly spaced in `u` (one point:
    /// the middle of the range).
    ///
    /// # Errors
    /// [`crate::Error::Shape`] for `n = 0`.
    pub fn point_obstacles(&self, n: usize) -> Result<Vec<Obstacle>> {
        self.curves
            .iter()
            .map(|c| c.sample(n).and_then(PointCloud::new).map(Obstacle::Cloud))
            .collect()
    }
}
