//! Point clouds on parry3d's bounding-volume hierarchy, and their closest point to an arc.
//!
//! The query is a best-first descent of the [`Bvh`] (`Bvh::find_best`). A box is skipped
//! when a lower bound of its distance to the arc is no better than the best point found:
//! every point of the box lies within its half-diagonal `r` of the centre `c`, and the
//! distance to the arc is 1-Lipschitz, so `dist(p, arc) ≥ dist(c, arc) − r`, with
//! `dist(c, arc)` closed form. Leaves are single points, measured exactly; the result is
//! exact (no chord approximation is needed for points).

use parry3d_f64::bounding_volume::Aabb;
use parry3d_f64::math::Vector as PVec;
use parry3d_f64::partitioning::{Bvh, BvhBuildStrategy};

use super::arc_point::PlacedArc;
use crate::error::{Error, Result};
use crate::math::Vec3;

/// A set of obstacle points with a bounding-volume hierarchy over them.
#[derive(Clone)]
pub struct PointCloud {
    points: Vec<Vec3>,
    bvh: Bvh,
}

impl std::fmt::Debug for PointCloud {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PointCloud")
            .field("len", &self.points.len())
            .finish()
    }
}

#[inline]
pub(crate) fn to_parry(v: &Vec3) -> PVec {
    PVec::new(v.x, v.y, v.z)
}

#[inline]
pub(crate) fn from_parry(v: PVec) -> Vec3 {
    Vec3::new(v.x, v.y, v.z)
}

impl PointCloud {
    /// A cloud of `points`.
    ///
    /// # Errors
    /// [`Error::Shape`] for an empty cloud, otherwise as
    /// [`super::obstacle::check_points`].
    pub fn new(points: Vec<Vec3>) -> Result<Self> {
        if points.is_empty() {
            return Err(Error::shape("points", "at least one point", "none"));
        }
        super::obstacle::check_points("points", &points)?;
        let leaves: Vec<Aabb> = points
            .iter()
            .map(|p| {
                let q = to_parry(p);
                Aabb::new(q, q)
            })
            .collect();
        let bvh = Bvh::from_leaves(BvhBuildStrategy::Binned, &leaves);
        Ok(PointCloud { points, bvh })
    }

    /// The points.
    pub fn points(&self) -> &[Vec3] {
        &self.points
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// Always false: a cloud has at least one point.
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// Closest point of the cloud to `arc`, if closer than `max_dist`:
    /// `(distance, s, point index)`. Best-first search of the hierarchy.
    pub fn closest_to_arc(&self, arc: &PlacedArc, max_dist: f64) -> Option<(f64, f64, usize)> {
        let aabb_cost = |node: &parry3d_f64::partitioning::BvhNode, _best: f64| {
            let c = from_parry(node.center());
            let r = from_parry(node.aabb().half_extents()).norm();
            arc.closest_to_point(&c).2 - r
        };
        let leaf_cost = |leaf: u32, _best: f64| {
            let p = self.points.get(leaf as usize)?;
            let (s, _, d) = arc.closest_to_point(p);
            Some((d, s))
        };
        self.bvh
            .find_best(max_dist, aabb_cost, leaf_cost)
            .map(|(i, (d, s))| (d, s, i as usize))
    }

    /// The same answer by brute force over every point (the paper's baseline).
    pub fn closest_to_arc_brute_force(&self, arc: &PlacedArc) -> (f64, f64, usize) {
        let mut best = (f64::INFINITY, 0.0, 0);
        for (i, p) in self.points.iter().enumerate() {
            let (s, _, d) = arc.closest_to_point(p);
            if d < best.0 {
                best = (d, s, i);
            }
        }
        best
    }

    /// Closest cloud point to `x` by brute force: `(distance, index)`.
    pub fn closest_to_point_brute_force(&self, x: &Vec3) -> (f64, usize) {
        let mut best = (f64::INFINITY, 0);
        for (i, p) in self.points.iter().enumerate() {
            let d2 = (p - x).norm_squared();
            if d2 < best.0 {
                best = (d2, i);
            }
        }
        (best.0.sqrt(), best.1)
    }
}
