//! Obstacles of every kind, and the closest pair between an arm and one obstacle.

use super::arc_cloud::PointCloud;
use super::arc_curve::{closest_arc_curve, closest_arc_curve_within, ArcCurveHit};
use super::arc_mesh::TriangleMesh;
use super::arc_point::PlacedArc;
use super::polynomial::{PolynomialCurve, Segment};
use crate::chain::{check_q_arcs, section_arc_unchecked};
use crate::error::{Error, Result, MAX_POSITION};
use crate::kinematics::Kinematics;
use crate::math::Vec3;

/// An obstacle: a curve (eq. 10), a segment, a point, a point cloud or a triangle mesh.
#[derive(Debug, Clone)]
pub enum Obstacle {
    /// A parametric polynomial curve.
    Curve(PolynomialCurve),
    /// A line segment.
    Segment(Segment),
    /// A single point.
    Point(Vec3),
    /// A point cloud (parry BVH).
    Cloud(PointCloud),
    /// A triangle mesh (parry TriMesh, chord approximation of the arc).
    Mesh(TriangleMesh),
}

/// The one check of obstacle geometry, used by every obstacle form (points, clouds,
/// segments, mesh vertices; curves check their bounding sphere the same way): every
/// coordinate finite and within [`MAX_POSITION`] of the origin. Errors index the flattened
/// (N, 3) array.
///
/// # Errors
/// [`Error::NonFinite`] for NaN or infinity, [`Error::OutOfRange`] for a coordinate beyond
/// [`MAX_POSITION`].
pub fn check_points(arg: &str, points: &[Vec3]) -> Result<()> {
    for (i, p) in points.iter().enumerate() {
        for (j, &v) in p.iter().enumerate() {
            if !v.is_finite() {
                return Err(Error::NonFinite {
                    arg: arg.to_owned(),
                    index: 3 * i + j,
                    value: v,
                });
            }
            if v.abs() > MAX_POSITION {
                return Err(Error::OutOfRange {
                    arg: format!("{arg}[{}]", 3 * i + j),
                    value: v,
                    min: -MAX_POSITION,
                    max: MAX_POSITION,
                });
            }
        }
    }
    Ok(())
}

impl Obstacle {
    /// A point obstacle, checked by [`check_points`].
    ///
    /// # Errors
    /// As [`check_points`].
    pub fn point(p: Vec3) -> Result<Self> {
        check_points("point", &[p])?;
        Ok(Obstacle::Point(p))
    }

    /// Checks the obstacle; every query entry point calls it. Curves, segments, clouds and
    /// meshes are checked when built (their fields are private, so they stay valid); a
    /// point is a public variant and is checked here, by the same [`check_points`].
    ///
    /// # Errors
    /// As [`check_points`], naming `arg`.
    pub fn validate(&self, arg: &str) -> Result<()> {
        match self {
            Obstacle::Point(p) => check_points(arg, &[*p]),
            _ => Ok(()),
        }
    }
}

/// [`Obstacle::validate`] on every obstacle, naming `obstacles[k]`.
///
/// # Errors
/// As [`check_points`].
pub fn check_obstacles(obstacles: &[Obstacle]) -> Result<()> {
    for (k, ob) in obstacles.iter().enumerate() {
        ob.validate(&format!("obstacles[{k}]"))?;
    }
    Ok(())
}

impl From<PolynomialCurve> for Obstacle {
    fn from(c: PolynomialCurve) -> Self {
        Obstacle::Curve(c)
    }
}
impl From<Segment> for Obstacle {
    fn from(s: Segment) -> Self {
        Obstacle::Segment(s)
    }
}
impl From<PointCloud> for Obstacle {
    fn from(c: PointCloud) -> Self {
        Obstacle::Cloud(c)
    }
}
impl From<TriangleMesh> for Obstacle {
    fn from(m: TriangleMesh) -> Self {
        Obstacle::Mesh(m)
    }
}

/// The closest pair between an arm and an obstacle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Closest {
    /// Distance (m); 0 when they touch or cross. For a mesh, a conservative lower bound
    /// (see [`super::arc_mesh`]).
    pub distance: f64,
    /// Section holding the arm point (0 = proximal).
    pub section: usize,
    /// Fraction along that section.
    pub s: f64,
    /// Obstacle parameter: `u` of a curve, the fraction along a segment, the index of a
    /// cloud's point or of a mesh's triangle, 0 for a point.
    pub u: f64,
    /// Closest arm point (base frame).
    pub arm_point: Vec3,
    /// Closest obstacle point (base frame).
    pub obstacle_point: Vec3,
}

impl Closest {
    /// The pair of the arm point `arm_point` (fraction `s` of section `section`) and the
    /// obstacle point `obstacle_point` (parameter `u`, see [`Closest::u`]), `distance`
    /// apart.
    #[inline]
    pub fn new(
        section: usize,
        s: f64,
        arm_point: Vec3,
        u: f64,
        obstacle_point: Vec3,
        distance: f64,
    ) -> Self {
        Closest {
            distance,
            section,
            s,
            u,
            arm_point,
            obstacle_point,
        }
    }

    /// No pair: infinitely far (what a search over no arc returns).
    pub fn none() -> Self {
        Closest::new(0, 0.0, Vec3::zeros(), 0.0, Vec3::zeros(), f64::INFINITY)
    }

    /// An arc ↔ curve (or segment) pair on section `section`.
    #[inline]
    pub fn from_curve_hit(section: usize, h: &ArcCurveHit) -> Self {
        Closest::new(section, h.s, h.arc_point, h.u, h.curve_point, h.distance)
    }

    /// The arc point `s` of `arc` (section `section`) and the cloud's point `index`,
    /// `distance` apart.
    #[inline]
    fn cloud_point(
        section: usize,
        arc: &PlacedArc,
        s: f64,
        cloud: &PointCloud,
        index: usize,
        distance: f64,
    ) -> Self {
        Closest::new(
            section,
            s,
            arc.point(s),
            index as f64,
            cloud.points()[index],
            distance,
        )
    }

    /// The same pair, credited to section `section`.
    #[inline]
    pub fn in_section(self, section: usize) -> Self {
        Closest { section, ..self }
    }
}

/// Every section's arc at configuration `q` (which must already be checked).
pub fn placed_arcs<K: Kinematics + ?Sized>(model: &K, q: &[f64]) -> Vec<PlacedArc> {
    (0..model.n_sections())
        .map(|i| {
            let (frame, params) = section_arc_unchecked(model, q, i);
            PlacedArc::new(frame, params)
        })
        .collect()
}

/// Closest pair between one arc (section `section`) and `obstacle`.
pub fn closest_to_arc(arc: &PlacedArc, section: usize, obstacle: &Obstacle) -> Closest {
    match obstacle {
        Obstacle::Curve(c) => Closest::from_curve_hit(section, &closest_arc_curve(arc, c)),
        Obstacle::Segment(seg) => {
            Closest::from_curve_hit(section, &closest_arc_curve(arc, seg.as_curve()))
        }
        Obstacle::Point(p) => {
            let (s, a, d) = arc.closest_to_point(p);
            Closest::new(section, s, a, 0.0, *p, d)
        }
        Obstacle::Cloud(cloud) => {
            let (d, s, i) = cloud
                .closest_to_arc(arc, f64::MAX)
                .unwrap_or_else(|| cloud.closest_to_arc_brute_force(arc));
            Closest::cloud_point(section, arc, s, cloud, i, d)
        }
        Obstacle::Mesh(mesh) => {
            let h = mesh.closest_to_arc(arc);
            Closest::new(
                section,
                h.s,
                h.arc_point,
                h.triangle as f64,
                h.mesh_point,
                h.distance,
            )
        }
    }
}

/// Closest pair between all `arcs` and `obstacle`. For a cloud, later sections reuse the
/// best distance so far to prune the hierarchy.
pub fn closest_to_arcs(arcs: &[PlacedArc], obstacle: &Obstacle) -> Closest {
    let mut best: Option<Closest> = None;
    for (i, arc) in arcs.iter().enumerate() {
        let hit = match (obstacle, &best) {
            (Obstacle::Cloud(cloud), Some(b)) => match cloud.closest_to_arc(arc, b.distance) {
                Some((d, s, k)) => Closest::cloud_point(i, arc, s, cloud, k, d),
                None => continue,
            },
            _ => closest_to_arc(arc, i, obstacle),
        };
        if best.is_none_or(|b| hit.distance < b.distance) {
            best = Some(hit);
        }
    }
    best.unwrap_or_else(Closest::none)
}

/// [`closest_to_arcs`] when the distance is below `cutoff`, else `None`. Exact; curves and
/// segments skip far arcs by bounding spheres and prune against the best so far.
pub fn closest_to_arcs_within(
    arcs: &[PlacedArc],
    obstacle: &Obstacle,
    cutoff: f64,
) -> Option<Closest> {
    let curve = match obstacle {
        Obstacle::Curve(c) => c,
        Obstacle::Segment(s) => s.as_curve(),
        Obstacle::Cloud(cloud) => {
            // The hierarchy prunes against the cutoff, then against the best so far.
            let mut best: Option<Closest> = None;
            let mut limit = cutoff;
            for (i, arc) in arcs.iter().enumerate() {
                if let Some((d, s, k)) = cloud.closest_to_arc(arc, limit) {
                    limit = d;
                    best = Some(Closest::cloud_point(i, arc, s, cloud, k, d));
                }
            }
            return best;
        }
        _ => {
            let c = closest_to_arcs(arcs, obstacle);
            return (c.distance < cutoff).then_some(c);
        }
    };
    let mut best: Option<Closest> = None;
    let mut limit = cutoff;
    for (i, arc) in arcs.iter().enumerate() {
        if let Some(h) = closest_arc_curve_within(arc, curve, limit) {
            limit = h.distance;
            best = Some(Closest::from_curve_hit(i, &h));
        }
    }
    best
}

/// The closest pair between the arm `model` at configuration `q` and `obstacle`, over
/// every section (planning paper eq. 12–18: the global minimum over sections, `s` and `u`).
///
/// # Errors
/// [`crate::Error::Shape`] / [`crate::Error::NonFinite`] / [`crate::Error::OutOfRange`] for a
/// bad `q`, [`crate::Error::Parameter`] for a `q` that gives a section a non-positive arc
/// length, and as [`Obstacle::validate`] for a bad obstacle.
///
/// # Example
/// ```
/// use softarm_core::{ArcChain, distance::{closest, Obstacle, Segment}, Vec3};
/// let chain = ArcChain::new(&[1.0, 1.0, 1.0]).unwrap();
/// let q = chain.straight();
/// let seg = Segment::new(Vec3::new(0.5, -1.0, 1.5), Vec3::new(0.5, 1.0, 1.5)).unwrap();
/// let c = closest(&chain, &q, &Obstacle::Segment(seg)).unwrap();
/// assert!((c.distance - 0.5).abs() < 1e-12 && c.section == 1);
/// ```
pub fn closest<K: Kinematics + ?Sized>(
    model: &K,
    q: &[f64],
    obstacle: &Obstacle,
) -> Result<Closest> {
    check_q_arcs(model, q)?;
    obstacle.validate("obstacle")?;
    Ok(closest_to_arcs(&placed_arcs(model, q), obstacle))
}
